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
//!
//! **Which input was swept**, in order of precedence: [`CsvColumns::primary`] (`frf
//! --swept`); else the file's [`CsvColumns::primary_column`] (default `primary`, which
//! `sweephold decode` writes on every row), whose value must be the same on every kept
//! row; else the input with the largest RMS about its trend line, and the record is
//! marked [`Record::primary_guessed`].

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
    /// The swept input (a channel name, `frf --swept`); it overrides the file's primary
    /// column. `None`: the primary column names it, else the input with the largest RMS
    /// about its trend line does.
    pub primary: Option<String>,
    /// Column naming the swept axis on each row, read when the file has it and `primary`
    /// is `None`. Its value must be the same on every kept row and name an input, by its
    /// channel name or by the decode command column it is read from (`lat` names the
    /// input read from `cmd_lat`, whatever that input is called).
    pub primary_column: Option<String>,
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
            primary_column: Some(PRIMARY_COLUMN.into()),
            phase_column: Some("phase".into()),
            sweep_band: None,
        }
    }
}

/// The column `sweephold decode` writes the swept axis into.
pub const PRIMARY_COLUMN: &str = "primary";

/// Phases kept when the file has a phase column.
const EXCITATION_PHASES: [&str; 3] = ["fade_in", "sweep", "fade_out"];

fn field(raw: &str) -> &str {
    raw.trim().trim_matches('"').trim()
}

/// Load a record from a CSV file.
pub fn load_csv(path: impl AsRef<Path>, columns: &CsvColumns) -> Result<Record, FrfError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|error| FrfError::Io {
        path: path.to_path_buf(),
        error,
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
    let input_names = || {
        columns
            .inputs
            .iter()
            .map(|(name, _)| name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(name) = &columns.primary {
        if !columns.inputs.iter().any(|(n, _)| n == name) {
            return Err(error(
                0,
                format!(
                    "swept input `{name}` is not among the inputs ({})",
                    input_names()
                ),
            ));
        }
    }
    // The primary column, read only when no swept input was named.
    let primary_column = columns
        .primary
        .is_none()
        .then_some(columns.primary_column.as_deref())
        .flatten()
        .and_then(|c| names.iter().position(|n| *n == c).map(|i| (c, i)));
    // Its value and the first and last kept lines that carried it.
    let mut named_axis: Option<(String, usize, usize)> = None;

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
        if let Some((column, index)) = primary_column {
            let value = fields[index];
            match &mut named_axis {
                None if value.is_empty() => {
                    return Err(error(line_number, format!("column `{column}` is empty")));
                }
                None => named_axis = Some((value.to_string(), line_number, line_number)),
                Some((axis, _, last)) if axis == value => *last = line_number,
                Some((axis, first, last)) => {
                    let kept = if phase_index.is_some() {
                        " (rows in the fade-in, sweep and fade-out phases)"
                    } else {
                        ""
                    };
                    return Err(error(
                        line_number,
                        format!(
                            "column `{column}` names `{value}` here but `{axis}` on lines {first}–{last}: one swept axis per file{kept}; split the file or name the swept input (--swept)"
                        ),
                    ));
                }
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
    // Several records in one file (e.g. `decode a.bin b.bin -o x.csv`: its time restarts
    // with each dump) are one record per file here.
    if let Some(i) = time.windows(2).position(|t| t[1] <= t[0]) {
        return Err(error(
            0,
            format!(
                "time column `{}` steps back at kept row {} ({} s → {} s): a CSV file holds \
                 one record here; decode each dump to its own file",
                columns.time,
                i + 1,
                time[i],
                time[i + 1]
            ),
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
    let named = match (&columns.primary, &named_axis, primary_column) {
        (Some(name), _, _) => Some(name.clone()),
        (None, Some((axis, _, _)), Some((column, _))) => {
            // By channel name, or by the decode command column (`cmd_lat` for `lat`).
            let command_column = format!("cmd_{axis}");
            let input = columns
                .inputs
                .iter()
                .find(|(name, _)| name == axis)
                .or_else(|| columns.inputs.iter().find(|(_, c)| *c == command_column))
                .map(|(name, _)| name.clone());
            Some(input.ok_or_else(|| {
                error(
                    0,
                    format!(
                        "column `{column}` names `{axis}`, which is not among the inputs ({}); name the swept input (--swept)",
                        input_names()
                    ),
                )
            })?)
        }
        _ => None,
    };
    let primary_guessed = named.is_none();
    let primary = match named {
        Some(name) => name,
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
        primary_guessed,
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
        trim_samples: 0,
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
            primary_column: Some(PRIMARY_COLUMN.into()),
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
        assert!(record.primary_guessed);
        assert_eq!(record.input("lon").unwrap()[10], 0.001 * 0.2);
        assert_eq!(record.notes.len(), 1);
    }

    /// A lateral sweep as `decode` lays it out: idle rows, then excitation rows whose
    /// `primary` is `lat`, while the longitudinal stick moves more than the lateral one.
    fn decoded_lateral_sweep(primary_of_row: impl Fn(usize) -> &'static str) -> String {
        let mut text = String::from("t,phase,primary,cmd_lat,cmd_lon,p\n");
        for k in 0..60 {
            let t = k as f64 * 0.02;
            let phase = if k < 10 { "idle" } else { "sweep" };
            let (lat, lon) = (0.01 * (3.0 * t).sin(), 0.2 * (1.3 * t).cos());
            text += &format!("{t},{phase},{},{lat},{lon},{}\n", primary_of_row(k), lat);
        }
        text
    }

    fn decode_columns() -> CsvColumns {
        CsvColumns {
            inputs: vec![
                ("lat".into(), "cmd_lat".into()),
                ("lon".into(), "cmd_lon".into()),
            ],
            ..columns()
        }
    }

    #[test]
    fn the_swept_axis_comes_from_the_option_then_the_primary_column_then_activity() {
        let text = decoded_lateral_sweep(|_| "lat");
        // The primary column names `lat`, though `lon` is the most active.
        let record = parse_csv(&text, "d.csv", &decode_columns()).unwrap();
        assert_eq!(record.primary, "lat");
        assert!(!record.primary_guessed && record.notes.is_empty());
        // Without the column the most active input is taken.
        let no_column = CsvColumns {
            primary_column: None,
            ..decode_columns()
        };
        let record = parse_csv(&text, "d.csv", &no_column).unwrap();
        assert_eq!(record.primary, "lon");
        assert!(record.primary_guessed);
        // A named swept input overrides the column.
        let named = CsvColumns {
            primary: Some("lon".into()),
            ..decode_columns()
        };
        let record = parse_csv(&text, "d.csv", &named).unwrap();
        assert_eq!(
            (record.primary.as_str(), record.primary_guessed),
            ("lon", false)
        );
        // Inputs renamed: the column's `lat` still finds the input read from `cmd_lat`.
        let renamed = CsvColumns {
            inputs: vec![
                ("roll".into(), "cmd_lat".into()),
                ("pitch".into(), "cmd_lon".into()),
            ],
            ..decode_columns()
        };
        assert_eq!(parse_csv(&text, "d.csv", &renamed).unwrap().primary, "roll");
        // Idle rows may name another axis: only the kept rows must agree.
        let idle_other = decoded_lateral_sweep(|k| if k < 10 { "ped" } else { "lat" });
        assert_eq!(
            parse_csv(&idle_other, "d.csv", &decode_columns())
                .unwrap()
                .primary,
            "lat"
        );
    }

    #[test]
    fn a_primary_column_that_changes_or_names_no_input_is_refused() {
        let text = decoded_lateral_sweep(|k| if k < 40 { "lat" } else { "lon" });
        let err = parse_csv(&text, "d.csv", &decode_columns()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "d.csv:42: column `primary` names `lon` here but `lat` on lines 12–41: one swept axis per file (rows in the fade-in, sweep and fade-out phases); split the file or name the swept input (--swept)"
        );
        // Naming the swept input sets the column aside.
        let named = CsvColumns {
            primary: Some("lat".into()),
            ..decode_columns()
        };
        assert_eq!(parse_csv(&text, "d.csv", &named).unwrap().primary, "lat");
        let text = decoded_lateral_sweep(|_| "col");
        let err = parse_csv(&text, "d.csv", &decode_columns()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "d.csv: column `primary` names `col`, which is not among the inputs (lat, lon); name the swept input (--swept)"
        );
        let unknown = CsvColumns {
            primary: Some("ped".into()),
            ..decode_columns()
        };
        let err = parse_csv(&text, "d.csv", &unknown).unwrap_err();
        assert_eq!(
            err.to_string(),
            "d.csv: swept input `ped` is not among the inputs (lat, lon)"
        );
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
