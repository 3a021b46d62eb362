//! What a plot shows, before it is drawn: axes ([`Scale`]) with their ticks, line series,
//! panels (axes, series, a shaded x range, reference lines), figures (panels in rows under
//! one legend) and bar charts, in pixels of the SVG they become.

use plotters::style::RGBColor;

/// Width of a full-width figure \[px\] (the page scales it to its column).
pub const FIGURE_WIDTH: u32 = 900;

/// Colours of the series (colour-blind-safe Okabe–Ito palette, and greys).
pub mod colors {
    use plotters::style::RGBColor;

    /// Measured data.
    pub const DATA: RGBColor = RGBColor(0x00, 0x00, 0x00);
    /// The identified model.
    pub const MODEL: RGBColor = RGBColor(0x00, 0x72, 0xB2);
    /// The simulator's truth.
    pub const TRUTH: RGBColor = RGBColor(0xD5, 0x5E, 0x00);
    /// A third series.
    pub const GREEN: RGBColor = RGBColor(0x00, 0x9E, 0x73);
    /// A fourth series.
    pub const PURPLE: RGBColor = RGBColor(0xCC, 0x79, 0xA7);
    /// A fifth series.
    pub const ORANGE: RGBColor = RGBColor(0xE6, 0x9F, 0x00);
    /// A sixth series.
    pub const SKY: RGBColor = RGBColor(0x56, 0xB4, 0xE9);
    /// A series drawn behind the others (e.g. the SISO response under the MISO one).
    pub const GREY: RGBColor = RGBColor(0x96, 0x96, 0x96);
    /// Grid lines.
    pub const GRID: RGBColor = RGBColor(0xDD, 0xDD, 0xDD);
    /// The frame of a panel.
    pub const FRAME: RGBColor = RGBColor(0x88, 0x88, 0x88);
    /// Reference lines and their labels.
    pub const REFERENCE: RGBColor = RGBColor(0x55, 0x55, 0x55);
    /// A shaded x range (e.g. the fit range).
    pub const SHADE: RGBColor = RGBColor(0xEE, 0xF4, 0xFB);

    /// Colours for curves told apart by colour alone, in order.
    pub const CYCLE: [RGBColor; 6] = [MODEL, TRUTH, GREEN, PURPLE, ORANGE, SKY];
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

    /// The same linear axis extended by a quarter of its span on either side.
    pub fn padded(self) -> Self {
        let pad = 0.25 * (self.max - self.min);
        Scale::linear(self.min - pad, self.max + pad, &self.label)
    }

    /// The same linear axis widened to span at least `minimum` (a nearly flat curve is
    /// not blown up).
    pub fn widened_to(self, minimum: f64) -> Self {
        let span = self.max - self.min;
        if span >= minimum {
            self
        } else {
            let middle = (self.max + self.min) / 2.0;
            Scale::linear(middle - minimum / 2.0, middle + minimum / 2.0, &self.label)
        }
    }

    /// Where `value` lies on the drawn axis: itself on a linear axis, its log₁₀ on a
    /// logarithmic one (drawn as a linear axis of log₁₀ x, its ticks labelled with x).
    pub fn project(&self, value: f64) -> f64 {
        if self.log {
            value.log10()
        } else {
            value
        }
    }

    /// Position of `value` in [0, 1] along the axis (outside for values off the axis).
    pub fn fraction(&self, value: f64) -> f64 {
        (self.project(value) - self.project(self.min))
            / (self.project(self.max) - self.project(self.min))
    }

    /// Tick positions and their labels.
    pub fn ticks(&self) -> Vec<(f64, String)> {
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
pub fn number_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if (0.01..1e5).contains(&a) {
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
    }
}

/// A line series.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend name.
    pub name: String,
    /// (x, y) points; non-finite y breaks the line.
    pub points: Vec<(f64, f64)>,
    /// Stroke colour.
    pub color: RGBColor,
    /// Dashed stroke.
    pub dashed: bool,
    /// Stroke width \[px\].
    pub width: u32,
}

impl Series {
    /// A solid series of width 1.
    pub fn new(name: &str, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Series {
            name: name.to_string(),
            points,
            color,
            dashed: false,
            width: 1,
        }
    }

    /// The same, dashed.
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }

    /// The same, with stroke width `width` \[px\].
    pub fn width(mut self, width: u32) -> Self {
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
    /// Height of the plotting area \[px\].
    pub height: u32,
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
            height: 150,
        }
    }

    /// The series cut into the stretches drawn: each a run of points with finite values
    /// inside both axes' ranges (and x > 0 on a log axis). A line leaves the plot rather
    /// than running along its edge.
    pub fn runs(&self, series: &Series) -> Vec<Vec<(f64, f64)>> {
        finite_runs(&series.points, &self.x, &self.y)
    }
}

/// One entry of a figure's legend.
#[derive(Clone, Debug, PartialEq)]
pub struct LegendEntry {
    /// Text.
    pub name: String,
    /// Line colour.
    pub color: RGBColor,
    /// Dashed line.
    pub dashed: bool,
}

impl LegendEntry {
    /// A solid entry.
    pub fn new(name: &str, color: RGBColor) -> Self {
        LegendEntry {
            name: name.to_string(),
            color,
            dashed: false,
        }
    }

    /// The same, dashed.
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
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
    /// Legend entries.
    pub legend: Vec<LegendEntry>,
    /// Width \[px\]: [`FIGURE_WIDTH`] for a full-width figure, less for one shown in a
    /// half-width column (so that its text keeps a readable size once scaled).
    pub width: u32,
}

impl Figure {
    /// A one-column figure whose legend lists the first panel's named series.
    pub fn new(title: &str, panels: Vec<Panel>) -> Self {
        let legend = panels
            .first()
            .map(|p| {
                p.series
                    .iter()
                    .filter(|s| !s.name.is_empty())
                    .map(|s| LegendEntry {
                        name: s.name.clone(),
                        color: s.color,
                        dashed: s.dashed,
                    })
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
}

/// The points split where a value is not finite, x is not on a log axis, or the point
/// lies off the axes' ranges: a line leaves the plot rather than running along its edge.
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
    /// Bars: label, value (not finite: no bar, `-` above), colour.
    pub bars: Vec<(String, f64, RGBColor)>,
    /// Vertical axis.
    pub y: Scale,
    /// Reference lines: value and label.
    pub references: Vec<(f64, String)>,
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
    fn widened_keeps_wide_ranges_and_padded_adds_a_quarter() {
        let s = Scale::linear(0.0, 1.0, "x").widened_to(6.0);
        assert!((s.max - s.min - 6.0).abs() < 1e-12);
        let s = Scale::linear(0.0, 10.0, "x").widened_to(6.0);
        assert_eq!((s.min, s.max), (0.0, 10.0));
        let s = Scale::linear(0.0, 4.0, "x").padded();
        assert_eq!((s.min, s.max), (-1.0, 5.0));
    }
}
