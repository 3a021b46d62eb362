//! Measured against predicted, one SVG per compared output.

use std::fmt;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{Verification, VerifyError};

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
pub fn render_verification_plots(
    verification: &Verification,
) -> Result<Vec<(String, String)>, VerifyError> {
    let plot_error = |path: &Path, e: &dyn fmt::Display| VerifyError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let stem = Path::new(&verification.source).file_stem().map_or_else(
        || "record".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let mut plots = Vec::new();
    let h = 1.0 / verification.sample_rate_hz;
    for ((score, measured), predicted) in verification
        .outputs
        .iter()
        .zip(&verification.measured)
        .zip(&verification.predicted)
    {
        let name = format!("{}-{}.svg", file_stem(&stem), file_stem(&score.output));
        let path = PathBuf::from(&name);
        let mut svg = String::new();
        let root = SVGBackend::with_string(&mut svg, (1000, 400)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_error(&path, &e))?;
        let (lo, hi) = measured
            .iter()
            .chain(predicted)
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let (lo, hi) = if lo.is_finite() && hi > lo {
            (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
        } else {
            (-1.0, 1.0)
        };
        let end = measured.len().max(2) as f64 * h;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "{}: {} measured vs predicted (TIC {:.3})",
                    stem, score.output, score.theil
                ),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..end, lo..hi)
            .map_err(|e| plot_error(&path, &e))?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .y_desc(format!("{} (perturbation)", score.output))
            .draw()
            .map_err(|e| plot_error(&path, &e))?;
        for (series, label, color) in [
            (measured, "measured", BLACK.to_rgba()),
            (predicted, "predicted", RED.to_rgba()),
        ] {
            let points = series.iter().enumerate().map(|(k, v)| (k as f64 * h, *v));
            chart
                .draw_series(LineSeries::new(points, color.stroke_width(1)))
                .map_err(|e| plot_error(&path, &e))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| plot_error(&path, &e))?;
        root.present().map_err(|e| plot_error(&path, &e))?;
        drop(chart);
        drop(root);
        plots.push((name, svg));
    }
    Ok(plots)
}
