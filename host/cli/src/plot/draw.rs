//! Figures and bar charts drawn with plotters' SVG backend: one `<svg>` each, its text as
//! `<text>` elements in the viewer's sans-serif font (nothing fetched). [`Figure::to_svg`]
//! gives a standalone SVG file; [`Figure::to_html`] the same drawing as an element that
//! scales to the width of the page's column.

use std::fmt;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::figure::{colors, BarChart, Figure, Panel, Scale, FIGURE_WIDTH};

/// Width of the y label area: tick labels and the axis label [px].
const MARGIN_LEFT: u32 = 70;
/// Room right of a panel [px].
const MARGIN_RIGHT: u32 = 20;
/// Room above a panel for its title [px].
const PANEL_TITLE: u32 = 22;
/// Room below a panel for the tick labels and the axis label [px].
const PANEL_BOTTOM: u32 = 36;
/// Height of the legend row on top of a figure [px].
const LEGEND_HEIGHT: u32 = 26;
/// Height of a bar chart [px].
const BAR_CHART_HEIGHT: u32 = 300;
/// Font size handed to plotters, which writes `font-size` as this over 1.24: 12 px text.
const FONT_SIZE: f64 = 12.0 * 1.24;

/// A drawing that plotters could not make.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotError(pub String);

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "plot failed: {}", self.0)
    }
}

impl std::error::Error for PlotError {}

fn failed(error: impl fmt::Display) -> PlotError {
    PlotError(error.to_string())
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

fn font<'a>() -> TextStyle<'a> {
    ("sans-serif", FONT_SIZE).into_font().color(&BLACK)
}

fn bold<'a>() -> TextStyle<'a> {
    ("sans-serif", FONT_SIZE)
        .into_font()
        .style(FontStyle::Bold)
        .color(&BLACK)
}

impl Figure {
    /// Width and height of the drawing \[px\].
    pub fn size(&self) -> (u32, u32) {
        let height = LEGEND_HEIGHT + self.row_heights().iter().sum::<u32>();
        (self.width, height)
    }

    fn row_heights(&self) -> Vec<u32> {
        self.panels
            .chunks(self.columns.max(1))
            .map(|row| row.iter().map(|p| p.height).max().unwrap_or(0) + PANEL_TITLE + PANEL_BOTTOM)
            .collect()
    }

    /// The figure as a standalone SVG file.
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let (width, height) = self.size();
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(failed)?;
            self.draw(&root)?;
            root.present().map_err(failed)?;
        }
        Ok(with_title(svg, &self.title))
    }

    /// The figure as an `<svg>` element of an HTML page, as wide as its column.
    pub fn to_html(&self) -> Result<String, PlotError> {
        let (width, height) = self.size();
        self.to_svg().map(|svg| inline(&svg, width, height))
    }

    fn draw(&self, root: &Area) -> Result<(), PlotError> {
        draw_legend(root, &self.legend)?;
        let (_, body) = root.split_vertically(LEGEND_HEIGHT);
        let columns = self.columns.max(1);
        let column_width = self.width / columns as u32;
        let column_breaks: Vec<u32> = (1..columns as u32).map(|c| c * column_width).collect();
        let mut row_breaks = Vec::new();
        let mut top = 0;
        for height in self.row_heights() {
            top += height;
            row_breaks.push(top);
        }
        row_breaks.pop();
        let cells = body.split_by_breakpoints(column_breaks, row_breaks);
        for (panel, cell) in self.panels.iter().zip(&cells) {
            // Each panel as high as its own plotting area, at the top of its row.
            let (_, cell_height) = cell.dim_in_pixel();
            let height = (panel.height + PANEL_TITLE + PANEL_BOTTOM).min(cell_height);
            let (area, _) = cell.split_vertically(height);
            draw_panel(&area, panel)?;
        }
        Ok(())
    }
}

/// The legend on top of a figure: a line and a name per entry, in a row.
fn draw_legend(root: &Area, legend: &[super::figure::LegendEntry]) -> Result<(), PlotError> {
    let mut x = MARGIN_LEFT as i32;
    let y = (LEGEND_HEIGHT / 2) as i32;
    for entry in legend {
        let style = entry.color.stroke_width(2);
        let line = vec![(x, y), (x + 24, y)];
        if entry.dashed {
            root.draw(&DashedPathElement::new(line, 6, 4, style))
                .map_err(failed)?;
        } else {
            root.draw(&PathElement::new(line, style)).map_err(failed)?;
        }
        root.draw(&Text::new(
            entry.name.clone(),
            (x + 30, y),
            font().pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(failed)?;
        x += 40 + 7 * entry.name.chars().count() as i32;
    }
    Ok(())
}

/// The axis of `scale` as plotters draws it: the projected range, the projected ticks
/// (the mesh's lines and labels) and their labels by projected position.
struct Axis {
    range: std::ops::Range<f64>,
    ticks: Vec<f64>,
    labels: Vec<(f64, String)>,
}

/// A linear plotters coordinate whose grid lines and labels are exactly the given ticks
/// (plotters would pick its own), labelled by the mesh's formatter.
struct Ticked {
    linear: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.linear.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        // The ticks are the mesh's bold lines; no light lines between them.
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.linear.range()
    }
}

impl Axis {
    fn of(scale: &Scale) -> Axis {
        let labels: Vec<(f64, String)> = scale
            .ticks()
            .into_iter()
            .map(|(v, label)| (scale.project(v), label))
            .collect();
        Axis {
            range: scale.project(scale.min)..scale.project(scale.max),
            ticks: labels.iter().map(|(v, _)| *v).collect(),
            labels,
        }
    }

    /// The plotters coordinate of this axis.
    fn coordinate(&self) -> Ticked {
        Ticked {
            linear: self.range.clone().into(),
            ticks: self.ticks.clone(),
        }
    }

    /// The label of the tick at `value` (a projected tick position).
    fn label(&self, value: f64) -> String {
        let tolerance = 1e-9 * (self.range.end - self.range.start).abs();
        self.labels
            .iter()
            .find(|(v, _)| (v - value).abs() <= tolerance)
            .map_or_else(String::new, |(_, label)| label.clone())
    }
}

/// One panel in `area`: its title, shaded range, grid, frame, reference lines and series.
fn draw_panel(area: &Area, panel: &Panel) -> Result<(), PlotError> {
    area.draw(&Text::new(
        panel.title.clone(),
        (MARGIN_LEFT as i32, PANEL_TITLE as i32 - 7),
        bold().pos(Pos::new(HPos::Left, VPos::Bottom)),
    ))
    .map_err(failed)?;
    let (x, y) = (Axis::of(&panel.x), Axis::of(&panel.y));
    let mut chart = ChartBuilder::on(area)
        .margin_top(PANEL_TITLE)
        .margin_right(MARGIN_RIGHT)
        .x_label_area_size(PANEL_BOTTOM)
        .y_label_area_size(MARGIN_LEFT)
        .build_cartesian_2d(x.coordinate(), y.coordinate())
        .map_err(failed)?;
    let (x0, x1) = (x.range.start, x.range.end);
    let (y0, y1) = (y.range.start, y.range.end);
    if let Some([lo, hi]) = panel.shaded {
        let (a, b) = (
            panel.x.project(lo).clamp(x0, x1),
            panel.x.project(hi).clamp(x0, x1),
        );
        if b > a {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(a, y0), (b, y1)],
                    colors::SHADE.filled(),
                )))
                .map_err(failed)?;
        }
    }
    let x_label = |v: &f64| x.label(*v);
    let y_label = |v: &f64| y.label(*v);
    chart
        .configure_mesh()
        .bold_line_style(colors::GRID)
        .light_line_style(TRANSPARENT)
        .axis_style(colors::FRAME)
        .set_all_tick_mark_size(4)
        .x_desc(panel.x.label.clone())
        .y_desc(panel.y.label.clone())
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .label_style(font())
        .axis_desc_style(font())
        .draw()
        .map_err(failed)?;
    chart
        .plotting_area()
        .draw(&Rectangle::new([(x0, y0), (x1, y1)], colors::FRAME))
        .map_err(failed)?;
    for (value, label) in &panel.references {
        let f = panel.y.fraction(*value);
        if !(0.0..=1.0).contains(&f) {
            continue;
        }
        let v = panel.y.project(*value);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x0, v), (x1, v)],
                2,
                3,
                colors::REFERENCE.stroke_width(1),
            ))
            .map_err(failed)?;
        let (px, py) = chart.backend_coord(&(x1, v));
        area.draw(&Text::new(
            label.clone(),
            (
                px - 4 - area.get_base_pixel().0,
                py - 4 - area.get_base_pixel().1,
            ),
            font()
                .color(&colors::REFERENCE)
                .pos(Pos::new(HPos::Right, VPos::Bottom)),
        ))
        .map_err(failed)?;
    }
    for series in &panel.series {
        let style = series.color.stroke_width(series.width);
        for run in panel.runs(series) {
            let points: Vec<(f64, f64)> = run
                .iter()
                .map(|&(a, b)| (panel.x.project(a), panel.y.project(b)))
                .collect();
            if series.dashed {
                chart
                    .draw_series(DashedLineSeries::new(points, 6, 4, style))
                    .map_err(failed)?;
            } else {
                chart
                    .draw_series(LineSeries::new(points, style))
                    .map_err(failed)?;
            }
        }
    }
    Ok(())
}

impl BarChart {
    /// The chart as a standalone SVG file.
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (FIGURE_WIDTH, BAR_CHART_HEIGHT))
                .into_drawing_area();
            root.fill(&WHITE).map_err(failed)?;
            self.draw(&root)?;
            root.present().map_err(failed)?;
        }
        Ok(with_title(svg, &self.title))
    }

    /// The chart as an `<svg>` element of an HTML page, as wide as its column.
    pub fn to_html(&self) -> Result<String, PlotError> {
        self.to_svg()
            .map(|svg| inline(&svg, FIGURE_WIDTH, BAR_CHART_HEIGHT))
    }

    fn draw(&self, root: &Area) -> Result<(), PlotError> {
        let n = self.bars.len().max(1);
        let y = Axis::of(&self.y);
        let centres: Vec<f64> = (0..n).map(|i| i as f64 + 0.5).collect();
        let mut chart = ChartBuilder::on(root)
            .margin_top(20)
            .margin_right(MARGIN_RIGHT)
            .x_label_area_size(40)
            .y_label_area_size(MARGIN_LEFT)
            .build_cartesian_2d(
                Ticked {
                    linear: (0.0..n as f64).into(),
                    ticks: centres,
                },
                y.coordinate(),
            )
            .map_err(failed)?;
        let bar_label = |v: &f64| {
            let i = v.floor() as usize;
            self.bars
                .get(i)
                .map_or_else(String::new, |(label, _, _)| label.clone())
        };
        let y_label = |v: &f64| y.label(*v);
        chart
            .configure_mesh()
            .disable_x_mesh()
            .bold_line_style(colors::GRID)
            .light_line_style(TRANSPARENT)
            .axis_style(colors::FRAME)
            .set_all_tick_mark_size(4)
            .y_desc(self.y.label.clone())
            .x_label_formatter(&bar_label)
            .y_label_formatter(&y_label)
            .x_label_style(bold())
            .y_label_style(font())
            .axis_desc_style(font())
            .draw()
            .map_err(failed)?;
        // Bars half a slot wide, at most 120 px.
        let (plot_width, _) = chart.plotting_area().dim_in_pixel();
        let slot = f64::from(plot_width) / n as f64;
        let half = (0.25f64).min(60.0 / slot);
        let (y0, y1) = (y.range.start, y.range.end);
        for (i, (_, value, color)) in self.bars.iter().enumerate() {
            let centre = i as f64 + 0.5;
            let top = if value.is_finite() {
                self.y.project(*value).clamp(y0, y1)
            } else {
                y0
            };
            if value.is_finite() {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(centre - half, y0), (centre + half, top)],
                        color.filled(),
                    )))
                    .map_err(failed)?;
            }
            let (px, py) = chart.backend_coord(&(centre, top));
            root.draw(&Text::new(
                if value.is_finite() {
                    format!("{value:.3}")
                } else {
                    "-".into()
                },
                (px, py - 5),
                font().pos(Pos::new(HPos::Center, VPos::Bottom)),
            ))
            .map_err(failed)?;
        }
        for (value, label) in &self.references {
            let v = self.y.project(*value).clamp(y0, y1);
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(0.0, v), (n as f64, v)],
                    4,
                    3,
                    colors::REFERENCE.stroke_width(1),
                ))
                .map_err(failed)?;
            let (px, py) = chart.backend_coord(&(n as f64, v));
            root.draw(&Text::new(
                label.clone(),
                (px - 4, py - 4),
                font()
                    .color(&colors::REFERENCE)
                    .pos(Pos::new(HPos::Right, VPos::Bottom)),
            ))
            .map_err(failed)?;
        }
        Ok(())
    }
}

/// `svg` with `<title>` (its accessible description) as the first child of its root.
fn with_title(svg: String, title: &str) -> String {
    match svg.find('>') {
        Some(end) => format!(
            "{}\n<title>{}</title>{}",
            &svg[..=end],
            escape(title),
            &svg[end + 1..]
        ),
        None => svg,
    }
}

/// A standalone SVG of `width` × `height` as an element of an HTML page: no namespace or
/// fixed size, `width="100%"` so that it scales to its column (the page's style keeps the
/// aspect ratio of its `viewBox`).
fn inline(svg: &str, width: u32, height: u32) -> String {
    let body = svg.find('>').map_or(svg, |end| &svg[end + 1..]);
    format!(
        "<svg viewBox=\"0 0 {width} {height}\" width=\"100%\" role=\"img\">{}",
        body.trim_end()
    )
}

/// Escape text for XML content and attributes (of SVG, and of the HTML page around it).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::figure::Series;

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
        let figure = Figure::new("t", vec![panel]);
        let svg = figure.to_html().unwrap();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"), "{svg}");
        assert!(svg.contains(r#"width="100%""#) && svg.contains("viewBox"));
        assert!(!svg.contains("http"), "{svg}");
        assert!(svg.contains("p/lat &lt;data&gt;") && svg.contains("data &amp; model"));
        assert!(svg.contains("<title>t</title>"));
        assert_eq!(svg.matches("<svg").count(), 1);
        // The series (width 1) beside its legend line (width 2).
        assert_eq!(
            svg.matches(r##"stroke="#000000" stroke-width="1" points"##)
                .count(),
            1,
            "{svg}"
        );
        let file = figure.to_svg().unwrap();
        assert!(file.starts_with("<svg") && file.contains("xmlns"));
    }

    #[test]
    fn bar_chart_labels_its_bars_and_values() {
        let chart = BarChart {
            title: "bars".into(),
            bars: vec![
                ("cah".into(), 0.17, colors::MODEL),
                ("noise".into(), f64::NAN, colors::GREEN),
            ],
            y: Scale::linear(0.0, 1.0, "γ²"),
            references: vec![(0.2, "bar 0.2".into())],
        };
        let svg = chart.to_html().unwrap();
        for text in ["cah", "noise", "0.170", "\n-\n", "bar 0.2", "γ²"] {
            assert!(svg.contains(text), "{text}: {svg}");
        }
        assert_eq!(svg.matches("<svg").count(), 1);
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
            let svg = Figure::new("f", vec![panel]).to_html().unwrap();
            proptest::prop_assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
            proptest::prop_assert!(!svg.contains("NaN") && !svg.contains("inf"), "{}", svg);
            proptest::prop_assert!(svg.matches("<svg").count() == 1);
        }
    }
}
