//! A-priori knowledge of a parameter as a weighted term of the cost: a parameter with a
//! prior `θ_p ± σ` (structure file: `prior`, `sigma`) adds one residual
//!
//! ```text
//! r_prior = (θ − θ_p) / σ,      ∂r_prior/∂θ = 1/σ
//! ```
//!
//! to the pairs' weighted residuals, so the total cost becomes Σ_pairs J + Σ_priors r².
//!
//! Why this scaling: the pairs' residuals are already weighted as if each had unit
//! variance (W_g = 1 dB⁻², W_p = 0.01745 deg⁻²: [`super::accuracy`] takes H = J_rᵀJ_r
//! with no rescaling, CR_i = √((H⁻¹)_ii)). A prior of standard deviation σ is one more
//! independent measurement of θ with that unit-variance residual, so the same Gauss–Newton
//! Hessian gains exactly the prior's information 1/σ² on its diagonal:
//!
//! ```text
//! H = J_dᵀJ_d + diag(1/σ_k²)        CR_i = √((H⁻¹)_ii)
//! ```
//!
//! and a parameter the data do not see keeps CR = σ (its prior), one they see well gets
//! the data's bound, and the minimum is the maximum a-posteriori estimate under Gaussian
//! errors. For a scalar θ with a linear data residual a(θ − θ_d) the minimum is
//! θ* = (a²θ_d + θ_p/σ²)/(a² + 1/σ²) with CR = 1/√(a² + 1/σ²) (checked in the tests).
//!
//! Only free parameters carry the term (a fixed one's residual is a constant that moves
//! nothing). J_ave stays the pairs' mean; the priors' cost is reported beside it
//! ([`cost`]), and the fit's objective counts it as the trim balances are counted.

use nalgebra::{DMatrix, DVector};

use super::structure::ModelStructure;
pub use super::structure::Prior;

/// The free parameters (of `free`, base-parameter indices) that carry a prior, as
/// (column in the Jacobian, base index, prior).
fn with_priors<'a>(
    structure: &'a ModelStructure,
    free: &'a [usize],
) -> impl Iterator<Item = (usize, usize, Prior)> + 'a {
    free.iter().enumerate().filter_map(|(column, &index)| {
        structure.parameters[index]
            .prior
            .map(|prior| (column, index, prior))
    })
}

/// Number of prior residuals for the free parameters `free`.
pub fn count(structure: &ModelStructure, free: &[usize]) -> usize {
    with_priors(structure, free).count()
}

/// The prior residuals (θ − θ_p)/σ at `values` and their Jacobian (one row each, 1/σ in
/// the parameter's column), for the free parameters `free`.
pub fn residuals_and_jacobian(
    structure: &ModelStructure,
    values: &[f64],
    free: &[usize],
) -> (DVector<f64>, DMatrix<f64>) {
    let rows: Vec<(usize, usize, Prior)> = with_priors(structure, free).collect();
    let mut residual = DVector::zeros(rows.len());
    let mut jacobian = DMatrix::zeros(rows.len(), free.len());
    for (row, &(column, index, prior)) in rows.iter().enumerate() {
        residual[row] = prior.distance(values[index]);
        jacobian[(row, column)] = 1.0 / prior.sigma;
    }
    (residual, jacobian)
}

/// Σ over the free parameters with a prior of ((θ − θ_p)/σ)²: the priors' share of the
/// total cost at `values`.
pub fn cost(structure: &ModelStructure, values: &[f64]) -> f64 {
    let free = structure.free_indices();
    residuals_and_jacobian(structure, values, &free)
        .0
        .norm_squared()
}

/// `a` with `b` stacked below it (rows), both over the same columns.
pub(crate) fn stack(
    (a, ja): (DVector<f64>, DMatrix<f64>),
    (b, jb): (DVector<f64>, DMatrix<f64>),
) -> (DVector<f64>, DMatrix<f64>) {
    let residual = DVector::from_iterator(a.len() + b.len(), a.iter().chain(b.iter()).copied());
    let mut jacobian = DMatrix::zeros(ja.nrows() + jb.nrows(), ja.ncols());
    jacobian.rows_mut(0, ja.nrows()).copy_from(&ja);
    jacobian.rows_mut(ja.nrows(), jb.nrows()).copy_from(&jb);
    (residual, jacobian)
}

#[cfg(test)]
mod tests;
