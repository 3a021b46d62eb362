//! The pilot-mode loops around the plant: the loop matrix at the actuator input, each
//! loop broken there with the others closed, and the attitude responses to the sticks.
//!
//! With `u` the three commands the board sends to the servos (lat, lon, ped) and `m` the
//! six signals it measures (p, q, r, φ, θ, ψ):
//!
//! ```text
//! u = K_f·stick − K_b·m,   m = P_m·u,   P_m = filter · P · diag(hold · servo)
//! L = K_b·P_m          (3 × 3, the return ratio at the actuator input)
//! ```
//!
//! Loop k broken at its actuator input with the other two closed (the point ArduPilot's
//! and CONDUIT's broken-loop analyses use): `1/(1 + L_k) = [(I + L)⁻¹]_kk`, so
//! `L_k = 1/[(I + L)⁻¹]_kk − 1`, and `S_k = [(I + L)⁻¹]_kk` is the sensitivity at that
//! point. The stick responses are the aircraft's (unfiltered) attitude to each stick
//! with all loops closed: `P·diag(hold·servo)·(I + L)⁻¹·K_f`.

use nalgebra::DMatrix;
use num_complex::Complex64;

use crate::law::{BoardLaw, LoopMode};
use crate::plant::{Plant, PSI};

/// A frequency response sampled on a grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampled {
    /// Frequencies [rad/s], increasing.
    pub omega: Vec<f64>,
    /// Response at each frequency.
    pub values: Vec<Complex64>,
}

/// Which loops are closed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Configuration {
    /// Roll and pitch stick mode (Rate: rate loops; Level: level loops around them).
    pub mode: LoopMode,
    /// The tail in heading hold (pedal centred) rather than its rate loop.
    pub heading_hold: bool,
}

/// Everything at one frequency.
struct Frame {
    /// (I + L)⁻¹.
    sensitivity: DMatrix<Complex64>,
    /// P·diag(hold·servo): commands to the true signals.
    plant: DMatrix<Complex64>,
    /// K_f (diagonal).
    stick: [Complex64; 3],
}

/// `count` log-spaced frequencies from `low` to `high` [rad/s].
pub fn log_grid(low: f64, high: f64, count: usize) -> Vec<f64> {
    let (a, b) = (low.ln(), high.ln());
    let last = (count.max(2) - 1) as f64;
    (0..count.max(2))
        .map(|i| (a + (b - a) * i as f64 / last).exp())
        .collect()
}

fn frame(
    response: &DMatrix<Complex64>,
    law: &BoardLaw,
    config: Configuration,
    omega: f64,
) -> Option<Frame> {
    let path = law.output_path(omega);
    let filter = law.measurement(omega);
    let commanded = DMatrix::from_fn(6, 3, |i, k| response[(i, k)] * path * law.servo(k, omega));
    let axes = law.axes();
    let mut feedback = DMatrix::<Complex64>::zeros(3, 6);
    let mut stick = [Complex64::new(0.0, 0.0); 3];
    for (axis, gains) in axes.iter().enumerate() {
        let terms = law.axis_terms(gains, omega);
        let mode = if axis == 2 && !config.heading_hold {
            LoopMode::Rate
        } else {
            config.mode
        };
        feedback[(axis, axis)] = terms.feedback;
        let outer = law.outer_gain(axis, mode);
        if outer != 0.0 {
            let angle = if axis == 2 { PSI } else { 3 + axis };
            feedback[(axis, angle)] = terms.target * outer;
        }
        // The stick response flies the tail on its rate loop (pedal out of the band).
        let stick_mode = if axis == 2 {
            LoopMode::Rate
        } else {
            config.mode
        };
        stick[axis] = terms.target * law.stick_gain(axis, stick_mode);
    }
    let loop_matrix = &feedback * (&commanded * filter);
    let sensitivity = (DMatrix::<Complex64>::identity(3, 3) + loop_matrix).try_inverse()?;
    Some(Frame {
        sensitivity,
        plant: commanded,
        stick,
    })
}

/// Responses of one configuration on a grid.
#[derive(Clone, Debug, PartialEq)]
pub struct LoopResponses {
    /// Broken loop L_k at each actuator input (lat, lon, ped).
    pub broken: [Sampled; 3],
    /// Sensitivity S_k = 1/(1 + L_k) at each actuator input.
    pub sensitivity: [Sampled; 3],
    /// Attitude (φ, θ, ψ) to its stick (lat, lon, ped), loops closed.
    pub stick_attitude: [Sampled; 3],
}

/// The responses of `config` on `grid`; `None` when the model is singular at a
/// frequency of the grid.
pub fn responses(
    plant: &Plant,
    law: &BoardLaw,
    config: Configuration,
    grid: &[f64],
) -> Option<LoopResponses> {
    let empty = || Sampled {
        omega: grid.to_vec(),
        values: Vec::with_capacity(grid.len()),
    };
    let mut broken = [empty(), empty(), empty()];
    let mut sensitivity = [empty(), empty(), empty()];
    let mut stick_attitude = [empty(), empty(), empty()];
    for &omega in grid {
        let frame = frame(&plant.response(omega)?, law, config, omega)?;
        for k in 0..3 {
            let s = frame.sensitivity[(k, k)];
            sensitivity[k].values.push(s);
            broken[k].values.push(Complex64::new(1.0, 0.0) / s - 1.0);
            // Attitude row: φ, θ, ψ (signals 3, 4, 5) to stick k.
            let row = frame.plant.row(3 + k);
            let column = frame.sensitivity.column(k) * frame.stick[k];
            stick_attitude[k]
                .values
                .push((0..3).map(|j| row[j] * column[j]).sum());
        }
    }
    Some(LoopResponses {
        broken,
        sensitivity,
        stick_attitude,
    })
}

/// The broken loops of `config` on `grid` from the plant's responses already computed
/// there (`Plant::response` at each frequency of `grid`): a design that tries many
/// gains on one model computes the model's responses once.
pub fn broken_loops_from(
    responses: &[DMatrix<Complex64>],
    law: &BoardLaw,
    config: Configuration,
    grid: &[f64],
) -> Option<[Sampled; 3]> {
    let mut broken: [Sampled; 3] = std::array::from_fn(|_| Sampled {
        omega: grid.to_vec(),
        values: Vec::with_capacity(grid.len()),
    });
    for (response, &omega) in responses.iter().zip(grid) {
        let frame = frame(response, law, config, omega)?;
        for (k, loop_k) in broken.iter_mut().enumerate() {
            loop_k
                .values
                .push(Complex64::new(1.0, 0.0) / frame.sensitivity[(k, k)] - 1.0);
        }
    }
    Some(broken)
}

/// The command `u_k` the board computes per unit of axis k's rate target ω_t, with the
/// loops of `config` closed, at ω: `[(I + L)⁻¹]_kk·F_ω`.
pub fn command_per_target(
    response: &DMatrix<Complex64>,
    law: &BoardLaw,
    config: Configuration,
    axis: usize,
    omega: f64,
) -> Option<Complex64> {
    let frame = frame(response, law, config, omega)?;
    let terms = law.axis_terms(law.axes()[axis], omega);
    Some(frame.sensitivity[(axis, axis)] * terms.target)
}
