//! The report's sections, top to bottom as a flight-test engineer reads them: campaign
//! summary against the bars of the issues, the sweep input (paper Fig. 1/6), cross-control
//! coherence (Fig. 3/7), Bode plots data vs model vs truth (Fig. 10), the parameter table
//! (Table 3), the modes of the identified model beside the truth's, the cost table, and
//! the verification time histories.

use std::path::Path;

use sysid::document::PairResponse;
use sysid::fit::modes::{
    eigenvalue_text, hover_summary, origin_text, ModeName, HOVER_MODE_LIMIT_RAD_S,
    HOVER_MODE_TOLERANCE_PERCENT, ORIGIN_LIMIT_RAD_S,
};
use sysid::fit::verify::BiasMode;
use sysid::fit::Model;

use super::html::{figure, note, section, table, Cell, Mark};
use super::inputs::ReportInputs;
use super::svg::{colors, min_max_decimate, BarChart, Figure, Panel, Scale, Series};
use crate::artifacts::stage::Stage;
use crate::artifacts::summary::{FitSummary, ModeSummary, ParameterSummary};

/// Section ids of the plot sections, in page order (each holds at least one `<svg>`).
pub const PLOT_SECTIONS: [&str; 4] = ["sweep-input", "cross-coherence", "bode", "verification"];

/// Parameters the fit issue requires within 10 % of the truth (τ_f, L_β1s, M_β1c, Z_col,
/// N_ped and the four flapping control derivatives).
pub const KEY_PARAMETERS: [&str; 9] = [
    "tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Lf_lat", "Lf_lon", "Mf_lat", "Mf_lon",
];

/// The paper's averaged lat–lon cross-control coherence of the lateral sweeps.
const PAPER_COHERENCE: [(&str, Option<f64>); 3] = [
    ("cah", Some(0.17)),
    ("standard", Some(0.95)),
    ("noise", None),
];

/// Width in SVG units of the figures shown two per row (about their pixel width at 1280).
const HALF_WIDTH: f64 = 600.0;

const ANGULAR_RATES: [&str; 3] = ["p", "q", "r"];

fn fmt(value: Option<f64>, digits: usize) -> String {
    super::html::number(value, digits)
}

fn mode_of<'a>(inputs: &'a ReportInputs, mode: &str) -> Option<&'a ModeSummary> {
    match mode {
        "cah" => inputs.summary.modes.cah.as_ref(),
        "standard" => inputs.summary.modes.standard.as_ref(),
        _ => inputs.summary.modes.noise.as_ref(),
    }
}

/// One row of the bars table: what, measured, bar, met.
fn bar_row(what: &str, measured: String, bar: &str, met: Option<bool>) -> Vec<Cell> {
    vec![
        Cell::name(what),
        match met {
            Some(ok) => Cell::judged(measured, ok),
            None => Cell::plain(measured),
        },
        Cell::plain(bar),
    ]
}

/// The campaign summary: setup, the issues' bars with pass/fail, timings.
pub fn summary_section(inputs: &ReportInputs) -> String {
    let s = &inputs.summary;
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
            super::svg::escape(&error.stage),
            super::svg::escape(&error.message)
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
        rows.push(bar_row(
            &format!("{mode}: aborted records"),
            format!("{} of {}", m.aborts, m.records),
            if mode == "cah" { "0" } else { "reported" },
            (mode == "cah").then_some(m.aborts == 0),
        ));
    }
    if let Some(fit) = &s.fit {
        rows.extend(fit_bar_rows(fit));
    }
    if let Some(verify) = &s.verify {
        for output in ANGULAR_RATES {
            if let Some(tic) = verify.tic.get(output) {
                rows.push(bar_row(
                    &format!(
                        "verification TIC, {output} (mean over the doublets, {} bias)",
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
    if let Some(total) = s.timings_s.get("total") {
        rows.push(bar_row(
            "wall time of the campaign",
            format!("{total:.1} s"),
            "≤ 30 s (default campaign)",
            (!s.quick).then_some(*total <= 30.0),
        ));
    }
    content += &table(&["check", "measured", "bar"], &rows);

    let timing_rows: Vec<Vec<Cell>> = stage_order(&s.timings_s)
        .into_iter()
        .map(|(stage, seconds)| vec![Cell::name(stage), Cell::plain(format!("{seconds:.2}"))])
        .collect();
    content += "<h3>Wall time per stage [s]</h3>\n";
    content += &table(&["stage", "seconds"], &timing_rows);
    section("campaign-summary", "Campaign summary", &content)
}

/// Stages in run order, `total` last.
fn stage_order(timings: &std::collections::BTreeMap<String, f64>) -> Vec<(String, f64)> {
    let mut order = Stage::ALL.map(Stage::name).to_vec();
    order.push("total");
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
    rows
}

fn fit_bar_rows(fit: &FitSummary) -> Vec<Vec<Cell>> {
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

/// The identified model's modes beside the truth's: one row per identified mode with the
/// truth mode paired with it, then the truth modes left without a counterpart.
pub fn modes_section(inputs: &ReportInputs) -> String {
    let title = "Modes: identified vs truth";
    let Some(fit) = &inputs.summary.fit else {
        return section("modes", title, &note("No fit in this campaign."));
    };
    if fit.modes.is_empty() {
        return section(
            "modes",
            title,
            &note(
                "The modes of this fit were not computed (a summary written before they \
were, or a model without eigenvalues).",
            ),
        );
    }
    let time = |double: Option<f64>, half: Option<f64>| match (double, half) {
        (Some(t), _) => format!("double {t:.2}"),
        (None, Some(t)) => format!("half {t:.2}"),
        (None, None) => "-".to_string(),
    };
    let is_hover = |eigenvalue: [f64; 2]| {
        let magnitude = eigenvalue[0].hypot(eigenvalue[1]);
        (ORIGIN_LIMIT_RAD_S..HOVER_MODE_LIMIT_RAD_S).contains(&magnitude)
    };
    let mut rows: Vec<Vec<Cell>> = fit
        .modes
        .iter()
        .map(|mode| {
            let origin = mode.name == ModeName::Origin.as_str();
            let error = match (mode.error_percent, mode.truth) {
                (Some(e), Some(truth)) if is_hover(truth) => {
                    Cell::judged(format!("{e:.1}"), e <= HOVER_MODE_TOLERANCE_PERCENT)
                }
                (e, _) => Cell::plain(fmt(e, 1)),
            };
            vec![
                if origin {
                    Cell::judged(mode.name.clone(), false)
                } else {
                    Cell::name(mode.name.clone())
                },
                Cell::plain(eigenvalue_text(mode.eigenvalue)),
                Cell::plain(fmt(mode.omega_n, 3)),
                Cell::plain(fmt(mode.zeta, 3)),
                Cell::plain(time(mode.time_to_double_s, mode.time_to_half_s)),
                Cell::plain(mode.shape()),
                Cell::plain(mode.truth_name.clone().unwrap_or_else(|| "-".into())),
                Cell::plain(mode.truth.map_or("-".to_string(), eigenvalue_text)),
                error,
            ]
        })
        .collect();
    for truth in fit.truth_modes.iter().filter(|t| t.identified.is_none()) {
        rows.push(vec![
            // A truth hover mode the identified model lacks is a miss.
            if truth.hover {
                Cell::judged("(none)", false)
            } else {
                Cell::name("(none)")
            },
            Cell::plain("-"),
            Cell::plain("-"),
            Cell::plain("-"),
            Cell::plain("-"),
            Cell::plain(""),
            Cell::plain(truth.name.clone()),
            Cell::plain(eigenvalue_text(truth.eigenvalue)),
            Cell::plain("-"),
        ]);
    }
    let verdict = match (fit.hover_modes_matched, fit.poles_at_origin) {
        (Some(hover), Some(poles)) => format!(" Here: {}.", hover_summary(&hover, poles)),
        _ => String::new(),
    };
    let content = note(&format!(
        "Eigenvalues λ of A = M⁻¹F of the identified model, one row per real pole or \
complex pair (its Im > 0 member), sorted by |λ|; ω_n = |λ|, ζ = −Re λ/|λ|, time to double \
(ln 2/Re λ) or to half (ln 2/−Re λ) the amplitude (of the envelope for a pair). Each mode is \
named from its eigenvector (shape: the largest shares, rates divided by ω_s = max(|λ|, 0.1 \
rad/s) and speeds multiplied by ω_s/g so that each reads as the attitude it amounts to; rules \
in sysid::fit::modes) and paired with a mode of the truth model (the same structure at the \
simulator's truth values): same name first, then the nearest eigenvalue. Error = \
100·|λ − λ_truth|/|λ_truth|, green/red against 25 % for the truth's hover modes (|λ| < 3 \
rad/s); a pole at the origin (|λ| < 1e−6 rad/s) is red.{verdict}"
    )) + &table(
        &[
            "identified mode",
            "λ [rad/s]",
            "ω_n [rad/s]",
            "ζ",
            "t2 / t½ [s]",
            "shape",
            "truth mode",
            "truth λ [rad/s]",
            "error %",
        ],
        &rows,
    );
    section("modes", title, &content)
}

/// The lateral `cah` sweep: the stick inputs and the attitudes (paper Fig. 1/6).
pub fn sweep_input_section(inputs: &ReportInputs) -> String {
    let Some(record) = &inputs.sweep else {
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
            let mut series = vec![Series::new(name, color, series_of(values, 1.0)).width(1.0)];
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
                        .width(1.0),
                );
                series.push(Series::new("", colors::TRUTH, series_of(&lower, 1.0)).width(1.0));
            }
            let mut panel = Panel::new(label, time(), "fraction of travel", series);
            panel.y = panel.y.with_intervals(4);
            panel.height = 90.0;
            panels.push(panel);
        }
    }
    let attitudes: Vec<Series> = [("phi", colors::MODEL), ("theta", colors::TRUTH)]
        .iter()
        .filter_map(|(name, color)| {
            record.output(name).map(|values| {
                Series::new(
                    &format!("{name} [deg]"),
                    color,
                    series_of(values, 180.0 / std::f64::consts::PI),
                )
                .width(1.0)
            })
        })
        .collect();
    if !attitudes.is_empty() {
        let mut panel = Panel::new("attitudes φ (blue), θ (red)", time(), "deg", attitudes);
        panel.height = 110.0;
        panels.push(panel);
    }
    let mut fig = Figure::new("Lateral sweep input, conditional attitude hold", panels);
    fig.legend = vec![
        ("swept control".into(), colors::MODEL, false),
        (
            "off-axis controls (hold corrections and noise); on the swept control: the applied amplitude"
                .into(),
            colors::TRUTH,
            false,
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
        &figure(&fig.to_svg(), &caption),
    )
}

/// The peak |x| of each half cycle of `values` (the stretches between sign changes),
/// repeated over that half cycle: the amplitude of a sweep whose amplitude changes only at
/// its zero crossings.
pub fn half_cycle_envelope(values: &[f64]) -> Vec<f64> {
    let mut envelope = vec![0.0; values.len()];
    let mut start = 0;
    for k in 1..=values.len() {
        let crossed = k == values.len() || (values[k] > 0.0) != (values[k - 1] > 0.0);
        if crossed {
            let peak = values[start..k].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            envelope[start..k].iter_mut().for_each(|e| *e = peak);
            start = k;
        }
    }
    envelope
}

/// Cross-control coherence: bars of the average per mode, curves versus frequency.
pub fn coherence_section(inputs: &ReportInputs) -> String {
    let mode_colors = [
        ("cah", colors::MODEL),
        ("standard", colors::TRUTH),
        ("noise", colors::GREEN),
    ];
    let bars: Vec<(String, f64, &'static str)> = mode_colors
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
        &chart.to_svg(),
        "Average lat–lon cross-control coherence of the two lateral records per mode \
(bias-corrected; the paper: 0.17 with conditional attitude hold, 0.95 with the standard hold).",
    );
    let mut series = Vec::new();
    let mut band: Option<[f64; 2]> = None;
    for coherence in &inputs.coherence {
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
        panel.height = 220.0;
        let fig = Figure::new("Cross-control coherence versus frequency", vec![panel]);
        content += &figure(
            &fig.to_svg(),
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

/// Unwrap a phase series [deg] so that consecutive points differ by less than 180°.
pub fn unwrap_deg(phase: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(phase.len());
    let mut offset = 0.0;
    let mut previous: Option<f64> = None;
    for &p in phase {
        if let Some(prev) = previous {
            if p.is_finite() && prev.is_finite() {
                let jump = p + offset - out.last().copied().unwrap_or(prev);
                offset -= 360.0 * (jump / 360.0).round();
            }
        }
        out.push(p + offset);
        if p.is_finite() {
            previous = Some(p);
        }
    }
    out
}

/// A model's response on the data's frequencies: magnitude [dB] and phase [deg], the
/// phase unwrapped and shifted by whole turns onto the data at the fit range's start.
fn model_response(
    model: &Model,
    pair: &PairResponse,
    anchor: Option<f64>,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let input = model.control_index(&pair.input)?;
    let output = model.output_index(&pair.output)?;
    let responses: Vec<_> = pair
        .omega
        .iter()
        .map(|&w| model.frequency_response(input, output, w))
        .collect();
    let magnitude: Vec<f64> = responses.iter().map(|t| 20.0 * t.norm().log10()).collect();
    let mut phase = unwrap_deg(
        &responses
            .iter()
            .map(|t| t.arg().to_degrees())
            .collect::<Vec<_>>(),
    );
    // Turns are arbitrary: align with the data where the fit starts.
    let at = anchor.unwrap_or(pair.omega[0]);
    let k = pair.omega.iter().position(|&w| w >= at).unwrap_or(0);
    if let (Some(data), Some(model)) = (pair.phase_deg.get(k), phase.get(k)) {
        if data.is_finite() && model.is_finite() {
            let shift = 360.0 * ((data - model) / 360.0).round();
            phase.iter_mut().for_each(|p| *p += shift);
        }
    }
    Some((magnitude, phase))
}

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
            magnitude.push(Series::new("identified", colors::MODEL, zip(&m)).width(2.0));
            phase.push(Series::new("identified", colors::MODEL, zip(&p)).width(2.0));
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
        mag_panel.y = pad_scale(widen_scale(
            Scale::fit_y(&magnitude.iter().map(in_range).collect::<Vec<_>>(), "dB"),
            6.0,
        ));
        mag_panel.shaded = Some(fitted.range);
        mag_panel.height = 120.0;
        let mut phase_panel = Panel::new("phase", x.clone(), "deg", phase.clone());
        phase_panel.y = pad_scale(widen_scale(
            Scale::fit_y(&phase.iter().map(in_range).collect::<Vec<_>>(), "deg"),
            30.0,
        ));
        phase_panel.shaded = Some(fitted.range);
        phase_panel.height = 120.0;
        let mut coherence_panel = Panel::new(
            "coherence (partial γ²)",
            x,
            "γ²",
            vec![Series::new("data", colors::DATA, zip(&pair.coherence))],
        );
        coherence_panel.y = Scale::linear(0.0, 1.0, "γ²").with_intervals(2);
        coherence_panel.shaded = Some(fitted.range);
        coherence_panel.references = vec![(0.6, "0.6".into())];
        coherence_panel.height = 60.0;
        let mut fig = Figure::new(
            &format!("{}/{} Bode plot", fitted.output, fitted.input),
            vec![mag_panel, phase_panel, coherence_panel],
        );
        fig.legend = vec![
            ("data".into(), colors::DATA, false),
            ("identified".into(), colors::MODEL, false),
            ("truth".into(), colors::TRUTH, true),
        ];
        fig.width = HALF_WIDTH;
        figures += &figure(
            &fig.to_svg(),
            &format!(
                "{}/{}: fit range {:.2}–{:.2} rad/s (shaded), J = {:.1}",
                fitted.output, fitted.input, fitted.range[0], fitted.range[1], fitted.cost
            ),
        );
    }
    let content = note(
        "Composite MISO-conditioned responses of the cah records (black), the identified \
9-DOF hybrid model (blue) and the same structure at the simulator's truth values (red, \
dashed), for every fitted pair. Shaded: the pair's fit range.",
    ) + "<div class=\"grid\">\n"
        + &figures
        + "</div>\n";
    section(
        "bode",
        "Frequency responses: data, identified model, truth (paper Fig. 10)",
        &content,
    )
}

/// `scale` extended by a quarter of its span on either side.
fn pad_scale(scale: Scale) -> Scale {
    let pad = 0.25 * (scale.max - scale.min);
    Scale::linear(scale.min - pad, scale.max + pad, &scale.label)
}

/// `scale` widened to span at least `minimum` (a nearly flat curve is not blown up).
fn widen_scale(scale: Scale, minimum: f64) -> Scale {
    let span = scale.max - scale.min;
    if span >= minimum {
        scale
    } else {
        let middle = (scale.max + scale.min) / 2.0;
        Scale::linear(middle - minimum / 2.0, middle + minimum / 2.0, &scale.label)
    }
}

/// The parameter table (paper Table 3) with truth and flags.
pub fn parameter_section(inputs: &ReportInputs) -> String {
    let Some(fit) = &inputs.summary.fit else {
        return section(
            "parameters",
            "Identified parameters",
            &note("No fit in this campaign."),
        );
    };
    let rows: Vec<Vec<Cell>> = fit
        .params
        .iter()
        .map(|p| {
            let free = p.status == "free";
            let cr_flag = free && p.cr_percent.is_none_or(|v| v > 20.0);
            let insensitivity_flag = free && p.insensitivity_percent.is_none_or(|v| v > 10.0);
            let key = KEY_PARAMETERS.contains(&p.name.as_str());
            let error_cell = match (p.error_percent, key) {
                (Some(e), true) => Cell::judged(format!("{e:+.1}"), e.abs() <= 10.0),
                (e, _) => Cell::plain(e.map_or("-".to_string(), |e| format!("{e:+.1}"))),
            };
            vec![
                Cell::name(if key {
                    format!("{} *", p.name)
                } else {
                    p.name.clone()
                }),
                Cell::plain(format!("{:.5}", p.value)),
                Cell::marked(
                    fmt(p.cr_percent, 2),
                    if cr_flag { Mark::Flag } else { Mark::Plain },
                ),
                Cell::marked(
                    fmt(p.insensitivity_percent, 2),
                    if insensitivity_flag {
                        Mark::Flag
                    } else {
                        Mark::Plain
                    },
                ),
                Cell::plain(fmt(p.truth, 5)),
                error_cell,
                Cell::plain(p.status.clone()),
                Cell::marked(
                    p.flags.join(", "),
                    if p.flags.is_empty() {
                        Mark::Plain
                    } else {
                        Mark::Flag
                    },
                ),
            ]
        })
        .collect();
    let content = note(&format!(
        "{} after reduction. CR: Cramér–Rao bound, insensitivity: both in % of |value| \
(guidelines ≤ 20 % and ≤ 10 %; orange: beyond). Truth: the simulator's linearization at hover \
mapped onto the structure; error = 100·(value − truth)/|truth|. * marks the parameters the \
fit issue requires within 10 % of the truth (green/red).",
        fit.structure
    )) + &table(
        &[
            "parameter",
            "value",
            "CR %",
            "insens. %",
            "truth",
            "error %",
            "status",
            "flags",
        ],
        &rows,
    );
    section(
        "parameters",
        "Identified parameters (paper Table 3)",
        &content,
    )
}

/// J per pair, fit and against the truth.
pub fn cost_section(inputs: &ReportInputs) -> String {
    let Some(fit) = &inputs.summary.fit else {
        return section("costs", "Cost per pair", &note("No fit in this campaign."));
    };
    let mut rows: Vec<Vec<Cell>> = fit
        .pairs
        .iter()
        .map(|p| {
            let rate = ANGULAR_RATES.contains(&p.output.as_str());
            vec![
                Cell::name(format!("{}/{}", p.output, p.input)),
                Cell::plain(format!("{:.2}–{:.2}", p.range[0], p.range[1])),
                Cell::judged(format!("{:.1}", p.cost), p.cost <= 100.0),
                match p.truth_cost {
                    Some(c) if rate => Cell::judged(format!("{c:.1}"), c <= 20.0),
                    other => Cell::plain(fmt(other, 1)),
                },
            ]
        })
        .collect();
    rows.push(vec![
        Cell::name("J_ave"),
        Cell::plain(""),
        Cell::judged(format!("{:.1}", fit.cost_ave), fit.cost_ave <= 50.0),
        Cell::plain(fmt(fit.truth_cost_ave, 1)),
    ]);
    let content = note(&format!(
        "J = 20/n_ω Σ W_γ[W_g(Δ|T| dB)² + W_p(Δ∠T deg)²] on 20 points per pair: ≤ 100 \
acceptable per pair (green), J_ave ≤ 50 the bar. J truth: the identified model against the \
truth model over the same range (bar ≤ 20 for the angular rates). The 6-DOF start had \
J_ave {:.1}.",
        fit.start_cost_ave
    )) + &table(&["pair", "range [rad/s]", "J", "J truth"], &rows);
    section("costs", "Cost per pair (J table)", &content)
}

/// Outputs drawn per verification record, in this order when compared.
const VERIFY_PLOTTED: [&str; 6] = ["p", "q", "r", "phi", "theta", "az"];

/// Verification on the held-out doublets: TIC table and measured vs predicted.
pub fn verification_section(inputs: &ReportInputs) -> String {
    let Some(verify) = &inputs.verify else {
        return section(
            "verification",
            "Verification",
            &note("No verification in this campaign."),
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
            let rates: Vec<f64> = record
                .outputs
                .iter()
                .filter(|o| ANGULAR_RATES.contains(&o.name.as_str()))
                .map(|o| o.tic)
                .collect();
            row.push(Cell::plain(if rates.is_empty() {
                "-".to_string()
            } else {
                format!("{:.3}", rates.iter().sum::<f64>() / rates.len() as f64)
            }));
            row.push(Cell::plain(format!("{:.3}", record.tic_mean)));
            row
        })
        .collect();
    let header_refs: Vec<&str> = headers.iter().map(String::as_str).collect();
    let mut content = note(&format!(
        "The identified model simulated on the commands of held-out doublet records (seed {}, \
not used in the fit){}; {}. TIC = rms(y − b − ŷ) / (rms(y − b) + rms(ŷ)): 0 perfect, \
≤ 0.25 the bar for p, q, r.",
        inputs.summary.verification_seed,
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
                Series::new("predicted", colors::MODEL, predicted).width(2.0),
            ];
            let mut panel = Panel::new(
                &format!("{name}  TIC {:.3}", o.tic),
                Scale::linear(0.0, end, "t [s]"),
                name,
                series.clone(),
            );
            // The measured range sets the scale: a runaway prediction leaves the plot.
            panel.y = widen_scale(Scale::fit_y(&series[..1], name), 1e-3).with_intervals(3);
            panel.height = 90.0;
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
        content += &figure(&fig.to_svg(), &caption);
    }
    section(
        "verification",
        "Verification on held-out doublets: measured vs predicted",
        &content,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use sysid::fit::modes::{HoverModeScore, ModeRecord, TruthModeRecord};

    #[test]
    fn unwrap_removes_turns() {
        let wrapped = [170.0, -175.0, -160.0, 175.0];
        let unwrapped = unwrap_deg(&wrapped);
        assert_eq!(unwrapped, vec![170.0, 185.0, 200.0, 175.0]);
    }

    #[test]
    fn model_phase_is_put_on_the_data_branch_at_the_fit_range() {
        // p/lat = 3/(s + 2): phase from −2.9° to −84° over 0.1–20 rad/s.
        let mut model = Model::zeros(vec!["p".into()], vec!["lat".into()], vec!["p".into()]);
        model.m[(0, 0)] = 1.0;
        model.f[(0, 0)] = -2.0;
        model.g[(0, 0)] = 3.0;
        model.h0[(0, 0)] = 1.0;
        let omega: Vec<f64> = (0..30).map(|k| 0.1 * 1.2f64.powi(k)).collect();
        let exact: Vec<f64> = omega
            .iter()
            .map(|w| -(w / 2.0).atan().to_degrees())
            .collect();
        let pair = PairResponse {
            input: "lat".into(),
            output: "p".into(),
            omega: omega.clone(),
            mag_db: vec![0.0; omega.len()],
            // The data sit one turn down, as an unwrapped estimate may.
            phase_deg: exact.iter().map(|p| p - 360.0).collect(),
            coherence: vec![1.0; omega.len()],
            random_error: vec![0.0; omega.len()],
            valid_range: None,
            group: None,
            multiple_coherence: Vec::new(),
        };
        let (magnitude, phase) = model_response(&model, &pair, Some(0.5)).unwrap();
        let gain_db = 20.0 * (3.0 / (omega[0].powi(2) + 4.0).sqrt()).log10();
        assert!((magnitude[0] - gain_db).abs() < 1e-9);
        for (p, e) in phase.iter().zip(&exact) {
            assert!((p - (e - 360.0)).abs() < 1e-9, "{p} vs {e}");
        }
        let other = PairResponse {
            input: "lon".into(),
            ..pair
        };
        assert!(model_response(&model, &other, None).is_none());
    }

    /// A report's inputs holding only a summary with `fit`.
    fn inputs_with_fit(fit: FitSummary) -> ReportInputs {
        use crate::artifacts::summary::{CampaignSummary, Modes};
        ReportInputs {
            dir: std::path::PathBuf::from("campaign"),
            summary: CampaignSummary {
                vehicle: "bo105".into(),
                seed: 1,
                verification_seed: 2,
                t_rec_s: 90.0,
                quick: false,
                modes: Modes::default(),
                fit: Some(fit),
                verify: None,
                timings_s: Default::default(),
                error: None,
            },
            frf: None,
            model: None,
            truth_model: None,
            verify: None,
            sweep: None,
            coherence: Vec::new(),
        }
    }

    fn mode(name: &str, eigenvalue: [f64; 2], truth: Option<([f64; 2], f64)>) -> ModeRecord {
        ModeRecord {
            name: name.into(),
            eigenvalue,
            omega_n: Some(eigenvalue[0].hypot(eigenvalue[1])),
            zeta: None,
            time_to_double_s: None,
            time_to_half_s: Some(1.0),
            poles: if eigenvalue[1] == 0.0 { 1 } else { 2 },
            shares: Default::default(),
            truth: truth.map(|t| t.0),
            truth_name: truth.map(|_| name.to_string()),
            error_percent: truth.map(|t| t.1),
        }
    }

    fn fit_with_modes(
        modes: Vec<ModeRecord>,
        truth_modes: Vec<TruthModeRecord>,
        hover: HoverModeScore,
        poles: usize,
    ) -> FitSummary {
        FitSummary {
            structure: "bo105-9dof-hybrid".into(),
            cost_ave: 16.0,
            truth_cost_ave: Some(10.0),
            start_cost_ave: 17.0,
            pairs: Vec::new(),
            params: Vec::new(),
            model_file: "model9.json".into(),
            modes,
            truth_modes,
            hover_modes_matched: Some(hover),
            poles_at_origin: Some(poles),
            speed_derivatives: Vec::new(),
            trim: None,
        }
    }

    #[test]
    fn the_half_cycle_envelope_is_each_half_cycles_peak() {
        // Two half cycles of amplitude 1, then two of amplitude 3 (a step at a zero
        // crossing, as the adaptive sweep makes it).
        let values: Vec<f64> = (0..40)
            .map(|k| {
                let amplitude = if k < 20 { 1.0 } else { 3.0 };
                amplitude * (std::f64::consts::PI * (k as f64 + 0.5) / 10.0).sin()
            })
            .collect();
        let envelope = half_cycle_envelope(&values);
        let peak_1 = (std::f64::consts::PI * 4.5 / 10.0).sin();
        assert!((envelope[0] - peak_1).abs() < 1e-12 && (envelope[19] - peak_1).abs() < 1e-12);
        assert!((envelope[20] - 3.0 * peak_1).abs() < 1e-12);
        assert!((envelope[39] - 3.0 * peak_1).abs() < 1e-12);
        assert!(half_cycle_envelope(&[]).is_empty());
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
        let rows = fit_bar_rows(&fit);
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

    #[test]
    fn widen_scale_keeps_wide_ranges() {
        let s = widen_scale(Scale::linear(0.0, 1.0, "x"), 6.0);
        assert!((s.max - s.min - 6.0).abs() < 1e-12);
        let s = widen_scale(Scale::linear(0.0, 10.0, "x"), 6.0);
        assert_eq!((s.min, s.max), (0.0, 10.0));
    }
}
