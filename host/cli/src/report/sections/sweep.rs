//! The sweep input: the stick inputs of the first lateral `cah` sweep, the applied sweep
//! amplitude on the swept control, and the attitudes (paper Fig. 1/6).

use std::path::Path;

use crate::plot::{colors, min_max_decimate, Figure, LegendEntry, Panel, Scale, Series};
use crate::report::curves::half_cycle_envelope;
use crate::report::html::{figure, note, section};
use crate::report::inputs::ReportInputs;

/// The lateral `cah` sweep: the stick inputs and the attitudes (paper Fig. 1/6).
pub fn sweep_input_section(inputs: &ReportInputs) -> String {
    let Some(record) = &inputs.flown.sweep else {
        return section(
            "sweep-input",
            "Sweep input time history",
            &note("No lateral cah record in this folder (the fly stage did not complete)."),
        );
    };
    let dt = 1.0 / record.sample_rate_hz;
    let series_of = |values: &[f64], scale: f64| -> Vec<(f64, f64)> {
        let points: Vec<(f64, f64)> = values
            .iter()
            .enumerate()
            .map(|(k, v)| (k as f64 * dt, v * scale))
            .collect();
        min_max_decimate(&points, 700)
    };
    let end = record.duration_s();
    let time = || Scale::linear(0.0, end, "time from the excitation record's start [s]");
    let mut panels = Vec::new();
    for (name, label) in [
        ("lat", "lateral stick (swept)"),
        ("lon", "longitudinal stick (off-axis)"),
        ("ped", "pedals (off-axis)"),
        ("col", "collective (off-axis)"),
    ] {
        if let Some(values) = record.input(name) {
            let primary = name == record.primary.as_str();
            let color = if primary {
                colors::MODEL
            } else {
                colors::TRUTH
            };
            let mut series = vec![Series::new(name, color, series_of(values, 1.0)).width(1)];
            // The sweep's applied amplitude (fixed, or shaped by `--amplitude adaptive`):
            // the peak of the injected excitation over each of its half cycles, about the
            // trim the stick holds at the start.
            if let Some(reference) = record.reference(name).filter(|_| primary) {
                let trim = values.first().copied().unwrap_or(0.0);
                let envelope = half_cycle_envelope(reference);
                let upper: Vec<f64> = envelope.iter().map(|a| trim + a).collect();
                let lower: Vec<f64> = envelope.iter().map(|a| trim - a).collect();
                series.push(
                    Series::new("applied amplitude", colors::TRUTH, series_of(&upper, 1.0))
                        .width(1),
                );
                series.push(Series::new("", colors::TRUTH, series_of(&lower, 1.0)).width(1));
            }
            let mut panel = Panel::new(label, time(), "fraction of travel", series);
            panel.y = panel.y.with_intervals(4);
            panel.height = 90;
            panels.push(panel);
        }
    }
    let attitudes: Vec<Series> = [("phi", colors::MODEL), ("theta", colors::TRUTH)]
        .iter()
        .filter_map(|(name, color)| {
            record.output(name).map(|values| {
                Series::new(
                    &format!("{name} [deg]"),
                    *color,
                    series_of(values, 180.0 / std::f64::consts::PI),
                )
                .width(1)
            })
        })
        .collect();
    if !attitudes.is_empty() {
        let mut panel = Panel::new("attitudes φ (blue), θ (red)", time(), "deg", attitudes);
        panel.height = 110;
        panels.push(panel);
    }
    let mut fig = Figure::new("Lateral sweep input, conditional attitude hold", panels);
    fig.legend = vec![
        LegendEntry::new("swept control", colors::MODEL),
        LegendEntry::new(
            "off-axis controls (hold corrections and noise); on the swept control: the applied amplitude",
            colors::TRUTH,
        ),
    ];
    let caption = format!(
        "{}: the applied commands of the first lateral sweep in cah mode ({:.0} s at {:.0} Hz, \
min/max per pixel column) and the attitudes. On the swept control, the red envelope is the \
applied sweep amplitude about the starting trim: the peak of the injected excitation over \
each of its half cycles (constant for the paper's fixed amplitude, shaped with frequency by \
`--amplitude adaptive`). The off-axis controls move only when the hold engages (attitude \
beyond its threshold) and with the small off-axis noise.",
        Path::new(&record.source)
            .strip_prefix(&inputs.dir)
            .map_or(record.source.clone(), |p| p.display().to_string()),
        end,
        record.sample_rate_hz
    );
    section(
        "sweep-input",
        "Sweep input time history (paper Fig. 1/6)",
        &figure(fig.to_html(), &caption),
    )
}
