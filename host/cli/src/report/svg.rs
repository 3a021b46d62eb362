//! Hand-written SVG plots for the report: stacked panels of line series on linear or
//! logarithmic axes, and bar charts. Each figure is one `<svg>` with a `viewBox` and
//! `width="100%"`, so it scales to the page and never scrolls sideways.

use std::fmt::Write as _;

/// Width of every figure in SVG user units (scaled by the browser to the column).
pub const FIGURE_WIDTH: f64 = 900.0;
const MARGIN_LEFT: f64 = 70.0;
const MARGIN_RIGHT: f64 = 20.0;
const PANEL_TITLE: f64 = 22.0;
const PANEL_BOTTOM: f64 = 36.0;
const LEGEND_HEIGHT: f64 = 26.0;

/// Colours of the report's series (colour-blind-safe Okabe–Ito palette).
pub mod colors {
    /// Measured data.
    pub const DATA: &str = "#000000";
    /// The identified model.
    pub const MODEL: &str = "#0072B2";
    /// The simulator's truth.
    pub const TRUTH: &str = "#D55E00";
    /// A third series.
    pub const GREEN: &str = "#009E73";
    /// A fourth series.
    pub const PURPLE: &str = "#CC79A7";
    /// Reference lines and grid.
    pub const GRID: &str = "#dddddd";
}

/// Escape text for XML content and attributes.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

/// One axis of a panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Scale {
    /// Lower end.
    pub min: f64,
    /// Upper end.
    pub max: f64,
    /// Logarithmic (base 10); `min` must then be > 0.
    pub log: bool,
    /// Label with units.
    pub label: String,
    /// About how many tick intervals a linear axis gets.
    pub intervals: usize,
}

impl Scale {
    /// A linear axis.
    pub fn linear(min: f64, max: f64, label: &str) -> Self {
        let (min, max) = widen(min, max);
        Scale {
            min,
            max,
            log: false,
            label: label.to_string(),
            intervals: 5,
        }
    }

    /// A logarithmic axis over [min, max] (both > 0).
    pub fn log(min: f64, max: f64, label: &str) -> Self {
        let min = if min > 0.0 && min.is_finite() {
            min
        } else {
            1e-3
        };
        let max = if max > min && max.is_finite() {
            max
        } else {
            min * 10.0
        };
        Scale {
            min,
            max,
            log: true,
            label: label.to_string(),
            intervals: 5,
        }
    }

    /// A linear axis that fits every finite value of `series`, with 5 % margins.
    pub fn fit_y(series: &[Series], label: &str) -> Self {
        let values = series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .filter(|v| v.is_finite());
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        if !lo.is_finite() {
            return Scale::linear(-1.0, 1.0, label);
        }
        if hi - lo <= 1e-9 * hi.abs().max(lo.abs()).max(1e-12) {
            // A constant: ±10 % of its size (or ±1 around zero) keeps the labels distinct.
            let d = if hi.abs() > 1e-12 {
                0.1 * hi.abs()
            } else {
                1.0
            };
            return Scale::linear(lo - d, hi + d, label);
        }
        let pad = 0.05 * (hi - lo);
        Scale::linear(lo - pad, hi + pad, label)
    }

    /// The same axis with about `intervals` tick intervals.
    pub fn with_intervals(mut self, intervals: usize) -> Self {
        self.intervals = intervals;
        self
    }

    /// Position of `value` in [0, 1] along the axis (outside for values off the axis).
    fn fraction(&self, value: f64) -> f64 {
        if self.log {
            (value.ln() - self.min.ln()) / (self.max.ln() - self.min.ln())
        } else {
            (value - self.min) / (self.max - self.min)
        }
    }

    /// Tick positions and their labels.
    fn ticks(&self) -> Vec<(f64, String)> {
        if self.log {
            // Decades, plus 2 and 5 when the axis spans less than three decades.
            let span = (self.max / self.min).log10();
            let mantissas: &[f64] = if span < 3.0 { &[1.0, 2.0, 5.0] } else { &[1.0] };
            let mut ticks = Vec::new();
            let mut decade = 10f64.powf(self.min.log10().floor());
            while decade <= self.max * 1.0001 {
                for &m in mantissas {
                    let v = m * decade;
                    if v >= self.min * 0.9999 && v <= self.max * 1.0001 {
                        ticks.push((v, number_label(v)));
                    }
                }
                decade *= 10.0;
            }
            ticks
        } else {
            // A 1-2-5 step giving about five intervals.
            let raw = (self.max - self.min) / self.intervals.max(1) as f64;
            let exponent = raw.log10().floor() as i32;
            let magnitude = 10f64.powi(exponent);
            let mantissa = [1.0, 2.0, 5.0, 10.0]
                .into_iter()
                .find(|m| m * magnitude >= raw)
                .unwrap_or(10.0);
            let step = mantissa * magnitude;
            // k·mantissa·10^e, divided by 10^-e for a negative e so that 3·0.1 prints as
            // 0.3 and not 0.30000000000000004 (no running sum either: it would drift).
            let value = |k: i64| {
                let units = k as f64 * mantissa;
                if exponent < 0 {
                    units / 10f64.powi(-exponent)
                } else {
                    units * magnitude
                }
            };
            let first = (self.min / step - 1e-9).ceil() as i64;
            let last = (self.max / step + 1e-9).floor() as i64;
            let mut ticks = Vec::new();
            for k in first..=last {
                let v = value(k);
                ticks.push((v, number_label(v)));
            }
            ticks
        }
    }
}

/// A degenerate range widened so that the axis has a length.
fn widen(min: f64, max: f64) -> (f64, f64) {
    if !(min.is_finite() && max.is_finite()) {
        (-1.0, 1.0)
    } else if max - min < 1e-12 {
        let d = min.abs().max(1.0) * 0.1;
        (min - d, max + d)
    } else {
        (min, max)
    }
}

/// Compact tick label: no trailing zeros.
fn number_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    let text = if (0.01..1e5).contains(&a) {
        let digits = if a >= 100.0 {
            0
        } else if a >= 1.0 {
            2
        } else {
            3
        };
        let t = format!("{v:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{v:.0e}")
    };
    text
}

/// A line series.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend name.
    pub name: String,
    /// (x, y) points; non-finite y breaks the line.
    pub points: Vec<(f64, f64)>,
    /// Stroke colour.
    pub color: &'static str,
    /// Dashed stroke.
    pub dashed: bool,
    /// Stroke width.
    pub width: f64,
}

impl Series {
    /// A solid series of width 1.5.
    pub fn new(name: &str, color: &'static str, points: Vec<(f64, f64)>) -> Self {
        Series {
            name: name.to_string(),
            points,
            color,
            dashed: false,
            width: 1.5,
        }
    }

    /// The same, dashed.
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }

    /// The same, with stroke width `width`.
    pub fn width(mut self, width: f64) -> Self {
        self.width = width;
        self
    }
}

/// One panel: axes, series, an optional shaded x range and horizontal reference lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// Horizontal axis.
    pub x: Scale,
    /// Vertical axis.
    pub y: Scale,
    /// Lines, drawn in order.
    pub series: Vec<Series>,
    /// Shaded x range (e.g. the fit range).
    pub shaded: Option<[f64; 2]>,
    /// Horizontal reference lines: value and label.
    pub references: Vec<(f64, String)>,
    /// Height of the plotting area in SVG units.
    pub height: f64,
}

impl Panel {
    /// A panel of height 150 with y fitted to the series.
    pub fn new(title: &str, x: Scale, y_label: &str, series: Vec<Series>) -> Self {
        let y = Scale::fit_y(&series, y_label);
        Panel {
            title: title.to_string(),
            x,
            y,
            series,
            shaded: None,
            references: Vec::new(),
            height: 150.0,
        }
    }
}

/// A figure: panels stacked vertically (or in `columns` columns) under one legend.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Accessible description (`<title>`).
    pub title: String,
    /// The panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
    /// Legend entries: name, colour, dashed.
    pub legend: Vec<(String, &'static str, bool)>,
    /// Width in SVG units: [`FIGURE_WIDTH`] for a full-width figure, less for one shown in
    /// a half-width column (so that its text keeps a readable size once scaled).
    pub width: f64,
}

impl Figure {
    /// A one-column figure whose legend lists the first panel's series.
    pub fn new(title: &str, panels: Vec<Panel>) -> Self {
        let legend = panels
            .first()
            .map(|p| {
                p.series
                    .iter()
                    .map(|s| (s.name.clone(), s.color, s.dashed))
                    .collect()
            })
            .unwrap_or_default();
        Figure {
            title: title.to_string(),
            panels,
            columns: 1,
            legend,
            width: FIGURE_WIDTH,
        }
    }

    /// The figure as an `<svg>` element.
    pub fn to_svg(&self) -> String {
        let columns = self.columns.max(1);
        let column_width = self.width / columns as f64;
        let rows: Vec<&[Panel]> = self.panels.chunks(columns).collect();
        let row_heights: Vec<f64> = rows
            .iter()
            .map(|row| {
                row.iter().map(|p| p.height).fold(0.0, f64::max) + PANEL_TITLE + PANEL_BOTTOM
            })
            .collect();
        let height = LEGEND_HEIGHT + row_heights.iter().sum::<f64>();
        let mut svg = String::new();
        let _ = write!(
            svg,
            r#"<svg viewBox="0 0 {:.0} {height:.0}" width="100%" role="img" font-family="sans-serif" font-size="12"><title>{}</title>"#,
            self.width,
            escape(&self.title)
        );
        self.legend_svg(&mut svg);
        let mut top = LEGEND_HEIGHT;
        for (row, row_height) in rows.iter().zip(&row_heights) {
            for (c, panel) in row.iter().enumerate() {
                panel_svg(&mut svg, panel, c as f64 * column_width, top, column_width);
            }
            top += row_height;
        }
        svg.push_str("</svg>");
        svg
    }

    fn legend_svg(&self, svg: &mut String) {
        let mut x = MARGIN_LEFT;
        for (name, color, dashed) in &self.legend {
            let dash = if *dashed {
                r#" stroke-dasharray="6 4""#
            } else {
                ""
            };
            let _ = write!(
                svg,
                r#"<line x1="{x:.1}" y1="13" x2="{:.1}" y2="13" stroke="{color}" stroke-width="2"{dash}/><text x="{:.1}" y="17">{}</text>"#,
                x + 24.0,
                x + 30.0,
                escape(name)
            );
            x += 40.0 + 7.0 * name.chars().count() as f64;
        }
    }
}

/// Draw one panel with its top-left corner at (`left`, `top`) in a cell `width` wide.
fn panel_svg(svg: &mut String, panel: &Panel, left: f64, top: f64, width: f64) {
    let x0 = left + MARGIN_LEFT;
    let x1 = left + width - MARGIN_RIGHT;
    let y0 = top + PANEL_TITLE;
    let y1 = y0 + panel.height;
    let px = |x: f64| x0 + panel.x.fraction(x) * (x1 - x0);
    let py = |y: f64| y1 - panel.y.fraction(y) * (y1 - y0);
    let _ = write!(
        svg,
        r#"<text x="{x0:.1}" y="{:.1}" font-weight="bold">{}</text>"#,
        y0 - 7.0,
        escape(&panel.title)
    );
    if let Some([lo, hi]) = panel.shaded {
        let (a, b) = (px(lo).clamp(x0, x1), px(hi).clamp(x0, x1));
        if b > a {
            let _ = write!(
                svg,
                "<rect x=\"{a:.1}\" y=\"{y0:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#eef4fb\"/>",
                b - a,
                y1 - y0
            );
        }
    }
    for (v, label) in panel.x.ticks() {
        let x = px(v);
        let _ = write!(
            svg,
            r#"<line x1="{x:.1}" y1="{y0:.1}" x2="{x:.1}" y2="{y1:.1}" stroke="{}"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            colors::GRID,
            y1 + 14.0,
            escape(&label)
        );
    }
    for (v, label) in panel.y.ticks() {
        let y = py(v);
        let _ = write!(
            svg,
            r#"<line x1="{x0:.1}" y1="{y:.1}" x2="{x1:.1}" y2="{y:.1}" stroke="{}"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
            colors::GRID,
            x0 - 5.0,
            y + 4.0,
            escape(&label)
        );
    }
    let _ = write!(
        svg,
        r##"<rect x="{x0:.1}" y="{y0:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#888"/>"##,
        x1 - x0,
        y1 - y0
    );
    let _ = write!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        (x0 + x1) / 2.0,
        y1 + 29.0,
        escape(&panel.x.label)
    );
    let _ = write!(
        svg,
        r#"<text transform="translate({:.1} {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        left + 14.0,
        (y0 + y1) / 2.0,
        escape(&panel.y.label)
    );
    for (value, label) in &panel.references {
        if panel.y.fraction(*value) < 0.0 || panel.y.fraction(*value) > 1.0 {
            continue;
        }
        let y = py(*value);
        let _ = write!(
            svg,
            r##"<line x1="{x0:.1}" y1="{y:.1}" x2="{x1:.1}" y2="{y:.1}" stroke="#555" stroke-dasharray="2 3"/><text x="{:.1}" y="{:.1}" text-anchor="end" fill="#555">{}</text>"##,
            x1 - 4.0,
            y - 4.0,
            escape(label)
        );
    }
    for series in &panel.series {
        let dash = if series.dashed {
            r#" stroke-dasharray="6 4""#
        } else {
            ""
        };
        for run in finite_runs(&series.points, &panel.x, &panel.y) {
            let points: Vec<String> = run
                .iter()
                .map(|&(x, y)| format!("{:.1},{:.1}", px(x).clamp(x0, x1), py(y).clamp(y0, y1)))
                .collect();
            let _ = write!(
                svg,
                r#"<polyline fill="none" stroke="{}" stroke-width="{}"{dash} points="{}"/>"#,
                series.color,
                series.width,
                points.join(" ")
            );
        }
    }
}

/// The points split where a value is not finite, x is not on a log axis, or the point
/// lies off the axes' ranges: a line leaves the plot rather than running along its edge
/// (no clip paths: their ids would have to be unique across the whole page).
fn finite_runs(points: &[(f64, f64)], x: &Scale, y: &Scale) -> Vec<Vec<(f64, f64)>> {
    let inside = |scale: &Scale, v: f64| {
        let f = scale.fraction(v);
        (-1e-9..=1.0 + 1e-9).contains(&f)
    };
    let mut runs = vec![Vec::new()];
    for &(px, py) in points {
        let ok = px.is_finite()
            && py.is_finite()
            && (!x.log || px > 0.0)
            && inside(x, px)
            && inside(y, py);
        if ok {
            if let Some(run) = runs.last_mut() {
                run.push((px, py));
            }
        } else if runs.last().is_some_and(|r| !r.is_empty()) {
            runs.push(Vec::new());
        }
    }
    runs.retain(|r| r.len() >= 2);
    runs
}

/// At most about `2·buckets` points from a long series: the minimum and maximum of each
/// bucket in time order, so that peaks survive (plain striding would alias a fast sweep).
pub fn min_max_decimate(points: &[(f64, f64)], buckets: usize) -> Vec<(f64, f64)> {
    if points.len() <= 2 * buckets || buckets == 0 {
        return points.to_vec();
    }
    let size = points.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets + 2);
    for chunk in points.chunks(size) {
        let mut lo = chunk[0];
        let mut hi = chunk[0];
        for &p in chunk {
            if p.1 < lo.1 {
                lo = p;
            }
            if p.1 > hi.1 {
                hi = p;
            }
        }
        if lo.0 <= hi.0 {
            out.push(lo);
            out.push(hi);
        } else {
            out.push(hi);
            out.push(lo);
        }
    }
    out
}

/// A bar chart: one bar per category, value printed above, horizontal reference lines.
#[derive(Clone, Debug, PartialEq)]
pub struct BarChart {
    /// Accessible description.
    pub title: String,
    /// Bars: label, value, colour.
    pub bars: Vec<(String, f64, &'static str)>,
    /// Vertical axis.
    pub y: Scale,
    /// Reference lines: value and label.
    pub references: Vec<(f64, String)>,
}

impl BarChart {
    /// The chart as an `<svg>` element.
    pub fn to_svg(&self) -> String {
        let height = 300.0;
        let (x0, x1, y0, y1) = (
            MARGIN_LEFT,
            FIGURE_WIDTH - MARGIN_RIGHT,
            20.0,
            height - 40.0,
        );
        let py = |y: f64| y1 - self.y.fraction(y).clamp(0.0, 1.0) * (y1 - y0);
        let mut svg = String::new();
        let _ = write!(
            svg,
            r#"<svg viewBox="0 0 {FIGURE_WIDTH} {height}" width="100%" role="img" font-family="sans-serif" font-size="12"><title>{}</title>"#,
            escape(&self.title)
        );
        for (v, label) in self.y.ticks() {
            let y = py(v);
            let _ = write!(
                svg,
                r#"<line x1="{x0}" y1="{y:.1}" x2="{x1}" y2="{y:.1}" stroke="{}"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
                colors::GRID,
                x0 - 5.0,
                y + 4.0,
                escape(&label)
            );
        }
        let _ = write!(
            svg,
            r#"<text transform="translate(14 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
            (y0 + y1) / 2.0,
            escape(&self.y.label)
        );
        let n = self.bars.len().max(1) as f64;
        let slot = (x1 - x0) / n;
        for (i, (label, value, color)) in self.bars.iter().enumerate() {
            let cx = x0 + slot * (i as f64 + 0.5);
            let w = (slot * 0.5).min(120.0);
            let top = py(if value.is_finite() { *value } else { 0.0 });
            let _ = write!(
                svg,
                r#"<rect x="{:.1}" y="{top:.1}" width="{w:.1}" height="{:.1}" fill="{color}"/><text x="{cx:.1}" y="{:.1}" text-anchor="middle">{}</text><text x="{cx:.1}" y="{:.1}" text-anchor="middle" font-weight="bold">{}</text>"#,
                cx - w / 2.0,
                (y1 - top).max(0.0),
                top - 5.0,
                if value.is_finite() {
                    format!("{value:.3}")
                } else {
                    "-".into()
                },
                y1 + 18.0,
                escape(label)
            );
        }
        for (value, label) in &self.references {
            let y = py(*value);
            let _ = write!(
                svg,
                r##"<line x1="{x0}" y1="{y:.1}" x2="{x1}" y2="{y:.1}" stroke="#555" stroke-dasharray="4 3"/><text x="{:.1}" y="{:.1}" text-anchor="end" fill="#555">{}</text>"##,
                x1 - 4.0,
                y - 4.0,
                escape(label)
            );
        }
        let _ = write!(
            svg,
            r##"<line x1="{x0}" y1="{y1:.1}" x2="{x1}" y2="{y1:.1}" stroke="#888"/></svg>"##
        );
        svg
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_are_round_numbers_inside_the_range() {
        let ticks = Scale::linear(-0.07, 0.43, "x").ticks();
        let values: Vec<f64> = ticks.iter().map(|t| t.0).collect();
        assert_eq!(values, vec![0.0, 0.1, 0.2, 0.3, 0.4]);
        assert_eq!(ticks[1].1, "0.1");
    }

    #[test]
    fn log_ticks_are_decades_and_2_5() {
        let ticks = Scale::log(0.3, 30.0, "w").ticks();
        let labels: Vec<&str> = ticks.iter().map(|t| t.1.as_str()).collect();
        assert_eq!(labels, vec!["0.5", "1", "2", "5", "10", "20"]);
    }

    #[test]
    fn non_finite_values_break_lines() {
        let points = vec![
            (1.0, 1.0),
            (2.0, 2.0),
            (3.0, f64::NAN),
            (4.0, 1.0),
            (5.0, 0.0),
        ];
        let y = Scale::linear(-1.0, 3.0, "");
        let runs = finite_runs(&points, &Scale::linear(0.0, 5.0, ""), &y);
        assert_eq!(runs.len(), 2);
        assert!(finite_runs(&[(0.0, 1.0), (1.0, 2.0)], &Scale::log(0.1, 2.0, ""), &y).is_empty());
        // Off the y range: the line stops instead of running along the edge.
        let off = [(1.0, 1.0), (2.0, 2.0), (3.0, 9.0), (4.0, 1.0), (5.0, 0.0)];
        assert_eq!(finite_runs(&off, &Scale::linear(0.0, 5.0, ""), &y).len(), 2);
    }

    #[test]
    fn decimation_keeps_the_peaks() {
        let points: Vec<(f64, f64)> = (0..10_000)
            .map(|k| (k as f64, if k == 5_123 { 9.0 } else { (k as f64).sin() }))
            .collect();
        let kept = min_max_decimate(&points, 100);
        assert!(kept.len() <= 202);
        assert!(kept.iter().any(|p| p.1 == 9.0));
        assert!(kept.windows(2).all(|w| w[0].0 <= w[1].0));
    }

    #[test]
    fn figure_is_one_scalable_svg_with_escaped_text() {
        let panel = Panel::new(
            "p/lat <data>",
            Scale::log(0.1, 10.0, "ω [rad/s]"),
            "dB",
            vec![Series::new(
                "data & model",
                colors::DATA,
                vec![(0.1, 1.0), (10.0, 2.0)],
            )],
        );
        let svg = Figure::new("t", vec![panel]).to_svg();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.contains(r#"width="100%""#) && svg.contains("viewBox"));
        assert!(svg.contains("p/lat &lt;data&gt;") && svg.contains("data &amp; model"));
        assert_eq!(svg.matches("<polyline").count(), 1);
    }

    proptest::proptest! {
        /// Whatever the values (NaN, infinities, huge, constant), a figure is one SVG whose
        /// coordinates and labels are all finite numbers.
        #[test]
        fn any_series_gives_a_finite_svg(
            ys in proptest::collection::vec(
                proptest::prop_oneof![
                    -1e12f64..1e12,
                    proptest::strategy::Just(f64::NAN),
                    proptest::strategy::Just(f64::INFINITY),
                    proptest::strategy::Just(0.0),
                ],
                0..60,
            ),
            log_x in proptest::bool::ANY,
            x_max in 1e-3f64..1e4,
        ) {
            let points: Vec<(f64, f64)> = ys
                .iter()
                .enumerate()
                .map(|(k, y)| ((k as f64 + 1.0) * x_max / 60.0, *y))
                .collect();
            let x = if log_x {
                Scale::log(x_max / 60.0, x_max, "x")
            } else {
                Scale::linear(0.0, x_max, "x")
            };
            let series = vec![Series::new("s", colors::DATA, points)];
            let mut panel = Panel::new("p", x, "y", series);
            panel.shaded = Some([0.0, x_max / 2.0]);
            panel.references = vec![(0.5, "ref".into())];
            let svg = Figure::new("f", vec![panel]).to_svg();
            proptest::prop_assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
            proptest::prop_assert!(!svg.contains("NaN") && !svg.contains("inf"), "{}", svg);
            proptest::prop_assert!(svg.matches("<svg").count() == 1);
        }
    }
}
