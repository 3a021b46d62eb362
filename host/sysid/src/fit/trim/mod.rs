//! Parameters from trim points: the steady-state balance of the identified model.
//!
//! A **trim point** is steady flight — hover, a little forward, aft, left, right, a slow
//! climb or descent, a turn on the spot — with the body velocities, rates and attitude it
//! was flown at and the four stick positions that held it. A pilot flies them; for the
//! simulator `sweephold sim trim-points` trims the nonlinear model at the same
//! conditions. In steady flight every acceleration is zero, so the linear model
//! `M ẋ = F x + G u` must satisfy, at each point i (Δ relative to the mean of the points,
//! which leaves out the unknown linearization point),
//!
//! ```text
//! 0 = F Δx_i + G Δu_i.
//! ```
//!
//! The paper (Jung, Shim & Kim, Eq. 28–30) uses this to fix the speed derivatives the
//! frequency responses barely inform, from the stick gradients and the identified control
//! derivatives: for a speed change Δu at constant collective the pitching-moment row reads
//! `0 = M_u Δu + M_w Δw + M_lon Δδ_lon` with `Δw = −Z_u/Z_w Δu` from the heave row, so
//! `M_u = −M_lon ∂δ_lon/∂u + M_w Z_u/Z_w`; likewise `L_v = −L_lat ∂δ_lat/∂v −
//! L_ped ∂δ_ped/∂v` and `N_v = −N_ped ∂δ_ped/∂v`. This module does the same for any
//! structure and any set of parameters (`trim_derived` in the structure file), using
//! every measured state of the points instead of the paper's approximations:
//!
//! 1. The states the points give (u v w p q r φ θ) are *measured*; the others (the
//!    flapping b1c, b1s) are *hidden* and take their steady value from their own rows,
//!    `x_h = −F_hh⁻¹ (F_hm x_m + G_h u)` — the quasi-static (residualized) flapping, so the
//!    control derivatives used are the model's quasi-static ones.
//! 2. Each measured row's residual `r_i = F_m· x_i + G_m· u_i` is affine in the derived
//!    parameters θ_T: they enter F and G linearly, and not M or F_hh, so x_h is affine in
//!    them too (a flap-back term such as M_f,u, in a flapping row, is allowed):
//!    `r_i = r_i(0) + Σ_k c_ik θ_k`, with c_ik read off by setting one θ_k to 1.
//! 3. θ_T minimises Σ_i Σ_rows r_i² (linear least squares) over the moment rows p, q, r
//!    — the paper's equations — and any other measured row a derived parameter enters
//!    directly (w for Z_w): exact when the points come from a linear model whose other
//!    parameters are the model's.
//!
//! A derived parameter multiplies a state that must vary over the points (no climb, no
//! Z_w): a column of c that is (numerically) zero is refused with the state named. The
//! fit iterates: fit with θ_T free, derive θ_T, hold it (status `trim`) and refit from
//! there, re-derive, until θ_T moves less than [`SETTLED_RELATIVE_CHANGE`]. With
//! [`TrimBalance::Joint`] (an option; the default is [`TrimBalance::Hold`]) it then releases θ_T and refits with the balances
//! as residuals of the cost ([`joint`]).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::structure::ModelStructure;

mod balance;
mod error;
pub mod joint;
mod points;
mod quasi_static;

use balance::{balance_rows, residuals, BalanceRows};
pub use error::TrimError;
pub use points::{TrimPoint, TrimPoints, CONTROL_COLUMNS, PLAUSIBLE_RANGES, STATE_COLUMNS};
pub use quasi_static::{quasi_static_derivative, SPEED_DERIVATIVES};

/// Smallest singular value, relative to the largest, of the balance's matrix with its
/// columns scaled to unit length, for the derived parameters to count as independently
/// informed: collinear points give exactly dependent columns (rounding, ~10⁻¹⁶), the
/// simulator's points ~10⁻¹.
const INDEPENDENCE_TOLERANCE: f64 = 1e-9;

/// The iteration stops when no derived parameter moved by more than this fraction of its
/// value between two derivations.
pub const SETTLED_RELATIVE_CHANGE: f64 = 0.01;
/// Most derive-and-refit rounds.
pub const MAX_ROUNDS: usize = 6;

/// How a fit uses its trim points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TrimBalance {
    /// Derive the structure's `trim_derived` parameters from the balance, hold them and
    /// refit the others; repeat until they settle ([`derive()`]).
    Hold,
    /// Fit the derived parameters with the others, the balances of the points weighted
    /// residuals of the cost ([`joint`]); `stick_sigma` is the points' stick uncertainty
    /// (fraction of travel).
    Joint {
        /// Stick uncertainty of the trim points (fraction of travel).
        stick_sigma: f64,
    },
}

/// One parameter derived from trim points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrimDerivation {
    /// The parameter.
    pub name: String,
    /// Its value.
    pub value: f64,
}

/// What the trim-point step of a fit did (`model.json` `trim`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrimOutcome {
    /// Points used.
    pub points: usize,
    /// Derive-and-refit rounds.
    pub rounds: usize,
    /// Whether the last round moved no parameter by more than
    /// [`SETTLED_RELATIVE_CHANGE`].
    pub settled: bool,
    /// The derived parameters at the end.
    pub parameters: Vec<TrimDerivation>,
}

/// Derive the parameters named in `names` from `points`, the other parameters at
/// `values` (module documentation). Returns their values in the order of `names`.
pub fn derive(
    structure: &ModelStructure,
    values: &[f64],
    points: &TrimPoints,
    names: &[String],
) -> Result<Vec<TrimDerivation>, TrimError> {
    if points.points.len() < 2 {
        return Err(TrimError::TooFewPoints(points.points.len()));
    }
    let BalanceRows {
        indices,
        base,
        rows,
    } = balance_rows(structure, values, names)?;
    let r0 = residuals(structure, &base, points)?;
    let step = derivation_step(&r0);
    let mut columns: Vec<Vec<DVector<f64>>> = Vec::with_capacity(indices.len());
    for &k in &indices {
        let mut one = base.clone();
        one[k] = step;
        let r1 = residuals(structure, &one, points)?;
        columns.push(r1.iter().zip(&r0).map(|(a, b)| (a - b) / step).collect());
    }
    let n_obs = rows.len() * points.points.len();
    let a = DMatrix::from_fn(n_obs, indices.len(), |obs, k| {
        let (point, row) = (obs / rows.len(), rows[obs % rows.len()]);
        columns[k][point][row]
    });
    let b = DVector::from_fn(n_obs, |obs, _| {
        let (point, row) = (obs / rows.len(), rows[obs % rows.len()]);
        -r0[point][row]
    });
    // A derived parameter whose column is (numerically) zero is not informed by the
    // points: the state it multiplies does not vary. Judged on the column alone — not
    // against the others, whose size a poorly identified flapping (x_h of 10⁶) can blow up.
    for (k, name) in names.iter().enumerate() {
        let norm = a.column(k).norm();
        if norm.is_nan() || norm < 1e-12 {
            return Err(TrimError::NotInformed {
                parameter: name.clone(),
            });
        }
    }
    check_independent(&a, names, points)?;
    let svd = a.svd(true, true);
    let theta = svd
        .solve(&b, 1e-12 * svd.singular_values.max())
        .map_err(|e| TrimError::Model(e.to_string()))?;
    Ok(names
        .iter()
        .zip(theta.iter())
        .map(|(name, value)| TrimDerivation {
            name: name.clone(),
            value: *value,
        })
        .collect())
}

/// The step of a derived parameter that reads its column of the balance,
/// `(r(θ_k = h) − r(0))/h`: exact for any h (the balance is affine), but the difference
/// keeps only the digits by which `h·c_k` exceeds the rounding of r(0), ε·‖r(0)‖. With
/// h = 1 a degenerate minimum (other parameters of 10¹⁵, r(0) of 10¹⁶–10²²) rounds a
/// column of order 1 to exactly 0, and the rank check then blames the points. So h is
/// relative to the residual, `max(1, 10⁻⁶·‖r(0)‖∞)`, which keeps ten digits of a column of
/// order 1 whatever the residual; the floor of 1 leaves every balance with residuals below
/// 10⁶ (every non-degenerate one) computed as before.
fn derivation_step(r0: &[DVector<f64>]) -> f64 {
    let largest = r0.iter().map(|r| r.amax()).fold(0.0, f64::max);
    if largest.is_finite() {
        (DERIVATION_STEP_RELATIVE * largest).max(1.0)
    } else {
        1.0
    }
}

/// [`derivation_step`]'s step relative to the largest residual.
const DERIVATION_STEP_RELATIVE: f64 = 1e-6;

/// Refuse a balance whose derived parameters the points cannot tell apart: the matrix
/// `a` of [`derive`] (one column per parameter), each column scaled to unit length so
/// that their sizes do not matter, must have full column rank. The error names the
/// parameters of the null space and the state columns the points vary, with the rank of
/// their differences.
fn check_independent(
    a: &DMatrix<f64>,
    names: &[String],
    points: &TrimPoints,
) -> Result<(), TrimError> {
    let mut scaled = a.clone();
    for mut column in scaled.column_iter_mut() {
        let norm = column.norm();
        column /= norm;
    }
    let svd = scaled.svd(false, true);
    let largest = svd.singular_values.max();
    let v_t = svd.v_t.as_ref().expect("asked for V");
    let mut tangled = vec![false; names.len()];
    for (k, &sigma) in svd.singular_values.iter().enumerate() {
        if sigma <= INDEPENDENCE_TOLERANCE * largest {
            for (slot, weight) in tangled.iter_mut().zip(v_t.row(k).iter()) {
                *slot |= weight.abs() > 1e-6;
            }
        }
    }
    if names.len() <= a.nrows() && !tangled.contains(&true) {
        return Ok(());
    }
    if names.len() > a.nrows() {
        tangled.iter_mut().for_each(|slot| *slot = true);
    }
    // The state columns the points vary, and in how many directions.
    let count = points.points.len() as f64;
    let varied: Vec<usize> = (0..STATE_COLUMNS.len())
        .filter(|&k| {
            let mean = points.points.iter().map(|p| p.states[k]).sum::<f64>() / count;
            points.points.iter().any(|p| p.states[k] != mean)
        })
        .collect();
    let differences = DMatrix::from_fn(points.points.len(), varied.len(), |i, j| {
        points.points[i].states[varied[j]] - points.points[0].states[varied[j]]
    });
    let values = differences.singular_values();
    let directions = values
        .iter()
        .filter(|&&sigma| sigma > 1e-9 * values.max())
        .count();
    Err(TrimError::NotIndependent {
        parameters: names
            .iter()
            .zip(&tangled)
            .filter(|(_, &tangled)| tangled)
            .map(|(name, _)| name.clone())
            .collect(),
        varied: varied
            .iter()
            .map(|&k| STATE_COLUMNS[k])
            .collect::<Vec<_>>()
            .join(" "),
        directions,
    })
}

#[cfg(test)]
mod tests;
