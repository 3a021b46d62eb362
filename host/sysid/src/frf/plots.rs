//! SVG plots: one Bode plot per pair (magnitude, phase, coherence stacked on a common
//! log-frequency axis; the conditioned response in blue, the SISO one in grey, the
//! multiple coherence in orange, the valid range between green lines, the coherence
//! threshold in red), and one cross-control coherence plot per swept axis (like
//! the paper's Fig. 3 and 7).

use std::path::Path;

use plotters::prelude::*;

use crate::document::PairResponse;

use super::analysis::{CoherenceCurve, FrfAnalysis, MultipleCoherence};
use super::FrfError;

const WIDTH: u32 = 800;
const HEIGHT: u32 = 900;

fn plot_error(path: &Path, e: impl std::fmt::Display) -> FrfError {
    FrfError::Plot(format!("{}: {e}", path.display()))
}

/// The plots of `analysis`, as `(file name, SVG text)`: `frf_<input>_<output>.svg` per
/// pair and `cross_coherence_<axis>.svg` per record group. The caller writes them (the
/// CLI writes each file whole, atomically).
pub fn render_plots(analysis: &FrfAnalysis) -> Result<Vec<(String, String)>, FrfError> {
    let mut plots = Vec::new();
    let document = &analysis.document;
    for pair in &document.pairs {
        let siso = document
            .siso
            .iter()
            .find(|s| s.input == pair.input && s.output == pair.output);
        let multiple = analysis
            .multiple_coherence
            .iter()
            .find(|m| m.input == pair.input && m.output == pair.output);
        let name = format!("frf_{}_{}.svg", pair.input, pair.output);
        let mut svg = String::new();
        bode_plot(
            &mut svg,
            Path::new(&name),
            pair,
            siso,
            multiple,
            document.coherence_threshold,
        )?;
        plots.push((name, svg));
    }
    let mut axes: Vec<&str> = analysis
        .cross_coherence_curves
        .iter()
        .map(|c| c.axis.as_str())
        .collect();
    axes.dedup();
    for axis in axes {
        let curves: Vec<&CoherenceCurve> = analysis
            .cross_coherence_curves
            .iter()
            .filter(|c| c.axis == axis)
            .collect();
        let name = format!("cross_coherence_{axis}.svg");
        let mut svg = String::new();
        coherence_plot(&mut svg, Path::new(&name), axis, &curves)?;
        plots.push((name, svg));
    }
    Ok(plots)
}

/// Range of finite values with a margin; a flat or empty series gets a unit span.
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let margin = ((hi - lo) * 0.05).max(0.5);
    (lo - margin, hi + margin)
}

fn bode_plot(
    svg: &mut String,
    path: &Path,
    pair: &PairResponse,
    siso: Option<&PairResponse>,
    multiple: Option<&MultipleCoherence>,
    threshold: f64,
) -> Result<(), FrfError> {
    let root = SVGBackend::with_string(svg, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let panels = root.split_evenly((3, 1));
    let all = || {
        pair.omega
            .iter()
            .chain(siso.iter().flat_map(|s| s.omega.iter()))
            .copied()
    };
    let (w_lo, w_hi) = {
        let (lo, hi) = all().fold((f64::INFINITY, 0.0f64), |(lo, hi), w| {
            (lo.min(w), hi.max(w))
        });
        if lo.is_finite() && hi > lo {
            (lo, hi)
        } else {
            (0.1, 100.0)
        }
    };
    let series = |p: &PairResponse, which: usize| -> Vec<(f64, f64)> {
        let values = match which {
            0 => &p.mag_db,
            1 => &p.phase_deg,
            _ => &p.coherence,
        };
        p.omega
            .iter()
            .copied()
            .zip(values.iter().copied())
            .collect()
    };
    let labels = ["magnitude [dB]", "phase [deg]", "coherence γ²"];
    for (which, panel) in panels.iter().enumerate() {
        let y_range = if which == 2 {
            (0.0, 1.05)
        } else {
            let values = series(pair, which)
                .into_iter()
                .chain(siso.map(|s| series(s, which)).unwrap_or_default())
                .map(|(_, v)| v);
            span(values)
        };
        let mut chart = ChartBuilder::on(panel)
            .caption(
                if which == 0 {
                    format!("{} → {}", pair.input, pair.output)
                } else {
                    String::new()
                },
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d((w_lo..w_hi).log_scale(), y_range.0..y_range.1)
            .map_err(|e| plot_error(path, e))?;
        chart
            .configure_mesh()
            .x_desc("ω [rad/s]")
            .y_desc(labels[which])
            .draw()
            .map_err(|e| plot_error(path, e))?;
        if let Some([lo, hi]) = pair.valid_range {
            let band = vec![
                (lo, y_range.0),
                (lo, y_range.1),
                (hi, y_range.1),
                (hi, y_range.0),
            ];
            chart
                .draw_series(LineSeries::new(band, GREEN.mix(0.6)))
                .map_err(|e| plot_error(path, e))?;
        }
        if let Some(s) = siso {
            chart
                .draw_series(LineSeries::new(series(s, which), RGBColor(150, 150, 150)))
                .map_err(|e| plot_error(path, e))?
                .label("SISO")
                .legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(150, 150, 150))
                });
        }
        chart
            .draw_series(LineSeries::new(series(pair, which), BLUE.stroke_width(2)))
            .map_err(|e| plot_error(path, e))?
            .label("MISO conditioned")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
        if let (2, Some(m)) = (which, multiple) {
            let points: Vec<(f64, f64)> = m
                .omega
                .iter()
                .copied()
                .zip(m.coherence.iter().copied())
                .collect();
            let orange = RGBColor(230, 140, 0);
            chart
                .draw_series(LineSeries::new(points, orange))
                .map_err(|e| plot_error(path, e))?
                .label("multiple coherence")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], orange));
            chart
                .configure_series_labels()
                .border_style(BLACK)
                .background_style(WHITE.mix(0.8))
                .draw()
                .map_err(|e| plot_error(path, e))?;
        }
        if which == 2 {
            let line = vec![(w_lo, threshold), (w_hi, threshold)];
            chart
                .draw_series(LineSeries::new(line, RED.mix(0.7)))
                .map_err(|e| plot_error(path, e))?;
        }
        if which == 0 {
            chart
                .configure_series_labels()
                .border_style(BLACK)
                .background_style(WHITE.mix(0.8))
                .draw()
                .map_err(|e| plot_error(path, e))?;
        }
    }
    root.present().map_err(|e| plot_error(path, e))
}

fn coherence_plot(
    svg: &mut String,
    path: &Path,
    axis: &str,
    curves: &[&CoherenceCurve],
) -> Result<(), FrfError> {
    let root = SVGBackend::with_string(svg, (WIDTH, 450)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let (w_lo, w_hi) = curves
        .iter()
        .flat_map(|c| c.omega.iter().copied())
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), w| {
            (lo.min(w), hi.max(w))
        });
    let (w_lo, w_hi) = if w_lo.is_finite() && w_hi > w_lo {
        (w_lo, w_hi)
    } else {
        (0.1, 100.0)
    };
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("cross-control coherence, {axis} sweep"),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d((w_lo..w_hi).log_scale(), 0.0..1.05)
        .map_err(|e| plot_error(path, e))?;
    chart
        .configure_mesh()
        .x_desc("ω [rad/s]")
        .y_desc("coherence γ²")
        .draw()
        .map_err(|e| plot_error(path, e))?;
    for (i, curve) in curves.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let points: Vec<(f64, f64)> = curve
            .omega
            .iter()
            .copied()
            .zip(curve.coherence.iter().copied())
            .collect();
        chart
            .draw_series(LineSeries::new(points, color.stroke_width(2)))
            .map_err(|e| plot_error(path, e))?
            .label(format!(
                "{}–{} (mean {:.2})",
                curve.a,
                curve.b,
                curve.mean()
            ))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    chart
        .draw_series(LineSeries::new(
            vec![(w_lo, 0.5), (w_hi, 0.5)],
            RED.mix(0.7),
        ))
        .map_err(|e| plot_error(path, e))?
        .label("guideline 0.5 (mean)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.mix(0.7)));
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    root.present().map_err(|e| plot_error(path, e))
}
