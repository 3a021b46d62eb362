//! The text of modes on the console and in the report: the mode table `sweephold fit`
//! prints, and the one-line summaries of the hover modes and the poles at the origin.
//! The library returns the data (`sysid::fit::modes`); its text is here.

use std::fmt::Write as _;

use sysid::fit::modes::{
    eigenvalue_text, HoverModeScore, ModeRecord, HOVER_MODE_TOLERANCE_PERCENT,
};

fn cell(value: Option<f64>, precision: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.precision$}"))
}

/// The text table of modes: name, eigenvalue, ω_n, ζ, time to double or half, shape, and
/// the truth's mode and error when any record has one.
pub fn mode_table(records: &[ModeRecord]) -> String {
    let with_truth = records.iter().any(|r| r.truth.is_some());
    let mut out = String::new();
    let truth_header = if with_truth {
        format!(
            "  {:<32} {:>22} {:>8}",
            "truth mode", "truth λ [rad/s]", "error %"
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        out,
        "{:<32} {:>22} {:>8} {:>7} {:>13}  {:<26}{truth_header}",
        "mode", "λ [rad/s]", "ω_n", "ζ", "t2 / t½ [s]", "shape"
    );
    for record in records {
        let time = match (record.time_to_double_s, record.time_to_half_s) {
            (Some(t), _) => format!("double {t:.2}"),
            (None, Some(t)) => format!("half {t:.2}"),
            (None, None) => "-".to_string(),
        };
        let truth_cells = if with_truth {
            format!(
                "  {:<32} {:>22} {:>8}",
                record.truth_name.as_deref().unwrap_or("-"),
                record.truth.map_or("-".to_string(), eigenvalue_text),
                cell(record.error_percent, 1)
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            out,
            "{:<32} {:>22} {:>8} {:>7} {:>13}  {:<26}{truth_cells}",
            record.name,
            eigenvalue_text(record.eigenvalue),
            cell(record.omega_n, 3),
            cell(record.zeta, 3),
            time,
            record.shape()
        );
    }
    out
}

/// One line on the hover modes, e.g. `hover modes 3/4 within 25 % of the truth (worst
/// 41.2 %), 1 pole at the origin`.
pub fn hover_summary(hover: &HoverModeScore, poles_at_origin: usize) -> String {
    format!(
        "hover modes {}/{} within {:.0} % of the truth{}, {}",
        hover.matched,
        hover.of,
        HOVER_MODE_TOLERANCE_PERCENT,
        hover
            .worst_error_percent
            .map_or(String::new(), |w| format!(" (worst {w:.1} %)")),
        origin_text(poles_at_origin)
    )
}

/// `no pole at the origin`, `1 pole at the origin`, `2 poles at the origin`.
pub fn origin_text(poles_at_origin: usize) -> String {
    match poles_at_origin {
        0 => "no pole at the origin".to_string(),
        1 => "1 pole at the origin".to_string(),
        n => format!("{n} poles at the origin"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(name: &str, eigenvalue: [f64; 2], truth: Option<[f64; 2]>) -> ModeRecord {
        ModeRecord {
            name: name.into(),
            eigenvalue,
            omega_n: (name != "origin").then(|| eigenvalue[0].hypot(eigenvalue[1])),
            zeta: None,
            time_to_double_s: None,
            time_to_half_s: (eigenvalue[0] < 0.0).then(|| std::f64::consts::LN_2 / -eigenvalue[0]),
            poles: 1,
            shares: [("w".to_string(), 0.79), ("r".to_string(), 0.21)].into(),
            truth,
            truth_name: truth.map(|_| "heave".to_string()),
            error_percent: truth.map(|_| 100.0),
        }
    }

    #[test]
    fn hover_line_names_the_matched_modes_the_worst_error_and_the_origin() {
        let hover = HoverModeScore {
            matched: 3,
            of: 4,
            worst_error_percent: Some(100.0),
        };
        assert_eq!(
            hover_summary(&hover, 1),
            "hover modes 3/4 within 25 % of the truth (worst 100.0 %), 1 pole at the origin"
        );
        let none = HoverModeScore {
            matched: 0,
            of: 0,
            worst_error_percent: None,
        };
        assert_eq!(
            hover_summary(&none, 2),
            "hover modes 0/0 within 25 % of the truth, 2 poles at the origin"
        );
        assert_eq!(origin_text(0), "no pole at the origin");
    }

    #[test]
    fn mode_table_has_truth_columns_only_when_a_record_has_a_truth() {
        let with = mode_table(&[
            record("origin", [0.0, 0.0], Some([-0.4, 0.0])),
            record("yaw", [-0.3, 0.0], None),
        ]);
        let lines: Vec<&str> = with.lines().collect();
        assert_eq!(lines.len(), 3, "{with}");
        assert!(
            lines[0].contains("truth mode") && lines[0].ends_with("error %"),
            "{with}"
        );
        assert!(
            lines[1].starts_with("origin ") && lines[1].ends_with("100.0"),
            "{with}"
        );
        assert!(
            lines[2].contains("half 2.31") && lines[2].contains("w 79 %, r 21 %"),
            "{with}"
        );
        let without = mode_table(&[record("yaw", [-0.3, 0.0], None)]);
        assert!(
            !without.contains("error %") && without.contains("-0.3000"),
            "{without}"
        );
    }
}
