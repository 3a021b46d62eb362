//! How a mode is named from its eigenvalue and eigenvector.
//!
//! The eigenvector `x` (of `(A − λI) x = 0`, the right singular vector of the smallest
//! singular value of `A − λI`) has components in the states' own units: m/s, rad/s, rad.
//! They are made comparable by expressing each as the attitude \[rad\] it amounts to in this
//! mode, `ω_s = max(|λ|, 0.1 rad/s)` being the mode's rate of change:
//!
//! ```text
//! angle (φ, θ, ψ, flapping b1c, b1s)   a = |x_i|                 [rad]
//! rate  (p, q, r)                       a = |x_i| / ω_s           (θ̇ = q  ⇒  |θ| = |q|/|λ|)
//! speed (u, v, w)                       a = |x_i| · ω_s / g       (u̇ = −g θ  ⇒  |θ| = |u|·|λ|/g)
//! ```
//!
//! so that a rate and the attitude it integrates to, or a speed and the attitude whose
//! gravity component drives it, weigh the same (g = 9.80665 m/s², or 32.174 ft/s² when the
//! model's gravity term says its speeds are in ft/s: [`super::state_kinds`]). A state of
//! another name keeps its own unit. The floor of 0.1 rad/s ([`SCALING_FLOOR_RAD_S`], a 63 s
//! period) keeps a drift from being named by a trace of attitude: with `|λ|` itself a heave
//! mode that has lost its damping (`Z_w` = 0, λ = −0.0007 rad/s, eigenvector w 1, θ 0.0018
//! — seed 2 of the default campaign) would weigh its speed by 7·10⁻⁵ and read as a pitch
//! mode. The share of state i is `a_i² / Σ_j a_j²` (the shares sum to
//! 1), and the states fall into groups: lateral body `v p φ`, longitudinal body `u q θ`,
//! heave `w`, yaw `r ψ`, rotor `b1s` (lateral) and `b1c` (longitudinal) (also
//! `beta1s`/`beta1c`); a state of another name joins the group of what drives it in the
//! model (a flap or stabilizer-bar state driven by p or q is that axis's rotor, a yaw
//! damper's state driven by r is yaw: [`super::state_kinds`]), else other. The rules,
//! first match wins:
//!
//! 1. `|λ| < 10⁻⁶` rad/s → `origin`.
//! 2. rotor share ≥ 0.10 ([`ROTOR_SHARE_LIMIT`]) → `roll–flap` when
//!    `rotor lateral + lateral ≥ rotor longitudinal + longitudinal`, else `pitch–flap`. (The flap states with p or q:
//!    fast modes, above 7 rad/s on the Bo-105; on it the roll–flap pair's rotor share is
//!    0.25.)
//! 3. complex pair, `|λ| < 3` rad/s ([`HOVER_MODE_LIMIT_RAD_S`]): yaw the largest group →
//!    `yaw oscillation`; heave the largest → `heave oscillation`; otherwise
//!    `hover oscillation (lateral)` when lateral ≥ 2 × longitudinal
//!    ([`AXIS_DOMINANCE`]), `hover oscillation (longitudinal)` when longitudinal ≥ 2 ×
//!    lateral, else `hover oscillation (coupled)`.
//! 4. complex pair, `|λ| ≥ 3` rad/s: by the largest group, `roll oscillation`,
//!    `pitch oscillation`, `yaw oscillation`, `heave oscillation`.
//! 5. real, `|λ| < 1` rad/s ([`SPIRAL_LIMIT_RAD_S`]) with lateral ≥ 0.25 and yaw ≥ 0.25
//!    ([`SPIRAL_SHARE`]) → `spiral` (the slow roll–yaw real mode).
//! 6. real: by the largest group, `roll subsidence`, `pitch subsidence`, `yaw`, `heave`.
//! 7. anything else (the largest group is `other`): `other`.
//!
//! A coupled mode is not forced into an axis: on the Bo-105 at hover both low-frequency
//! oscillations carry roll, pitch and yaw in nearly equal shares (the truth's: lateral
//! 0.40 / longitudinal 0.42 and 0.35 / 0.32), and naming them by the larger share would
//! name them by noise.
//!

use std::fmt;

use num_complex::Complex64;

use super::state_kinds::{Group, StateKinds, Unit};

/// A mode with `|λ|` below this [rad/s] is a pole at the origin.
pub const ORIGIN_LIMIT_RAD_S: f64 = 1e-6;
/// Modes below this natural frequency [rad/s] are hover modes (the hover oscillations,
/// heave, yaw): the issue's acceptance criteria compare them with the truth.
pub const HOVER_MODE_LIMIT_RAD_S: f64 = 3.0;
/// The eigenvector's rates and speeds are scaled with `max(|λ|, this)` [rad/s].
pub const SCALING_FLOOR_RAD_S: f64 = 0.1;
/// A mode whose flap states take at least this share is a rotor (flap) mode.
pub const ROTOR_SHARE_LIMIT: f64 = 0.10;
/// A hover oscillation is lateral (longitudinal) when its lateral (longitudinal) share is
/// at least this many times the other.
pub const AXIS_DOMINANCE: f64 = 2.0;
/// A spiral is a real mode slower than this [rad/s] …
pub const SPIRAL_LIMIT_RAD_S: f64 = 1.0;
/// … with at least this share in both the lateral and the yaw group.
pub const SPIRAL_SHARE: f64 = 0.25;

/// The name of a mode (rules in this module's documentation). In JSON and tables: the
/// strings of [`ModeName::as_str`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ModeName {
    /// `|λ| < 10⁻⁶` rad/s.
    Origin,
    /// Lateral flapping with roll (`roll–flap`).
    RollFlap,
    /// Longitudinal flapping with pitch (`pitch–flap`).
    PitchFlap,
    /// Complex pair below 3 rad/s, lateral body motion dominant.
    HoverOscillationLateral,
    /// Complex pair below 3 rad/s, longitudinal body motion dominant.
    HoverOscillationLongitudinal,
    /// Complex pair below 3 rad/s, lateral and longitudinal within a factor 2.
    HoverOscillationCoupled,
    /// Complex pair at or above 3 rad/s, lateral body motion the largest group.
    RollOscillation,
    /// Complex pair at or above 3 rad/s, longitudinal body motion the largest group.
    PitchOscillation,
    /// Complex pair, yaw the largest group.
    YawOscillation,
    /// Complex pair, heave the largest group.
    HeaveOscillation,
    /// Real, lateral body motion the largest group.
    RollSubsidence,
    /// Real, longitudinal body motion the largest group.
    PitchSubsidence,
    /// Real, yaw the largest group.
    Yaw,
    /// Real, heave the largest group.
    Heave,
    /// Real, slower than 1 rad/s, lateral and yaw both ≥ 0.25.
    Spiral,
    /// States of other names the largest group.
    Other,
}

impl ModeName {
    /// The name as written in JSON and tables.
    pub fn as_str(self) -> &'static str {
        match self {
            ModeName::Origin => "origin",
            ModeName::RollFlap => "roll–flap",
            ModeName::PitchFlap => "pitch–flap",
            ModeName::HoverOscillationLateral => "hover oscillation (lateral)",
            ModeName::HoverOscillationLongitudinal => "hover oscillation (longitudinal)",
            ModeName::HoverOscillationCoupled => "hover oscillation (coupled)",
            ModeName::RollOscillation => "roll oscillation",
            ModeName::PitchOscillation => "pitch oscillation",
            ModeName::YawOscillation => "yaw oscillation",
            ModeName::HeaveOscillation => "heave oscillation",
            ModeName::RollSubsidence => "roll subsidence",
            ModeName::PitchSubsidence => "pitch subsidence",
            ModeName::Yaw => "yaw",
            ModeName::Heave => "heave",
            ModeName::Spiral => "spiral",
            ModeName::Other => "other",
        }
    }
}

impl fmt::Display for ModeName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Shares of a mode per group of states (they sum to 1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GroupShares {
    /// `v p φ`.
    pub lateral: f64,
    /// `u q θ`.
    pub longitudinal: f64,
    /// `w`.
    pub heave: f64,
    /// `r ψ`.
    pub yaw: f64,
    /// `b1s`.
    pub rotor_lateral: f64,
    /// `b1c`.
    pub rotor_longitudinal: f64,
    /// States of other names.
    pub other: f64,
}

impl GroupShares {
    fn add(&mut self, group: Group, share: f64) {
        let slot = match group {
            Group::Lateral => &mut self.lateral,
            Group::Longitudinal => &mut self.longitudinal,
            Group::Heave => &mut self.heave,
            Group::Yaw => &mut self.yaw,
            Group::RotorLateral => &mut self.rotor_lateral,
            Group::RotorLongitudinal => &mut self.rotor_longitudinal,
            Group::Other => &mut self.other,
        };
        *slot += share;
    }

    /// Flap states together.
    pub fn rotor(&self) -> f64 {
        self.rotor_lateral + self.rotor_longitudinal
    }

    /// The largest body group (lateral, longitudinal, heave, yaw, other); ties go to the
    /// first in that order.
    fn largest_body_group(&self) -> Group {
        let groups = [
            (Group::Lateral, self.lateral),
            (Group::Longitudinal, self.longitudinal),
            (Group::Heave, self.heave),
            (Group::Yaw, self.yaw),
            (Group::Other, self.other),
        ];
        groups
            .iter()
            .fold(
                (Group::Lateral, f64::NEG_INFINITY),
                |best, &(group, share)| {
                    if share > best.1 {
                        (group, share)
                    } else {
                        best
                    }
                },
            )
            .0
    }
}

/// Shares `a_i² / Σ a_j²` of the attitude-equivalent components (module documentation).
pub(super) fn scaled_shares(kinds: &StateKinds, magnitudes: &[f64], omega: f64) -> Vec<f64> {
    let omega = omega.max(SCALING_FLOOR_RAD_S);
    let scaled: Vec<f64> = kinds
        .kinds
        .iter()
        .zip(magnitudes)
        .map(|(&(unit, _), magnitude)| {
            let factor = match unit {
                Unit::Angle | Unit::Own => 1.0,
                Unit::Rate => 1.0 / omega,
                Unit::Speed => omega / kinds.gravity,
            };
            (magnitude * factor).powi(2)
        })
        .collect();
    let total: f64 = scaled.iter().sum();
    if total > 0.0 && total.is_finite() {
        scaled.iter().map(|s| s / total).collect()
    } else {
        vec![0.0; scaled.len()]
    }
}

/// The shares of the states by group (they sum to 1 when `shares` do).
pub(super) fn group_shares(kinds: &StateKinds, shares: &[f64]) -> GroupShares {
    let mut groups = GroupShares::default();
    for (&(_, group), share) in kinds.kinds.iter().zip(shares) {
        groups.add(group, *share);
    }
    groups
}

/// The name of a mode from its eigenvalue, its poles (1 real, 2 a complex pair) and its
/// group shares (rules 1–7 of the module documentation).
pub(super) fn name_of(eigenvalue: Complex64, poles: usize, g: &GroupShares) -> ModeName {
    let omega = eigenvalue.norm();
    if omega < ORIGIN_LIMIT_RAD_S {
        return ModeName::Origin;
    }
    if g.rotor() >= ROTOR_SHARE_LIMIT {
        return if g.rotor_lateral + g.lateral >= g.rotor_longitudinal + g.longitudinal {
            ModeName::RollFlap
        } else {
            ModeName::PitchFlap
        };
    }
    let largest = g.largest_body_group();
    if poles == 2 {
        return match largest {
            Group::Yaw => ModeName::YawOscillation,
            Group::Heave => ModeName::HeaveOscillation,
            Group::Other => ModeName::Other,
            _ if omega < HOVER_MODE_LIMIT_RAD_S => {
                if g.lateral >= AXIS_DOMINANCE * g.longitudinal {
                    ModeName::HoverOscillationLateral
                } else if g.longitudinal >= AXIS_DOMINANCE * g.lateral {
                    ModeName::HoverOscillationLongitudinal
                } else {
                    ModeName::HoverOscillationCoupled
                }
            }
            Group::Lateral => ModeName::RollOscillation,
            _ => ModeName::PitchOscillation,
        };
    }
    if omega < SPIRAL_LIMIT_RAD_S && g.lateral >= SPIRAL_SHARE && g.yaw >= SPIRAL_SHARE {
        return ModeName::Spiral;
    }
    match largest {
        Group::Lateral => ModeName::RollSubsidence,
        Group::Longitudinal => ModeName::PitchSubsidence,
        Group::Heave => ModeName::Heave,
        Group::Yaw => ModeName::Yaw,
        _ => ModeName::Other,
    }
}
