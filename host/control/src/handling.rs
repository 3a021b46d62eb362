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
//! The levels are the boundaries of ADS-33E-PRF's small-amplitude attitude charts for
//! hover and low speed (section 3.3, Figures 3.3.2.1 (pitch and roll) and 3.3.5.1
//! (yaw)), simplified here to rectangles: Level 1 when ω_BW ≥ ω₁ and τ_p ≤ τ₁, Level 2
//! when ω_BW ≥ ω₂ and τ_p ≤ τ₂, Level 3 otherwise. The numbers and their status are in
//! docs/method.md.

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

/// One chart's simplified boundaries.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LevelBoundary {
    /// Least bandwidth for Level 1 [rad/s].
    pub level1_bandwidth_rad_s: f64,
    /// Largest phase delay for Level 1 \[s\].
    pub level1_phase_delay_s: f64,
    /// Least bandwidth for Level 2 [rad/s].
    pub level2_bandwidth_rad_s: f64,
    /// Largest phase delay for Level 2 \[s\].
    pub level2_phase_delay_s: f64,
}

/// The boundaries used, per axis (roll, pitch, yaw) and task class (docs/method.md).
pub const fn boundary(axis: usize, class: TaskClass) -> LevelBoundary {
    let (w1, t1, w2, t2) = match (axis, class) {
        (0, TaskClass::Tracking) => (2.5, 0.12, 1.5, 0.20),
        (1, TaskClass::Tracking) => (2.0, 0.14, 1.0, 0.24),
        (_, TaskClass::Tracking) => (3.5, 0.13, 2.0, 0.22),
        (0, TaskClass::Other) => (2.0, 0.15, 1.0, 0.25),
        (1, TaskClass::Other) => (1.0, 0.20, 0.5, 0.30),
        (_, TaskClass::Other) => (2.0, 0.15, 1.0, 0.25),
    };
    LevelBoundary {
        level1_bandwidth_rad_s: w1,
        level1_phase_delay_s: t1,
        level2_bandwidth_rad_s: w2,
        level2_phase_delay_s: t2,
    }
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

/// The level (1, 2, 3) of `figures` against `limits`; `None` without a bandwidth.
pub fn level(figures: &Bandwidth, limits: &LevelBoundary) -> Option<u8> {
    let bw = figures.bandwidth_rad_s?;
    // A phase delay beyond the grid is taken as none (the attitude never lags 180°
    // twice over inside the band), which favours the response: say so in the table.
    let delay = figures.phase_delay_s.unwrap_or(0.0);
    Some(
        if bw >= limits.level1_bandwidth_rad_s && delay <= limits.level1_phase_delay_s {
            1
        } else if bw >= limits.level2_bandwidth_rad_s && delay <= limits.level2_phase_delay_s {
            2
        } else {
            3
        },
    )
}
