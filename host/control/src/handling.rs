//! ADS-33E-PRF bandwidth and phase delay of the attitude response to a stick, and the
//! handling-quality level they fall in (docs/method.md, "Handling qualities").
//!
//! ```text
//! ω_180        the lowest frequency where the attitude's phase reaches −180°
//! ω_BW,phase   where the phase is −135° (45° of phase margin for the pilot)
//! ω_BW,gain    where the gain is 6 dB above its value at ω_180
//! ω_BW         rate response types: min(ω_BW,gain, ω_BW,phase); attitude command /
//!              attitude hold: ω_BW,phase
//! τ_p          −(∠(2ω_180) + 180°) / (57.3 · 2ω_180)
//! ```
//!
//! The phase is unwrapped along the grid and shifted by whole turns so that at
//! [`ANCHOR_RAD_S`] it lies in (−270°, 90°]: there a rate response lags about 90° and an
//! attitude command less than its bandwidth's 135°. Anchoring at the grid's lowest
//! frequency instead would count the turns of the unstable hover modes that a rate
//! stick leaves open (the Bo-105's roll rate stick turns by 180° through 0.3–0.5 rad/s),
//! and put the response's phase a whole turn off.
//!
//! The levels are read from ADS-33E-PRF's small-amplitude attitude charts for hover and
//! low speed (paragraphs 3.3.2.1, pitch and roll, and 3.3.5.1, yaw; one chart for target
//! acquisition and tracking, one for all other MTEs). Each chart's Level 1/2 and Level 2/3
//! boundaries are polylines on the (ω_BW, τ_p) plane, from the τ_p = 0 axis to the
//! chart's right edge, and each level's region is the polygon they close with that axis
//! and edge ([`ChartBoundary`]): a point is classified by which polygon holds it, so a
//! sloped segment is classified as drawn. The corner points used are the ones recalled in
//! docs/method.md (no citable source of the charts' coordinates was found): their
//! boundaries are a vertical then a horizontal segment, kept until the specification's
//! corners replace them.

use crate::loops::Sampled;
use crate::margins::bode;

/// Where the phase's whole turns are fixed [rad/s] (see the module documentation).
pub const ANCHOR_RAD_S: f64 = 1.0;

/// What the response type of the stick is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResponseType {
    /// Rate command (the Rate stick; the pedal).
    Rate,
    /// Attitude command / attitude hold (the Level stick).
    AttitudeCommand,
}

/// The mission-task-element class of a chart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TaskClass {
    /// Target acquisition and tracking.
    Tracking,
    /// All other MTEs.
    Other,
}

/// Where the charts' regions are closed on the right [rad/s]: beyond every chart's last
/// tick (the charts end at a few rad/s; a larger bandwidth is classified as at this edge).
pub const CHART_RIGHT_EDGE_RAD_S: f64 = 100.0;

/// One chart's two boundaries, as polylines of (ω_BW [rad/s], τ_p \[s\]) corners from
/// the τ_p = 0 axis up and right to [`CHART_RIGHT_EDGE_RAD_S`]. A level's region lies
/// below and right of its boundary.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ChartBoundary {
    /// The task class of the chart.
    pub task: TaskClass,
    /// The Level 1/2 boundary.
    pub level1: &'static [[f64; 2]],
    /// The Level 2/3 boundary.
    pub level2: &'static [[f64; 2]],
}

/// A boundary of a vertical segment at ω from τ_p = 0 to τ, then a horizontal one to the
/// right edge: the shape of every chart as recalled (docs/method.md).
macro_rules! corner {
    ($w:expr, $t:expr) => {
        &[[$w, 0.0], [$w, $t], [CHART_RIGHT_EDGE_RAD_S, $t]]
    };
}

/// The boundaries of every chart, per axis (0 roll, 1 pitch, 2 yaw) and task class; the
/// numbers and their status are in docs/method.md.
pub const fn boundary(axis: usize, class: TaskClass) -> ChartBoundary {
    let (level1, level2): (&'static [[f64; 2]], &'static [[f64; 2]]) = match (axis, class) {
        (0, TaskClass::Tracking) => (corner!(2.5, 0.12), corner!(1.5, 0.20)),
        (1, TaskClass::Tracking) => (corner!(2.0, 0.14), corner!(1.0, 0.24)),
        (_, TaskClass::Tracking) => (corner!(3.5, 0.13), corner!(2.0, 0.22)),
        (0, TaskClass::Other) => (corner!(2.0, 0.15), corner!(1.0, 0.25)),
        (1, TaskClass::Other) => (corner!(1.0, 0.20), corner!(0.5, 0.30)),
        (_, TaskClass::Other) => (corner!(2.0, 0.15), corner!(1.0, 0.25)),
    };
    ChartBoundary {
        task: class,
        level1,
        level2,
    }
}

/// Whether (ω, τ) lies inside the region below and right of `boundary`: the polygon of
/// its corners closed along the right edge and the τ_p = 0 axis (even-odd ray casting).
pub fn inside_boundary(boundary: &[[f64; 2]], omega: f64, tau: f64) -> bool {
    let (Some(first), Some(last)) = (boundary.first(), boundary.last()) else {
        return false;
    };
    let mut polygon = boundary.to_vec();
    polygon.push([last[0], 0.0]);
    if first[1] != 0.0 {
        polygon.push([first[0], 0.0]);
    }
    let mut inside = false;
    let mut j = polygon.len() - 1;
    for i in 0..polygon.len() {
        let ([xi, yi], [xj, yj]) = (polygon[i], polygon[j]);
        if (yi > tau) != (yj > tau) && omega < xi + (tau - yi) * (xj - xi) / (yj - yi) {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Bandwidth and phase delay of one attitude response.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Bandwidth {
    /// ω_180 [rad/s].
    pub omega_180_rad_s: Option<f64>,
    /// ω_BW,phase [rad/s].
    pub phase_bandwidth_rad_s: Option<f64>,
    /// ω_BW,gain [rad/s].
    pub gain_bandwidth_rad_s: Option<f64>,
    /// ω_BW [rad/s].
    pub bandwidth_rad_s: Option<f64>,
    /// τ_p \[s\] (null when 2ω_180 lies beyond the grid).
    pub phase_delay_s: Option<f64>,
}

/// First frequency where `y` reaches `level` going the way `falling` says, log-interpolated.
fn first_crossing(omega: &[f64], y: &[f64], level: f64, falling: bool) -> Option<f64> {
    (0..y.len().saturating_sub(1))
        .find(|&i| {
            if falling {
                y[i] > level && y[i + 1] <= level
            } else {
                y[i] < level && y[i + 1] >= level
            }
        })
        .map(|i| {
            let f = (level - y[i]) / (y[i + 1] - y[i]);
            (omega[i].ln() + f * (omega[i + 1].ln() - omega[i].ln())).exp()
        })
}

/// Value of `y` at `w` (log-interpolated), `None` outside the grid.
fn at(omega: &[f64], y: &[f64], w: f64) -> Option<f64> {
    let i = omega.windows(2).position(|p| p[0] <= w && w <= p[1])?;
    let f = (w.ln() - omega[i].ln()) / (omega[i + 1].ln() - omega[i].ln());
    Some(y[i] + f * (y[i + 1] - y[i]))
}

/// ADS-33 bandwidth and phase delay of `response` (attitude per stick).
pub fn bandwidth(response: &Sampled, kind: ResponseType) -> Bandwidth {
    let omega = &response.omega;
    let (db, mut phase) = bode(&response.values);
    let anchor = omega.iter().position(|w| *w >= ANCHOR_RAD_S).unwrap_or(0);
    if let Some(&reference) = phase.get(anchor) {
        // Into (−270°, 90°]: wrap_180 of (p + 90°), less 90°.
        let shift = crate::margins::wrap_180(reference + 90.0) - 90.0 - reference;
        phase.iter_mut().for_each(|p| *p += shift);
    }
    let omega_180 = first_crossing(omega, &phase, -180.0, true);
    let phase_bw = first_crossing(omega, &phase, -135.0, true);
    let gain_bw = omega_180
        .and_then(|w| at(omega, &db, w))
        .and_then(|g180| first_crossing(omega, &db, g180 + 6.0, true));
    let bandwidth = match kind {
        ResponseType::AttitudeCommand => phase_bw,
        ResponseType::Rate => match (phase_bw, gain_bw) {
            (Some(p), Some(g)) => Some(p.min(g)),
            (p, g) => p.or(g),
        },
    };
    let phase_delay = omega_180
        .and_then(|w| at(omega, &phase, 2.0 * w).map(|p| -(p + 180.0).to_radians() / (2.0 * w)));
    Bandwidth {
        omega_180_rad_s: omega_180,
        phase_bandwidth_rad_s: phase_bw,
        gain_bandwidth_rad_s: gain_bw,
        bandwidth_rad_s: bandwidth,
        phase_delay_s: phase_delay,
    }
}

/// The level (1, 2, 3) of `figures` on `chart`; `None` without a bandwidth.
pub fn level(figures: &Bandwidth, chart: &ChartBoundary) -> Option<u8> {
    let bw = figures.bandwidth_rad_s?;
    Some(chart_level(chart, bw, figures.phase_delay_s))
}

/// The level (1, 2, 3) of the point (`bandwidth`, `phase_delay`) on `chart`.
pub fn chart_level(chart: &ChartBoundary, bandwidth: f64, phase_delay: Option<f64>) -> u8 {
    // A phase delay beyond the grid is taken as none (the attitude never lags 180°
    // twice over inside the band), which favours the response: say so in the table. A
    // negative one (phase above −180° at 2ω_180) is none too: the charts start at 0.
    let delay = phase_delay.unwrap_or(0.0).max(0.0);
    // Just inside the right edge, so that a larger bandwidth reads as the edge does.
    let omega = bandwidth.min(CHART_RIGHT_EDGE_RAD_S * (1.0 - 1e-9));
    if inside_boundary(chart.level1, omega, delay) {
        1
    } else if inside_boundary(chart.level2, omega, delay) {
        2
    } else {
        3
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const AXES: [&str; 3] = ["roll", "pitch", "yaw"];

    fn charts() -> Vec<(String, ChartBoundary)> {
        let mut charts = Vec::new();
        for (axis, name) in AXES.iter().enumerate() {
            for class in [TaskClass::Tracking, TaskClass::Other] {
                charts.push((format!("{name} {class:?}"), boundary(axis, class)));
            }
        }
        charts
    }

    /// Points a little to either side of the middle of every drawn segment of both
    /// boundaries: inside the Level 1 boundary is Level 1, just outside it Level 2; inside
    /// the Level 2 boundary (and outside Level 1's) Level 2, just outside it Level 3.
    #[test]
    fn points_either_side_of_every_segment_fall_in_the_levels_it_separates() {
        let step = 1e-3;
        for (name, chart) in charts() {
            for (boundary, inner, outer) in [(chart.level1, 1, 2), (chart.level2, 2, 3)] {
                assert!(boundary.len() >= 2, "{name}");
                for segment in boundary.windows(2) {
                    let ([x0, y0], [x1, y1]) = (segment[0], segment[1]);
                    let (mx, my) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
                    // The normal pointing right/down of the segment, going up and right:
                    // (dy, −dx) normalised on the chart's axes scaled to similar sizes.
                    let (dx, dy) = ((x1 - x0) / 10.0, y1 - y0);
                    let norm = dx.hypot(dy);
                    let (nx, ny) = (dy / norm * 10.0 * step, -dx / norm * step);
                    let level_at = |x: f64, y: f64| chart_level(&chart, x, Some(y));
                    assert_eq!(
                        level_at(mx + nx, my + ny),
                        inner,
                        "{name}: inside the segment {segment:?}"
                    );
                    assert_eq!(
                        level_at(mx - nx, my - ny),
                        outer,
                        "{name}: outside the segment {segment:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_level_1_region_lies_inside_the_level_2_region() {
        for (name, chart) in charts() {
            for [w, t] in chart.level1 {
                // Each Level 1 corner, nudged into its own region, is inside Level 2's.
                let (w, t) = ((w * 1.001).min(CHART_RIGHT_EDGE_RAD_S * 0.999), t * 0.999);
                assert!(inside_boundary(chart.level2, w, t), "{name}: {w} {t}");
            }
        }
    }

    #[test]
    fn far_points_and_missing_delays_are_classified() {
        let chart = boundary(0, TaskClass::Tracking);
        assert_eq!(chart_level(&chart, 0.1, Some(0.01)), 3);
        assert_eq!(chart_level(&chart, 500.0, Some(0.01)), 1);
        assert_eq!(chart_level(&chart, 500.0, Some(0.5)), 3);
        assert_eq!(chart_level(&chart, 10.0, None), 1);
        assert_eq!(chart_level(&chart, 10.0, Some(-0.01)), 1);
        let none = Bandwidth::default();
        assert_eq!(level(&none, &chart), None);
    }
}
