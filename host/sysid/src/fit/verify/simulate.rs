//! The model as a discrete-time system at the record's sample interval (first-order hold,
//! delays by interpolation) and its simulation from trim; see the module documentation
//! of [`super`].

use nalgebra::{DMatrix, DVector};

use super::error::VerifyError;
use crate::fit::model::Model;

/// The discrete-time form of a model at one sample interval.
#[derive(Clone, Debug)]
pub struct DiscreteModel {
    /// Φ = e^{Ah}.
    pub phi: DMatrix<f64>,
    /// Γ0: response to the input held at its sample value.
    pub gamma_hold: DMatrix<f64>,
    /// Γ1: response to the input's ramp rate over the interval.
    pub gamma_ramp: DMatrix<f64>,
    /// C = H0 + H1·A.
    pub c: DMatrix<f64>,
    /// D = H1·B.
    pub d: DMatrix<f64>,
    /// Sample interval h \[s\].
    pub step_s: f64,
}

fn check_model(model: &Model) -> Result<(), VerifyError> {
    let (n, m, p) = (
        model.states.len(),
        model.controls.len(),
        model.outputs.len(),
    );
    let shapes = [
        ("M", model.m.shape(), (n, n)),
        ("F", model.f.shape(), (n, n)),
        ("G", model.g.shape(), (n, m)),
        ("H0", model.h0.shape(), (p, n)),
        ("H1", model.h1.shape(), (p, n)),
    ];
    for (name, shape, expected) in shapes {
        if shape != expected {
            return Err(VerifyError::BadModel {
                reason: format!(
                    "{name} is {}×{}, expected {}×{}",
                    shape.0, shape.1, expected.0, expected.1
                ),
            });
        }
    }
    if model.delays.len() != m {
        return Err(VerifyError::BadModel {
            reason: format!("{} delays for {m} controls", model.delays.len()),
        });
    }
    if let Some(bad) = model.delays.iter().find(|d| !(d.is_finite() && **d >= 0.0)) {
        return Err(VerifyError::BadModel {
            reason: format!("delay {bad} s"),
        });
    }
    let all = [&model.m, &model.f, &model.g, &model.h0, &model.h1];
    if all.iter().any(|x| x.iter().any(|v| !v.is_finite())) {
        return Err(VerifyError::BadModel {
            reason: "a matrix entry is not finite".into(),
        });
    }
    Ok(())
}

impl DiscreteModel {
    /// Discretise `model` at sample interval `step_s` (first-order hold, see the module
    /// documentation).
    pub fn new(model: &Model, step_s: f64) -> Result<DiscreteModel, VerifyError> {
        check_model(model)?;
        if !(step_s.is_finite() && step_s > 0.0) {
            return Err(VerifyError::BadModel {
                reason: format!("sample interval {step_s} s"),
            });
        }
        let (n, m) = (model.states.len(), model.controls.len());
        let lu = model.m.clone().lu();
        let singular = || VerifyError::BadModel {
            reason: "M is singular".into(),
        };
        let a = lu.solve(&model.f).ok_or_else(singular)?;
        let b = lu.solve(&model.g).ok_or_else(singular)?;
        // Augmented generator [[A, B, 0], [0, 0, I], [0, 0, 0]]·h.
        let size = n + 2 * m;
        let mut generator = DMatrix::zeros(size, size);
        generator.view_mut((0, 0), (n, n)).copy_from(&a);
        generator.view_mut((0, n), (n, m)).copy_from(&b);
        for j in 0..m {
            generator[(n + j, n + m + j)] = 1.0;
        }
        generator *= step_s;
        let exponential = generator.exp();
        if exponential.iter().any(|v| !v.is_finite()) {
            // e^{A·h} overflows: an unstable mode grows past f64 within one sample step,
            // so the response runs away at once. A verification scores that like any other
            // run-away (TIC 1) rather than refusing the model.
            return Err(VerifyError::Diverged { sample: 0 });
        }
        let c = &model.h0 + &model.h1 * &a;
        let d = &model.h1 * &b;
        Ok(DiscreteModel {
            phi: exponential.view((0, 0), (n, n)).into_owned(),
            gamma_hold: exponential.view((0, n), (n, m)).into_owned(),
            // The third block column maps the ramp rate v = Δu/h to x(h): Γ1 itself.
            gamma_ramp: exponential.view((0, n + m), (n, m)).into_owned(),
            c,
            d,
            step_s,
        })
    }
}

/// `values` delayed by `delay_samples` (≥ 0, fractional): `u(k − s)` by linear
/// interpolation between samples; 0 (trim) before the first sample.
pub fn delayed(values: &[f64], delay_samples: f64) -> Vec<f64> {
    let whole = delay_samples.floor();
    let fraction = delay_samples - whole;
    let whole = whole as isize;
    let at = |i: isize| -> f64 {
        if i < 0 {
            0.0
        } else {
            values.get(i as usize).copied().unwrap_or(0.0)
        }
    };
    (0..values.len() as isize)
        .map(|k| {
            // u(k − whole − fraction) between samples k − whole − 1 and k − whole.
            let later = at(k - whole);
            let earlier = at(k - whole - 1);
            later + fraction * (earlier - later)
        })
        .collect()
}

/// Simulate `model` from zero state on `inputs` (one perturbation series per control, in
/// the model's control order, all the same length) sampled at `sample_rate_hz`; returns
/// one series per model output.
pub fn simulate(
    model: &Model,
    inputs: &[Vec<f64>],
    sample_rate_hz: f64,
) -> Result<Vec<Vec<f64>>, VerifyError> {
    simulate_with_resets(model, inputs, sample_rate_hz, &[])
}

/// [`simulate`], with the state set to the given vector at the given sample indices
/// (before that sample's output is formed): segment-wise verification restarts an
/// unstable model from the measured state this way.
pub fn simulate_with_resets(
    model: &Model,
    inputs: &[Vec<f64>],
    sample_rate_hz: f64,
    resets: &[(usize, DVector<f64>)],
) -> Result<Vec<Vec<f64>>, VerifyError> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(VerifyError::BadRecord {
            record: "inputs".into(),
            reason: format!("sample rate {sample_rate_hz} Hz"),
        });
    }
    if inputs.len() != model.controls.len() {
        return Err(VerifyError::BadModel {
            reason: format!(
                "{} input series for {} controls",
                inputs.len(),
                model.controls.len()
            ),
        });
    }
    // Known actuators become states here (the frequency domain keeps them as factors).
    let with_actuators = model.with_actuator_states();
    let actuated: Vec<usize> = (0..model.controls.len())
        .filter(|&j| model.actuators.get(j).copied().flatten().is_some())
        .collect();
    let model = &with_actuators;
    let discrete = DiscreteModel::new(model, 1.0 / sample_rate_hz)?;
    let length = inputs.first().map_or(0, Vec::len);
    if inputs.iter().any(|series| series.len() != length) {
        return Err(VerifyError::BadRecord {
            record: "inputs".into(),
            reason: "input series differ in length".into(),
        });
    }
    let delayed_inputs: Vec<Vec<f64>> = inputs
        .iter()
        .zip(&model.delays)
        .map(|(series, delay)| delayed(series, delay * sample_rate_hz))
        .collect();
    let (n, m, p) = (
        model.states.len(),
        model.controls.len(),
        model.outputs.len(),
    );
    let input_at = |k: usize| DVector::from_fn(m, |j, _| delayed_inputs[j][k]);
    let mut outputs = vec![Vec::with_capacity(length); p];
    let mut state = DVector::zeros(n);
    // A reset gives the model's own states; an actuator restarts at rest at its input.
    let own = n - 2 * actuated.len();
    if let Some((_, bad)) = resets.iter().find(|(_, x)| x.len() != own) {
        return Err(VerifyError::BadModel {
            reason: format!("reset state of length {} for {own} states", bad.len()),
        });
    }
    let resets: Vec<(usize, DVector<f64>)> = resets
        .iter()
        .map(|(at, x)| {
            let mut full = DVector::zeros(n);
            full.rows_mut(0, own).copy_from(x);
            for (k, &j) in actuated.iter().enumerate() {
                full[own + 2 * k] = delayed_inputs[j].get(*at).copied().unwrap_or(0.0);
            }
            (*at, full)
        })
        .collect();
    let mut next_reset = resets.iter().peekable();
    for k in 0..length {
        while let Some((_, reset)) = next_reset.next_if(|(at, _)| *at <= k) {
            state.copy_from(reset);
        }
        let u = input_at(k);
        let y = &discrete.c * &state + &discrete.d * &u;
        if y.iter().any(|v| !v.is_finite()) {
            return Err(VerifyError::Diverged { sample: k });
        }
        for (series, value) in outputs.iter_mut().zip(y.iter()) {
            series.push(*value);
        }
        if k + 1 < length {
            let rate = (input_at(k + 1) - &u) * sample_rate_hz;
            state =
                &discrete.phi * &state + &discrete.gamma_hold * &u + &discrete.gamma_ramp * rate;
        }
    }
    Ok(outputs)
}
