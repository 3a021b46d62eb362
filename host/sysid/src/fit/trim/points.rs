//! Trim points: the steady flights a fit derives its hover derivatives from, read from
//! their CSV file ([`TrimPoints`]) and checked for plausibility.

use serde::{Deserialize, Serialize};

use super::error::TrimError;

/// The state columns of a trim-point file, in their order in [`TrimPoint::states`]:
/// body velocities [m/s], body rates [rad/s], attitude \[rad\].
pub const STATE_COLUMNS: [&str; 8] = ["u", "v", "w", "p", "q", "r", "phi", "theta"];
/// The stick columns, in their order in [`TrimPoint::controls`] (fractions of travel).
pub const CONTROL_COLUMNS: [&str; 4] = ["lat", "lon", "ped", "col"];

/// Plausible trim points, checked when a file is read, before any work: the largest
/// magnitude of each column group, with its unit. Beyond these no helicopter flies
/// steadily (the fastest reach ~110 m/s; a steady bank or pitch past 90° is no trim; a
/// pirouette of 3 turns a second is 19 rad/s), and a stick cannot pass full travel.
pub const PLAUSIBLE_RANGES: [(&str, &[&str], f64, &str); 4] = [
    ("a speed", &["u", "v", "w"], 150.0, "m/s"),
    ("a rate", &["p", "q", "r"], 20.0, "rad/s"),
    (
        "an angle",
        &["phi", "theta"],
        std::f64::consts::FRAC_PI_2,
        "rad",
    ),
    ("a stick", &["lat", "lon", "ped", "col"], 1.0, "of travel"),
];

/// One steady flight condition.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrimPoint {
    /// Free text (`hover`, `forward`, …); may be empty.
    pub label: String,
    /// u v w [m/s], p q r [rad/s], φ θ \[rad\] ([`STATE_COLUMNS`]).
    pub states: [f64; 8],
    /// lat lon ped col stick fractions ([`CONTROL_COLUMNS`]).
    pub controls: [f64; 4],
}

/// A set of trim points (one CSV file).
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct TrimPoints {
    /// The points, in file order.
    pub points: Vec<TrimPoint>,
}

impl TrimPoints {
    /// Parse the CSV form: a header naming the columns (`label` optional, then every one
    /// of [`STATE_COLUMNS`] and [`CONTROL_COLUMNS`], in any order, and optionally the
    /// annotations `identify --gnss` writes, which are not read), one point per line;
    /// blank lines and lines starting with `#` are skipped. Every number must be finite.
    pub fn parse_csv(text: &str) -> Result<TrimPoints, TrimError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, line)| (i + 1, line.trim()))
            .filter(|(_, line)| !line.is_empty() && !line.starts_with('#'));
        let Some((header_line, header)) = lines.next() else {
            return Err(TrimError::Csv {
                line: 1,
                reason: "no header line".into(),
            });
        };
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let column = |name: &str| names.iter().position(|n| *n == name);
        for name in &names {
            if *name != "label"
                && !STATE_COLUMNS.contains(name)
                && !CONTROL_COLUMNS.contains(name)
                && !is_annotation(name)
            {
                return Err(TrimError::Csv {
                    line: header_line,
                    reason: format!("unknown column `{name}`"),
                });
            }
            if names.iter().filter(|n| *n == name).count() > 1 {
                return Err(TrimError::Csv {
                    line: header_line,
                    reason: format!("column `{name}` appears twice"),
                });
            }
        }
        let find = |name: &str| {
            column(name).ok_or_else(|| TrimError::Csv {
                line: header_line,
                reason: format!("missing column `{name}`"),
            })
        };
        let state_at = STATE_COLUMNS.map(find);
        let control_at = CONTROL_COLUMNS.map(find);
        let mut state_index = [0; 8];
        for (slot, found) in state_index.iter_mut().zip(state_at) {
            *slot = found?;
        }
        let mut control_index = [0; 4];
        for (slot, found) in control_index.iter_mut().zip(control_at) {
            *slot = found?;
        }
        let label_index = column("label");
        let mut points = Vec::new();
        let mut seen: std::collections::HashMap<Vec<u64>, usize> = std::collections::HashMap::new();
        for (line, text) in lines {
            let cells: Vec<&str> = text.split(',').map(str::trim).collect();
            if cells.len() != names.len() {
                return Err(TrimError::Csv {
                    line,
                    reason: format!("{} fields, the header has {}", cells.len(), names.len()),
                });
            }
            let number = |index: usize| -> Result<f64, TrimError> {
                let cell = cells[index];
                match cell.parse::<f64>() {
                    Ok(value) if value.is_finite() => Ok(value),
                    _ => Err(TrimError::Csv {
                        line,
                        reason: format!("`{}` is not a finite number: `{cell}`", names[index]),
                    }),
                }
            };
            let mut states = [0.0; 8];
            for (value, &index) in states.iter_mut().zip(&state_index) {
                *value = number(index)?;
            }
            let mut controls = [0.0; 4];
            for (value, &index) in controls.iter_mut().zip(&control_index) {
                *value = number(index)?;
            }
            check_plausible(line, &states, &controls)?;
            let point = TrimPoint {
                label: label_index.map_or_else(String::new, |i| cells[i].to_string()),
                states,
                controls,
            };
            // Keyed by the numbers' bits (+ 0.0 makes −0 a 0): linear in the points.
            let key: Vec<u64> = states
                .iter()
                .chain(&controls)
                .map(|v| (v + 0.0).to_bits())
                .collect();
            if let Some(first) = seen.insert(key, line) {
                return Err(TrimError::Csv {
                    line,
                    reason: format!(
                        "the same flight as line {first} (every state and stick equal): a \
                         duplicate adds no gradient"
                    ),
                });
            }
            points.push(point);
        }
        if points.len() < 2 {
            return Err(TrimError::TooFewPoints(points.len()));
        }
        Ok(TrimPoints { points })
    }

    /// The CSV form [`Self::parse_csv`] reads (a `label` column first, numbers in
    /// shortest round-trip form).
    pub fn to_csv(&self) -> String {
        let mut out = String::from("label");
        for name in STATE_COLUMNS.iter().chain(&CONTROL_COLUMNS) {
            out.push(',');
            out.push_str(name);
        }
        out.push('\n');
        for point in &self.points {
            out.push_str(&point.label.replace(',', ";"));
            for value in point.states.iter().chain(&point.controls) {
                out.push(',');
                // + 0.0 writes a negative zero as 0.0.
                out.push_str(&format!("{:?}", value + 0.0));
            }
            out.push('\n');
        }
        out
    }
}

/// Columns a trim-point file may carry beside the point (`identify --gnss` writes them,
/// the fit reads past them): a column's standard error (`u_se` … `col_se`) and the ticks
/// of the log's stretch the point was averaged over (`first_tick`, `last_tick`).
fn is_annotation(name: &str) -> bool {
    name == "first_tick"
        || name == "last_tick"
        || name.strip_suffix("_se").is_some_and(|column| {
            STATE_COLUMNS.contains(&column) || CONTROL_COLUMNS.contains(&column)
        })
}

/// Refuse a point outside [`PLAUSIBLE_RANGES`], naming the column, its value and the range.
fn check_plausible(line: usize, states: &[f64; 8], controls: &[f64; 4]) -> Result<(), TrimError> {
    let columns = STATE_COLUMNS
        .iter()
        .zip(states)
        .chain(CONTROL_COLUMNS.iter().zip(controls));
    for (name, &value) in columns {
        let (what, _, limit, unit) = PLAUSIBLE_RANGES
            .iter()
            .find(|(_, names, _, _)| names.contains(name))
            .expect("every column has a range");
        if value.abs() > *limit {
            // 1e30 as 1e30, not 31 digits.
            let value = if value.abs() >= 1e6 {
                format!("{value:e}")
            } else {
                value.to_string()
            };
            return Err(TrimError::Csv {
                line,
                reason: format!(
                    "`{name}` = {value} is not a plausible trim point: {what} lies within \
                     ±{limit:.4} {unit}"
                ),
            });
        }
    }
    Ok(())
}

/// Index of a trim-point state column for a structure state name, if the points give it.
pub(super) fn measured_column(state: &str) -> Option<usize> {
    STATE_COLUMNS.iter().position(|c| *c == state)
}
