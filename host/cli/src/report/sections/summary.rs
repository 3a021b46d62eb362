//! The campaign summary: the setup, the issues' bars with pass/fail, the wall time per
//! stage. The model's bars (`model_rows`) and the timings (`timing_table`) serve the
//! identify folder's summary too, there without the truth's bars.

use crate::mode_text::origin_text;
use sysid::fit::modes::{HOVER_MODE_LIMIT_RAD_S, HOVER_MODE_TOLERANCE_PERCENT};

use super::shared::{fmt, mode_of, KEY_PARAMETERS};
use crate::artifacts::stage::Stage;
use crate::artifacts::summary::{
    CampaignSummary, FitSummary, ParameterSummary, VerifySummary, ANGULAR_RATES,
};
use crate::report::html::{escape, note, section, table, Cell, Mark};
use crate::report::inputs::ReportInputs;

/// The paper's averaged lat–lon cross-control coherence of the lateral sweeps.
const PAPER_COHERENCE: [(&str, Option<f64>); 3] = [
    ("cah", Some(0.17)),
    ("standard", Some(0.95)),
    ("noise", None),
];

/// One row of the bars table: what, measured, bar, met.
pub(super) fn bar_row(what: &str, measured: String, bar: &str, met: Option<bool>) -> Vec<Cell> {
    vec![
        Cell::name(what),
        match met {
            Some(ok) => Cell::judged(measured, ok),
            None => Cell::plain(measured),
        },
        Cell::plain(bar),
    ]
}

/// The campaign summary (`s`, the folder's `summary.json`): setup, the issues' bars with
/// pass/fail, timings.
pub fn summary_section(inputs: &ReportInputs, s: &CampaignSummary) -> String {
    let mut content = note(&format!(
        "Vehicle {}, seed {} (held-out doublets: seed {}), sweep records {:.0} s{}. \
Green: the bar is met; red: it is not. Every figure below is drawn from the files in this \
folder (`sweephold report DIR` redraws it).",
        s.vehicle,
        s.seed,
        s.verification_seed,
        s.t_rec_s,
        if s.quick { " (--quick)" } else { "" }
    ));
    if let Some(error) = &s.error {
        content += &format!(
            "<p class=\"note\"><strong>The campaign stopped at stage `{}`: {}</strong></p>\n",
            escape(&error.stage),
            escape(&error.message)
        );
    }
    let mut rows = Vec::new();
    for (mode, paper) in PAPER_COHERENCE {
        let Some(m) = mode_of(inputs, mode) else {
            continue;
        };
        let (bar, met) = match mode {
            "cah" => ("≤ 0.2", m.cross_coherence_lat_lon.map(|c| c <= 0.2)),
            "standard" => ("≥ 0.8", m.cross_coherence_lat_lon.map(|c| c >= 0.8)),
            _ => ("reported", None),
        };
        let paper = paper.map_or(String::new(), |p| format!(" (paper {p})"));
        rows.push(bar_row(
            &format!("{mode}: lat–lon cross-control coherence, lateral sweeps{paper}"),
            fmt(m.cross_coherence_lat_lon, 3),
            bar,
            met,
        ));
        let attitude_bar = if mode == "cah" {
            "≤ 10°"
        } else {
            "reported"
        };
        rows.push(bar_row(
            &format!("{mode}: max |φ|, |θ| over all records"),
            format!("{:.1}°, {:.1}°", m.max_abs_deg.phi, m.max_abs_deg.theta),
            attitude_bar,
            (mode == "cah").then_some(m.max_abs_deg.phi <= 10.0 && m.max_abs_deg.theta <= 10.0),
        ));
        if let Some(from_trim) = m.max_from_trim_deg {
            rows.push(bar_row(
                &format!("{mode}: max |φ − φ_trim|, |θ − θ_trim| from the captured trim"),
                format!("{:.1}°, {:.1}°", from_trim.phi, from_trim.theta),
                attitude_bar,
                (mode == "cah").then_some(from_trim.phi <= 10.0 && from_trim.theta <= 10.0),
            ));
        }
        rows.push(bar_row(
            &format!("{mode}: aborted records"),
            format!("{} of {}", m.aborts, m.records),
            if mode == "cah" { "0" } else { "reported" },
            (mode == "cah").then_some(m.aborts == 0),
        ));
    }
    rows.extend(model_rows(s.fit.as_ref(), s.verify.as_ref(), true));
    if let Some(total) = s.timings_s.get("total") {
        rows.push(bar_row(
            "wall time of the campaign",
            format!("{total:.1} s"),
            "≤ 30 s (default campaign)",
            (!s.quick).then_some(*total <= 30.0),
        ));
    }
    content += &table(&["check", "measured", "bar"], &rows);

    let mut order = Stage::ALL.map(Stage::name).to_vec();
    order.push("total");
    content += &timing_table(&s.timings_s, &order);
    section("campaign-summary", "Campaign summary", &content)
}

/// The bars of the model: whether it is degenerate, its fit's bars (those against the
/// truth only `with_truth`) and its verification's.
pub(super) fn model_rows(
    fit: Option<&FitSummary>,
    verify: Option<&VerifySummary>,
    with_truth: bool,
) -> Vec<Vec<Cell>> {
    // A degenerate model meets no bar of the model's (its fit's and its verification's):
    // its figures are drawn, each marked not met.
    let degenerate = fit.is_some_and(|fit| !fit.degenerate.is_empty());
    let mut rows = Vec::new();
    if let Some(fit) = fit {
        rows.extend(degenerate_row(fit));
        rows.extend(fit_bar_rows(fit, with_truth));
    }
    if let Some(verify) = verify {
        // A campaign's held-out tests are its doublets.
        let held_out = if with_truth {
            "the doublets"
        } else {
            "the held-out tests"
        };
        for output in ANGULAR_RATES {
            if let Some(tic) = verify.tic.get(output) {
                rows.push(bar_row(
                    &format!(
                        "verification TIC, {output} (mean over {held_out}, {} bias)",
                        verify.bias
                    ),
                    format!("{tic:.3}"),
                    "≤ 0.25",
                    Some(*tic <= 0.25),
                ));
            }
        }
        if let Some(mean) = verify.mean_pqr() {
            rows.push(bar_row(
                "verification TIC, mean over p, q, r",
                format!("{mean:.3}"),
                "reported",
                None,
            ));
        }
        rows.push(bar_row(
            &format!(
                "verification TIC, mean over all {} outputs ({})",
                verify.tic.len(),
                verify.tic.keys().cloned().collect::<Vec<_>>().join(" ")
            ),
            format!("{:.3}", verify.mean_all()),
            "reported",
            None,
        ));
    }
    if degenerate {
        for row in &mut rows {
            if matches!(row[1].mark, Mark::Good) {
                row[1].mark = Mark::Bad;
            }
        }
    }
    rows
}

/// The table of the wall time per stage, under its heading: the stages of `order` in
/// that order, then the others by name.
pub(super) fn timing_table(
    timings: &std::collections::BTreeMap<String, f64>,
    order: &[&str],
) -> String {
    let mut rows: Vec<(String, f64)> = order
        .iter()
        .filter_map(|name| timings.get(*name).map(|v| (name.to_string(), *v)))
        .collect();
    rows.extend(
        timings
            .iter()
            .filter(|(k, _)| !order.contains(&k.as_str()))
            .map(|(k, v)| (k.clone(), *v)),
    );
    let rows: Vec<Vec<Cell>> = rows
        .into_iter()
        .map(|(stage, seconds)| vec![Cell::name(stage), Cell::plain(format!("{seconds:.2}"))])
        .collect();
    "<h3>Wall time per stage [s]</h3>\n".to_string() + &table(&["stage", "seconds"], &rows)
}

/// The row saying the model is degenerate (`degenerate` of the summary), red; none when
/// it is not.
fn degenerate_row(fit: &FitSummary) -> Option<Vec<Cell>> {
    (!fit.degenerate.is_empty()).then(|| {
        bar_row(
            &format!("{}: degenerate minimum", fit.structure),
            sysid::fit::degenerate::describe(&fit.degenerate),
            "not degenerate (no bar of a degenerate model is met)",
            Some(false),
        )
    })
}

/// The fit's bars; those against the truth (key parameters, hover modes, speed
/// derivatives, J against the truth model) only `with_truth`.
fn fit_bar_rows(fit: &FitSummary, with_truth: bool) -> Vec<Vec<Cell>> {
    let mut rows = vec![bar_row(
        &format!("{}: J_ave (paper's acceptable level 100)", fit.structure),
        format!("{:.1}", fit.cost_ave),
        "≤ 50",
        Some(fit.cost_ave <= 50.0),
    )];
    let free: Vec<_> = fit.params.iter().filter(|p| p.status == "free").collect();
    // A parameter the reduction kept because the fit needs it is accepted, and counted apart.
    let needed = |p: &&&ParameterSummary| p.flags.iter().any(|f| f == "needed");
    let over_cr = free
        .iter()
        .filter(|p| p.cr_percent.is_none_or(|v| v > 20.0))
        .filter(|p| !needed(p))
        .count();
    let over_insensitivity = free
        .iter()
        .filter(|p| p.insensitivity_percent.is_none_or(|v| v > 10.0))
        .filter(|p| !needed(p))
        .count();
    let needed_count = free.iter().filter(|p| needed(p)).count();
    rows.push(bar_row(
        "free parameters with CR > 20 % / insensitivity > 10 %, not flagged needed",
        format!(
            "{over_cr} / {over_insensitivity} of {} ({needed_count} needed)",
            free.len()
        ),
        "0 / 0",
        Some(over_cr == 0 && over_insensitivity == 0),
    ));
    if !with_truth {
        return rows;
    }
    for name in KEY_PARAMETERS {
        if let Some(p) = fit.params.iter().find(|p| p.name == name) {
            rows.push(bar_row(
                &format!("{name}: error against the truth"),
                p.error_percent
                    .map_or("-".to_string(), |e| format!("{e:+.1} %")),
                "within ±10 %",
                p.error_percent.map(|e| e.abs() <= 10.0),
            ));
        }
    }
    if let Some(row) = hover_mode_bar(fit) {
        rows.push(row);
    }
    for derivative in fit.speed_derivatives.iter().filter(|d| d.truth.is_some()) {
        rows.push(bar_row(
            &format!(
                "quasi-static {}: error against the truth{}",
                derivative.name,
                if fit.trim.is_some() {
                    " (from trim points)"
                } else {
                    ""
                }
            ),
            derivative
                .error_percent
                .map_or("-".to_string(), |e| format!("{e:+.1} %")),
            "within ±25 %",
            derivative.error_percent.map(|e| e.abs() <= 25.0),
        ));
    }
    let rate_pairs: Vec<_> = fit
        .pairs
        .iter()
        .filter(|p| ANGULAR_RATES.contains(&p.output.as_str()))
        .collect();
    if rate_pairs.iter().any(|p| p.truth_cost.is_some()) {
        let worst = rate_pairs
            .iter()
            .filter_map(|p| {
                p.truth_cost
                    .map(|c| (c, format!("{}/{}", p.output, p.input)))
            })
            .fold((f64::NEG_INFINITY, String::new()), |a, b| {
                if b.0 > a.0 {
                    b
                } else {
                    a
                }
            });
        rows.push(bar_row(
            "J against the truth model, worst angular-rate pair",
            format!("{:.1} ({})", worst.0, worst.1),
            "≤ 20 for every p, q, r pair",
            Some(worst.0 <= 20.0),
        ));
    }
    rows
}

/// The hover-mode bar: every truth hover mode (|λ| < 3 rad/s) matched by an identified
/// mode within 25 %, and no pole of the identified model at the origin. Red, not absent,
/// when the truth was scored but the modes are missing; absent before the truth stage.
fn hover_mode_bar(fit: &FitSummary) -> Option<Vec<Cell>> {
    let what = format!(
        "hover modes (truth |λ| < {HOVER_MODE_LIMIT_RAD_S} rad/s) within \
{HOVER_MODE_TOLERANCE_PERCENT:.0} % of the truth, poles at the origin"
    );
    let bar = "every hover mode within 25 %, no pole at the origin";
    match (fit.hover_modes_matched, fit.poles_at_origin) {
        (Some(hover), Some(poles)) => Some(bar_row(
            &what,
            format!(
                "{}/{}{}, {}",
                hover.matched,
                hover.of,
                hover
                    .worst_error_percent
                    .map_or(String::new(), |w| format!(" (worst {w:.0} %)")),
                origin_text(poles)
            ),
            bar,
            Some(hover.all_matched() && poles == 0),
        )),
        _ if fit.truth_cost_ave.is_some() => {
            Some(bar_row(&what, "not computed".to_string(), bar, Some(false)))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::super::modes::modes_section;
    use super::super::test_support::{fit_with_modes, inputs_with_fit, mode};
    use super::*;
    use sysid::fit::modes::{HoverModeScore, TruthModeRecord};

    /// The summary section of a campaign whose summary holds only `fit`.
    fn campaign_summary(fit: FitSummary) -> String {
        let inputs = inputs_with_fit(fit);
        summary_section(&inputs, inputs.summary.campaign().unwrap())
    }

    #[test]
    fn a_needed_parameter_is_counted_apart_and_the_speed_derivatives_are_judged() {
        let parameter = |name: &str, flags: &[&str]| ParameterSummary {
            name: name.into(),
            value: 1.0,
            status: "free".into(),
            cr_percent: Some(12.0),
            insensitivity_percent: Some(11.0),
            truth: None,
            error_percent: None,
            flags: flags.iter().map(|f| f.to_string()).collect(),
        };
        let hover = HoverModeScore {
            matched: 4,
            of: 4,
            worst_error_percent: Some(3.0),
        };
        let mut fit = fit_with_modes(Vec::new(), Vec::new(), hover, 0);
        fit.params = vec![
            parameter("Zw", &["insensitive", "needed"]),
            parameter("Xr", &["insensitive"]),
        ];
        fit.speed_derivatives = vec![
            crate::artifacts::summary::SpeedDerivativeSummary {
                name: "Mu".into(),
                value: Some(0.11),
                truth: Some(0.10),
                error_percent: Some(10.0),
            },
            crate::artifacts::summary::SpeedDerivativeSummary {
                name: "Nv".into(),
                value: Some(0.07),
                truth: Some(0.05),
                error_percent: Some(40.0),
            },
        ];
        let rows = fit_bar_rows(&fit, true);
        let find = |prefix: &str| {
            rows.iter()
                .find(|row| row[0].text.starts_with(prefix))
                .unwrap_or_else(|| panic!("no row {prefix}"))
        };
        let flagged = find("free parameters");
        assert_eq!(flagged[1].text, "0 / 1 of 2 (1 needed)");
        assert_eq!(flagged[1].mark, Mark::Bad);
        assert_eq!(find("quasi-static Mu")[1].mark, Mark::Good);
        assert_eq!(find("quasi-static Nv")[1].mark, Mark::Bad);
    }

    #[test]
    fn a_model_without_its_hover_modes_reads_red() {
        // Heave lost to the origin, the lateral oscillation 40 % off, yaw missing.
        let modes = vec![
            mode("origin", [0.0, 0.0], Some(([-0.32, 0.0], 100.0))),
            mode(
                "hover oscillation (coupled)",
                [0.2, 0.6],
                Some(([0.31, 0.6], 40.0)),
            ),
            mode("roll–flap", [-7.0, 12.0], Some(([-7.2, 12.5], 3.0))),
        ];
        let unpaired_yaw = TruthModeRecord {
            name: "yaw".into(),
            eigenvalue: [-0.36, 0.0],
            omega_n: Some(0.36),
            zeta: None,
            hover: true,
            identified: None,
            identified_name: None,
            error_percent: None,
        };
        let hover = HoverModeScore {
            matched: 0,
            of: 3,
            worst_error_percent: Some(100.0),
        };
        let fit = fit_with_modes(modes, vec![unpaired_yaw], hover, 1);
        let bar = hover_mode_bar(&fit).unwrap();
        assert_eq!(bar[1].mark, Mark::Bad);
        assert_eq!(bar[1].text, "0/3 (worst 100 %), 1 pole at the origin");
        let html = modes_section(&inputs_with_fit(fit.clone()));
        assert!(html.contains(r#"<td class="bad">origin</td>"#), "{html}");
        assert!(html.contains(r#"<td class="bad">40.0</td>"#), "{html}");
        // The rotor mode is no hover mode: its error is not judged.
        assert!(html.contains("<td>3.0</td>"), "{html}");
        assert!(
            html.contains(r#"<td class="bad">(none)</td><td>-</td>"#),
            "{html}"
        );
        assert!(html.contains("Here: hover modes 0/3 within 25 %"), "{html}");

        // Every hover mode within 25 % and no origin: green.
        let passing = fit_with_modes(
            vec![mode("heave", [-0.3, 0.0], Some(([-0.32, 0.0], 6.3)))],
            Vec::new(),
            HoverModeScore {
                matched: 1,
                of: 1,
                worst_error_percent: Some(6.3),
            },
            0,
        );
        assert_eq!(hover_mode_bar(&passing).unwrap()[1].mark, Mark::Good);
        // Scored against the truth but without modes: red, not a pass.
        let missing = FitSummary {
            hover_modes_matched: None,
            poles_at_origin: None,
            modes: Vec::new(),
            ..passing.clone()
        };
        assert_eq!(hover_mode_bar(&missing).unwrap()[1].mark, Mark::Bad);
        assert!(modes_section(&inputs_with_fit(missing.clone())).contains("not computed"));
        // Before the truth stage: no bar.
        let unscored = FitSummary {
            truth_cost_ave: None,
            ..missing
        };
        assert!(hover_mode_bar(&unscored).is_none());
    }

    /// A degenerate model: a red row naming it, and none of its bars met, the J_ave
    /// (16, within 50) and the hover modes (all matched) included.
    #[test]
    fn a_degenerate_model_meets_no_bar() {
        use sysid::fit::degenerate::{DegenerateKind, DegenerateReason};
        let hover = HoverModeScore {
            matched: 1,
            of: 1,
            worst_error_percent: Some(6.3),
        };
        let passing = fit_with_modes(Vec::new(), Vec::new(), hover, 0);
        let good = campaign_summary(passing.clone());
        assert!(good.contains(r#"<td class="good">16.0</td>"#), "{good}");
        assert!(!good.contains("degenerate minimum"), "{good}");
        let degenerate = FitSummary {
            degenerate: vec![DegenerateReason {
                parameter: "tau_f".into(),
                value: 0.005,
                reason: DegenerateKind::OnLowerBound,
                limit: 0.005,
            }],
            ..passing
        };
        let html = campaign_summary(degenerate);
        assert!(
            html.contains(r#"<td class="bad">`tau_f` = 0.005 on its lower bound 0.005</td>"#),
            "{html}"
        );
        assert!(html.contains(r#"<td class="bad">16.0</td>"#), "{html}");
        assert!(!html.contains(r#"class="good""#), "{html}");
    }
}
