//! The steady-state balance of a model at the trim points: each point's residual of the
//! measured rows, the quasi-static control derivatives, and the rows the derivation of
//! parameters uses (the module documentation of `fit::trim`, steps 1–3). The derivation
//! ([`super::derive`]) and the joint cost ([`super::joint`]) are built on it.

use nalgebra::{DMatrix, DVector};

use super::error::TrimError;
use super::points::{measured_column, TrimPoints, CONTROL_COLUMNS};
use crate::fit::structure::ModelStructure;

/// Residuals of the measured rows at every point for parameter values `values`: one
/// vector per point, `n_measured` long, centred data (the module documentation of `fit::trim`, step 1–2).
pub(super) fn residuals(
    structure: &ModelStructure,
    values: &[f64],
    points: &TrimPoints,
) -> Result<Vec<DVector<f64>>, TrimError> {
    Ok(balance(structure, values, points)?.0)
}

/// The residuals of [`residuals`] and the quasi-static control derivatives of the
/// measured rows, `G_m − F_mh F_hh⁻¹ G_h` (`n_measured × n_controls`): what one stick
/// fraction does to each measured row's acceleration with the hidden states at their
/// steady values.
pub(super) fn balance(
    structure: &ModelStructure,
    values: &[f64],
    points: &TrimPoints,
) -> Result<(Vec<DVector<f64>>, DMatrix<f64>), TrimError> {
    let model = structure
        .model(values)
        .map_err(|e| TrimError::Model(e.to_string()))?;
    let n = model.states.len();
    let measured: Vec<(usize, usize)> = (0..n)
        .filter_map(|i| measured_column(&model.states[i]).map(|c| (i, c)))
        .collect();
    let hidden: Vec<usize> = (0..n)
        .filter(|&i| measured_column(&model.states[i]).is_none())
        .collect();
    let controls: Vec<Option<usize>> = model
        .controls
        .iter()
        .map(|c| CONTROL_COLUMNS.iter().position(|k| k == c))
        .collect();
    let count = points.points.len() as f64;
    let mean_state: Vec<f64> = (0..8)
        .map(|k| points.points.iter().map(|p| p.states[k]).sum::<f64>() / count)
        .collect();
    let mean_control: Vec<f64> = (0..4)
        .map(|k| points.points.iter().map(|p| p.controls[k]).sum::<f64>() / count)
        .collect();
    let f_hh = DMatrix::from_fn(hidden.len(), hidden.len(), |a, b| {
        model.f[(hidden[a], hidden[b])]
    });
    let f_hh_lu = f_hh.lu();
    if !hidden.is_empty() && !f_hh_lu.is_invertible() {
        return Err(TrimError::HiddenStatesSingular);
    }
    let mut out = Vec::with_capacity(points.points.len());
    for point in &points.points {
        let mut x = DVector::zeros(n);
        for &(i, c) in &measured {
            x[i] = point.states[c] - mean_state[c];
        }
        let u = DVector::from_iterator(
            controls.len(),
            controls
                .iter()
                .map(|c| c.map_or(0.0, |k| point.controls[k] - mean_control[k])),
        );
        if !hidden.is_empty() {
            // F_hh x_h = −(F_hm x_m + G_h u): x holds x_m and zeros at the hidden states.
            let rhs = DVector::from_fn(hidden.len(), |a, _| {
                -((model.f.row(hidden[a]) * &x)[0] + (model.g.row(hidden[a]) * &u)[0])
            });
            let x_h = f_hh_lu.solve(&rhs).ok_or(TrimError::HiddenStatesSingular)?;
            for (a, &i) in hidden.iter().enumerate() {
                x[i] = x_h[a];
            }
        }
        let full = &model.f * &x + &model.g * &u;
        out.push(DVector::from_iterator(
            measured.len(),
            measured.iter().map(|&(i, _)| full[i]),
        ));
    }
    let n_controls = model.controls.len();
    let mut control = DMatrix::from_fn(measured.len(), n_controls, |a, c| {
        model.g[(measured[a].0, c)]
    });
    if !hidden.is_empty() {
        let g_h = DMatrix::from_fn(hidden.len(), n_controls, |a, c| model.g[(hidden[a], c)]);
        let steady = f_hh_lu.solve(&g_h).ok_or(TrimError::HiddenStatesSingular)?;
        let f_mh = DMatrix::from_fn(measured.len(), hidden.len(), |a, b| {
            model.f[(measured[a].0, hidden[b])]
        });
        control -= f_mh * steady;
    }
    Ok((out, control))
}

/// The derived parameters' indices, `values` with them at zero, and the positions among
/// the measured states of the rows the balance uses ([`balance_rows`]).
pub(super) struct BalanceRows {
    pub(super) indices: Vec<usize>,
    pub(super) base: Vec<f64>,
    pub(super) rows: Vec<usize>,
}

/// Which rows the balance of `names` uses: the moment rows (p, q, r: the paper's
/// equations) and every measured row a derived parameter enters directly (w for Z_w).
/// The balance must stay affine in the derived parameters: none may enter M or the
/// hidden states' own block F_hh (through which x_h depends on them non-linearly).
/// Checked by setting each to 1 and comparing the matrices with all at 0.
pub(super) fn balance_rows(
    structure: &ModelStructure,
    values: &[f64],
    names: &[String],
) -> Result<BalanceRows, TrimError> {
    let indices: Vec<usize> = names
        .iter()
        .map(|name| {
            structure
                .parameter_index(name)
                .ok_or_else(|| TrimError::Model(format!("no parameter `{name}`")))
        })
        .collect::<Result<_, _>>()?;
    let mut base = values.to_vec();
    for &k in &indices {
        base[k] = 0.0;
    }
    let model_at = |v: &[f64]| {
        structure
            .model(v)
            .map_err(|e| TrimError::Model(e.to_string()))
    };
    let base_model = model_at(&base)?;
    let states = &base_model.states;
    let is_hidden = |i: usize| measured_column(&states[i]).is_none();
    let mut direct_rows = vec![false; states.len()];
    for (&k, name) in indices.iter().zip(names) {
        let mut one = base.clone();
        one[k] = 1.0;
        let moved = model_at(&one)?;
        let n = states.len();
        let hidden_block_moved = (0..n).filter(|&i| is_hidden(i)).any(|i| {
            (0..n)
                .filter(|&j| is_hidden(j))
                .any(|j| moved.f[(i, j)] != base_model.f[(i, j)])
        });
        if hidden_block_moved || moved.m != base_model.m {
            return Err(TrimError::NotLinear(name.clone()));
        }
        for (i, direct) in direct_rows.iter_mut().enumerate() {
            if !is_hidden(i)
                && (moved.f.row(i) != base_model.f.row(i) || moved.g.row(i) != base_model.g.row(i))
            {
                *direct = true;
            }
        }
    }
    // Positions of the used rows among the measured ones (the residual vectors' order).
    let measured_states: Vec<usize> = (0..states.len()).filter(|&i| !is_hidden(i)).collect();
    let rows: Vec<usize> = measured_states
        .iter()
        .enumerate()
        .filter(|&(_, &i)| direct_rows[i] || ["p", "q", "r"].contains(&states[i].as_str()))
        .map(|(position, _)| position)
        .collect();
    Ok(BalanceRows {
        indices,
        base,
        rows,
    })
}
