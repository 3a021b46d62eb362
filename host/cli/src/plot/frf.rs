//! The plots of `sweephold frf --plots`: one Bode plot per pair (magnitude, phase and
//! coherence stacked on a common log-frequency axis; the conditioned response in blue, the
//! SISO one in grey, the multiple coherence in orange, the valid range shaded, the
//! coherence threshold as a dashed line), and one cross-control coherence plot per swept
//! axis (like the paper's Fig. 3 and 7).

use sysid::document::PairResponse;
use sysid::frf::analysis::{CoherenceCurve, MultipleCoherence};
use sysid::frf::FrfAnalysis;

use super::draw::PlotError;
use super::figure::{colors, Figure, LegendEntry, Panel, Scale, Series};

/// Width of the plots [px].
const WIDTH: u32 = 800;

/// The plots of `analysis`, as `(file name, SVG text)`: `frf_<input>_<output>.svg` per
/// pair and `cross_coherence_<axis>.svg` per record group. The caller writes them (the
/// CLI writes each file whole, atomically).
pub fn frf_plots(analysis: &FrfAnalysis) -> Result<Vec<(String, String)>, PlotError> {
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
        let figure = bode_figure(pair, siso, multiple, document.coherence_threshold);
        plots.push((name, figure.to_svg()?));
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
        plots.push((name, coherence_figure(axis, &curves).to_svg()?));
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

/// The frequency band of `omegas`, or 0.1–100 rad/s when they give none.
fn band(omegas: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = omegas.fold((f64::INFINITY, 0.0f64), |(lo, hi), w| {
        (lo.min(w), hi.max(w))
    });
    if lo.is_finite() && lo > 0.0 && hi > lo {
        (lo, hi)
    } else {
        (0.1, 100.0)
    }
}

/// Magnitude, phase and coherence of one pair.
fn bode_figure(
    pair: &PairResponse,
    siso: Option<&PairResponse>,
    multiple: Option<&MultipleCoherence>,
    threshold: f64,
) -> Figure {
    let (w_lo, w_hi) = band(
        pair.omega
            .iter()
            .chain(siso.iter().flat_map(|s| s.omega.iter()))
            .copied(),
    );
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
    let mut panels = Vec::new();
    for (which, label) in labels.iter().enumerate() {
        let mut lines = Vec::new();
        if let Some(s) = siso {
            lines.push(Series::new("SISO", colors::GREY, series(s, which)));
        }
        lines.push(Series::new("MISO conditioned", colors::MODEL, series(pair, which)).width(2));
        if let (2, Some(m)) = (which, multiple) {
            let points = m
                .omega
                .iter()
                .copied()
                .zip(m.coherence.iter().copied())
                .collect();
            lines.push(Series::new("multiple coherence", colors::ORANGE, points));
        }
        let y = if which == 2 {
            Scale::linear(0.0, 1.05, label)
        } else {
            let (lo, hi) = span(lines.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
            Scale::linear(lo, hi, label)
        };
        let title = match which {
            0 => format!("{} → {}", pair.input, pair.output),
            1 => "phase".to_string(),
            _ => "coherence".to_string(),
        };
        let mut panel = Panel::new(&title, Scale::log(w_lo, w_hi, "ω [rad/s]"), label, lines);
        panel.y = y;
        panel.shaded = pair.valid_range;
        panel.height = 220;
        if which == 2 {
            panel.references = vec![(threshold, format!("threshold {threshold}"))];
        }
        panels.push(panel);
    }
    let mut figure = Figure::new(
        &format!("{} → {} Bode plot", pair.input, pair.output),
        panels,
    );
    if multiple.is_some() {
        figure
            .legend
            .push(LegendEntry::new("multiple coherence", colors::ORANGE));
    }
    figure.width = WIDTH;
    figure
}

/// The cross-control coherence curves of one swept axis.
fn coherence_figure(axis: &str, curves: &[&CoherenceCurve]) -> Figure {
    let (w_lo, w_hi) = band(curves.iter().flat_map(|c| c.omega.iter().copied()));
    let lines: Vec<Series> = curves
        .iter()
        .enumerate()
        .map(|(i, curve)| {
            let points = curve
                .omega
                .iter()
                .copied()
                .zip(curve.coherence.iter().copied())
                .collect();
            Series::new(
                &format!("{}–{} (mean {:.2})", curve.a, curve.b, curve.mean()),
                colors::CYCLE[i % colors::CYCLE.len()],
                points,
            )
            .width(2)
        })
        .collect();
    let mut panel = Panel::new(
        &format!("cross-control coherence, {axis} sweep"),
        Scale::log(w_lo, w_hi, "ω [rad/s]"),
        "coherence γ²",
        lines,
    );
    panel.y = Scale::linear(0.0, 1.05, "coherence γ²");
    panel.references = vec![(0.5, "guideline 0.5 (mean)".into())];
    panel.height = 330;
    let mut figure = Figure::new(
        &format!("cross-control coherence, {axis} sweep"),
        vec![panel],
    );
    figure.width = WIDTH;
    figure
}
