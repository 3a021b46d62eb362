//! The simulator's own first-order expansion about a trim, flown in place of the nonlinear
//! model when [`SimOptions::linearized_plant`](crate::SimOptions) is set.
//!
//! With x the 15 simulator states and a the four actuator positions,
//!
//!   ẋ = f(x₀, a₀) + ∂f/∂x·(x − x₀) + ∂f/∂a·(a − a₀),
//!   F = F(x₀, a₀) + ∂F/∂x·(x − x₀) + ∂F/∂a·(a − a₀)   (body force, for the accelerometers),
//!
//! the Jacobians by central differences of the same `Model::derivative` and `Model::loads`
//! the nonlinear simulation integrates. Flown with the flight controller in the loop, its
//! frequency responses are exactly the linearization's, so what an identification gets
//! wrong on it is the estimator's (closed loop, windowing, noise), not the aircraft's
//! nonlinearity. Still air only: wind, gusts and external loads are not part of it.

use crate::integrator::rk4_from;
use crate::model::{self, Model, ModelFlags, STATE_LEN};
use crate::trim::Trim;

/// Central-difference step: states and actuator positions are O(0.1–10) in their units,
/// so 1e-5 keeps truncation (∝ h²) and rounding (∝ ε/h) errors both near 1e-10.
const DIFFERENCE_STEP: f64 = 1e-5;

/// Iterations of the momentum inflow per evaluation: converged, unlike the flight loop's
/// single warm-started Newton step (each difference starts from the trim inflow).
const INFLOW_STEPS: u32 = 60;

/// ẋ and F as affine functions of (x, a) about a trim.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LinearPlant {
    state_trim: [f64; STATE_LEN],
    actuator_trim: [f64; 4],
    derivative_trim: [f64; STATE_LEN],
    force_trim: [f64; 3],
    /// ∂f/∂x, row i = state derivative i.
    state_jacobian: [[f64; STATE_LEN]; STATE_LEN],
    /// ∂f/∂a.
    actuator_jacobian: [[f64; 4]; STATE_LEN],
    /// ∂F/∂x.
    force_state_jacobian: [[f64; STATE_LEN]; 3],
    /// ∂F/∂a.
    force_actuator_jacobian: [[f64; 4]; 3],
}

impl LinearPlant {
    /// Expand `model` about `trim` (still air).
    pub(crate) fn about(model: &Model, trim: &Trim, flags: ModelFlags) -> LinearPlant {
        let flags = ModelFlags {
            inflow_steps: INFLOW_STEPS,
            ..flags
        };
        let evaluate = |x: &[f64; STATE_LEN], a: &[f64; 4]| {
            let pitch = model.heli.blade_pitch(*a);
            let mut warm = [trim.inflow, trim.tail_inflow];
            let (derivative, loads) = model.derivative(x, &pitch, [0.0; 3], flags, &mut warm);
            (derivative, loads.force)
        };
        let state_trim = trim.state.0;
        let actuator_trim = trim.controls;
        let (derivative_trim, force_trim) = evaluate(&state_trim, &actuator_trim);
        let mut plant = LinearPlant {
            state_trim,
            actuator_trim,
            derivative_trim,
            force_trim,
            state_jacobian: [[0.0; STATE_LEN]; STATE_LEN],
            actuator_jacobian: [[0.0; 4]; STATE_LEN],
            force_state_jacobian: [[0.0; STATE_LEN]; 3],
            force_actuator_jacobian: [[0.0; 4]; 3],
        };
        let half = 0.5 / DIFFERENCE_STEP;
        for column in 0..STATE_LEN {
            // Without dynamic inflow the inflow "state" is an iteration seed, not a state.
            if column == model::LAMBDA && !flags.dynamic_inflow {
                continue;
            }
            let (mut plus, mut minus) = (state_trim, state_trim);
            plus[column] += DIFFERENCE_STEP;
            minus[column] -= DIFFERENCE_STEP;
            let ((d_plus, f_plus), (d_minus, f_minus)) = (
                evaluate(&plus, &actuator_trim),
                evaluate(&minus, &actuator_trim),
            );
            for row in 0..STATE_LEN {
                plant.state_jacobian[row][column] = (d_plus[row] - d_minus[row]) * half;
            }
            for row in 0..3 {
                plant.force_state_jacobian[row][column] = (f_plus[row] - f_minus[row]) * half;
            }
        }
        for column in 0..4 {
            let (mut plus, mut minus) = (actuator_trim, actuator_trim);
            plus[column] += DIFFERENCE_STEP;
            minus[column] -= DIFFERENCE_STEP;
            let ((d_plus, f_plus), (d_minus, f_minus)) =
                (evaluate(&state_trim, &plus), evaluate(&state_trim, &minus));
            for row in 0..STATE_LEN {
                plant.actuator_jacobian[row][column] = (d_plus[row] - d_minus[row]) * half;
            }
            for row in 0..3 {
                plant.force_actuator_jacobian[row][column] = (f_plus[row] - f_minus[row]) * half;
            }
        }
        plant
    }

    /// ẋ at (x, a).
    pub(crate) fn derivative(&self, x: &[f64; STATE_LEN], a: &[f64; 4]) -> [f64; STATE_LEN] {
        self.expand(
            self.derivative_trim,
            &self.state_jacobian,
            &self.actuator_jacobian,
            x,
            a,
        )
    }

    /// Body force [N] at (x, a).
    pub(crate) fn force(&self, x: &[f64; STATE_LEN], a: &[f64; 4]) -> [f64; 3] {
        self.expand(
            self.force_trim,
            &self.force_state_jacobian,
            &self.force_actuator_jacobian,
            x,
            a,
        )
    }

    /// value₀ + J_x·(x − x₀) + J_a·(a − a₀), row by row.
    fn expand<const ROWS: usize>(
        &self,
        value_at_trim: [f64; ROWS],
        state_jacobian: &[[f64; STATE_LEN]; ROWS],
        actuator_jacobian: &[[f64; 4]; ROWS],
        x: &[f64; STATE_LEN],
        a: &[f64; 4],
    ) -> [f64; ROWS] {
        let mut value = value_at_trim;
        for (row, out) in value.iter_mut().enumerate() {
            let states: f64 = (0..STATE_LEN)
                .map(|j| state_jacobian[row][j] * (x[j] - self.state_trim[j]))
                .sum();
            let actuators: f64 = (0..4)
                .map(|j| actuator_jacobian[row][j] * (a[j] - self.actuator_trim[j]))
                .sum();
            *out += states + actuators;
        }
        value
    }

    /// One classical RK4 step of size h with the actuators held at `a`.
    pub(crate) fn rk4_step(&self, x: &mut [f64; STATE_LEN], a: &[f64; 4], h: f64) {
        let k1 = self.derivative(x, a);
        rk4_from(x, h, k1, |stage| self.derivative(stage, a));
    }
}
