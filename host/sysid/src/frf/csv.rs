//! Records from CSV files, so data logged by other systems can be analysed too.
//!
//! The file has one header row naming the columns, then one row per sample, fields
//! separated by commas (surrounding spaces and double quotes around a field are
//! ignored; quoted fields may not contain commas). Which columns are time, inputs and
//! outputs is given by [`CsvColumns`]. The time column must be uniformly sampled (each
//! step within 25 % of the mean step); it sets the sample rate.
//!
//! A CSV written by `sweephold decode` holds every phase of a test; when the file has a
//! column named by [`CsvColumns::phase_column`] (default `phase`), only rows whose phase
//! is `fade_in`, `sweep` or `fade_out` are kept, as for dumps.

use std::path::Path;

use super::records::{remove_line, rms, Channel, Record};
use super::FrfError;

/// Which CSV columns to read.
#[derive(Clone, Debug, PartialEq)]
pub struct CsvColumns {
    /// Time column \[s\].
    pub time: String,
    /// Inputs as (channel name, column name).
    pub inputs: Vec<(String, String)>,
    /// Outputs as (channel name, column name).
    pub outputs: Vec<(String, String)>,
    /// The swept input (a channel name); `None`: the input with the largest RMS about
    /// its trend line.
    pub primary: Option<String>,
    /// Phase column used to keep only excitation rows, when the file has it.
    pub phase_column: Option<String>,
    /// Sweep band [rad/s], if known.
    pub sweep_band: Option<[f64; 2]>,
}

impl Default for CsvColumns {
    /// The columns of `sweephold decode` CSV output.
    fn default() -> Self {
        let same = |names: &[&str]| {
            names
                .iter()
                .map(|n| (n.to_string(), n.to_string()))
                .collect()
        };
        CsvColumns {
            time: "time_s".into(),
            inputs: vec![
                ("lat".into(), "cmd_lat".into()),
                ("lon".into(), "cmd_lon".into()),
                ("ped".into(), "cmd_ped".into()),
                ("col".into(), "cmd_col".into()),
            ],
            outputs: same(&[
                "u", "v", "w", "p", "q", "r", "ax", "ay", "az", "phi", "theta",
            ]),
            primary: None,
            phase_column: Some("phase".into()),
            sweep_band: None,
        }
    }
}

/// Phases kept when the file has a phase column.
const EXCITATION_PHASES: [&str; 3] = ["fade_in", "sweep", "fade_out"];

fn field(raw: &str) -> &str {
    raw.trim().trim_matches('"').trim()
}

/// Load a record from a CSV file.
pub fn load_csv(path: impl AsRef<Path>, columns: &CsvColumns) -> Result<Record, FrfError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| FrfError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_csv(&text, &path.display().to_string(), columns)
}

/// Parse CSV text; `source` names it in messages.
pub fn parse_csv(text: &str, source: &str, columns: &CsvColumns) -> Result<Record, FrfError> {
    let error = |line: usize, message: String| FrfError::Csv {
        path: source.into(),
        line,
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or_else(|| error(0, "empty file".into()))?;
    let names: Vec<&str> = header.split(',').map(field).collect();
    let find = |column: &str| {
        names.iter().position(|n| *n == column).ok_or_else(|| {
            error(
                1,
                format!("no column `{column}` (columns: {})", names.join(", ")),
            )
        })
    };
    let time_index = find(&columns.time)?;
    let input_index = columns
        .inputs
        .iter()
        .map(|(_, c)| find(c))
        .collect::<Result<Vec<_>, _>>()?;
    let output_index = columns
        .outputs
        .iter()
        .map(|(_, c)| find(c))
        .collect::<Result<Vec<_>, _>>()?;
    if input_index.is_empty() || output_index.is_empty() {
        return Err(error(
            0,
            "need at least one input and one output column".into(),
        ));
    }
    let phase_index = columns
        .phase_column
        .as_deref()
        .and_then(|c| names.iter().position(|n| *n == c));

    let mut time = Vec::new();
    let mut inputs = vec![Vec::new(); input_index.len()];
    let mut outputs = vec![Vec::new(); output_index.len()];
    for (number, line) in lines {
        let line_number = number + 1;
        let fields: Vec<&str> = line.split(',').map(field).collect();
        if fields.len() != names.len() {
            return Err(error(
                line_number,
                format!("{} fields, the header has {}", fields.len(), names.len()),
            ));
        }
        if let Some(p) = phase_index {
            if !EXCITATION_PHASES.contains(&fields[p]) {
                continue;
            }
        }
        let number = |index: usize| {
            fields[index]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    error(
                        line_number,
                        format!(
                            "`{}` in column `{}` is not a finite number",
                            fields[index], names[index]
                        ),
                    )
                })
        };
        time.push(number(time_index)?);
        for (values, &index) in inputs.iter_mut().zip(&input_index) {
            values.push(number(index)?);
        }
        for (values, &index) in outputs.iter_mut().zip(&output_index) {
            values.push(number(index)?);
        }
    }
    if time.len() < 2 {
        return Err(error(
            0,
            if phase_index.is_some() {
                "fewer than two rows in the fade-in, sweep or fade-out phases: no sweep".into()
            } else {
                "fewer than two data rows".into()
            },
        ));
    }
    let span = time[time.len() - 1] - time[0];
    let step = span / (time.len() - 1) as f64;
    if step.is_nan() || step <= 0.0 {
        return Err(error(
            0,
            format!("time column `{}` does not increase", columns.time),
        ));
    }
    if let Some(i) = time
        .windows(2)
        .position(|t| ((t[1] - t[0]) - step).abs() > 0.25 * step)
    {
        return Err(error(
            0,
            format!(
                "time column `{}` is not uniformly sampled: step {} s at row {} (mean {step} s)",
                columns.time,
                time[i + 1] - time[i],
                i + 2
            ),
        ));
    }

    let mut notes = Vec::new();
    let primary = match &columns.primary {
        Some(name) => name.clone(),
        None => {
            // The most active input about its trend line.
            let activity = |values: &Vec<f64>| {
                let mut v = values.clone();
                remove_line(&mut v);
                rms(&v)
            };
            let best = inputs
                .iter()
                .enumerate()
                .max_by(|a, b| activity(a.1).total_cmp(&activity(b.1)))
                .map_or(0, |(i, _)| i);
            let name = columns.inputs[best].0.clone();
            notes.push(format!(
                "{source}: swept input taken to be `{name}` (the most active)"
            ));
            name
        }
    };
    let record = Record {
        source: source.into(),
        sample_rate_hz: 1.0 / step,
        primary,
        sweep_band: columns.sweep_band,
        inputs: columns
            .inputs
            .iter()
            .zip(inputs)
            .map(|((name, _), values)| Channel::new(name.clone(), values))
            .collect(),
        outputs: columns
            .outputs
            .iter()
            .zip(outputs)
            .map(|((name, _), values)| Channel::new(name.clone(), values))
            .collect(),
        references: Vec::new(),
        notes,
    };
    record.validate()?;
    Ok(record)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn columns() -> CsvColumns {
        CsvColumns {
            time: "t".into(),
            inputs: vec![
                ("lat".into(), "d_lat".into()),
                ("lon".into(), "d_lon".into()),
            ],
            outputs: vec![("p".into(), "p".into())],
            primary: None,
            phase_column: Some("phase".into()),
            sweep_band: Some([1.0, 10.0]),
        }
    }

    #[test]
    fn reads_named_columns_and_picks_the_swept_input() {
        let mut text = String::from("t, d_lat ,\"d_lon\",p,extra\n");
        for k in 0..50 {
            let t = k as f64 * 0.02;
            text += &format!("{t},{},{},{},x\n", (3.0 * t).sin(), 0.001 * t, 2.0 * t);
        }
        let record = parse_csv(&text, "log.csv", &columns()).unwrap();
        assert_eq!(record.len(), 50);
        assert!((record.sample_rate_hz - 50.0).abs() < 1e-9);
        assert_eq!(record.primary, "lat");
        assert_eq!(record.input("lon").unwrap()[10], 0.001 * 0.2);
        assert_eq!(record.notes.len(), 1);
    }

    #[test]
    fn keeps_only_excitation_rows_when_there_is_a_phase_column() {
        let mut text = String::from("t,phase,d_lat,d_lon,p\n");
        for k in 0..30 {
            let phase = ["idle", "fade_in", "sweep", "fade_out", "done"][k / 6];
            text += &format!("{},{phase},{k},0,1\n", k as f64 * 0.1);
        }
        let record = parse_csv(&text, "d.csv", &columns()).unwrap();
        assert_eq!(record.len(), 18);
        assert_eq!(record.input("lat").unwrap()[0], 6.0);
    }

    #[test]
    fn clear_errors() {
        let err = parse_csv("t,d_lat,p\n0,1,2\n", "a.csv", &columns()).unwrap_err();
        assert!(err.to_string().contains("no column `d_lon`"), "{err}");
        let err = parse_csv(
            "t,d_lat,d_lon,p\n0,1,2,3\n0.1,1,nan,3\n",
            "b.csv",
            &columns(),
        )
        .unwrap_err();
        assert!(err.to_string().starts_with("b.csv:3:"), "{err}");
        let err = parse_csv(
            "t,d_lat,d_lon,p\n0,1,2,3\n0.1,1,2,3\n0.5,1,2,3\n",
            "c.csv",
            &columns(),
        )
        .unwrap_err();
        assert!(err.to_string().contains("not uniformly sampled"), "{err}");
        let err = parse_csv("", "e.csv", &columns()).unwrap_err();
        assert!(err.to_string().contains("empty"), "{err}");
    }
}
