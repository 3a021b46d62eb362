//! The identified model's responses at the board's sensors: p, q, r, φ, θ, ψ to the
//! three stabilised controls lat, lon, ped, found by name in the model.
//!
//! `T(s) = (H0 + s·H1)(sM − F)⁻¹ G · diag(A_j(s) e^{−τ_j s})` as `sysid` defines it
//! (one complex LU of `sM − F` per frequency for all three controls). The heading is no
//! state of the shipped structures: ψ is taken as r/s (hover, small trim attitude), the
//! way the heading hold sees it over the loop's frequencies. A model without a `phi` or
//! `theta` output but with such a state reads the state.

use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use sysid::fit::Model;

/// The stabilised controls, in the loops' order.
pub const CONTROLS: [&str; 3] = ["lat", "lon", "ped"];
/// The measured signals the loops use, in order.
pub const SIGNALS: [&str; 6] = ["p", "q", "r", "phi", "theta", "psi"];
/// Index of ψ in [`SIGNALS`].
pub const PSI: usize = 5;

/// Where a measured signal comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    /// Row of the model's outputs (H0 + sH1).
    Output(usize),
    /// A state read directly.
    State(usize),
    /// r/s: the heading from the yaw rate.
    Heading,
}

/// The model, with the rows and columns the loops need located.
#[derive(Clone, Debug)]
pub struct Plant {
    model: Model,
    controls: [usize; 3],
    sources: [Source; 6],
}

impl Plant {
    /// Locate lat, lon, ped and p, q, r, φ, θ in `model`; one line saying what is missing
    /// otherwise.
    pub fn new(model: Model) -> Result<Plant, String> {
        let mut controls = [0; 3];
        for (slot, name) in controls.iter_mut().zip(CONTROLS) {
            *slot = model
                .controls
                .iter()
                .position(|c| c == name)
                .ok_or_else(|| format!("the model has no control `{name}`"))?;
        }
        let mut sources = [Source::Heading; 6];
        for (slot, name) in sources.iter_mut().zip(SIGNALS).take(PSI) {
            *slot = if let Some(i) = model.outputs.iter().position(|o| o == name) {
                Source::Output(i)
            } else if let Some(i) = model.states.iter().position(|s| s == name) {
                Source::State(i)
            } else {
                return Err(format!(
                    "the model has neither an output nor a state `{name}`"
                ));
            };
        }
        if !model.delays.iter().all(|d| d.is_finite() && *d >= 0.0) {
            return Err("the model has a delay that is negative or not finite".into());
        }
        Ok(Plant {
            model,
            controls,
            sources,
        })
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The 6 × 3 response (signals × controls) at ω [rad/s]; `None` where `sM − F` is
    /// singular.
    pub fn response(&self, omega: f64) -> Option<DMatrix<Complex64>> {
        let model = &self.model;
        let n = model.states.len();
        let s = Complex64::new(0.0, omega);
        let system = DMatrix::from_fn(n, n, |i, j| {
            s * model.m[(i, j)] - Complex64::new(model.f[(i, j)], 0.0)
        });
        let columns = DMatrix::from_fn(n, 3, |i, k| {
            Complex64::new(model.g[(i, self.controls[k])], 0.0)
        });
        let x = system.lu().solve(&columns)?;
        // ẋ = s·x for the H1 part.
        let mut out = DMatrix::zeros(6, 3);
        for k in 0..3 {
            let control = self.controls[k];
            let factor = input_factor(model, control, s);
            let column = x.column(k);
            for (row, source) in self.sources.iter().enumerate().take(PSI) {
                let value = match *source {
                    Source::Output(o) => {
                        let h = DVector::from_fn(n, |j, _| {
                            Complex64::new(model.h0[(o, j)], 0.0) + s * model.h1[(o, j)]
                        });
                        h.dot(&column)
                    }
                    Source::State(i) => column[i],
                    Source::Heading => unreachable_heading(),
                };
                out[(row, k)] = value * factor;
            }
            out[(PSI, k)] = out[(2, k)] / s;
        }
        out.iter().all(|v| v.is_finite()).then_some(out)
    }
}

/// Sources other than ψ are located in `new`; ψ is filled after the loop.
fn unreachable_heading() -> Complex64 {
    Complex64::new(f64::NAN, f64::NAN)
}

/// A_j(s)·e^{−τ_j s} of control `j`.
fn input_factor(model: &Model, j: usize, s: Complex64) -> Complex64 {
    let delay = (-s * model.delays[j]).exp();
    match model.actuators.get(j).copied().flatten() {
        Some(actuator) => actuator.response(s) * delay,
        None => delay,
    }
}
