//! The speed derivatives trim points stand for, read off a model: its quasi-static
//! derivative with the states the points do not give (the flapping) at their steady value.

use nalgebra::{DMatrix, DVector};

use super::points::measured_column;
use crate::fit::model::Model;
use crate::fit::modes::state_matrix;

/// The speed derivatives the trim points stand for: (name, acceleration row, speed).
pub const SPEED_DERIVATIVES: [(&str, &str, &str); 3] =
    [("Mu", "q", "u"), ("Lv", "p", "v"), ("Nv", "r", "v")];

/// The quasi-static derivative ∂(ẋ_row)/∂x_column of `model` with every state a trim
/// point does not give (the flapping) at its steady value: `A_qs = A_mm − A_mh A_hh⁻¹ A_hm`
/// with `A = M⁻¹F` — what the paper's Eq. 28–30 and a 6-DOF model call M_u, L_v, N_v,
/// whichever parameters of the structure carry it. None when a state is missing or the
/// hidden block is singular.
pub fn quasi_static_derivative(model: &Model, row: &str, column: &str) -> Option<f64> {
    let a = state_matrix(model).ok()?;
    let states = &model.states;
    let i = states.iter().position(|s| s == row)?;
    let j = states.iter().position(|s| s == column)?;
    let hidden: Vec<usize> = (0..states.len())
        .filter(|&k| measured_column(&states[k]).is_none())
        .collect();
    if hidden.is_empty() {
        return Some(a[(i, j)]);
    }
    let a_hh = DMatrix::from_fn(hidden.len(), hidden.len(), |x, y| a[(hidden[x], hidden[y])]);
    let a_hm = DVector::from_fn(hidden.len(), |x, _| a[(hidden[x], j)]);
    let steady = a_hh.lu().solve(&a_hm)?;
    let a_mh = DVector::from_fn(hidden.len(), |x, _| a[(i, hidden[x])]);
    Some(a[(i, j)] - a_mh.dot(&steady))
}
