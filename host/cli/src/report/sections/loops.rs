//! The board's pilot-mode loops on the identified model (`margins.json`,
//! `margins-loops.json`): the table of margins and disturbance-rejection bandwidths with
//! their spreads, a Bode plot of each broken loop with its crossovers marked, and the
//! ADS-33 bandwidth–phase-delay chart of each axis with the aircraft's points.

use nalgebra::Complex;

use super::shared::HALF_WIDTH;
use crate::margins::ExportedResponse;
use crate::plot::{colors, Figure, LegendEntry, Panel, Scale, Series};
use crate::report::html::{figure, note, section, table, Cell};
use crate::report::inputs::ReportInputs;
use crate::report::margins_file::{ChartRow, HandlingRow, LoopRow, MarginsFile, MeasuredRow};
use control::analysis::Figure as Spread;

const TITLE: &str = "Loop margins and handling qualities of the identified model";

/// Least phase margin [deg] and gain margin [dB] the table marks as met (the usual
/// design guidelines: 45°, 6 dB).
const PHASE_MARGIN_GUIDE_DEG: f64 = 45.0;
const GAIN_MARGIN_GUIDE_DB: f64 = 6.0;

/// The section: figures from margins.json, curves from margins-loops.json; an older
/// campaign without them gets a note.
pub fn loops_section(inputs: &ReportInputs) -> String {
    let Some(margins) = &inputs.margins else {
        return section(
            "loops",
            TITLE,
            &note(
                "No margins.json in this folder (a campaign from before the margins stage, \
one that stopped before it, or one whose model the analysis could not take: its margins \
line says why): `sweephold margins model9.json` computes the figures.",
            ),
        );
    };
    let mut content = note(&explanation(margins));
    content += &loop_table(&margins.loops);
    content += &measured_table(&margins.measured);
    content += &handling_table(&margins.handling);
    let mut figures = String::new();
    match &inputs.margins_loops {
        Some(sampled) => {
            for row in &margins.loops {
                let measured: Vec<&MeasuredRow> = margins
                    .measured
                    .iter()
                    .filter(|m| m.name == row.name)
                    .collect();
                match sampled.loops.iter().find(|l| l.name == row.name) {
                    Some(response) => figures += &loop_figure(row, response, &measured),
                    None => figures += &note(&format!("{}: no sampled loop.", row.name)),
                }
            }
        }
        None => {
            figures += &note("No margins-loops.json in this folder: no Bode plots of the loops.")
        }
    }
    for axis in ["roll", "pitch", "yaw"] {
        let rows: Vec<&HandlingRow> = margins.handling.iter().filter(|h| h.axis == axis).collect();
        if !rows.is_empty() {
            figures += &chart_figure(axis, &rows);
        }
    }
    content += &format!("<div class=\"grid\">\n{figures}</div>\n");
    section("loops", TITLE, &content)
}

fn explanation(margins: &MarginsFile) -> String {
    let law = &margins.law;
    let spread = if margins.drawn_parameters == 0 {
        format!("no spread ({})", margins.notes.join("; "))
    } else {
        format!(
            "± is the standard deviation over {} models drawn from the fit's Cramér–Rao \
bounds and correlations ({} parameters, seed {})",
            margins.samples - margins.failed_draws,
            margins.drawn_parameters,
            margins.seed
        )
    };
    format!(
        "The firmware's pilot-mode law (tick {:.1} ms, IMU filter bank {}, compute delay \
{:.1} ms, servo frame {}) around the identified model ({}), each loop broken at its \
actuator input with the others closed: gain crossover ω_c (the highest) and its phase \
margin, the least phase margin over all crossovers, the gain margin at the phase crossover \
ω_180, the disturbance-rejection bandwidth (|1/(1+L)| = −3 dB); green/red against PM 45°, \
GM 6 dB. Per stick, the ADS-33E-PRF bandwidth ω_BW and phase delay τ_p of the attitude \
response and its level for hover and low speed (target acquisition and tracking / all other \
MTEs), on charts whose corner points are recalled, not read from the specification \
(docs/method.md). {spread}.",
        law.tick_s * 1e3,
        if law.filter_bank { "on" } else { "off" },
        law.compute_delay_s * 1e3,
        law.servo_frame_hz
            .map_or("none".to_string(), |hz| format!("{hz} Hz")),
        margins.structure,
    )
}

/// `value ± spread` with `decimals`, or `-`.
fn text(figure: &Spread, decimals: usize) -> String {
    match (figure.value, figure.spread) {
        (Some(v), Some(s)) => format!("{v:.decimals$} ± {s:.decimals$}"),
        (Some(v), None) => format!("{v:.decimals$}"),
        (None, _) => "-".to_string(),
    }
}

/// A cell judged against `guide` when the figure is defined.
fn judged(figure: &Spread, decimals: usize, guide: f64) -> Cell {
    match figure.value {
        Some(v) => Cell::judged(text(figure, decimals), v >= guide),
        None => Cell::plain("-"),
    }
}

fn loop_table(loops: &[LoopRow]) -> String {
    let rows: Vec<Vec<Cell>> = loops
        .iter()
        .map(|l| {
            vec![
                Cell::name(l.name.clone()),
                Cell::plain(l.broken_at.clone()),
                Cell::plain(l.mode.clone()),
                Cell::plain(text(&l.crossover_rad_s, 2)),
                Cell::plain(text(&l.phase_margin_deg, 1)),
                judged(&l.min_phase_margin_deg, 1, PHASE_MARGIN_GUIDE_DEG),
                judged(&l.gain_margin_db, 1, GAIN_MARGIN_GUIDE_DB),
                Cell::plain(text(&l.phase_crossover_rad_s, 2)),
                Cell::plain(text(&l.drb_rad_s, 2)),
            ]
        })
        .collect();
    table(
        &[
            "loop",
            "broken at",
            "mode",
            "ω_c [rad/s]",
            "PM [deg]",
            "least PM [deg]",
            "GM [dB]",
            "ω_180 [rad/s]",
            "DRB [rad/s]",
        ],
        &rows,
    )
}

/// The loop tests measured beside the prediction (none: nothing).
fn measured_table(measured: &[MeasuredRow]) -> String {
    if measured.is_empty() {
        return String::new();
    }
    let cell = |v: Option<f64>, decimals: usize| {
        Cell::plain(v.map_or("-".to_string(), |v| format!("{v:.decimals$}")))
    };
    let pair =
        |measured: Option<f64>, error: Option<f64>, predicted: Option<f64>, decimals: usize| {
            let text = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.decimals$}"));
            let measured = match (measured, error) {
                (Some(v), Some(e)) => format!("{v:.decimals$} ± {e:.decimals$}"),
                _ => text(measured),
            };
            Cell::plain(format!("{measured} / {}", text(predicted)))
        };
    let rows: Vec<Vec<Cell>> = measured
        .iter()
        .map(|m| {
            vec![
                Cell::name(m.name.clone()),
                Cell::plain(m.source.clone()),
                pair(m.crossover_rad_s, None, m.predicted.crossover_rad_s, 2),
                pair(
                    m.phase_margin_deg,
                    m.phase_margin_random_error_deg,
                    m.predicted.phase_margin_deg,
                    1,
                ),
                cell(m.phase_margin_difference_deg, 1),
                pair(
                    m.gain_margin_db,
                    m.gain_margin_random_error_db,
                    m.predicted.gain_margin_db,
                    1,
                ),
                cell(m.gain_margin_difference_db, 2),
                Cell::plain(format!("{}/{}", m.valid_points, m.points)),
            ]
        })
        .collect();
    note(
        "Measured in the loop tests (the sweep added at the loop's actuator input with the \
loops closed; each loop's margins from its measured broken loop on the points of random \
error ≤ 0.15, ± one standard deviation from the random error at the crossover and at the \
phase crossover), beside the predicted figures of the loop it breaks.",
    ) + &table(
        &[
            "loop",
            "loop test",
            "ω_c meas / pred [rad/s]",
            "PM meas / pred [deg]",
            "ΔPM [deg]",
            "GM meas / pred [dB]",
            "ΔGM [dB]",
            "valid points",
        ],
        &rows,
    )
}

fn level_text(level: Option<u8>) -> String {
    level.map_or("-".to_string(), |l| l.to_string())
}

fn handling_table(handling: &[HandlingRow]) -> String {
    let rows: Vec<Vec<Cell>> = handling
        .iter()
        .map(|h| {
            vec![
                Cell::name(h.axis.clone()),
                Cell::plain(h.mode.clone()),
                Cell::plain(text(&h.bandwidth_rad_s, 2)),
                Cell::plain(text(&h.phase_delay_s, 3)),
                Cell::plain(level_text(h.level_tracking)),
                Cell::plain(level_text(h.level_other)),
            ]
        })
        .collect();
    table(
        &[
            "stick",
            "mode",
            "ω_BW [rad/s]",
            "τ_p [s]",
            "level, tracking",
            "level, other MTEs",
        ],
        &rows,
    )
}

/// A vertical line at `x` across `y`.
fn vertical(name: &str, color: plotters::style::RGBColor, x: f64, y: &Scale) -> Series {
    Series::new(name, color, vec![(x, y.min), (x, y.max)])
}

/// Magnitude and phase of one broken loop, its gain crossovers and phase crossover marked,
/// and the loop tests that measured it over their valid points.
fn loop_figure(row: &LoopRow, response: &ExportedResponse, measured: &[&MeasuredRow]) -> String {
    let values: Vec<Complex<f64>> = response
        .re
        .iter()
        .zip(&response.im)
        .map(|(re, im)| Complex::new(*re, *im))
        .collect();
    let (db, mut phase) = control::margins::bode(&values);
    let omega = &response.omega;
    if omega.len() < 2 || omega.len() != db.len() {
        return note(&format!("{}: the sampled loop is empty.", row.name));
    }
    // Whole turns chosen so that the phase crossover, where there is one, reads −180°.
    let anchor = row
        .phase_crossover_rad_s
        .value
        .or(row.crossover_rad_s.value)
        .and_then(|w| omega.iter().position(|o| *o >= w));
    if let Some(&reference) = anchor.and_then(|i| phase.get(i)) {
        let turns = ((reference + 180.0) / 360.0).round();
        phase.iter_mut().for_each(|p| *p -= 360.0 * turns);
    }
    let zip = |values: &[f64]| -> Vec<(f64, f64)> {
        omega.iter().copied().zip(values.iter().copied()).collect()
    };
    let x = Scale::log(omega[0], omega[omega.len() - 1], "ω [rad/s]");
    let curve = |values: &[f64]| Series::new("L(jω)", colors::MODEL, zip(values)).width(2);
    let mut panels = Vec::new();
    for (title, unit, values, reference) in [
        ("magnitude", "dB", &db, (0.0, "0 dB")),
        ("phase", "deg", &phase, (-180.0, "−180°")),
    ] {
        let line = curve(values);
        let y = Scale::fit_y(std::slice::from_ref(&line), unit);
        // The reference line inside the axis, so that it is drawn.
        let y = Scale::linear(
            y.min.min(reference.0 - 10.0),
            y.max.max(reference.0 + 10.0),
            unit,
        );
        let mut series = vec![line];
        for test in measured {
            let points = test.response.valid_values(
                crate::measured_loop::MAX_RANDOM_ERROR,
                test.resolved_from_rad_s,
            );
            let (omegas, measured_values): (Vec<f64>, Vec<Complex<f64>>) =
                points.into_iter().unzip();
            // Point by point (no unwrapping across the invalid points, which are NaN): each
            // phase is put in the predicted curve's turn below.
            let measured_db: Vec<f64> = measured_values
                .iter()
                .map(|v| 20.0 * v.norm().log10())
                .collect();
            let measured_phase: Vec<f64> = measured_values
                .iter()
                .map(|v| v.arg().to_degrees())
                .collect();
            let shown: Vec<(f64, f64)> = if unit == "dB" {
                omegas.into_iter().zip(measured_db).collect()
            } else {
                // Each measured phase in the turn nearest the predicted one there.
                omegas
                    .into_iter()
                    .zip(measured_phase)
                    .map(|(w, v)| {
                        let k = omega.partition_point(|o| *o < w).min(omega.len() - 1);
                        let turns = ((values[k] - v) / 360.0).round();
                        (w, v + 360.0 * turns)
                    })
                    .collect()
            };
            series.push(Series::new("measured", colors::DATA, shown));
        }
        for [w, _] in &row.all_crossovers {
            series.push(vertical("ω_c", colors::GREEN, *w, &y));
        }
        if let Some(w) = row.phase_crossover_rad_s.value {
            series.push(vertical("ω_180", colors::TRUTH, w, &y).dashed());
        }
        let mut panel = Panel::new(&format!("{} {title}", row.name), x.clone(), unit, series);
        panel.y = y;
        panel.references = vec![(reference.0, reference.1.to_string())];
        panel.height = 120;
        panels.push(panel);
    }
    let mut fig = Figure::new(&format!("{} broken-loop Bode plot", row.name), panels);
    fig.legend = vec![
        LegendEntry::new("L(jω)", colors::MODEL),
        LegendEntry::new("gain crossovers ω_c", colors::GREEN),
        LegendEntry::new("phase crossover ω_180", colors::TRUTH).dashed(),
    ];
    if !measured.is_empty() {
        fig.legend.push(LegendEntry::new("loop test", colors::DATA));
    }
    fig.width = HALF_WIDTH;
    let tests: Vec<&str> = measured.iter().map(|m| m.source.as_str()).collect();
    let measured_text = if tests.is_empty() {
        String::new()
    } else {
        format!(
            "; black: measured in the loop test {} on its points of random error ≤ {}",
            tests.join(", "),
            crate::measured_loop::MAX_RANDOM_ERROR
        )
    };
    figure(
        fig.to_html(),
        &format!(
            "{} broken at {}: ω_c {} rad/s, PM {}° (least {}°), GM {} dB at ω_180 {} rad/s, \
DRB {} rad/s{measured_text}",
            row.name,
            row.broken_at,
            text(&row.crossover_rad_s, 2),
            text(&row.phase_margin_deg, 1),
            text(&row.min_phase_margin_deg, 1),
            text(&row.gain_margin_db, 1),
            text(&row.phase_crossover_rad_s, 2),
            text(&row.drb_rad_s, 2),
        ),
    )
}

/// A boundary's corners as a line on the chart: each segment straight in ω (the charts'
/// axes are linear), cut at `x_max`.
fn boundary_line(corners: &[[f64; 2]], x_max: f64) -> Vec<(f64, f64)> {
    let mut points = Vec::new();
    for pair in corners.windows(2) {
        let ([w0, t0], [w1, t1]) = (pair[0], pair[1]);
        for k in 0..=20 {
            let f = f64::from(k) / 20.0;
            let (w, t) = (w0 + f * (w1 - w0), t0 + f * (t1 - t0));
            if w <= x_max {
                points.push((w, t));
            } else {
                // Where the segment leaves the chart, then no further.
                let f = if w1 != w0 {
                    (x_max - w0) / (w1 - w0)
                } else {
                    0.0
                };
                points.push((x_max, t0 + f * (t1 - t0)));
                return points;
            }
        }
    }
    points
}

/// The aircraft's point as a cross of ±spread (a small fixed cross without one).
fn point_cross(
    name: &str,
    color: plotters::style::RGBColor,
    row: &HandlingRow,
    x: &Scale,
    y: &Scale,
) -> Option<Vec<Series>> {
    let w = row.bandwidth_rad_s.value?;
    let t = row.phase_delay_s.value.unwrap_or(0.0).max(0.0);
    let dw = row.bandwidth_rad_s.spread.unwrap_or(0.0).max(w * 0.04);
    let dt = row
        .phase_delay_s
        .spread
        .unwrap_or(0.0)
        .max((y.max - y.min) * 0.015);
    let horizontal = vec![((w - dw).max(x.min), t), ((w + dw).min(x.max), t)];
    let vertical = vec![(w, (t - dt).max(y.min)), (w, (t + dt).min(y.max))];
    Some(vec![
        Series::new(name, color, horizontal).width(2),
        Series::new("", color, vertical).width(2),
    ])
}

/// The bandwidth–phase-delay chart of one axis: both task classes' boundaries and the
/// aircraft's point per stick.
fn chart_figure(axis: &str, rows: &[&HandlingRow]) -> String {
    let widest = rows
        .iter()
        .filter_map(|h| {
            h.bandwidth_rad_s
                .value
                .map(|w| w + h.bandwidth_rad_s.spread.unwrap_or(0.0))
        })
        .fold(0.0f64, f64::max);
    let highest = rows
        .iter()
        .filter_map(|h| {
            h.phase_delay_s
                .value
                .map(|t| t + h.phase_delay_s.spread.unwrap_or(0.0))
        })
        .fold(0.0f64, f64::max);
    let x = Scale::log(0.3, (1.5 * widest).clamp(10.0, 100.0), "ω_BW [rad/s]");
    let y = Scale::linear(0.0, (1.2 * highest).max(0.35), "τ_p [s]");
    // The legend names a colour per task class and the dash of Level 2/3 once (a row of
    // six entries would not fit the figure's width).
    let mut series = Vec::new();
    let mut legend = Vec::new();
    let charts: &[ChartRow] = &rows[0].boundaries;
    for chart in charts {
        let (color, task) = if chart.task == "tracking" {
            (colors::GREEN, "tracking")
        } else {
            (colors::PURPLE, "other MTEs")
        };
        series.push(Series::new(
            task,
            color,
            boundary_line(&chart.level1, x.max),
        ));
        series.push(Series::new(task, color, boundary_line(&chart.level2, x.max)).dashed());
        legend.push(LegendEntry::new(task, color));
    }
    legend.push(LegendEntry::new("Level 2/3", colors::REFERENCE).dashed());
    let mut described = Vec::new();
    for row in rows {
        let (color, name) = if row.mode == "rate" {
            (colors::MODEL, "rate")
        } else {
            (colors::TRUTH, "level")
        };
        match point_cross(name, color, row, &x, &y) {
            Some(cross) => {
                series.extend(cross);
                legend.push(LegendEntry::new(name, color));
            }
            None => described.push(format!("{name} stick: no bandwidth")),
        }
        described.push(format!(
            "{name} stick ω_BW {} rad/s, τ_p {} s, level {}/{}",
            text(&row.bandwidth_rad_s, 2),
            text(&row.phase_delay_s, 3),
            level_text(row.level_tracking),
            level_text(row.level_other),
        ));
    }
    let mut panel = Panel::new(
        &format!("{axis}: bandwidth and phase delay"),
        x,
        "τ_p [s]",
        series,
    );
    panel.y = y;
    panel.height = 220;
    let mut fig = Figure::new(&format!("{axis} ADS-33 bandwidth chart"), vec![panel]);
    fig.legend = legend;
    fig.width = HALF_WIDTH;
    figure(
        fig.to_html(),
        &format!(
            "{axis}: ADS-33E-PRF hover and low speed, small-amplitude attitude response: \
Level 1/2 boundary solid, Level 2/3 dashed, for target acquisition and tracking and for all \
other MTEs (corners recalled, docs/method.md); the point of the Rate (rate) and Level \
(level) stick with its ± spread; levels tracking/other. {}",
            described.join("; ")
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_boundary_is_cut_where_it_leaves_the_chart() {
        let line = boundary_line(&[[2.0, 0.0], [2.0, 0.1], [100.0, 0.1]], 10.0);
        assert_eq!(line.first(), Some(&(2.0, 0.0)));
        assert_eq!(line.last(), Some(&(10.0, 0.1)));
        assert!(line.iter().all(|(w, _)| *w <= 10.0));
        // A sloped segment is drawn straight in ω: its middle point lies on the chord.
        let sloped = boundary_line(&[[1.0, 0.0], [3.0, 0.2]], 10.0);
        assert!(sloped
            .iter()
            .any(|p| (p.0 - 2.0).abs() < 1e-12 && (p.1 - 0.1).abs() < 1e-12));
    }
}

#[cfg(test)]
mod section_tests {
    use super::*;
    use crate::margins::{analyse, MarginsArgs};
    use crate::report::sections::test_support::{fit_with_modes, inputs_with_fit};

    /// The report's inputs with the margins of the shipped TREX 700L fixture model, read
    /// back from their JSON as the report reads the campaign's files.
    fn inputs_with_margins() -> ReportInputs {
        let model = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../control/tests/fixtures/trex700l-quick-seed1-model9.json");
        let argv = [
            model.into_os_string(),
            "--vehicle".into(),
            "trex700l".into(),
            "--samples".into(),
            "5".into(),
        ];
        let args: MarginsArgs = crate::campaign::verb_args("margins", argv).unwrap();
        let analysis = analyse(&args).unwrap();
        let file = serde_json::to_string(&analysis.result).unwrap();
        let loops = serde_json::to_string(&analysis.sampled(Some(100)).unwrap()).unwrap();
        let mut inputs = inputs_with_fit(fit_with_modes(
            Vec::new(),
            Vec::new(),
            Default::default(),
            0,
        ));
        inputs.margins = Some(serde_json::from_str(&file).unwrap());
        inputs.margins_loops = Some(serde_json::from_str(&loops).unwrap());
        inputs
    }

    #[test]
    fn the_section_has_a_bode_plot_per_loop_and_a_chart_per_axis() {
        let inputs = inputs_with_margins();
        let html = loops_section(&inputs);
        assert!(html.starts_with("<section id=\"loops\">"), "{html}");
        // Six loops, three axes.
        assert_eq!(html.matches("<svg").count(), 9, "{html}");
        for name in [
            "roll_rate broken at lat",
            "heading broken at ped",
            "yaw: ADS-33E-PRF",
        ] {
            assert!(html.contains(name), "{name}");
        }
        assert!(html.contains("class=\"good\"") || html.contains("class=\"bad\""));
        // Same inputs, same bytes.
        assert_eq!(loops_section(&inputs), html);
        // Without the sampled loops: the tables and charts, no Bode plots.
        let mut without_curves = inputs.clone();
        without_curves.margins_loops = None;
        let html = loops_section(&without_curves);
        assert_eq!(html.matches("<svg").count(), 3);
        assert!(html.contains("No margins-loops.json"));
    }

    #[test]
    fn a_folder_without_margins_says_so() {
        let inputs = inputs_with_fit(fit_with_modes(
            Vec::new(),
            Vec::new(),
            Default::default(),
            0,
        ));
        let html = loops_section(&inputs);
        assert!(html.contains("No margins.json in this folder"), "{html}");
        assert!(!html.contains("<svg"));
        assert!(crate::report::render(&inputs).contains("<section id=\"loops\">"));
    }
}
