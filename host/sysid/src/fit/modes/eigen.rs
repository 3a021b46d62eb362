//! The eigen-analysis of a linear model `M ẋ = F x + G u`: the eigenvalues of the state
//! matrix `A = M⁻¹F` and the magnitudes of their eigenvectors, as [`Mode`]s.
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

use std::f64::consts::LN_2;

use nalgebra::linalg::{Schur, SVD};
use nalgebra::DMatrix;
use num_complex::Complex64;

use super::naming::{
    group_shares, name_of, scaled_shares, GroupShares, ModeName, HOVER_MODE_LIMIT_RAD_S,
    ORIGIN_LIMIT_RAD_S,
};
use super::state_kinds::StateKinds;
use crate::fit::model::Model;

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

/// One mode of a model.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// Its name (rules in the module documentation).
    pub name: ModeName,
    /// The eigenvalue [rad/s]; of a complex pair the member with Im λ > 0.
    pub eigenvalue: Complex64,
    /// Poles the mode stands for: 1 (real) or 2 (complex pair).
    pub poles: usize,
    /// Shares of the states (in the model's state order), scaled as [`naming`](super::naming)
    /// says; they sum to 1.
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
    let kinds = StateKinds::of(&model.states, &a);
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
        let shares = scaled_shares(&kinds, &magnitudes, eigenvalue.norm());
        let groups = group_shares(&kinds, &shares);
        let poles = if real { 1 } else { 2 };
        found.push(Mode {
            name: name_of(eigenvalue, poles, &groups),
            eigenvalue,
            poles,
            shares,
            groups,
        });
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
