//! The trim balances as residuals of the fit itself: one cost for the frequency responses
//! and the steady flights.
//!
//! Holding the derived parameters at the balance's solution and refitting the others
//! ([`super::derive`], the fit's `settle_trim`) ends at a point where neither step moves
//! any more: the frequency-response cost is at its minimum over the *other* parameters
//! with the derived ones held, and the derived ones satisfy the balance for the others.
//! That is not the minimum of the cost over the models that satisfy the balance: while
//! the refit moves, say, M_b1c it holds M_fu, so it does not see that the balance would
//! move M_fu with it (the quasi-static M_u = M_b1c·M_fu is what the points fix). The
//! joint cost sees it: with the derived parameters free, each point's balance residual
//! of each row the derivation uses (module documentation of [`super`], step 3) is one
//! more residual of the least-squares problem,
//!
//! ```text
//! e_i,row = (F_row Δx_i + G_row Δu_i) / (σ_δ · ‖G_qs,row‖)
//! ```
//!
//! with the flapping at its steady value as in the derivation. Dividing by the row's
//! quasi-static control power `‖G_qs,row‖` (what one stick fraction does to that row's
//! acceleration) turns the residual into the stick error that would close the balance,
//! and `σ_δ` is the trim points' stick uncertainty (fraction of travel): a residual of
//! σ_δ counts as much as one unit of Σ J. The cost is `Σ_pairs J + Σ e²`, its minimum
//! the model that fits the responses best among those that balance the points within
//! their uncertainty. On points from a linear model and responses of the same model the
//! minimum is that model exactly (tests).
//!
//! The Jacobian of `e` is taken by central differences: the balance costs a model build
//! and one small solve per point, far less than the responses' columns.

use nalgebra::{DMatrix, DVector};

use super::balance::{balance, balance_rows};
use super::error::TrimError;
use super::points::TrimPoints;
use crate::fit::structure::ModelStructure;

/// The default stick uncertainty of trim points [fraction of travel]: the quantization
/// of the stick positions a flight controller reads, one SBUS count over √12 (the
/// receiver's ±100 % travel is ±819.2 counts, `firmware/src/receiver/channel_map.rs`):
/// 1/(819.2·√12) = 3.5·10⁻⁴. A 1 m/s trim point moves the cyclic by 0.007–0.009 of
/// travel on the Bo-105, so each point's balance is known to about 5 %.
pub const DEFAULT_STICK_SIGMA: f64 = 1.0 / (819.2 * 3.464_101_615_137_754_6);

/// The balances of trim points as weighted residuals (module documentation), for one
/// structure and its derived parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct JointBalance {
    points: TrimPoints,
    /// Positions among the measured states of the rows used.
    rows: Vec<usize>,
    stick_sigma: f64,
}

impl JointBalance {
    /// The balances of `points` for the derived parameters `names` of `structure` (the
    /// rows [`super::derive`] uses), weighted with the stick uncertainty `stick_sigma`.
    pub fn new(
        structure: &ModelStructure,
        points: &TrimPoints,
        names: &[String],
        stick_sigma: f64,
    ) -> Result<JointBalance, TrimError> {
        if points.points.len() < 2 {
            return Err(TrimError::TooFewPoints(points.points.len()));
        }
        if !(stick_sigma > 0.0 && stick_sigma.is_finite()) {
            return Err(TrimError::Model(format!(
                "the trim points' stick uncertainty must be positive, not {stick_sigma}"
            )));
        }
        let rows = balance_rows(structure, &structure.values(), names)?.rows;
        Ok(JointBalance {
            points: points.clone(),
            rows,
            stick_sigma,
        })
    }

    /// Number of residuals: used rows × points.
    pub fn len(&self) -> usize {
        self.rows.len() * self.points.points.len()
    }

    /// Whether there are no residuals (no used row).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The weighted residuals at parameter values `values`, point by point.
    pub fn residuals(
        &self,
        structure: &ModelStructure,
        values: &[f64],
    ) -> Result<DVector<f64>, TrimError> {
        let (residuals, control) = balance(structure, values, &self.points)?;
        let rows = &self.rows;
        let mut out = DVector::zeros(self.len());
        for (point, residual) in residuals.iter().enumerate() {
            for (k, &row) in rows.iter().enumerate() {
                let power = control.row(row).norm();
                let scale = if power > 0.0 && power.is_finite() {
                    1.0 / (self.stick_sigma * power)
                } else {
                    1.0 / self.stick_sigma
                };
                out[point * rows.len() + k] = residual[row] * scale;
            }
        }
        Ok(out)
    }

    /// [`Self::residuals`] and their Jacobian with respect to the parameters `free`
    /// (base-parameter indices), by central differences.
    pub fn residuals_and_jacobian(
        &self,
        structure: &ModelStructure,
        values: &[f64],
        free: &[usize],
    ) -> Result<(DVector<f64>, DMatrix<f64>), TrimError> {
        let residual = self.residuals(structure, values)?;
        let mut jacobian = DMatrix::zeros(residual.len(), free.len());
        let mut shifted = values.to_vec();
        for (column, &parameter) in free.iter().enumerate() {
            let value = values[parameter];
            let step = 1e-6 * value.abs().max(1e-4);
            shifted[parameter] = value + step;
            let plus = self.residuals(structure, &shifted)?;
            shifted[parameter] = value - step;
            let minus = self.residuals(structure, &shifted)?;
            shifted[parameter] = value;
            jacobian.set_column(column, &((plus - minus) / (2.0 * step)));
        }
        Ok((residual, jacobian))
    }
}

#[cfg(test)]
mod tests;
