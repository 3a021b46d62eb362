//! Records from CSV files, so data logged by other systems can be analysed too.
//!
//! One row per sample, fields separated by commas (surrounding spaces and double quotes
//! around a field are ignored; quoted fields may not contain commas). The first row
//! names the columns, unless every field of it is a number (or empty): then the file has
//! no header and its columns are named by position. Which columns are time, inputs, outputs and
//! references is given by [`CsvColumns`]; a column is given by its header name or by
//! its position, 1 for the first (a header name that is itself a number wins).
//!
//! **Units** ([`units`]): the time column in s, ms or µs ([`CsvColumns::time_unit`];
//! not given, a median step above 0.5 is read as ms, above 500 as µs, with a note);
//! channels in rad/s, deg/s, rad or deg ([`CsvColumns::units`], converted to SI); a
//! body-rate channel without a unit that peaks above 15 gets a note that it looks like
//! deg/s.
//!
//! **Rows**: [`CsvColumns::window_s`] keeps only the rows whose time (in seconds) lies
//! in it. A row with an empty or non-finite field (`nan`, `inf`) in a column read is
//! left out, as a missing sample; a field that is not a number is an error naming its
//! line. Then the samples are put on a uniform grid ([`timing`]): uniform timestamps
//! (within 5 % of a step) are used as they are; jitter is resampled by linear
//! interpolation; gaps of up to 5 missing samples are filled; a longer gap splits the
//! file into several records of the same swept axis ([`parse_csv_records`]), joined as
//! records are. Each of these is said in a note. Time that steps back is refused.
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

pub mod columns;
pub mod timing;
pub mod units;

use std::path::Path;

use super::error::RecordError;
use super::record::{remove_line, rms, Channel, Record};
pub use columns::{CsvColumns, PRIMARY_COLUMN};
use timing::{median, uniform_samples};
use units::{deg_per_s_note, detected_time_unit, TimeUnit};

/// Phases kept when the file has a phase column.
const EXCITATION_PHASES: [&str; 3] = ["fade_in", "sweep", "fade_out"];

fn field(raw: &str) -> &str {
    raw.trim().trim_matches('"').trim()
}

fn read(path: &Path) -> Result<String, RecordError> {
    std::fs::read_to_string(path).map_err(|error| RecordError::Io {
        path: path.to_path_buf(),
        error,
    })
}

/// Load a record from a CSV file; a file that long gaps split into several records is
/// refused (read it with [`load_csv_records`]).
pub fn load_csv(path: impl AsRef<Path>, columns: &CsvColumns) -> Result<Record, RecordError> {
    let path = path.as_ref();
    parse_csv(&read(path)?, &path.display().to_string(), columns)
}

/// Load the records of a CSV file: one, or several when long gaps split it.
pub fn load_csv_records(
    path: impl AsRef<Path>,
    columns: &CsvColumns,
) -> Result<Vec<Record>, RecordError> {
    let path = path.as_ref();
    parse_csv_records(&read(path)?, &path.display().to_string(), columns)
}

/// Parse CSV text into one record; `source` names it in messages. A file that long gaps
/// split into several records is refused (read it with [`parse_csv_records`]).
pub fn parse_csv(text: &str, source: &str, columns: &CsvColumns) -> Result<Record, RecordError> {
    let mut records = parse_csv_records(text, source, columns)?;
    if records.len() > 1 {
        return Err(RecordError::Csv {
            path: source.into(),
            line: 0,
            message: format!(
                "gaps split this file into {} records; read it as several (parse_csv_records)",
                records.len()
            ),
        });
    }
    Ok(records.remove(0))
}

/// The rows read: times and channel values (inputs, outputs, references, in the order
/// of [`CsvColumns`]), and the rows left out for a missing value.
struct Rows {
    times: Vec<f64>,
    channels: Vec<Vec<f64>>,
    /// (line, time if it was read) of each row left out for an empty or non-finite field.
    missing: Vec<(usize, Option<f64>)>,
    /// The primary column's value and the first and last kept lines that carried it.
    named_axis: Option<(String, usize, usize)>,
    /// The primary column's name, when read.
    primary_column: Option<String>,
    /// Whether the file has a phase column.
    phased: bool,
}

/// Parse CSV text into records (one, or several when long gaps split it); `source`
/// names the file in messages.
pub fn parse_csv_records(
    text: &str,
    source: &str,
    columns: &CsvColumns,
) -> Result<Vec<Record>, RecordError> {
    let error = |line: usize, message: String| RecordError::Csv {
        path: source.into(),
        line,
        message,
    };
    let mut rows = read_rows(text, source, columns)?;
    let fewer_than_two = |rows: &Rows| {
        let missing = if rows.missing.is_empty() {
            String::new()
        } else {
            format!(
                " ({} row(s) with an empty or non-finite field left out)",
                rows.missing.len()
            )
        };
        error(
            0,
            if rows.phased {
                format!("fewer than two rows in the fade-in, sweep or fade-out phases: no sweep{missing}")
            } else {
                format!("fewer than two data rows{missing}")
            },
        )
    };
    if rows.times.len() < 2 {
        return Err(fewer_than_two(&rows));
    }
    let mut notes = Vec::new();

    // Time in seconds.
    let steps: Vec<f64> = rows.times.windows(2).map(|t| t[1] - t[0]).collect();
    let time_unit = match columns.time_unit {
        Some(unit) => unit,
        None => {
            let step = median(&steps);
            let unit = detected_time_unit(step);
            if unit != TimeUnit::Seconds {
                notes.push(format!(
                    "{source}: time column `{}` read in {}: its median step, {step}, would be a rate below 2 Hz in seconds (give its unit: --units time=s|ms|us)",
                    columns.time,
                    unit.symbol()
                ));
            }
            unit
        }
    };
    if time_unit != TimeUnit::Seconds {
        let factor = time_unit.to_seconds();
        rows.times.iter_mut().for_each(|t| *t *= factor);
        for (_, t) in &mut rows.missing {
            if let Some(t) = t {
                *t *= factor;
            }
        }
    }

    if let Some([t0, t1]) = columns.window_s {
        let inside = |t: f64| (t0..=t1).contains(&t);
        let (first, last) = (rows.times[0], rows.times[rows.times.len() - 1]);
        let keep: Vec<bool> = rows.times.iter().map(|&t| inside(t)).collect();
        let filter = |values: &mut Vec<f64>| {
            let mut k = keep.iter();
            values.retain(|_| *k.next().unwrap());
        };
        filter(&mut rows.times);
        rows.channels.iter_mut().for_each(filter);
        rows.missing.retain(|(_, t)| t.is_none_or(inside));
        if rows.times.len() < 2 {
            return Err(error(
                0,
                format!(
                    "window {t0}–{t1} s keeps {} row(s): the time column runs {first}–{last} s",
                    rows.times.len()
                ),
            ));
        }
    }

    let times = &rows.times;
    let span = times[times.len() - 1] - times[0];
    if span.is_nan() || span <= 0.0 {
        return Err(error(
            0,
            format!("time column `{}` does not increase", columns.time),
        ));
    }
    // Several records in one file (e.g. `decode a.bin b.bin -o x.csv`: its time restarts
    // with each dump) are one record per file here.
    if let Some(i) = times.windows(2).position(|t| t[1] <= t[0]) {
        return Err(error(
            0,
            format!(
                "time column `{}` steps back at kept row {} ({} s → {} s): a CSV file holds \
                 one record here; decode each dump to its own file",
                columns.time,
                i + 1,
                times[i],
                times[i + 1]
            ),
        ));
    }
    if !rows.missing.is_empty() {
        let lines: Vec<String> = rows
            .missing
            .iter()
            .take(5)
            .map(|(line, _)| line.to_string())
            .collect();
        let more = if rows.missing.len() > 5 { ", …" } else { "" };
        notes.push(format!(
            "{source}: {} row(s) with an empty or non-finite field left out as missing samples (line(s) {}{more})",
            rows.missing.len(),
            lines.join(", ")
        ));
    }

    // Channels in SI units.
    let channel_names: Vec<&str> = columns
        .inputs
        .iter()
        .chain(&columns.outputs)
        .chain(&columns.references)
        .map(|(name, _)| name.as_str())
        .collect();
    for (name, values) in channel_names.iter().zip(&mut rows.channels) {
        match columns.units.iter().find(|(n, _)| n == name) {
            Some((_, unit)) if unit.to_si() != 1.0 => {
                values.iter_mut().for_each(|v| *v *= unit.to_si());
            }
            Some(_) => {}
            None => notes.extend(deg_per_s_note(source, name, values)),
        }
    }

    let primary = swept_input(&rows, source, columns, &mut notes)?;
    let primary_guessed = primary.1;
    let (times, channels) = (rows.times, rows.channels);
    let uniform = uniform_samples(&times, channels).map_err(|message| error(0, message))?;
    notes.extend(uniform.notes.iter().map(|n| format!("{source}: {n}")));

    let count = uniform.parts.len();
    let (n_in, n_out) = (columns.inputs.len(), columns.outputs.len());
    let named = |list: &[(String, String)], values: &[Vec<f64>]| -> Vec<Channel> {
        list.iter()
            .zip(values)
            .map(|((name, _), v)| Channel::new(name.clone(), v.clone()))
            .collect()
    };
    let mut records = Vec::with_capacity(count);
    for (k, part) in uniform.parts.iter().enumerate() {
        let record = Record {
            source: if count == 1 {
                source.into()
            } else {
                format!(
                    "{source} (part {} of {count}, from {:.3} s)",
                    k + 1,
                    part.start_s
                )
            },
            sample_rate_hz: 1.0 / uniform.step_s,
            primary: primary.0.clone(),
            primary_guessed,
            sweep_band: columns.sweep_band,
            inputs: named(&columns.inputs, &part.channels[..n_in]),
            outputs: named(&columns.outputs, &part.channels[n_in..n_in + n_out]),
            references: named(&columns.references, &part.channels[n_in + n_out..]),
            // The file's notes once, with its first record.
            notes: if k == 0 {
                std::mem::take(&mut notes)
            } else {
                Vec::new()
            },
            trim_samples: 0,
            measurement_filter: None,
        };
        record.validate()?;
        records.push(record);
    }
    Ok(records)
}

/// The columns found in the first line: its header names, or `None` when every field
/// of it is a number or empty (no header: a first data row with a missing value), and
/// how many fields it has.
fn header(first: &str) -> (Option<Vec<&str>>, usize) {
    let fields: Vec<&str> = first.split(',').map(field).collect();
    let width = fields.len();
    let numbers = fields
        .iter()
        .all(|f| f.is_empty() || f.parse::<f64>().is_ok());
    ((!numbers).then_some(fields), width)
}

/// Read the rows of `text`: the kept rows' times and channel values.
fn read_rows<'a>(text: &str, source: &str, columns: &'a CsvColumns) -> Result<Rows, RecordError> {
    let error = |line: usize, message: String| RecordError::Csv {
        path: source.into(),
        line,
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .peekable();
    let &(_, first) = lines.peek().ok_or_else(|| error(0, "empty file".into()))?;
    let (names, width) = header(first);
    if names.is_some() {
        lines.next();
    }
    let find = |column: &str| -> Result<usize, RecordError> {
        if let Some(i) = names
            .as_ref()
            .and_then(|n| n.iter().position(|n| *n == column))
        {
            return Ok(i);
        }
        match column.parse::<usize>() {
            Ok(position) if (1..=width).contains(&position) => Ok(position - 1),
            _ => Err(error(
                1,
                match &names {
                    Some(names) => format!("no column `{column}` (columns: {})", names.join(", ")),
                    None => format!(
                        "no column `{column}`: the file has no header row (its first row is all numbers); give columns by position, 1–{width} (e.g. --time 1 --inputs NAME=2 --outputs NAME=3)"
                    ),
                },
            )),
        }
    };
    let column_name = |index: usize| match &names {
        Some(names) => names[index].to_string(),
        None => (index + 1).to_string(),
    };
    let time_index = find(&columns.time)?;
    let channel_index = columns
        .inputs
        .iter()
        .chain(&columns.outputs)
        .chain(&columns.references)
        .map(|(_, c)| find(c))
        .collect::<Result<Vec<_>, _>>()?;
    if columns.inputs.is_empty() || columns.outputs.is_empty() {
        return Err(error(
            0,
            "need at least one input and one output column".into(),
        ));
    }
    for (name, _) in &columns.references {
        if !columns.inputs.iter().any(|(n, _)| n == name) {
            return Err(error(
                0,
                format!(
                    "reference `{name}` is not named after an input ({})",
                    input_names(columns)
                ),
            ));
        }
    }
    for (name, _) in &columns.units {
        if !columns
            .inputs
            .iter()
            .chain(&columns.outputs)
            .any(|(n, _)| n == name)
        {
            let outputs: Vec<&str> = columns.outputs.iter().map(|(n, _)| n.as_str()).collect();
            return Err(error(
                0,
                format!(
                    "unit given for `{name}`, which is neither an input ({}) nor an output ({})",
                    input_names(columns),
                    outputs.join(", ")
                ),
            ));
        }
    }
    if let Some(name) = &columns.primary {
        if !columns.inputs.iter().any(|(n, _)| n == name) {
            return Err(error(
                0,
                format!(
                    "swept input `{name}` is not among the inputs ({})",
                    input_names(columns)
                ),
            ));
        }
    }
    // Phase and primary columns are found by header name only.
    let by_name = |column: Option<&'a str>| -> Option<(&'a str, usize)> {
        column.and_then(|c| {
            names
                .as_ref()
                .and_then(|n| n.iter().position(|n| *n == c))
                .map(|i| (c, i))
        })
    };
    let phase_index = by_name(columns.phase_column.as_deref()).map(|(_, i)| i);
    // The primary column, read only when no swept input was named.
    let primary_column = if columns.primary.is_none() {
        by_name(columns.primary_column.as_deref())
    } else {
        None
    };

    let mut rows = Rows {
        times: Vec::new(),
        channels: vec![Vec::new(); channel_index.len()],
        missing: Vec::new(),
        named_axis: None,
        primary_column: primary_column.map(|(c, _)| c.to_string()),
        phased: phase_index.is_some(),
    };
    for (number, line) in lines {
        let line_number = number + 1;
        let fields: Vec<&str> = line.split(',').map(field).collect();
        if fields.len() != width {
            let first = if names.is_some() {
                "the header"
            } else {
                "the first row"
            };
            return Err(error(
                line_number,
                format!("{} fields, {first} has {width}", fields.len()),
            ));
        }
        if let Some(p) = phase_index {
            if !EXCITATION_PHASES.contains(&fields[p]) {
                continue;
            }
        }
        if let Some((column, index)) = primary_column {
            let value = fields[index];
            match &mut rows.named_axis {
                None if value.is_empty() => {
                    return Err(error(line_number, format!("column `{column}` is empty")));
                }
                None => rows.named_axis = Some((value.to_string(), line_number, line_number)),
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
        // An empty or non-finite field is a missing sample; anything else must be a number.
        let number = |index: usize| -> Result<Option<f64>, RecordError> {
            let text = fields[index];
            if text.is_empty() {
                return Ok(None);
            }
            text.parse::<f64>()
                .map(|v| v.is_finite().then_some(v))
                .map_err(|_| {
                    error(
                        line_number,
                        format!(
                            "`{text}` in column `{}` is not a number (write a missing value as an empty field or nan)",
                            column_name(index)
                        ),
                    )
                })
        };
        let time = number(time_index)?;
        let values = channel_index
            .iter()
            .map(|&i| number(i))
            .collect::<Result<Vec<_>, _>>()?;
        match (time, values.iter().all(Option::is_some)) {
            (Some(t), true) => {
                rows.times.push(t);
                for (channel, value) in rows.channels.iter_mut().zip(values) {
                    channel.push(value.unwrap_or_default());
                }
            }
            _ => rows.missing.push((line_number, time)),
        }
    }
    Ok(rows)
}

/// The swept input's name and whether it was only guessed (module docs).
fn swept_input(
    rows: &Rows,
    source: &str,
    columns: &CsvColumns,
    notes: &mut Vec<String>,
) -> Result<(String, bool), RecordError> {
    let named = match (&columns.primary, &rows.named_axis, &rows.primary_column) {
        (Some(name), _, _) => Some(name.clone()),
        (None, Some((axis, _, _)), Some(column)) => {
            // By channel name, or by the decode command column (`cmd_lat` for `lat`).
            let command_column = format!("cmd_{axis}");
            let input = columns
                .inputs
                .iter()
                .find(|(name, _)| name == axis)
                .or_else(|| columns.inputs.iter().find(|(_, c)| *c == command_column))
                .map(|(name, _)| name.clone());
            Some(input.ok_or_else(|| RecordError::Csv {
                path: source.into(),
                line: 0,
                message: format!(
                    "column `{column}` names `{axis}`, which is not among the inputs ({}); name the swept input (--swept)",
                    input_names(columns)
                ),
            })?)
        }
        _ => None,
    };
    if let Some(name) = named {
        return Ok((name, false));
    }
    // The most active input about its trend line.
    let activity = |values: &Vec<f64>| {
        let mut v = values.clone();
        remove_line(&mut v);
        rms(&v)
    };
    let best = rows.channels[..columns.inputs.len()]
        .iter()
        .enumerate()
        .max_by(|a, b| activity(a.1).total_cmp(&activity(b.1)))
        .map_or(0, |(i, _)| i);
    let name = columns.inputs[best].0.clone();
    notes.push(format!(
        "{source}: swept input taken to be `{name}` (the most active)"
    ));
    Ok((name, true))
}

/// The input columns' names, comma-separated (for the messages that name them).
fn input_names(columns: &CsvColumns) -> String {
    columns
        .inputs
        .iter()
        .map(|(name, _)| name.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests;
