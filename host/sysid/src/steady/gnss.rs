//! A GNSS/compass unit's velocity and heading on the log's clock (`gnss.csv`, layout in
//! docs/formats.md, "GNSS CSV"): what gives a steady flight its body velocities.
//!
//! Hand-written: the file is five numeric columns, and every error must name its line
//! and column in one sentence (the `csv` crate would add a dependency for the split on
//! commas alone).

/// The columns of `gnss.csv`, in this order.
pub const GNSS_COLUMNS: [&str; 5] = ["tick", "vn", "ve", "vd", "heading"];

/// Plausible speed of a fix \[m/s\] (any aircraft that can hover stays far below).
const MAX_SPEED_M_S: f64 = 150.0;

/// One fix: the board tick it belongs to, the velocity over the ground and the heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssFix {
    /// The board's control tick the fix is stamped with (the `tick` of the log's Samples).
    pub tick: u32,
    /// Velocity north, east, down [m/s].
    pub velocity_ned: [f64; 3],
    /// Heading ψ \[rad\], in (−π, π].
    pub heading: f64,
}

/// What is wrong with a GNSS file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("line {line}: {reason}")]
pub struct GnssError {
    /// Line of the problem (1-based).
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

/// Parse `gnss.csv`: the header `tick,vn,ve,vd,heading` (exactly these, in this order),
/// then one fix per line with strictly increasing ticks; blank lines and lines starting
/// with `#` are skipped. At least one fix.
pub fn parse_gnss_csv(text: &str) -> Result<Vec<GnssFix>, GnssError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, line)| (i + 1, line.trim()))
        .filter(|(_, line)| !line.is_empty() && !line.starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(GnssError {
            line: 1,
            reason: "no header line".into(),
        });
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    if names != GNSS_COLUMNS {
        return Err(GnssError {
            line: header_line,
            reason: format!(
                "the header must be `{}`, not `{header}`",
                GNSS_COLUMNS.join(",")
            ),
        });
    }
    let mut fixes: Vec<GnssFix> = Vec::new();
    for (line, text) in lines {
        let cells: Vec<&str> = text.split(',').map(str::trim).collect();
        if cells.len() != GNSS_COLUMNS.len() {
            return Err(GnssError {
                line,
                reason: format!(
                    "{} fields, the header has {}",
                    cells.len(),
                    GNSS_COLUMNS.len()
                ),
            });
        }
        let tick: u32 = cells[0].parse().map_err(|_| GnssError {
            line,
            reason: format!("`tick` is not a tick count: `{}`", cells[0]),
        })?;
        let mut numbers = [0.0; 4];
        for (k, value) in numbers.iter_mut().enumerate() {
            let cell = cells[k + 1];
            *value = match cell.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                _ => {
                    return Err(GnssError {
                        line,
                        reason: format!(
                            "`{}` is not a finite number: `{cell}`",
                            GNSS_COLUMNS[k + 1]
                        ),
                    })
                }
            };
        }
        let [vn, ve, vd, heading] = numbers;
        let speed = vn.hypot(ve).hypot(vd);
        if speed > MAX_SPEED_M_S {
            return Err(GnssError {
                line,
                reason: format!(
                    "a speed of {speed:.1} m/s is not plausible (at most {MAX_SPEED_M_S} m/s)"
                ),
            });
        }
        if heading.abs() > std::f64::consts::PI + 1e-9 {
            return Err(GnssError {
                line,
                reason: format!("`heading` = {heading} lies outside ±π rad"),
            });
        }
        if let Some(last) = fixes.last() {
            if tick <= last.tick {
                return Err(GnssError {
                    line,
                    reason: format!("tick {tick} is not after the previous fix's {}", last.tick),
                });
            }
        }
        fixes.push(GnssFix {
            tick,
            velocity_ned: [vn, ve, vd],
            heading,
        });
    }
    if fixes.is_empty() {
        return Err(GnssError {
            line: header_line,
            reason: "no fix after the header".into(),
        });
    }
    Ok(fixes)
}

/// The CSV form [`parse_gnss_csv`] reads (numbers in shortest round-trip form).
pub fn gnss_csv(fixes: &[GnssFix]) -> String {
    let mut out = GNSS_COLUMNS.join(",");
    out.push('\n');
    for fix in fixes {
        let [vn, ve, vd] = fix.velocity_ned;
        out.push_str(&format!(
            "{},{:?},{:?},{:?},{:?}\n",
            fix.tick,
            vn + 0.0,
            ve + 0.0,
            vd + 0.0,
            fix.heading + 0.0
        ));
    }
    out
}
