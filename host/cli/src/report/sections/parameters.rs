//! The parameter table (paper Table 3) with the accuracy flags and, in a campaign, the
//! truth and the errors.

use super::shared::{fmt, no_fit, KEY_PARAMETERS};
use crate::artifacts::priors::{PriorSummary, MOVED_WARNING_SIGMA};
use crate::report::html::{note, section, table, Cell, Mark};
use crate::report::inputs::ReportInputs;

/// The parameter table (paper Table 3) with flags, and the truth in a campaign.
pub fn parameter_section(inputs: &ReportInputs) -> String {
    let with_truth = inputs.summary.has_truth();
    let Some(fit) = inputs.summary.fit() else {
        return section("parameters", "Identified parameters", &note(no_fit(inputs)));
    };
    let rows: Vec<Vec<Cell>> = fit
        .params
        .iter()
        .map(|p| {
            let free = p.status == "free";
            let cr_flag = free && p.cr_percent.is_none_or(|v| v > 20.0);
            let insensitivity_flag = free && p.insensitivity_percent.is_none_or(|v| v > 10.0);
            let key = KEY_PARAMETERS.contains(&p.name.as_str());
            let error_cell = match (p.error_percent, key) {
                (Some(e), true) => Cell::judged(format!("{e:+.1}"), e.abs() <= 10.0),
                (e, _) => Cell::plain(e.map_or("-".to_string(), |e| format!("{e:+.1}"))),
            };
            let mut row = vec![
                Cell::name(if key && with_truth {
                    format!("{} *", p.name)
                } else {
                    p.name.clone()
                }),
                Cell::plain(format!("{:.5}", p.value)),
                Cell::marked(
                    fmt(p.cr_percent, 2),
                    if cr_flag { Mark::Flag } else { Mark::Plain },
                ),
                Cell::marked(
                    fmt(p.insensitivity_percent, 2),
                    if insensitivity_flag {
                        Mark::Flag
                    } else {
                        Mark::Plain
                    },
                ),
            ];
            if with_truth {
                row.extend([Cell::plain(fmt(p.truth, 5)), error_cell]);
            }
            row.extend([
                Cell::plain(p.status.clone()),
                Cell::marked(
                    p.flags.join(", "),
                    if p.flags.is_empty() {
                        Mark::Plain
                    } else {
                        Mark::Flag
                    },
                ),
            ]);
            row
        })
        .collect();
    let mut explained = format!(
        "{} after reduction. CR: Cramér–Rao bound, insensitivity: both in % of |value| \
(guidelines ≤ 20 % and ≤ 10 %; orange: beyond).",
        fit.structure
    );
    let mut headers = vec!["parameter", "value", "CR %", "insens. %"];
    if with_truth {
        explained += " Truth: the simulator's linearization at hover mapped onto the \
structure; error = 100·(value − truth)/|truth|. * marks the parameters the fit issue requires \
within 10 % of the truth (green/red).";
        headers.extend(["truth", "error %"]);
    }
    headers.extend(["status", "flags"]);
    let content = note(&explained) + &table(&headers, &rows) + &priors_table(&fit.priors);
    section(
        "parameters",
        "Identified parameters (paper Table 3)",
        &content,
    )
}

/// The priors (`summary.json`'s `fit.priors`): the aircraft file's value, σ, the estimate
/// and how far the data moved it; beyond 3σ flagged with a warning. Empty without any.
fn priors_table(priors: &[PriorSummary]) -> String {
    if priors.is_empty() {
        return String::new();
    }
    let rows: Vec<Vec<Cell>> = priors
        .iter()
        .map(|p| {
            vec![
                Cell::name(p.name.clone()),
                Cell::plain(format!("{:.5}", p.file_value)),
                Cell::plain(fmt(p.sigma, 5)),
                Cell::plain(if p.estimated { "estimated" } else { "held" }),
                Cell::plain(format!("{:.5}", p.estimate)),
                Cell::marked(
                    p.moved_sigma
                        .map_or("-".to_string(), |m| format!("{m:+.2}")),
                    if p.warning { Mark::Flag } else { Mark::Plain },
                ),
            ]
        })
        .collect();
    let warned: Vec<&str> = priors
        .iter()
        .filter(|p| p.warning)
        .map(|p| p.name.as_str())
        .collect();
    let warning = if warned.is_empty() {
        String::new()
    } else {
        note(&format!(
            "Warning: the data moved {} by more than {MOVED_WARNING_SIGMA}σ from the aircraft \
file: check the file's value before trusting the model.",
            warned.join(", ")
        ))
    };
    note(
        "Priors: the aircraft file's a-priori values with their σ (− where the file states \
none); estimated ones are fitted with their prior as a weighted term of the cost, held ones are \
constants of the structure. moved = (estimate − file value)/σ; orange beyond 3σ.",
    ) + &warning
        + &table(
            &["prior", "file value", "σ", "", "estimate", "moved σ"],
            &rows,
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_prior_moved_beyond_three_sigma_is_flagged_with_a_warning() {
        let prior = |name: &str, moved: f64| PriorSummary {
            name: name.into(),
            constant: None,
            file_value: 60.0,
            sigma: Some(12.0),
            estimated: true,
            estimate: 60.0 + 12.0 * moved,
            moved_sigma: Some(moved),
            warning: moved.abs() > MOVED_WARNING_SIGMA,
        };
        assert!(priors_table(&[]).is_empty());
        let calm = priors_table(&[prior("servo_omega", -0.75)]);
        assert!(
            calm.contains("servo_omega") && calm.contains("-0.75"),
            "{calm}"
        );
        assert!(!calm.contains("Warning"));
        let moved = priors_table(&[prior("servo_omega", -3.5), prior("servo_zeta", 0.5)]);
        assert!(
            moved.contains("Warning: the data moved servo_omega by more than 3σ"),
            "{moved}"
        );
    }
}
