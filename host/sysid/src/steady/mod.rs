//! Trim points from a flight: the steady stretches of a board's log ([`segments`]) with
//! the velocities of a GNSS/compass unit ([`gnss`]), written as a trim-point file with
//! each point's standard error ([`steady_trim_points_csv`]).

pub mod gnss;
pub mod segments;

pub use gnss::{gnss_csv, parse_gnss_csv, GnssError, GnssFix, GNSS_COLUMNS};
pub use segments::{find_steady_segments, SteadinessRule, SteadySegment, STEADINESS_RULE};

use crate::fit::trim::{CONTROL_COLUMNS, STATE_COLUMNS};

/// The trim-point CSV of `segments` (docs/formats.md, "Trim points CSV"): the label, the
/// twelve columns, then each column's standard error (`u_se` … `col_se`) and the ticks of
/// the segment's first and last Sample (`first_tick`, `last_tick`). `fit --trim-points`
/// reads the file and ignores the extra columns.
pub fn steady_trim_points_csv(segments: &[SteadySegment]) -> String {
    let columns: Vec<&str> = STATE_COLUMNS
        .iter()
        .chain(&CONTROL_COLUMNS)
        .copied()
        .collect();
    let mut out = String::from("label");
    for name in &columns {
        out.push(',');
        out.push_str(name);
    }
    for name in &columns {
        out.push_str(&format!(",{name}_se"));
    }
    out.push_str(",first_tick,last_tick\n");
    for segment in segments {
        out.push_str(&segment.point.label.replace(',', ";"));
        let point = &segment.point;
        for value in point
            .states
            .iter()
            .chain(&point.controls)
            .chain(&segment.standard_error)
        {
            out.push_str(&format!(",{:?}", value + 0.0));
        }
        out.push_str(&format!(",{},{}\n", segment.ticks[0], segment.ticks[1]));
    }
    out
}

#[cfg(test)]
mod tests;
