//! The DERIVID cost function, its weighted residuals and their analytic Jacobian.
//!
//! Per pair, over n_ω log-spaced frequencies of its range (paper Eq. 3):
//!
//! ```text
//! J = (20/n_ω) Σ_ω W_γ [ W_g (|T̂| − |T|)² + W_p (∠T̂ − ∠T)² ]     |·| in dB, ∠ in deg
//! W_g = 1.0,  W_p = 0.01745,  W_γ = [1.58 (1 − e^{−γ²})]²
//! ```
//!
//! T̂ is the data, T the model; the phase difference is wrapped to ±180° before squaring.
//! Written as a sum of squares J = Σ r², with one magnitude and one phase residual per
//! frequency:
//!
//! ```text
//! r_mag = √(20/n_ω · W_γ · W_g) · (|T|_dB − |T̂|_dB)
//! r_ph  = √(20/n_ω · W_γ · W_p) · wrap(∠T − ∠T̂)
//! ```
//!
//! Derivatives: with A = sM − F, x = A⁻¹g_j, w = A⁻ᵀc_i (c_i = row i of H0 + sH1) and
//! T = wᵀg_j·e^{−τ_j s} = c_iᵀx·e^{−τ_j s}, an entry change gives
//!
//! ```text
//! ∂T/∂F_rc = w_r x_c e^{−τs}      ∂T/∂M_rc = −s w_r x_c e^{−τs}    ∂T/∂G_rj = w_r e^{−τs}
//! ∂T/∂H0_ic = x_c e^{−τs}         ∂T/∂H1_ic = s x_c e^{−τs}         ∂T/∂τ_j = −s T
//! ```
//!
//! and since ln T = ln|T| + j∠T: ∂|T|_dB = (20/ln 10)·Re(∂T/T), ∂∠T_deg = (180/π)·Im(∂T/T).
//! Parameters enter entries linearly (`coef·θ`), so ∂T/∂θ sums `coef·∂T/∂entry` over the
//! entries the parameter appears in. A parameter that is an actuator's ω or ζ enters
//! through the factor A(s) = ω²/(s² + 2ζωs + ω²): ∂T/∂p = T·∂ ln A/∂p
//! (`actuator_log_derivative`).

use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use super::error::FitError;
use super::model::{Actuator, Model};
use super::structure::{MatrixName, ModelStructure, PairRange};
use crate::document::{FrfDocument, PairResponse};

/// W_g: weight of the magnitude error [1/dB²].
pub const GAIN_WEIGHT: f64 = 1.0;
/// W_p: weight of the phase error [1/deg²] (1 dB ↔ 7.57°).
pub const PHASE_WEIGHT: f64 = 0.01745;
/// Usual number of fit frequencies per pair.
pub const DEFAULT_POINTS_PER_PAIR: usize = 20;

/// W_γ = [1.58 (1 − e^{−γ²})]²: ≈ 1 at γ² = 1, small where the data are incoherent.
pub fn coherence_weight(coherence: f64) -> f64 {
    let gamma2 = coherence.clamp(0.0, 1.0);
    let root = 1.58 * (1.0 - (-gamma2).exp());
    root * root
}

/// Wrap an angle in degrees to (−180, 180].
pub fn wrap_degrees(angle: f64) -> f64 {
    let wrapped = (angle + 180.0).rem_euclid(360.0) - 180.0;
    if wrapped == -180.0 {
        180.0
    } else {
        wrapped
    }
}

/// n log-spaced frequencies from lo to hi inclusive.
pub fn log_spaced(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if n == 1 {
        return vec![(lo * hi).sqrt()];
    }
    let (a, b) = (lo.ln(), hi.ln());
    (0..n)
        .map(|k| (a + (b - a) * k as f64 / (n - 1) as f64).exp())
        .collect()
}

/// Linear interpolation in ln ω; `omega` must lie in [data[0], data[last]].
pub(crate) fn interpolate_log(data_omega: &[f64], values: &[f64], omega: f64) -> f64 {
    let upper = data_omega.partition_point(|&w| w < omega);
    if upper == 0 {
        return values[0];
    }
    if upper >= data_omega.len() {
        return values[values.len() - 1];
    }
    let (w0, w1) = (data_omega[upper - 1].ln(), data_omega[upper].ln());
    let t = if w1 > w0 {
        (omega.ln() - w0) / (w1 - w0)
    } else {
        0.0
    };
    values[upper - 1] + t * (values[upper] - values[upper - 1])
}

/// A frequency band of one named pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairBand {
    /// Control name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// [lo, hi] rad/s.
    pub range: [f64; 2],
}

/// The data of one pair at its n_ω fit frequencies.
#[derive(Clone, Debug, PartialEq)]
pub struct PairGrid {
    /// Control name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Control index in the model.
    pub input_index: usize,
    /// Output index in the model.
    pub output_index: usize,
    /// The range actually fitted [rad/s].
    pub range: [f64; 2],
    /// Fit frequencies [rad/s].
    pub omega: Vec<f64>,
    /// Data magnitude \[dB\] at `omega`.
    pub mag_db: Vec<f64>,
    /// Data phase \[deg\] at `omega`.
    pub phase_deg: Vec<f64>,
    /// W_γ at `omega`.
    pub coherence_weight: Vec<f64>,
}

fn check_data(pair: &PairResponse) -> Result<(), String> {
    let n = pair.omega.len();
    if n < 2 {
        return Err("fewer than 2 frequencies".into());
    }
    if pair.mag_db.len() != n || pair.phase_deg.len() != n || pair.coherence.len() != n {
        return Err("omega, mag_db, phase_deg and coherence differ in length".into());
    }
    if pair.omega.windows(2).any(|w| w[1] <= w[0]) || pair.omega[0] <= 0.0 {
        return Err("frequencies must be positive and ascending".into());
    }
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if !finite(&pair.omega)
        || !finite(&pair.mag_db)
        || !finite(&pair.phase_deg)
        || !finite(&pair.coherence)
    {
        return Err("non-finite values in the data".into());
    }
    Ok(())
}

/// Interpolate one pair's data onto n log-spaced points of `range` (clipped to the data).
fn grid_from_data(
    pair: &PairResponse,
    input_index: usize,
    output_index: usize,
    range: [f64; 2],
    n_points: usize,
) -> Result<PairGrid, FitError> {
    let bad = |reason: String| FitError::BadPairData {
        input: pair.input.clone(),
        output: pair.output.clone(),
        reason,
    };
    check_data(pair).map_err(bad)?;
    let lo = range[0].max(pair.omega[0]);
    let hi = range[1].min(pair.omega[pair.omega.len() - 1]);
    if lo >= hi {
        return Err(bad(format!(
            "range [{}, {}] rad/s does not overlap the data ({} … {} rad/s)",
            range[0],
            range[1],
            pair.omega[0],
            pair.omega[pair.omega.len() - 1]
        )));
    }
    let omega = log_spaced(lo, hi, n_points.max(2));
    let at = |values: &[f64]| -> Vec<f64> {
        omega
            .iter()
            .map(|&w| interpolate_log(&pair.omega, values, w))
            .collect()
    };
    let coherence = at(&pair.coherence);
    Ok(PairGrid {
        input: pair.input.clone(),
        output: pair.output.clone(),
        input_index,
        output_index,
        range: [lo, hi],
        mag_db: at(&pair.mag_db),
        phase_deg: at(&pair.phase_deg),
        coherence_weight: coherence.into_iter().map(coherence_weight).collect(),
        omega,
    })
}

/// The fit grids of every pair the structure lists.
pub fn build_pair_grids(
    structure: &ModelStructure,
    data: &FrfDocument,
    n_points: usize,
) -> Result<Vec<PairGrid>, FitError> {
    if structure.pairs.is_empty() {
        return Err(FitError::NoPairs);
    }
    structure
        .pairs
        .iter()
        .map(|spec| {
            let pair =
                data.pair(&spec.input, &spec.output)
                    .ok_or_else(|| FitError::MissingPair {
                        input: spec.input.clone(),
                        output: spec.output.clone(),
                        line: spec.line,
                    })?;
            let range = match spec.range {
                PairRange::Explicit(band) => band,
                PairRange::Auto => {
                    let band = pair.valid_range.ok_or_else(|| FitError::NoValidRange {
                        input: spec.input.clone(),
                        output: spec.output.clone(),
                        line: spec.line,
                    })?;
                    match structure.auto_range_limit {
                        Some([lo, hi]) => [band[0].max(lo), band[1].min(hi)],
                        None => band,
                    }
                }
            };
            grid_from_data(pair, spec.input_index, spec.output_index, range, n_points)
        })
        .collect()
}

/// Magnitude [dB] and phase [deg] of a response (magnitude floored at 1e−30 so that an
/// exactly zero response stays finite).
fn bode(response: Complex64) -> (f64, f64) {
    let magnitude = response.norm().max(1e-30);
    (
        20.0 * magnitude.log10(),
        response.im.atan2(response.re).to_degrees(),
    )
}

/// √(20/n_ω · W_γ) for one point.
fn point_scale(grid: &PairGrid, point: usize) -> f64 {
    (20.0 / grid.omega.len() as f64 * grid.coherence_weight[point]).sqrt()
}

/// Weighted residuals of a model against the grids: for each grid, for each point,
/// [r_mag, r_ph] (the layout of the Jacobian rows too).
pub fn residuals(model: &Model, grids: &[PairGrid]) -> Result<Vec<f64>, FitError> {
    let mut out = Vec::with_capacity(grids.iter().map(|g| 2 * g.omega.len()).sum());
    for grid in grids {
        for (point, &omega) in grid.omega.iter().enumerate() {
            let response = model.frequency_response(grid.input_index, grid.output_index, omega);
            if !response.re.is_finite() || !response.im.is_finite() {
                return Err(FitError::SingularSystem { omega });
            }
            let (mag_db, phase_deg) = bode(response);
            let scale = point_scale(grid, point);
            out.push(scale * GAIN_WEIGHT.sqrt() * (mag_db - grid.mag_db[point]));
            out.push(scale * PHASE_WEIGHT.sqrt() * wrap_degrees(phase_deg - grid.phase_deg[point]));
        }
    }
    Ok(out)
}

/// J per pair from a residual vector laid out as [`residuals`] makes it.
pub fn pair_costs_from_residuals(grids: &[PairGrid], residuals: &[f64]) -> Vec<f64> {
    let mut offset = 0;
    grids
        .iter()
        .map(|grid| {
            let count = 2 * grid.omega.len();
            let cost = residuals[offset..offset + count]
                .iter()
                .map(|r| r * r)
                .sum();
            offset += count;
            cost
        })
        .collect()
}

/// J per pair of a model against the grids.
pub fn pair_costs(model: &Model, grids: &[PairGrid]) -> Result<Vec<f64>, FitError> {
    Ok(pair_costs_from_residuals(grids, &residuals(model, grids)?))
}

/// Mean of the pair costs (J_ave).
pub fn average(costs: &[f64]) -> f64 {
    if costs.is_empty() {
        0.0
    } else {
        costs.iter().sum::<f64>() / costs.len() as f64
    }
}

/// Where a parameter enters the model, with its coefficient.
#[derive(Clone, Debug)]
enum Occurrence {
    Entry {
        matrix: MatrixName,
        row: usize,
        column: usize,
        coefficient: f64,
    },
    Delay {
        control: usize,
        coefficient: f64,
    },
    /// The natural frequency (`damping` false) or damping of the control's actuator.
    Actuator {
        control: usize,
        damping: bool,
    },
}

/// Occurrences of each base parameter in the structure.
fn occurrences(structure: &ModelStructure) -> Vec<Vec<Occurrence>> {
    let mut list = vec![Vec::new(); structure.parameters.len()];
    for entry in &structure.entries {
        for &(index, coefficient) in &entry.expression.terms {
            list[index].push(Occurrence::Entry {
                matrix: entry.matrix,
                row: entry.row,
                column: entry.column,
                coefficient,
            });
        }
    }
    for (control, delay) in structure.delays.iter().enumerate() {
        for &(index, coefficient) in &delay.terms {
            list[index].push(Occurrence::Delay {
                control,
                coefficient,
            });
        }
    }
    for (control, indices) in structure.actuator_parameters.iter().enumerate() {
        for (which, index) in indices.iter().enumerate() {
            if let Some(&index) = index.as_ref() {
                list[index].push(Occurrence::Actuator {
                    control,
                    damping: which == 1,
                });
            }
        }
    }
    list
}

/// Residuals and their analytic Jacobian with respect to the parameters `free`
/// (base-parameter indices), at `values`.
pub fn residuals_and_jacobian(
    structure: &ModelStructure,
    values: &[f64],
    free: &[usize],
    grids: &[PairGrid],
) -> Result<(DVector<f64>, DMatrix<f64>), FitError> {
    let model = structure.model(values)?;
    let all_occurrences = occurrences(structure);
    let rows: usize = grids.iter().map(|g| 2 * g.omega.len()).sum();
    let mut residual = DVector::zeros(rows);
    let mut jacobian = DMatrix::zeros(rows, free.len());
    let db_per_neper = 20.0 / std::f64::consts::LN_10;
    let deg_per_rad = 180.0 / std::f64::consts::PI;
    let mut row = 0;
    for grid in grids {
        let (input, output) = (grid.input_index, grid.output_index);
        for (point, &omega) in grid.omega.iter().enumerate() {
            let solution = model
                .pair_solution(input, output, omega)
                .ok_or(FitError::SingularSystem { omega })?;
            let response = solution.response;
            if !response.re.is_finite() || !response.im.is_finite() {
                return Err(FitError::SingularSystem { omega });
            }
            let (mag_db, phase_deg) = bode(response);
            let scale = point_scale(grid, point);
            let gain_scale = scale * GAIN_WEIGHT.sqrt();
            let phase_scale = scale * PHASE_WEIGHT.sqrt();
            residual[row] = gain_scale * (mag_db - grid.mag_db[point]);
            residual[row + 1] = phase_scale * wrap_degrees(phase_deg - grid.phase_deg[point]);
            let inverse = if response.norm() > 1e-30 {
                1.0 / response
            } else {
                Complex64::new(1e30, 0.0)
            };
            let (s, delay) = (solution.s, solution.delay_factor);
            for (column, &parameter) in free.iter().enumerate() {
                let mut derivative = Complex64::new(0.0, 0.0);
                for occurrence in &all_occurrences[parameter] {
                    derivative += match *occurrence {
                        Occurrence::Entry {
                            matrix,
                            row: r,
                            column: c,
                            coefficient,
                        } => {
                            let d = match matrix {
                                MatrixName::F => solution.w[r] * solution.x[c],
                                MatrixName::M => -s * solution.w[r] * solution.x[c],
                                MatrixName::G if c == input => solution.w[r],
                                MatrixName::H0 if r == output => solution.x[c],
                                MatrixName::H1 if r == output => s * solution.x[c],
                                _ => Complex64::new(0.0, 0.0),
                            };
                            d * delay * coefficient
                        }
                        Occurrence::Delay {
                            control,
                            coefficient,
                        } if control == input => -s * response * coefficient,
                        Occurrence::Delay { .. } => Complex64::new(0.0, 0.0),
                        Occurrence::Actuator { control, damping } if control == input => {
                            model.actuators[input].map_or(Complex64::new(0.0, 0.0), |a| {
                                response * actuator_log_derivative(&a, s, damping)
                            })
                        }
                        Occurrence::Actuator { .. } => Complex64::new(0.0, 0.0),
                    };
                }
                let relative = derivative * inverse;
                jacobian[(row, column)] = gain_scale * db_per_neper * relative.re;
                jacobian[(row + 1, column)] = phase_scale * deg_per_rad * relative.im;
            }
            row += 2;
        }
    }
    Ok((residual, jacobian))
}

/// ∂ ln A/∂ω (`damping` false) or ∂ ln A/∂ζ of A(s) = ω²/D, D = s² + 2ζωs + ω²:
/// 2/ω − (2ζs + 2ω)/D and −2ωs/D. T carries A as a factor, so ∂T/∂p = T·∂ ln A/∂p.
fn actuator_log_derivative(actuator: &Actuator, s: Complex64, damping: bool) -> Complex64 {
    let (w, z) = (actuator.natural_frequency_rad_s, actuator.damping);
    let d = s * s + s * (2.0 * z * w) + w * w;
    if damping {
        -(s * (2.0 * w)) / d
    } else {
        Complex64::new(2.0 / w, 0.0) - (s * (2.0 * z) + 2.0 * w) / d
    }
}

/// J of each band and J_ave when `candidate` is scored against `reference`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelComparison {
    /// The bands compared, in the order given.
    pub bands: Vec<PairBand>,
    /// J per band.
    pub costs: Vec<f64>,
    /// Mean of `costs`.
    pub average: f64,
}

/// The DERIVID cost of model `candidate` against model `reference` (playing the data,
/// with coherence 1) over named pairs and ranges, n_points log-spaced points each. Used
/// to score an identified model against the truth model of a simulation.
pub fn cost_between_models(
    reference: &Model,
    candidate: &Model,
    bands: &[PairBand],
    n_points: usize,
) -> Result<ModelComparison, FitError> {
    let mut grids = Vec::with_capacity(bands.len());
    let unknown = |band: &PairBand| FitError::UnknownPairName {
        input: band.input.clone(),
        output: band.output.clone(),
    };
    for band in bands {
        let reference_input = reference
            .control_index(&band.input)
            .ok_or_else(|| unknown(band))?;
        let reference_output = reference
            .output_index(&band.output)
            .ok_or_else(|| unknown(band))?;
        let input_index = candidate
            .control_index(&band.input)
            .ok_or_else(|| unknown(band))?;
        let output_index = candidate
            .output_index(&band.output)
            .ok_or_else(|| unknown(band))?;
        if !(band.range[0] > 0.0 && band.range[0] < band.range[1]) {
            return Err(FitError::BadPairData {
                input: band.input.clone(),
                output: band.output.clone(),
                reason: "need 0 < lo < hi".into(),
            });
        }
        let omega = log_spaced(band.range[0], band.range[1], n_points.max(2));
        let mut mag_db = Vec::with_capacity(omega.len());
        let mut phase_deg = Vec::with_capacity(omega.len());
        for &w in &omega {
            let response = reference.frequency_response(reference_input, reference_output, w);
            if !response.re.is_finite() || !response.im.is_finite() {
                return Err(FitError::SingularSystem { omega: w });
            }
            let (m, p) = bode(response);
            mag_db.push(m);
            phase_deg.push(p);
        }
        grids.push(PairGrid {
            input: band.input.clone(),
            output: band.output.clone(),
            input_index,
            output_index,
            range: band.range,
            coherence_weight: vec![coherence_weight(1.0); omega.len()],
            omega,
            mag_db,
            phase_deg,
        });
    }
    let costs = pair_costs(candidate, &grids)?;
    Ok(ModelComparison {
        bands: bands.to_vec(),
        average: average(&costs),
        costs,
    })
}

#[cfg(test)]
mod tests;
