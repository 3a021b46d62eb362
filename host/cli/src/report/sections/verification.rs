//! Verification on the held-out doublets: the TIC table, and measured vs predicted time
//! histories per record.

use std::collections::BTreeMap;

use sysid::fit::verify::BiasMode;

use super::shared::fmt;
use crate::artifacts::summary::{mean_tic, ANGULAR_RATES};
use crate::plot::{colors, Figure, Panel, Scale, Series};
use crate::report::html::{figure, note, section, table, Cell};
use crate::report::inputs::ReportInputs;

/// Outputs drawn per verification record, in this order when compared.
const VERIFY_PLOTTED: [&str; 6] = ["p", "q", "r", "phi", "theta", "az"];

/// Verification on the held-out doublets: TIC table and measured vs predicted.
pub fn verification_section(inputs: &ReportInputs) -> String {
    let Some(verify) = &inputs.verify else {
        return section(
            "verification",
            "Verification",
            &note(if inputs.summary.has_truth() {
                "No verification in this campaign."
            } else {
                "No verification in this folder (no held-out test in the logs, or the \
verification did not complete)."
            }),
        );
    };
    let mut outputs: Vec<String> = Vec::new();
    for record in &verify.records {
        for o in &record.outputs {
            if !outputs.contains(&o.name) {
                outputs.push(o.name.clone());
            }
        }
    }
    let mut headers = vec!["record".to_string()];
    headers.extend(outputs.iter().cloned());
    headers.push("mean p q r".into());
    headers.push("mean all".into());
    let rows: Vec<Vec<Cell>> = verify
        .records
        .iter()
        .map(|record| {
            let mut row = vec![Cell::name(record.file.clone())];
            for name in &outputs {
                row.push(match record.outputs.iter().find(|o| &o.name == name) {
                    Some(o) if ANGULAR_RATES.contains(&name.as_str()) => {
                        Cell::judged(format!("{:.3}", o.tic), o.tic <= 0.25)
                    }
                    Some(o) => Cell::plain(format!("{:.3}", o.tic)),
                    None => Cell::plain("-"),
                });
            }
            let tic: BTreeMap<String, f64> = record
                .outputs
                .iter()
                .map(|o| (o.name.clone(), o.tic))
                .collect();
            row.push(Cell::plain(fmt(mean_tic(&tic, Some(&ANGULAR_RATES)), 3)));
            row.push(Cell::plain(format!("{:.3}", record.tic_mean)));
            row
        })
        .collect();
    let header_refs: Vec<&str> = headers.iter().map(String::as_str).collect();
    let held_out = match inputs.summary.campaign() {
        Some(campaign) => format!(
            "held-out doublet records (seed {}, not used in the fit)",
            campaign.verification_seed
        ),
        None => "the held-out tests of the logs (doublets, 3-2-1-1: not used in the fit)".into(),
    };
    let mut content = note(&format!(
        "The identified model simulated on the commands of {held_out}{}; {}. TIC = \
rms(y − b − ŷ) / (rms(y − b) + rms(ŷ)): 0 perfect, ≤ 0.25 the bar for p, q, r.",
        match verify.segment_s {
            Some(s) => format!(", restarted from the measured state every {s} s"),
            None => ", open loop over each record".to_string(),
        },
        match verify.bias {
            BiasMode::Trim =>
                "the bias b of each output (and the trim of each command) is its \
mean over the trim capture before the doublet (trim bias)",
            BiasMode::Fitted =>
                "a constant bias b per output is fitted by least squares, \
b = mean(y − ŷ) (fitted bias)",
        }
    )) + &table(&header_refs, &rows);
    for record in &verify.records {
        let mut panels = Vec::new();
        for name in VERIFY_PLOTTED {
            let Some(o) = record.outputs.iter().find(|o| o.name == name) else {
                continue;
            };
            let t = |k: usize| k as f64 * record.step_s;
            let measured: Vec<(f64, f64)> = o
                .measured
                .iter()
                .enumerate()
                .map(|(k, v)| (t(k), *v))
                .collect();
            let predicted: Vec<(f64, f64)> = o
                .predicted
                .iter()
                .enumerate()
                .map(|(k, v)| (t(k), *v))
                .collect();
            let end = t(o.measured.len().max(2) - 1);
            let series = vec![
                Series::new("measured", colors::DATA, measured),
                Series::new("predicted", colors::MODEL, predicted).width(2),
            ];
            let mut panel = Panel::new(
                &format!("{name}  TIC {:.3}", o.tic),
                Scale::linear(0.0, end, "t [s]"),
                name,
                series.clone(),
            );
            // The measured range sets the scale: a runaway prediction leaves the plot.
            panel.y = Scale::fit_y(&series[..1], name)
                .widened_to(1e-3)
                .with_intervals(3);
            panel.height = 90;
            panels.push(panel);
        }
        if panels.is_empty() {
            continue;
        }
        let mut fig = Figure::new(&format!("Verification on {}", record.file), panels);
        fig.columns = 2;
        let caption = match record.diverged_at_s {
            Some(at) => format!("{}: the model diverged at {at:.2} s", record.file),
            None => format!(
                "{}: measured (black) vs predicted (blue), perturbations from trim",
                record.file
            ),
        };
        content += &figure(fig.to_html(), &caption);
    }
    let heading = if inputs.summary.has_truth() {
        "Verification on held-out doublets: measured vs predicted"
    } else {
        "Verification on the held-out tests: measured vs predicted"
    };
    section("verification", heading, &content)
}
