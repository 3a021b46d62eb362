//! Start values from a frequency-domain equation-error fit: the state equations solved in
//! the least-squares sense with the measured state responses in place of the states.
//!
//! For a control j, the responses of the states to it, X_·j(ω), satisfy the model's rows
//! at every frequency: (jω M − F) X_·j = G_·j e^{−jωτ_j}. With measured responses each row
//! i leaves an equation error
//!
//! ```text
//! e_ij(ω) = Σ_l (jω M_il − F_il) X_lj(ω) − G_ij e^{−jωτ_j},      w_ij(ω) = √W_γ(γ²_ij(ω)) / s_ij
//! cost    = Σ_ij Σ_ω |w_ij(ω) e_ij(ω)|² / n_ij
//! ```
//!
//! over the frequencies where the response of state i to control j is valid (its
//! `valid_range`, clipped to the structure's `auto_range_limit`); `s_ij` is the RMS of
//! |jω X_ij| there, so each (row, control) block counts alike whatever its units, and W_γ
//! is the output-error cost's coherence weight. Every matrix entry is an affine expression
//! of the parameters (the structure file's grammar), so e is affine in every parameter but
//! the delays: one Gauss–Newton step solves those exactly, a few more settle the delays.
//! Unlike the output-error cost J of the fit proper, this has one minimum and needs no
//! good start; noise on the measured X biases it (errors in variables), so it only starts
//! the fit (Tischler & Remple, *Aircraft and Rotorcraft System Identification*, on
//! equation-error start values; Morelli & Klein on frequency-domain equation error).
//!
//! Applies when every state is measured — an output that reads the state directly — or is
//! given by a row without free parameters and without controls (the kinematics
//! φ̇ = p + tan θ₀ (sin φ₀ q + cos φ₀ r)), which is solved from the measured ones at each
//! frequency. The quasi-steady 6-DOF qualifies; the hybrid does not (the flapping is not
//! measured). Parameters no block informs (those only in H0/H1, or of a row whose responses
//! are not valid for any control) keep their start values.

use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

use super::cost::{coherence_weight, interpolate_log};
use super::error::FitError;
use super::structure::{MatrixName, ModelStructure, ParameterKind};
use crate::document::{FrfDocument, PairResponse};

/// Most frequencies per (row, control) block: the data's own frequencies in the block's
/// range, thinned evenly in ln ω to this many.
pub const MAX_POINTS_PER_BLOCK: usize = 60;
/// Fewest frequencies for a block to be used.
pub const MIN_POINTS_PER_BLOCK: usize = 5;
/// Most Gauss–Newton iterations (the affine part converges in one; the delays in a few).
pub const MAX_ITERATIONS: usize = 12;

/// One (row, control) block of equations.
#[derive(Clone, Debug, PartialEq)]
pub struct EquationBlock {
    /// State whose row is used.
    pub state: String,
    /// Control.
    pub control: String,
    /// Frequency range used [rad/s].
    pub range: [f64; 2],
    /// Number of frequencies.
    pub points: usize,
}

/// What [`equation_error_start`] gives.
#[derive(Clone, Debug)]
pub struct EquationErrorFit {
    /// The structure with the solved values as start values of its free parameters
    /// (clamped to their bounds).
    pub structure: ModelStructure,
    /// The blocks of equations used.
    pub blocks: Vec<EquationBlock>,
    /// Free parameters no block informs (kept at their start values).
    pub uninformed: Vec<String>,
    /// The weighted equation-error cost at the start values and at the solution.
    pub cost: [f64; 2],
    /// Gauss–Newton iterations made.
    pub iterations: usize,
}

/// One frequency of one block: the full state response vector and the point's weight.
struct BlockPoint {
    s: Complex64,
    /// Responses of every state to the block's control (measured, or solved from the
    /// known rows).
    x: DVector<Complex64>,
    weight: f64,
}

struct Block {
    row: usize,
    control: usize,
    points: Vec<BlockPoint>,
}

/// Solve the structure's state equations in the least-squares sense with the measured
/// responses in `data` (see the module docs), from the structure's start values.
pub fn equation_error_start(
    structure: &ModelStructure,
    data: &FrfDocument,
) -> Result<EquationErrorFit, FitError> {
    let refuse = |reason: String| FitError::StartValues(format!("equation error: {reason}"));
    let n = structure.states.len();
    // Output that reads each state directly, if any.
    let mut measured: Vec<Option<usize>> = vec![None; n];
    for &(output, state) in &structure.default_output_states {
        measured[state].get_or_insert(output);
    }
    let free: Vec<usize> = structure.free_indices();
    let is_free = |index: usize| structure.parameters[index].kind == ParameterKind::Free;
    let unmeasured: Vec<usize> = (0..n).filter(|&i| measured[i].is_none()).collect();
    for &state in &unmeasured {
        let known = structure.entries.iter().all(|entry| {
            let in_row = matches!(entry.matrix, MatrixName::M | MatrixName::F | MatrixName::G)
                && entry.row == state;
            !in_row
                || (!entry.expression.terms.iter().any(|&(k, _)| is_free(k))
                    && (entry.matrix != MatrixName::G || entry.expression.constant == 0.0))
        });
        if !known {
            return Err(refuse(format!(
                "state `{}` is neither an output nor given by a row without free parameters and controls",
                structure.states[state]
            )));
        }
    }
    let start = structure.values();
    let start_model = structure.model(&start)?;

    let mut blocks = Vec::new();
    for (control, control_name) in structure.controls.iter().enumerate() {
        // Every measured state's response to this control, or the control is not used.
        let responses: Option<Vec<(usize, &PairResponse)>> = (0..n)
            .filter_map(|state| measured[state].map(|output| (state, output)))
            .map(|(state, output)| {
                data.pair(control_name, &structure.outputs[output])
                    .map(|pair| (state, pair))
            })
            .collect();
        let Some(responses) = responses else { continue };
        for &(row, pair) in &responses {
            let Some(points) = block_frequencies(structure, pair) else {
                continue;
            };
            let mut block_points = Vec::with_capacity(points.len());
            for (omega, coherence) in points {
                let s = Complex64::new(0.0, omega);
                let mut x = DVector::from_element(n, Complex64::new(0.0, 0.0));
                let mut inside = true;
                for &(state, response) in &responses {
                    match response_at(response, omega) {
                        Some(value) => x[state] = value,
                        None => inside = false,
                    }
                }
                if !inside || !solve_unmeasured(&start_model, &unmeasured, s, &mut x) {
                    continue;
                }
                block_points.push(BlockPoint {
                    s,
                    x,
                    weight: coherence_weight(coherence).sqrt(),
                });
            }
            if block_points.len() < MIN_POINTS_PER_BLOCK {
                continue;
            }
            // s_ij: RMS of |jω X_ij|, and 1/√n_ij so that each block counts alike.
            let scale = (block_points
                .iter()
                .map(|p| (p.s * p.x[row]).norm_sqr())
                .sum::<f64>()
                / block_points.len() as f64)
                .sqrt();
            if !(scale.is_finite() && scale > 0.0) {
                continue;
            }
            let norm = 1.0 / (scale * (block_points.len() as f64).sqrt());
            for point in &mut block_points {
                point.weight *= norm;
            }
            blocks.push(Block {
                row,
                control,
                points: block_points,
            });
        }
    }
    if blocks.is_empty() {
        return Err(refuse(
            "no state has a valid response to any control in the data".into(),
        ));
    }

    let residuals = |values: &[f64]| -> Result<DVector<f64>, FitError> {
        let model = structure.model(values)?;
        let count: usize = blocks.iter().map(|b| b.points.len()).sum();
        let mut out = DVector::zeros(2 * count);
        let mut k = 0;
        for block in &blocks {
            let g = model.g[(block.row, block.control)];
            for point in &block.points {
                // The control as the state equation sees it: through its actuator, if
                // the structure has one, and its delay.
                let mut e = -g * model.input_factor(block.control, point.s);
                for l in 0..n {
                    let coefficient = point.s * model.m[(block.row, l)] - model.f[(block.row, l)];
                    e += coefficient * point.x[l];
                }
                e *= point.weight;
                out[k] = e.re;
                out[k + 1] = e.im;
                k += 2;
            }
        }
        Ok(out)
    };

    let mut values = start.clone();
    let mut current = residuals(&values)?;
    let start_cost = current.norm_squared();
    let mut iterations = 0;
    let mut informed = vec![false; free.len()];
    for iteration in 0..MAX_ITERATIONS {
        let jacobian = jacobian(residuals, &values, &free, current.len())?;
        let step = gauss_newton_step(&jacobian, &current, &mut informed);
        let mut next = values.clone();
        for (column, &index) in free.iter().enumerate() {
            let parameter = &structure.parameters[index];
            let mut value = values[index] + step[column];
            if let Some(lower) = parameter.lower {
                value = value.max(lower);
            }
            if let Some(upper) = parameter.upper {
                value = value.min(upper);
            }
            next[index] = value;
        }
        let candidate = residuals(&next)?;
        iterations = iteration + 1;
        let (old, new) = (current.norm_squared(), candidate.norm_squared());
        if !new.is_finite() || new > old {
            break;
        }
        values = next;
        current = candidate;
        if old - new <= 1e-10 * old {
            break;
        }
    }
    let uninformed = free
        .iter()
        .zip(&informed)
        .filter(|(_, &used)| !used)
        .map(|(&index, _)| structure.parameters[index].name.clone())
        .collect();
    Ok(EquationErrorFit {
        structure: structure.with_values(&values)?,
        blocks: blocks
            .iter()
            .map(|block| EquationBlock {
                state: structure.states[block.row].clone(),
                control: structure.controls[block.control].clone(),
                range: [
                    block.points[0].s.im,
                    block.points[block.points.len() - 1].s.im,
                ],
                points: block.points.len(),
            })
            .collect(),
        uninformed,
        cost: [start_cost, current.norm_squared()],
        iterations,
    })
}

/// The frequencies (and the pair's coherence there) of one block: the pair's own
/// frequencies inside its valid range clipped to the structure's `auto_range_limit`,
/// thinned to [`MAX_POINTS_PER_BLOCK`]; `None` without a valid range.
fn block_frequencies(structure: &ModelStructure, pair: &PairResponse) -> Option<Vec<(f64, f64)>> {
    let [mut lo, mut hi] = pair.valid_range?;
    if let Some([limit_lo, limit_hi]) = structure.auto_range_limit {
        lo = lo.max(limit_lo);
        hi = hi.min(limit_hi);
    }
    let inside: Vec<usize> = (0..pair.omega.len())
        .filter(|&k| pair.omega[k] >= lo && pair.omega[k] <= hi)
        .collect();
    if inside.len() < MIN_POINTS_PER_BLOCK {
        return None;
    }
    let picked: Vec<usize> = if inside.len() <= MAX_POINTS_PER_BLOCK {
        inside
    } else {
        // Evenly in ln ω: the nearest data frequency to each of the log-spaced targets.
        let (a, b) = (
            pair.omega[inside[0]].ln(),
            pair.omega[inside[inside.len() - 1]].ln(),
        );
        let mut chosen: Vec<usize> = (0..MAX_POINTS_PER_BLOCK)
            .map(|k| {
                let target = a + (b - a) * k as f64 / (MAX_POINTS_PER_BLOCK - 1) as f64;
                *inside
                    .iter()
                    .min_by(|&&i, &&j| {
                        (pair.omega[i].ln() - target)
                            .abs()
                            .total_cmp(&(pair.omega[j].ln() - target).abs())
                    })
                    .unwrap_or(&inside[0])
            })
            .collect();
        chosen.dedup();
        chosen
    };
    Some(
        picked
            .into_iter()
            .map(|k| (pair.omega[k], pair.coherence[k]))
            .collect(),
    )
}

/// The complex response of `pair` at `omega` (magnitude and unwrapped phase interpolated
/// in ln ω), or `None` outside its frequencies or where not finite.
fn response_at(pair: &PairResponse, omega: f64) -> Option<Complex64> {
    let (first, last) = (*pair.omega.first()?, *pair.omega.last()?);
    if omega < first || omega > last || pair.mag_db.len() != pair.omega.len() {
        return None;
    }
    let magnitude = 10f64.powf(interpolate_log(&pair.omega, &pair.mag_db, omega) / 20.0);
    let phase = interpolate_log(&pair.omega, &pair.phase_deg, omega).to_radians();
    let value = Complex64::from_polar(magnitude, phase);
    (value.re.is_finite() && value.im.is_finite()).then_some(value)
}

/// Fill the unmeasured states of `x` from the measured ones through their known rows:
/// (sM_UU − F_UU) x_U = −(sM_UM − F_UM) x_M (their controls are zero). False when that
/// system is singular at s.
fn solve_unmeasured(
    model: &super::model::Model,
    unmeasured: &[usize],
    s: Complex64,
    x: &mut DVector<Complex64>,
) -> bool {
    if unmeasured.is_empty() {
        return true;
    }
    let n = x.len();
    let u = unmeasured.len();
    let system = DMatrix::from_fn(u, u, |a, b| {
        let (i, j) = (unmeasured[a], unmeasured[b]);
        s * model.m[(i, j)] - model.f[(i, j)]
    });
    let right = DVector::from_fn(u, |a, _| {
        let i = unmeasured[a];
        (0..n)
            .filter(|l| !unmeasured.contains(l))
            .map(|l| -(s * model.m[(i, l)] - model.f[(i, l)]) * x[l])
            .sum::<Complex64>()
    });
    match system.lu().solve(&right) {
        Some(solution) => {
            for (a, &i) in unmeasured.iter().enumerate() {
                x[i] = solution[a];
            }
            solution
                .iter()
                .all(|v| v.re.is_finite() && v.im.is_finite())
        }
        None => false,
    }
}

/// ∂r/∂θ over the free parameters by central differences (exact for the affine entries;
/// the delays are the only nonlinear ones).
fn jacobian(
    residuals: impl Fn(&[f64]) -> Result<DVector<f64>, FitError>,
    values: &[f64],
    free: &[usize],
    rows: usize,
) -> Result<DMatrix<f64>, FitError> {
    let mut jacobian = DMatrix::zeros(rows, free.len());
    let mut probe = values.to_vec();
    for (column, &index) in free.iter().enumerate() {
        let h = 1e-6 * values[index].abs().max(1.0);
        probe[index] = values[index] + h;
        let up = residuals(&probe)?;
        probe[index] = values[index] - h;
        let down = residuals(&probe)?;
        probe[index] = values[index];
        jacobian.set_column(column, &((up - down) / (2.0 * h)));
    }
    Ok(jacobian)
}

/// The least-squares step −J⁺r with the columns scaled to unit norm, through the SVD
/// (singular values below 10⁻¹⁰ of the largest dropped: a direction the equations do not
/// see does not move). Marks the columns that are not zero in `informed`.
fn gauss_newton_step(
    jacobian: &DMatrix<f64>,
    residuals: &DVector<f64>,
    informed: &mut [bool],
) -> DVector<f64> {
    let columns = jacobian.ncols();
    let norms: Vec<f64> = (0..columns).map(|c| jacobian.column(c).norm()).collect();
    let largest = norms.iter().copied().fold(0.0, f64::max);
    let mut scaled = jacobian.clone();
    for (c, &norm) in norms.iter().enumerate() {
        let used = norm > 1e-12 * largest.max(f64::MIN_POSITIVE);
        informed[c] |= used;
        let divisor = if used { norm } else { 1.0 };
        scaled
            .column_mut(c)
            .scale_mut(if used { 1.0 / divisor } else { 0.0 });
    }
    let svd = scaled.svd(true, true);
    let step = svd
        .solve(&(-residuals), 1e-10 * svd.singular_values.max())
        .unwrap_or_else(|_| DVector::zeros(columns));
    DVector::from_fn(columns, |c, _| {
        if informed[c] && norms[c] > 0.0 {
            step[c] / norms[c]
        } else {
            0.0
        }
    })
}

#[cfg(test)]
mod tests;
