//! The modes of the identified model beside the truth's: one row per identified mode with
//! the truth mode paired with it, then the truth modes left without a counterpart. In an
//! identify folder, the identified modes alone.

use crate::mode_text::hover_summary;
use sysid::fit::modes::{
    eigenvalue_text, ModeName, HOVER_MODE_LIMIT_RAD_S, HOVER_MODE_TOLERANCE_PERCENT,
    ORIGIN_LIMIT_RAD_S,
};

use super::shared::{fmt, no_fit};
use crate::report::html::{note, section, table, Cell};
use crate::report::inputs::ReportInputs;

/// The identified model's modes beside the truth's: one row per identified mode with the
/// truth mode paired with it, then the truth modes left without a counterpart.
pub fn modes_section(inputs: &ReportInputs) -> String {
    let with_truth = inputs.summary.has_truth();
    let title = if with_truth {
        "Modes: identified vs truth"
    } else {
        "Modes of the identified model"
    };
    let Some(fit) = inputs.summary.fit() else {
        return section("modes", title, &note(no_fit(inputs)));
    };
    if fit.modes.is_empty() {
        return section(
            "modes",
            title,
            &note(
                "The modes of this fit were not computed (a summary written before they \
were, or a model without eigenvalues).",
            ),
        );
    }
    let time = |double: Option<f64>, half: Option<f64>| match (double, half) {
        (Some(t), _) => format!("double {t:.2}"),
        (None, Some(t)) => format!("half {t:.2}"),
        (None, None) => "-".to_string(),
    };
    let is_hover = |eigenvalue: [f64; 2]| {
        let magnitude = eigenvalue[0].hypot(eigenvalue[1]);
        (ORIGIN_LIMIT_RAD_S..HOVER_MODE_LIMIT_RAD_S).contains(&magnitude)
    };
    let mut rows: Vec<Vec<Cell>> = fit
        .modes
        .iter()
        .map(|mode| {
            let origin = mode.name == ModeName::Origin.as_str();
            let error = match (mode.error_percent, mode.truth) {
                (Some(e), Some(truth)) if is_hover(truth) => {
                    Cell::judged(format!("{e:.1}"), e <= HOVER_MODE_TOLERANCE_PERCENT)
                }
                (e, _) => Cell::plain(fmt(e, 1)),
            };
            let mut row = vec![
                if origin {
                    Cell::judged(mode.name.clone(), false)
                } else {
                    Cell::name(mode.name.clone())
                },
                Cell::plain(eigenvalue_text(mode.eigenvalue)),
                Cell::plain(fmt(mode.omega_n, 3)),
                Cell::plain(fmt(mode.zeta, 3)),
                Cell::plain(time(mode.time_to_double_s, mode.time_to_half_s)),
                Cell::plain(mode.shape()),
            ];
            if with_truth {
                row.extend([
                    Cell::plain(mode.truth_name.clone().unwrap_or_else(|| "-".into())),
                    Cell::plain(mode.truth.map_or("-".to_string(), eigenvalue_text)),
                    error,
                ]);
            }
            row
        })
        .collect();
    if !with_truth {
        let content = note(&format!(
            "{IDENTIFIED_MODES}. A pole at the origin (|λ| < 1e−6 rad/s) is red."
        )) + &table(&IDENTIFIED_HEADERS, &rows);
        return section("modes", title, &content);
    }
    for truth in fit.truth_modes.iter().filter(|t| t.identified.is_none()) {
        rows.push(vec![
            // A truth hover mode the identified model lacks is a miss.
            if truth.hover {
                Cell::judged("(none)", false)
            } else {
                Cell::name("(none)")
            },
            Cell::plain("-"),
            Cell::plain("-"),
            Cell::plain("-"),
            Cell::plain("-"),
            Cell::plain(""),
            Cell::plain(truth.name.clone()),
            Cell::plain(eigenvalue_text(truth.eigenvalue)),
            Cell::plain("-"),
        ]);
    }
    let verdict = match (fit.hover_modes_matched, fit.poles_at_origin) {
        (Some(hover), Some(poles)) => format!(" Here: {}.", hover_summary(&hover, poles)),
        _ => String::new(),
    };
    let content = note(&format!(
        "{IDENTIFIED_MODES} and paired with a mode of the truth model (the same structure at the \
simulator's truth values): same name first, then the nearest eigenvalue. Error = \
100·|λ − λ_truth|/|λ_truth|, green/red against 25 % for the truth's hover modes (|λ| < 3 \
rad/s); a pole at the origin (|λ| < 1e−6 rad/s) is red.{verdict}"
    )) + &table(
        &[
            IDENTIFIED_HEADERS[0],
            IDENTIFIED_HEADERS[1],
            IDENTIFIED_HEADERS[2],
            IDENTIFIED_HEADERS[3],
            IDENTIFIED_HEADERS[4],
            IDENTIFIED_HEADERS[5],
            "truth mode",
            "truth λ [rad/s]",
            "error %",
        ],
        &rows,
    );
    section("modes", title, &content)
}

/// The columns of an identified mode.
const IDENTIFIED_HEADERS: [&str; 6] = [
    "identified mode",
    "λ [rad/s]",
    "ω_n [rad/s]",
    "ζ",
    "t2 / t½ [s]",
    "shape",
];

/// How the identified modes are computed and named (without a truth to pair them with).
const IDENTIFIED_MODES: &str = "Eigenvalues λ of A = M⁻¹F of the identified model, one row \
per real pole or complex pair (its Im > 0 member), sorted by |λ|; ω_n = |λ|, ζ = −Re λ/|λ|, \
time to double (ln 2/Re λ) or to half (ln 2/−Re λ) the amplitude (of the envelope for a pair). \
Each mode is named from its eigenvector (shape: the largest shares, rates divided by ω_s = \
max(|λ|, 0.1 rad/s) and speeds multiplied by ω_s/g so that each reads as the attitude it \
amounts to; rules in sysid::fit::modes)";
