//! The summary of an identify folder: the setup (aircraft, seed, where the trim and the
//! trim points came from), what the run could not do, the model's bars without the
//! truth's (the campaign summary's own rows), every test of the logs with what became of
//! it, the tests the responses and the verification took, and the wall time per stage.

use super::summary::{bar_row, model_rows, timing_table};
use crate::artifacts::identify_summary::{IdentifySummary, STAGES};
use crate::report::html::{escape, note, section, table, Cell};

/// The identify folder's summary (`summary` is its `summary.json`).
pub fn identify_summary_section(summary: &IdentifySummary) -> String {
    let s = summary;
    let trim = match s.captured_trim_rad {
        Some([phi, theta]) => format!(
            "the structure is written about the mean trim the flight controller captured \
over the sweep tests, φ0 = {:.2}°, θ0 = {:.2}°",
            phi.to_degrees(),
            theta.to_degrees()
        ),
        None => "the structure is written about its file's trim".to_string(),
    };
    let trim_points = match (&s.trim_points, s.trim_points_source.as_str()) {
        (Some(file), "flight") => format!(
            "trim points from the flight: {} steady segments, written to {file}",
            s.steady_segments.len()
        ),
        (Some(file), _) => format!("trim points from {file}"),
        (None, _) => "no trim points".to_string(),
    };
    let mut content = note(&format!(
        "Aircraft {}, fit seed {}; {trim}; {trim_points}. Green: the bar is met; red: it \
is not. Every figure below is drawn from the files in this folder (`sweephold report DIR` \
redraws it).",
        s.vehicle, s.seed
    ));
    if let Some(error) = &s.error {
        content += &format!(
            "<p class=\"note\"><strong>The run stopped at stage `{}`: {}</strong></p>\n",
            escape(&error.stage),
            escape(&error.message)
        );
    }
    if s.hover_derivatives_unanchored {
        content += "<p class=\"note\"><strong>Hover derivatives not anchored: no velocity \
source (no trim points, no GNSS), so the speed derivatives are fitted from the frequency \
responses alone, which barely inform them; the hover modes are not to be trusted.</strong></p>\n";
    }
    for text in &s.notes {
        content += &note(&format!("Note: {text}."));
    }
    let mut rows = vec![bar_row(
        "tests used: sweeps / held out / left out",
        format!(
            "{} / {} / {} of {}",
            s.sweeps.len(),
            s.held_out.len(),
            s.tests.iter().filter(|t| t.verdict != "used").count(),
            s.tests.len()
        ),
        "reported",
        None,
    )];
    rows.extend(model_rows(s.fit.as_ref(), s.verify.as_ref(), false));
    content += &table(&["check", "measured", "bar"], &rows);

    content += "<h3>Tests read</h3>\n";
    content += &note(
        "Every test of every log read (split at its Headers), in the order read, with what \
became of it: used, or why it was left out.",
    );
    let tests: Vec<Vec<Cell>> = s
        .tests
        .iter()
        .map(|t| {
            vec![
                Cell::name(t.file.clone()),
                Cell::name(t.test.clone()),
                Cell::judged(t.verdict.clone(), t.verdict == "used"),
            ]
        })
        .collect();
    content += &table(&["log", "test", "verdict"], &tests);
    let listed = |names: &[String]| -> Vec<Vec<Cell>> {
        names
            .iter()
            .enumerate()
            .map(|(i, name)| vec![Cell::plain((i + 1).to_string()), Cell::name(name.clone())])
            .collect()
    };
    content += &note("The sweep tests the frequency responses were computed from, in this order:");
    content += &table(&["#", "sweep test"], &listed(&s.sweeps));
    if !s.held_out.is_empty() {
        content += &note("The held-out tests the model was verified on (not used in the fit):");
        content += &table(&["#", "held-out test"], &listed(&s.held_out));
    }
    let mut order = STAGES.to_vec();
    order.push("total");
    content += &timing_table(&s.timings_s, &order);
    section("identify-summary", "Identification summary", &content)
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{fit_with_modes, identify_inputs_with_fit, mode};
    use crate::artifacts::summary::{PairSummary, ParameterSummary};
    use crate::report::render;
    use sysid::fit::modes::HoverModeScore;

    /// A fit carrying truth figures in every place a campaign's does: the identify page
    /// draws none of them, the campaign page of the same fit does.
    #[test]
    fn an_identify_page_draws_the_model_and_no_truth_even_when_the_fit_has_one() {
        let hover = HoverModeScore {
            matched: 1,
            of: 1,
            worst_error_percent: Some(6.3),
        };
        let mut fit = fit_with_modes(
            vec![mode("heave", [-0.3, 0.0], Some(([-0.32, 0.0], 6.3)))],
            Vec::new(),
            hover,
            0,
        );
        fit.params = vec![ParameterSummary {
            name: "Lb1s".into(),
            value: 3077.4,
            status: "free".into(),
            cr_percent: Some(4.27),
            insensitivity_percent: Some(2.96),
            truth: Some(3000.0),
            error_percent: Some(2.6),
            flags: Vec::new(),
        }];
        fit.pairs = vec![PairSummary {
            output: "p".into(),
            input: "lat".into(),
            cost: 9.7,
            range: [1.8, 62.8],
            truth_cost: Some(3.0),
        }];
        let inputs = identify_inputs_with_fit(fit);
        let page = render(&inputs);
        assert!(!page.to_lowercase().contains("truth"), "{page}");
        for expected in [
            "sweephold identify: trex700l seed 1",
            "<td class=\"name\">Lb1s</td><td>3077.40000</td><td>4.27</td>",
            "<td class=\"name\">heave</td>",
            "<td class=\"name\">p/lat</td>",
            "test 1: lat Sweep",
            "Note: no held-out test",
            "No verification in this folder",
        ] {
            assert!(page.contains(expected), "{expected}: {page}");
        }
        let campaign = render(&super::super::test_support::inputs_with_fit(
            inputs.summary.fit().unwrap().clone(),
        ));
        assert!(
            campaign.contains("<th>truth</th>") && campaign.contains("<th>J truth</th>"),
            "{campaign}"
        );
    }
}
