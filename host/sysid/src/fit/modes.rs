//! The modes of a linear model `M ẋ = F x + G u`: the eigenvalues of the state matrix
//! `A = M⁻¹F`, each named from its eigenvector by a fixed rule set, and the comparison of
//! an identified model's modes with a truth model's.
//!
//! # Figures of one mode
//!
//! A real eigenvalue is one mode, a complex-conjugate pair is one mode (reported by the
//! member with Im λ > 0). With `σ = Re λ`:
//!
//! ```text
//! ω_n = |λ|                      natural frequency [rad/s] (for a real pole, |σ|)
//! ζ   = −σ / |λ|                 damping ratio, complex pairs only
//! t_2 = ln 2 / σ                 time to double amplitude [s], when σ > 0
//! t_½ = ln 2 / (−σ)              time to half amplitude [s], when σ < 0
//! ```
//!
//! For a complex pair `t_2` and `t_½` are those of the envelope `e^{σt}` of the
//! oscillation. A mode with `|λ| < 10⁻⁶` rad/s is a pole at the origin
//! ([`ORIGIN_LIMIT_RAD_S`]): named `origin`, with no frequency, damping or time.
//!
//! # How a mode is named
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
//! gravity component drives it, weigh the same (g = 9.80665 m/s²). A state of another
//! name keeps its own unit. The floor of 0.1 rad/s ([`SCALING_FLOOR_RAD_S`], a 63 s
//! period) keeps a drift from being named by a trace of attitude: with `|λ|` itself a heave
//! mode that has lost its damping (`Z_w` = 0, λ = −0.0007 rad/s, eigenvector w 1, θ 0.0018
//! — seed 2 of the default campaign) would weigh its speed by 7·10⁻⁵ and read as a pitch
//! mode. The share of state i is `a_i² / Σ_j a_j²` (the shares sum to
//! 1), and the states fall into groups: lateral body `v p φ`, longitudinal body `u q θ`,
//! heave `w`, yaw `r ψ`, rotor `b1s` (lateral) and `b1c` (longitudinal) (also
//! `beta1s`/`beta1c`), other. The rules, first match wins:
//!
//! 1. `|λ| < 10⁻⁶` rad/s → `origin`.
//! 2. rotor share ≥ 0.10 ([`ROTOR_SHARE_LIMIT`]) → `roll–flap` when
//!    `b1s + lateral ≥ b1c + longitudinal`, else `pitch–flap`. (The flap states with p or q:
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
//! # Comparison with a truth model
//!
//! [`compare_modes`] pairs each identified mode with at most one truth mode, one to one:
//! first modes of the same name, then the rest by the nearest eigenvalue (each pass takes
//! the closest pairs `|λ_id − λ_true|` first). Its error is `|λ_id − λ_true| / |λ_true|`
//! (both by their Im ≥ 0 member). The truth's hover modes are its modes with
//! `|λ| < 3` rad/s, the origin excepted; one is matched when its counterpart is within
//! 25 % ([`HOVER_MODE_TOLERANCE_PERCENT`]). Both thresholds are the acceptance criteria of
//! the hover-modes issue (20).

use std::collections::BTreeMap;
use std::f64::consts::LN_2;
use std::fmt::{self, Write as _};

use nalgebra::linalg::{Schur, SVD};
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use super::model::Model;

/// A mode with `|λ|` below this [rad/s] is a pole at the origin.
pub const ORIGIN_LIMIT_RAD_S: f64 = 1e-6;
/// Modes below this natural frequency [rad/s] are hover modes (the hover oscillations,
/// heave, yaw): the issue's acceptance criteria compare them with the truth.
pub const HOVER_MODE_LIMIT_RAD_S: f64 = 3.0;
/// A truth hover mode is matched when its identified counterpart is within this relative
/// error [%] of its eigenvalue.
pub const HOVER_MODE_TOLERANCE_PERCENT: f64 = 25.0;
/// Gravity [m/s²] of the speed-to-attitude scaling of the eigenvector.
pub const STANDARD_GRAVITY: f64 = 9.80665;
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

/// Iteration limit of the Schur and SVD decompositions (they converge in a few dozen
/// sweeps for the 10-state models here; the limit only keeps a pathological matrix from
/// looping).
const MAX_ITERATIONS: usize = 10_000;

/// Why the modes of a model cannot be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModeError {
    /// `M` cannot be inverted: `A = M⁻¹F` does not exist.
    #[error("the mass matrix M is singular: A = M⁻¹F does not exist")]
    SingularMassMatrix,
    /// `M` or `F` has a NaN or an infinite entry, or `M⁻¹F` does (a nearly singular `M`).
    #[error("M, F or M⁻¹F has a NaN or infinite entry")]
    NotFinite,
    /// The eigenvalue or eigenvector decomposition did not converge.
    #[error("the eigenvalue decomposition did not converge")]
    NoConvergence,
}

/// The name of a mode (rules in the module documentation). In JSON and tables: the
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

/// The group a state's motion belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Group {
    Lateral,
    Longitudinal,
    Heave,
    Yaw,
    RotorLateral,
    RotorLongitudinal,
    Other,
}

/// The unit of a state, which sets how its eigenvector component is scaled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Unit {
    /// rad: as it is.
    Angle,
    /// rad/s: divided by |λ|.
    Rate,
    /// m/s: times |λ|/g.
    Speed,
    /// Anything else: as it is.
    Own,
}

/// Unit and group of a state by its name.
fn classify(state: &str) -> (Unit, Group) {
    match state {
        "u" => (Unit::Speed, Group::Longitudinal),
        "v" => (Unit::Speed, Group::Lateral),
        "w" => (Unit::Speed, Group::Heave),
        "p" => (Unit::Rate, Group::Lateral),
        "q" => (Unit::Rate, Group::Longitudinal),
        "r" => (Unit::Rate, Group::Yaw),
        "phi" => (Unit::Angle, Group::Lateral),
        "theta" => (Unit::Angle, Group::Longitudinal),
        "psi" => (Unit::Angle, Group::Yaw),
        "b1s" | "beta1s" => (Unit::Angle, Group::RotorLateral),
        "b1c" | "beta1c" => (Unit::Angle, Group::RotorLongitudinal),
        _ => (Unit::Own, Group::Other),
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

/// One mode of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// Its name (rules in the module documentation).
    pub name: ModeName,
    /// The eigenvalue [rad/s]; of a complex pair the member with Im λ > 0.
    pub eigenvalue: Complex64,
    /// Poles the mode stands for: 1 (real) or 2 (complex pair).
    pub poles: usize,
    /// Shares of the states (in the model's state order), scaled as the module
    /// documentation says; they sum to 1.
    pub shares: Vec<f64>,
    /// The same shares by group.
    pub groups: GroupShares,
}

impl Mode {
    /// ω_n = |λ| [rad/s]; None at the origin.
    pub fn natural_frequency(&self) -> Option<f64> {
        (self.name != ModeName::Origin).then(|| self.eigenvalue.norm())
    }

    /// ζ = −Re λ / |λ| of a complex pair; None for a real pole or at the origin.
    pub fn damping_ratio(&self) -> Option<f64> {
        (self.poles == 2 && self.name != ModeName::Origin)
            .then(|| -self.eigenvalue.re / self.eigenvalue.norm())
    }

    /// t_2 = ln 2 / Re λ \[s\] when Re λ > 0 (the envelope's, for a complex pair); None
    /// otherwise and at the origin.
    pub fn time_to_double_s(&self) -> Option<f64> {
        (self.name != ModeName::Origin && self.eigenvalue.re > 0.0)
            .then(|| LN_2 / self.eigenvalue.re)
    }

    /// t_½ = ln 2 / (−Re λ) \[s\] when Re λ < 0 (the envelope's, for a complex pair); None
    /// otherwise and at the origin.
    pub fn time_to_half_s(&self) -> Option<f64> {
        (self.name != ModeName::Origin && self.eigenvalue.re < 0.0)
            .then(|| LN_2 / -self.eigenvalue.re)
    }

    /// Whether this is a hover mode: 10⁻⁶ ≤ |λ| < 3 rad/s.
    pub fn is_hover_mode(&self) -> bool {
        self.name != ModeName::Origin && self.eigenvalue.norm() < HOVER_MODE_LIMIT_RAD_S
    }
}

/// `A = M⁻¹F` by an LU solve of `M A = F`.
pub fn state_matrix(model: &Model) -> Result<DMatrix<f64>, ModeError> {
    if model.m.iter().chain(model.f.iter()).any(|v| !v.is_finite()) {
        return Err(ModeError::NotFinite);
    }
    if model.m.nrows() != model.m.ncols() || model.f.shape() != model.m.shape() {
        return Err(ModeError::SingularMassMatrix);
    }
    let a = model
        .m
        .clone()
        .lu()
        .solve(&model.f)
        .ok_or(ModeError::SingularMassMatrix)?;
    if a.iter().any(|v| !v.is_finite()) {
        return Err(ModeError::NotFinite);
    }
    Ok(a)
}

/// The modes of `model`, sorted by |λ| (then Re λ, then Im λ).
pub fn modes(model: &Model) -> Result<Vec<Mode>, ModeError> {
    let a = state_matrix(model)?;
    let n = a.nrows();
    if n == 0 {
        return Ok(Vec::new());
    }
    let schur =
        Schur::try_new(a.clone(), f64::EPSILON, MAX_ITERATIONS).ok_or(ModeError::NoConvergence)?;
    let eigenvalues = schur.complex_eigenvalues();
    if eigenvalues
        .iter()
        .any(|z| !z.re.is_finite() || !z.im.is_finite())
    {
        return Err(ModeError::NotFinite);
    }
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1.0);
    let mut found = Vec::new();
    for lambda in eigenvalues.iter() {
        // Real when its imaginary part is at rounding level; a pair by its Im > 0 member.
        // At the origin every eigenvalue is a mode of its own: a double root at 0 may come
        // out of the Schur form as ±10⁻¹⁰j, and it stands for two lost modes, not one.
        let real = lambda.im.abs() <= 1e-12 * scale || lambda.norm() < ORIGIN_LIMIT_RAD_S;
        if !real && lambda.im < 0.0 {
            continue;
        }
        let eigenvalue = if real {
            Complex64::new(lambda.re, 0.0)
        } else {
            *lambda
        };
        let magnitudes = eigenvector_magnitudes(&a, eigenvalue)?;
        let shares = scaled_shares(&model.states, &magnitudes, eigenvalue.norm());
        let mut groups = GroupShares::default();
        for (state, share) in model.states.iter().zip(&shares) {
            groups.add(classify(state).1, *share);
        }
        let mut mode = Mode {
            name: ModeName::Other,
            eigenvalue,
            poles: if real { 1 } else { 2 },
            shares,
            groups,
        };
        mode.name = name_of(&mode);
        found.push(mode);
    }
    found.sort_by(|x, y| {
        x.eigenvalue
            .norm()
            .total_cmp(&y.eigenvalue.norm())
            .then(x.eigenvalue.re.total_cmp(&y.eigenvalue.re))
            .then(x.eigenvalue.im.total_cmp(&y.eigenvalue.im))
    });
    Ok(found)
}

/// |x_i| of the eigenvector of `a` for `lambda`: the right singular vector of the smallest
/// singular value of `A − λI` (its null vector), normalised to unit length.
fn eigenvector_magnitudes(a: &DMatrix<f64>, lambda: Complex64) -> Result<Vec<f64>, ModeError> {
    let n = a.nrows();
    let shifted = DMatrix::from_fn(n, n, |i, j| {
        let diagonal = if i == j {
            lambda
        } else {
            Complex64::new(0.0, 0.0)
        };
        Complex64::new(a[(i, j)], 0.0) - diagonal
    });
    let svd = SVD::try_new(shifted, false, true, f64::EPSILON, MAX_ITERATIONS)
        .ok_or(ModeError::NoConvergence)?;
    let v_t = svd.v_t.ok_or(ModeError::NoConvergence)?;
    // Singular values are sorted in descending order: the last row of Vᴴ is the null
    // vector (conjugated, which leaves the magnitudes alone).
    let magnitudes: Vec<f64> = (0..n).map(|j| v_t[(n - 1, j)].norm()).collect();
    if magnitudes.iter().any(|m| !m.is_finite()) {
        return Err(ModeError::NotFinite);
    }
    Ok(magnitudes)
}

/// Shares `a_i² / Σ a_j²` of the attitude-equivalent components (module documentation).
fn scaled_shares(states: &[String], magnitudes: &[f64], omega: f64) -> Vec<f64> {
    let omega = omega.max(SCALING_FLOOR_RAD_S);
    let scaled: Vec<f64> = states
        .iter()
        .zip(magnitudes)
        .map(|(state, magnitude)| {
            let factor = match classify(state).0 {
                Unit::Angle | Unit::Own => 1.0,
                Unit::Rate => 1.0 / omega,
                Unit::Speed => omega / STANDARD_GRAVITY,
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

/// The name of a mode from its eigenvalue and group shares (rules 1–7 of the module
/// documentation).
fn name_of(mode: &Mode) -> ModeName {
    let omega = mode.eigenvalue.norm();
    let g = &mode.groups;
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
    if mode.poles == 2 {
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

/// `|λ_id − λ_true| / |λ_true|` in %; None when the truth is at 0.
pub fn relative_error_percent(identified: Complex64, truth: Complex64) -> Option<f64> {
    let scale = truth.norm();
    (scale > 0.0).then(|| 100.0 * (identified - truth).norm() / scale)
}

/// Pair each identified mode with at most one truth mode, one to one: same name first,
/// then the nearest eigenvalue; each pass takes the closest pairs first (ties by index).
/// Returns, per identified mode, the index of its truth mode.
pub fn pair_modes(identified: &[Mode], truth: &[Mode]) -> Vec<Option<usize>> {
    let mut pairing = vec![None; identified.len()];
    let mut truth_taken = vec![false; truth.len()];
    for same_name_only in [true, false] {
        let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
        for (i, mode) in identified.iter().enumerate() {
            for (t, reference) in truth.iter().enumerate() {
                if !same_name_only || mode.name == reference.name {
                    let distance = (mode.eigenvalue - reference.eigenvalue).norm();
                    candidates.push((distance, i, t));
                }
            }
        }
        candidates.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        for (_, i, t) in candidates {
            if pairing[i].is_none() && !truth_taken[t] {
                pairing[i] = Some(t);
                truth_taken[t] = true;
            }
        }
    }
    pairing
}

/// A mode as written in `model.json` and `summary.json`; the `truth*` and
/// `error_percent` fields are null without a truth comparison (or when no truth mode was
/// left to pair with).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeRecord {
    /// The mode's name ([`ModeName::as_str`]).
    pub name: String,
    /// `[Re λ, Im λ]` [rad/s]; Im ≥ 0 (a complex pair by its upper member).
    pub eigenvalue: [f64; 2],
    /// ω_n = |λ| [rad/s]; null at the origin.
    pub omega_n: Option<f64>,
    /// ζ = −Re λ/|λ| of a complex pair; null for a real pole.
    pub zeta: Option<f64>,
    /// ln 2 / Re λ \[s\] when unstable; else null.
    pub time_to_double_s: Option<f64>,
    /// ln 2 / (−Re λ) \[s\] when stable; else null.
    pub time_to_half_s: Option<f64>,
    /// Poles the mode stands for: 1 (real) or 2 (complex pair).
    #[serde(default = "one_pole")]
    pub poles: usize,
    /// Share of each state in the mode (module documentation), states with ≥ 1 %.
    #[serde(default)]
    pub shares: BTreeMap<String, f64>,
    /// `[Re, Im]` of the paired truth mode.
    #[serde(default)]
    pub truth: Option<[f64; 2]>,
    /// Name of the paired truth mode.
    #[serde(default)]
    pub truth_name: Option<String>,
    /// `100·|λ_id − λ_true| / |λ_true|`.
    #[serde(default)]
    pub error_percent: Option<f64>,
}

fn one_pole() -> usize {
    1
}

/// Shares below this are left out of a [`ModeRecord`].
const RECORDED_SHARE: f64 = 0.01;

impl ModeRecord {
    /// The record of `mode`, without truth.
    pub fn new(mode: &Mode, states: &[String]) -> ModeRecord {
        ModeRecord {
            name: mode.name.as_str().to_string(),
            eigenvalue: [mode.eigenvalue.re, mode.eigenvalue.im],
            omega_n: mode.natural_frequency(),
            zeta: mode.damping_ratio(),
            time_to_double_s: mode.time_to_double_s(),
            time_to_half_s: mode.time_to_half_s(),
            poles: mode.poles,
            shares: states
                .iter()
                .zip(&mode.shares)
                .filter(|(_, share)| **share >= RECORDED_SHARE)
                .map(|(state, share)| (state.clone(), *share))
                .collect(),
            truth: None,
            truth_name: None,
            error_percent: None,
        }
    }

    /// The eigenvalue as a complex number.
    pub fn lambda(&self) -> Complex64 {
        Complex64::new(self.eigenvalue[0], self.eigenvalue[1])
    }

    /// The largest shares, e.g. `w 79 %, r 21 %` (at most three, each ≥ 10 %).
    pub fn shape(&self) -> String {
        let mut shares: Vec<(&String, &f64)> = self.shares.iter().collect();
        shares.sort_by(|x, y| y.1.total_cmp(x.1).then(x.0.cmp(y.0)));
        shares
            .iter()
            .filter(|(_, share)| **share >= 0.1)
            .take(3)
            .map(|(state, share)| format!("{state} {:.0} %", 100.0 * **share))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A truth mode and the identified mode paired with it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthModeRecord {
    /// The truth mode's name.
    pub name: String,
    /// `[Re λ, Im λ]` [rad/s], Im ≥ 0.
    pub eigenvalue: [f64; 2],
    /// ω_n = |λ| [rad/s]; null at the origin.
    pub omega_n: Option<f64>,
    /// ζ of a complex pair; null for a real pole.
    pub zeta: Option<f64>,
    /// Whether it is a hover mode (10⁻⁶ ≤ |λ| < 3 rad/s).
    pub hover: bool,
    /// `[Re, Im]` of the identified mode paired with it; null when none was left.
    pub identified: Option<[f64; 2]>,
    /// Name of that identified mode.
    pub identified_name: Option<String>,
    /// `100·|λ_id − λ_true| / |λ_true|`; null without a pair.
    pub error_percent: Option<f64>,
}

impl TruthModeRecord {
    /// Whether an identified mode is paired with it within
    /// [`HOVER_MODE_TOLERANCE_PERCENT`].
    pub fn within_tolerance(&self) -> bool {
        self.error_percent
            .is_some_and(|e| e <= HOVER_MODE_TOLERANCE_PERCENT)
    }
}

/// How the identified model reproduces the truth's hover modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HoverModeScore {
    /// Truth hover modes with an identified counterpart within 25 %.
    pub matched: usize,
    /// Truth hover modes (10⁻⁶ ≤ |λ| < 3 rad/s).
    pub of: usize,
    /// The largest error [%] among the truth hover modes that have a counterpart; null
    /// when none has.
    pub worst_error_percent: Option<f64>,
}

impl HoverModeScore {
    /// Every truth hover mode matched.
    pub fn all_matched(&self) -> bool {
        self.matched == self.of
    }
}

/// The modes of an identified model compared with those of a truth model.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeComparison {
    /// The identified modes, with their truth counterparts.
    pub identified: Vec<ModeRecord>,
    /// The truth's modes, with their identified counterparts.
    pub truth: Vec<TruthModeRecord>,
    /// The truth hover modes matched within 25 %.
    pub hover: HoverModeScore,
    /// Poles of the identified model at the origin (a pair counts 2).
    pub poles_at_origin: usize,
}

/// The records of `model`'s modes (no truth).
pub fn mode_records(model: &Model) -> Result<Vec<ModeRecord>, ModeError> {
    Ok(modes(model)?
        .iter()
        .map(|mode| ModeRecord::new(mode, &model.states))
        .collect())
}

/// Poles of `records` at the origin (a pair counts 2).
pub fn poles_at_origin(records: &[ModeRecord]) -> usize {
    records
        .iter()
        .filter(|r| r.name == ModeName::Origin.as_str())
        .map(|r| r.poles)
        .sum()
}

/// Compare the modes of `identified` with those of `truth` (module documentation).
pub fn compare_modes(identified: &Model, truth: &Model) -> Result<ModeComparison, ModeError> {
    let identified_modes = modes(identified)?;
    let truth_modes = modes(truth)?;
    let pairing = pair_modes(&identified_modes, &truth_modes);
    let mut identified_records: Vec<ModeRecord> = identified_modes
        .iter()
        .map(|mode| ModeRecord::new(mode, &identified.states))
        .collect();
    let mut truth_records: Vec<TruthModeRecord> = truth_modes
        .iter()
        .map(|mode| TruthModeRecord {
            name: mode.name.as_str().to_string(),
            eigenvalue: [mode.eigenvalue.re, mode.eigenvalue.im],
            omega_n: mode.natural_frequency(),
            zeta: mode.damping_ratio(),
            hover: mode.is_hover_mode(),
            identified: None,
            identified_name: None,
            error_percent: None,
        })
        .collect();
    for (i, paired) in pairing.iter().enumerate() {
        let Some(t) = *paired else { continue };
        let (mode, reference) = (&identified_modes[i], &truth_modes[t]);
        let error = relative_error_percent(mode.eigenvalue, reference.eigenvalue);
        let record = &mut identified_records[i];
        record.truth = Some([reference.eigenvalue.re, reference.eigenvalue.im]);
        record.truth_name = Some(reference.name.as_str().to_string());
        record.error_percent = error;
        let truth_record = &mut truth_records[t];
        truth_record.identified = Some([mode.eigenvalue.re, mode.eigenvalue.im]);
        truth_record.identified_name = Some(mode.name.as_str().to_string());
        truth_record.error_percent = error;
    }
    let hover_modes: Vec<&TruthModeRecord> = truth_records.iter().filter(|t| t.hover).collect();
    let hover = HoverModeScore {
        matched: hover_modes.iter().filter(|t| t.within_tolerance()).count(),
        of: hover_modes.len(),
        worst_error_percent: hover_modes
            .iter()
            .filter_map(|t| t.error_percent)
            .fold(None, |worst: Option<f64>, e| {
                Some(worst.map_or(e, |w| w.max(e)))
            }),
    };
    let poles_at_origin = poles_at_origin(&identified_records);
    Ok(ModeComparison {
        identified: identified_records,
        truth: truth_records,
        hover,
        poles_at_origin,
    })
}

fn cell(value: Option<f64>, precision: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.precision$}"))
}

/// `re ± im j` of an eigenvalue record.
pub fn eigenvalue_text(eigenvalue: [f64; 2]) -> String {
    if eigenvalue[1] == 0.0 {
        format!("{:.4}", eigenvalue[0])
    } else {
        format!("{:.4} ± {:.4}j", eigenvalue[0], eigenvalue[1])
    }
}

/// The text table of modes: name, eigenvalue, ω_n, ζ, time to double or half, shape, and
/// the truth's mode and error when any record has one.
pub fn mode_table(records: &[ModeRecord]) -> String {
    let with_truth = records.iter().any(|r| r.truth.is_some());
    let mut out = String::new();
    let truth_header = if with_truth {
        format!(
            "  {:<32} {:>22} {:>8}",
            "truth mode", "truth λ [rad/s]", "error %"
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        out,
        "{:<32} {:>22} {:>8} {:>7} {:>13}  {:<26}{truth_header}",
        "mode", "λ [rad/s]", "ω_n", "ζ", "t2 / t½ [s]", "shape"
    );
    for record in records {
        let time = match (record.time_to_double_s, record.time_to_half_s) {
            (Some(t), _) => format!("double {t:.2}"),
            (None, Some(t)) => format!("half {t:.2}"),
            (None, None) => "-".to_string(),
        };
        let truth_cells = if with_truth {
            format!(
                "  {:<32} {:>22} {:>8}",
                record.truth_name.as_deref().unwrap_or("-"),
                record.truth.map_or("-".to_string(), eigenvalue_text),
                cell(record.error_percent, 1)
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            out,
            "{:<32} {:>22} {:>8} {:>7} {:>13}  {:<26}{truth_cells}",
            record.name,
            eigenvalue_text(record.eigenvalue),
            cell(record.omega_n, 3),
            cell(record.zeta, 3),
            time,
            record.shape()
        );
    }
    out
}

/// One line on the hover modes, e.g. `hover modes 3/4 within 25 % of the truth (worst
/// 41.2 %), 1 pole at the origin`.
pub fn hover_summary(hover: &HoverModeScore, poles_at_origin: usize) -> String {
    format!(
        "hover modes {}/{} within {:.0} % of the truth{}, {}",
        hover.matched,
        hover.of,
        HOVER_MODE_TOLERANCE_PERCENT,
        hover
            .worst_error_percent
            .map_or(String::new(), |w| format!(" (worst {w:.1} %)")),
        origin_text(poles_at_origin)
    )
}

/// `no pole at the origin`, `1 pole at the origin`, `2 poles at the origin`.
pub fn origin_text(poles_at_origin: usize) -> String {
    match poles_at_origin {
        0 => "no pole at the origin".to_string(),
        1 => "1 pole at the origin".to_string(),
        n => format!("{n} poles at the origin"),
    }
}

#[cfg(test)]
mod tests;
