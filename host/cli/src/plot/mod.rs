//! Plots drawn with plotters' SVG backend: figures of stacked panels of line series on
//! linear or logarithmic axes under one legend, and bar charts ([`figure`] describes them,
//! [`draw`] draws them). The same figures serve the campaign report (inline `<svg>`), and
//! the SVG files of `sweephold frf --plots` ([`frf`]) and `sweephold verify --plots`
//! ([`verification`]).

pub mod draw;
pub mod figure;
pub mod frf;
pub mod verification;

pub use draw::PlotError;
pub use figure::{colors, min_max_decimate, BarChart, Figure, LegendEntry, Panel, Scale, Series};
