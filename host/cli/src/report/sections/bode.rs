//! Bode magnitude and phase with coherence for every fitted pair: data, identified model
//! and, in a campaign, truth (paper Fig. 10).

use super::shared::HALF_WIDTH;
use crate::plot::{colors, Figure, LegendEntry, Panel, Scale, Series};
use crate::report::curves::model_response;
use crate::report::html::{figure, note, section};
use crate::report::inputs::ReportInputs;

/// Bode magnitude and phase with coherence for every fitted pair: data, model, truth.
pub fn bode_section(inputs: &ReportInputs) -> String {
    let (Some(frf), Some(model_document)) = (&inputs.frf, &inputs.model) else {
        return section(
            "bode",
            "Frequency responses",
            &note("No fitted model in this folder (the fit did not complete)."),
        );
    };
    let Some(model) = model_document.model() else {
        return section(
            "bode",
            "Frequency responses",
            &note("model9.json's matrices do not match its names."),
        );
    };
    let with_truth = inputs.summary.has_truth();
    let truth = inputs.truth_model.as_ref().and_then(|t| t.model());
    let mut figures = String::new();
    for fitted in &model_document.pairs {
        let Some(pair) = frf.pair(&fitted.input, &fitted.output) else {
            continue;
        };
        if pair.omega.is_empty() {
            continue;
        }
        let anchor = Some(fitted.range[0]);
        let omega = &pair.omega;
        let zip = |values: &[f64]| -> Vec<(f64, f64)> {
            omega.iter().copied().zip(values.iter().copied()).collect()
        };
        let mut magnitude = vec![Series::new("data", colors::DATA, zip(&pair.mag_db))];
        let mut phase = vec![Series::new("data", colors::DATA, zip(&pair.phase_deg))];
        if let Some((m, p)) = model_response(&model, pair, anchor) {
            magnitude.push(Series::new("identified", colors::MODEL, zip(&m)).width(2));
            phase.push(Series::new("identified", colors::MODEL, zip(&p)).width(2));
        }
        if let Some((m, p)) = truth.as_ref().and_then(|t| model_response(t, pair, anchor)) {
            magnitude.push(Series::new("truth", colors::TRUTH, zip(&m)).dashed());
            phase.push(Series::new("truth", colors::TRUTH, zip(&p)).dashed());
        }
        let x = Scale::log(omega[0], omega[omega.len() - 1], "ω [rad/s]");
        // The y range follows the curves inside the fit range, plus a quarter of their
        // span either side, so that data far below the coherence threshold or a runaway
        // model outside the range does not flatten the plot (those lines leave it).
        let in_range = |s: &Series| Series {
            points: s
                .points
                .iter()
                .copied()
                .filter(|(w, _)| *w >= fitted.range[0] && *w <= fitted.range[1])
                .collect(),
            ..s.clone()
        };
        let mut mag_panel = Panel::new(
            &format!("{}/{} magnitude", fitted.output, fitted.input),
            x.clone(),
            "dB",
            magnitude.clone(),
        );
        mag_panel.y = Scale::fit_y(&magnitude.iter().map(in_range).collect::<Vec<_>>(), "dB")
            .widened_to(6.0)
            .padded();
        mag_panel.shaded = Some(fitted.range);
        mag_panel.height = 120;
        let mut phase_panel = Panel::new("phase", x.clone(), "deg", phase.clone());
        phase_panel.y = Scale::fit_y(&phase.iter().map(in_range).collect::<Vec<_>>(), "deg")
            .widened_to(30.0)
            .padded();
        phase_panel.shaded = Some(fitted.range);
        phase_panel.height = 120;
        let mut coherence_panel = Panel::new(
            "coherence (partial γ²)",
            x,
            "γ²",
            vec![Series::new("data", colors::DATA, zip(&pair.coherence))],
        );
        coherence_panel.y = Scale::linear(0.0, 1.0, "γ²").with_intervals(2);
        coherence_panel.shaded = Some(fitted.range);
        coherence_panel.references = vec![(0.6, "0.6".into())];
        coherence_panel.height = 60;
        let mut fig = Figure::new(
            &format!("{}/{} Bode plot", fitted.output, fitted.input),
            vec![mag_panel, phase_panel, coherence_panel],
        );
        fig.legend = vec![
            LegendEntry::new("data", colors::DATA),
            LegendEntry::new("identified", colors::MODEL),
        ];
        if with_truth {
            fig.legend
                .push(LegendEntry::new("truth", colors::TRUTH).dashed());
        }
        fig.width = HALF_WIDTH;
        figures += &figure(
            fig.to_html(),
            &format!(
                "{}/{}: fit range {:.2}–{:.2} rad/s (shaded), J = {:.1}",
                fitted.output, fitted.input, fitted.range[0], fitted.range[1], fitted.cost
            ),
        );
    }
    let (explained, heading) = if with_truth {
        (
            "Composite MISO-conditioned responses of the cah records (black), the identified \
9-DOF hybrid model (blue) and the same structure at the simulator's truth values (red, \
dashed), for every fitted pair. Shaded: the pair's fit range.",
            "Frequency responses: data, identified model, truth (paper Fig. 10)",
        )
    } else {
        (
            "Composite MISO-conditioned responses of the sweep tests (black) and the \
identified 9-DOF hybrid model (blue), for every fitted pair. Shaded: the pair's fit range.",
            "Frequency responses: data and identified model (paper Fig. 10)",
        )
    };
    let content = note(explained) + "<div class=\"grid\">\n" + &figures + "</div>\n";
    section("bode", heading, &content)
}
