//! The cost table: J per fitted pair, of the fit and (in a campaign) against the truth.

use super::shared::{fmt, no_fit};
use crate::artifacts::summary::ANGULAR_RATES;
use crate::report::html::{note, section, table, Cell};
use crate::report::inputs::ReportInputs;

/// J per pair, fit and (in a campaign) against the truth.
pub fn cost_section(inputs: &ReportInputs) -> String {
    let with_truth = inputs.summary.has_truth();
    let Some(fit) = inputs.summary.fit() else {
        return section("costs", "Cost per pair", &note(no_fit(inputs)));
    };
    let mut rows: Vec<Vec<Cell>> = fit
        .pairs
        .iter()
        .map(|p| {
            let rate = ANGULAR_RATES.contains(&p.output.as_str());
            let mut row = vec![
                Cell::name(format!("{}/{}", p.output, p.input)),
                Cell::plain(format!("{:.2}–{:.2}", p.range[0], p.range[1])),
                Cell::judged(format!("{:.1}", p.cost), p.cost <= 100.0),
            ];
            if with_truth {
                row.push(match p.truth_cost {
                    Some(c) if rate => Cell::judged(format!("{c:.1}"), c <= 20.0),
                    other => Cell::plain(fmt(other, 1)),
                });
            }
            row
        })
        .collect();
    let mut total = vec![
        Cell::name("J_ave"),
        Cell::plain(""),
        Cell::judged(format!("{:.1}", fit.cost_ave), fit.cost_ave <= 50.0),
    ];
    let mut headers = vec!["pair", "range [rad/s]", "J"];
    let mut explained = String::from(
        "J = 20/n_ω Σ W_γ[W_g(Δ|T| dB)² + W_p(Δ∠T deg)²] on 20 points per pair: ≤ 100 \
acceptable per pair (green), J_ave ≤ 50 the bar.",
    );
    if with_truth {
        total.push(Cell::plain(fmt(fit.truth_cost_ave, 1)));
        headers.push("J truth");
        explained += " J truth: the identified model against the truth model over the same \
range (bar ≤ 20 for the angular rates).";
    }
    rows.push(total);
    let content = note(&format!(
        "{explained} The 6-DOF start had J_ave {:.1}.",
        fit.start_cost_ave
    )) + &table(&headers, &rows);
    section("costs", "Cost per pair (J table)", &content)
}
