//! The plots of `sweephold verify --plots`: one per compared output of a verified record,
//! the measured perturbation (bias removed) and the model's prediction against time.

use std::path::Path;

use sysid::fit::verify::Verification;

use super::draw::PlotError;
use super::figure::{colors, Figure, Panel, Scale, Series};

/// File-name-safe form of a name.
fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// One SVG per compared output, as `(file name, SVG text)`: measured (bias removed) and
/// predicted against time, named `<record stem>-<output>.svg`. The caller writes them
/// (the CLI writes each file whole, atomically).
pub fn verification_plots(verification: &Verification) -> Result<Vec<(String, String)>, PlotError> {
    let stem = Path::new(&verification.source).file_stem().map_or_else(
        || "record".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let h = 1.0 / verification.sample_rate_hz;
    let mut plots = Vec::new();
    for ((score, measured), predicted) in verification
        .outputs
        .iter()
        .zip(&verification.measured)
        .zip(&verification.predicted)
    {
        let name = format!("{}-{}.svg", file_stem(&stem), file_stem(&score.output));
        let timed = |series: &[f64]| -> Vec<(f64, f64)> {
            series
                .iter()
                .enumerate()
                .map(|(k, v)| (k as f64 * h, *v))
                .collect()
        };
        let lines = vec![
            Series::new("measured", colors::DATA, timed(measured)),
            Series::new("predicted", colors::TRUTH, timed(predicted)),
        ];
        let end = measured.len().max(2) as f64 * h;
        let mut panel = Panel::new(
            &format!(
                "{}: {} measured vs predicted (TIC {:.3})",
                stem, score.output, score.theil
            ),
            Scale::linear(0.0, end, "t [s]"),
            &format!("{} (perturbation)", score.output),
            lines,
        );
        panel.height = 300;
        let mut figure = Figure::new(
            &format!("{stem}: {} measured vs predicted", score.output),
            vec![panel],
        );
        figure.width = 1000;
        plots.push((name, figure.to_svg()?));
    }
    Ok(plots)
}
