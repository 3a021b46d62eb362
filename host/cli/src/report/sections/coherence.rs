//! Cross-control coherence: bars of the average per mode (from the summary), curves versus
//! frequency (paper Fig. 3/7).

use plotters::style::RGBColor;

use super::shared::mode_of;
use crate::plot::{colors, BarChart, Figure, Panel, Scale, Series};
use crate::report::html::{figure, note, section};
use crate::report::inputs::ReportInputs;

/// Cross-control coherence: bars of the average per mode, curves versus frequency.
pub fn coherence_section(inputs: &ReportInputs) -> String {
    let mode_colors = [
        ("cah", colors::MODEL),
        ("standard", colors::TRUTH),
        ("noise", colors::GREEN),
    ];
    let bars: Vec<(String, f64, RGBColor)> = mode_colors
        .iter()
        .filter_map(|(mode, color)| {
            mode_of(inputs, mode).map(|m| {
                (
                    mode.to_string(),
                    m.cross_coherence_lat_lon.unwrap_or(f64::NAN),
                    *color,
                )
            })
        })
        .collect();
    if bars.is_empty() {
        return section(
            "cross-coherence",
            "Cross-control coherence",
            &note("No mode was flown."),
        );
    }
    let chart = BarChart {
        title: "Average lat–lon cross-control coherence of the lateral sweeps per mode".into(),
        bars,
        y: Scale::linear(0.0, 1.0, "mean coherence γ²"),
        references: vec![
            (0.2, "cah bar 0.2".into()),
            (0.8, "standard bar 0.8".into()),
        ],
    };
    let mut content = figure(
        chart.to_html(),
        "Average lat–lon cross-control coherence of the two lateral records per mode \
(bias-corrected; the paper: 0.17 with conditional attitude hold, 0.95 with the standard hold).",
    );
    let mut series = Vec::new();
    let mut band: Option<[f64; 2]> = None;
    for coherence in &inputs.flown.coherence {
        let color = mode_colors
            .iter()
            .find(|(m, _)| *m == coherence.mode)
            .map_or(colors::PURPLE, |c| c.1);
        if let Some(curve) = coherence
            .curves
            .iter()
            .find(|c| (c.a == "lat" && c.b == "lon") || (c.a == "lon" && c.b == "lat"))
        {
            if let (Some(first), Some(last)) = (curve.omega.first(), curve.omega.last()) {
                band =
                    Some(band.map_or([*first, *last], |[lo, hi]| [lo.min(*first), hi.max(*last)]));
            }
            series.push(Series::new(
                &coherence.mode,
                color,
                curve
                    .omega
                    .iter()
                    .copied()
                    .zip(curve.coherence.iter().copied())
                    .collect(),
            ));
        }
    }
    if let Some([lo, hi]) = band {
        let mut panel = Panel::new(
            "lat–lon coherence, joined lateral sweeps",
            Scale::log(lo, hi, "ω [rad/s]"),
            "γ²",
            series,
        );
        panel.y = Scale::linear(0.0, 1.0, "γ² (lat, lon)");
        panel.height = 220;
        let fig = Figure::new("Cross-control coherence versus frequency", vec![panel]);
        content += &figure(
            fig.to_html(),
            "Coherence between the lateral and longitudinal stick over the lateral sweeps, per \
mode (recomputed from the dumps): with the hold always on the lon stick follows the lat \
sweep and the responses cannot be separated; conditional hold keeps it low.",
        );
    }
    section(
        "cross-coherence",
        "Cross-control coherence, cah vs standard vs noise (paper Fig. 3/7)",
        &content,
    )
}
