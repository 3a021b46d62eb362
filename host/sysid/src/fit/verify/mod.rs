//! Time-domain verification: simulate an identified model on recorded inputs and measure
//! how well it predicts the recorded outputs (CIFER's VERIFID step).
//!
//! The model `M ẋ = F x + G u(t − τ)`, `y = H0 x + H1 ẋ` is brought to
//!
//! ```text
//! ẋ = A x + B u_d,   A = M⁻¹F, B = M⁻¹G,   u_d,j(t) = u_j(t − τ_j)
//! y = C x + D u_d,   C = H0 + H1·A, D = H1·B
//! ```
//!
//! **Inputs** are perturbations: each recorded control minus its trim, taken as the output
//! biases are (below): its mean over the record's trim samples, or (fitted bias) its
//! first sample. **Delays** shift each control by τ_j·f_s
//! samples, the fractional part by linear interpolation; before the record starts the
//! control is at trim (0). **Integration** is exact for inputs that are linear between
//! samples (first-order hold, consistent with the interpolation of the delay): with
//! h = 1/f_s and `v = (u_d[k+1] − u_d[k])/h`,
//!
//! ```text
//!        ⎡A B 0⎤        ⎡Φ Γ0 Γ1⎤
//! exp(h·⎢0 0 I⎥)   =   ⎢0 I  hI⎥ ,   x[k+1] = Φ x[k] + Γ0 u_d[k] + Γ1 v
//!        ⎣0 0 0⎦        ⎣0 0  I ⎦
//! ```
//!
//! (the zero-order-hold discretisation `exp(h·[[A, B], [0, 0]])` is the top-left part; the
//! third block row adds the ramp). The state starts at 0 (trim).
//!
//! **Bias.** The model predicts perturbations from trim; the recorded outputs are absolute.
//! Per output a constant b, its trim value (and any sensor bias), is removed, chosen by
//! [`BiasMode`]:
//!
//! * [`BiasMode::Trim`] (the default): `b = mean(y[0..n₀])`, the output's mean over the
//!   record's `n₀ = `[`Record::trim_samples`] samples taken at trim before the excitation
//!   starts (a dump's trim-capture phase), and each input's trim likewise
//!   `u₀ = mean(u[0..n₀])`. Nothing is taken from the prediction, so a model whose
//!   response is offset or drifts during the excitation pays for it in the TIC. A record
//!   without trim samples is refused ([`VerifyError::NoTrim`]), not scored another way.
//! * [`BiasMode::Fitted`]: `b = mean(y − ŷ)` over the whole record (least squares; inputs
//!   from their first sample). It removes any constant error of the prediction as well,
//!   and so flatters the model; kept for comparison with earlier results.
//!
//! Either way the score runs over the whole record, trim samples included. **Theil's
//! inequality coefficient** is then computed on perturbations, measured `y − b` against
//! predicted ŷ:
//!
//! ```text
//! TIC = √(Σ(y − b − ŷ)²/N) / (√(Σ(y − b)²/N) + √(Σŷ²/N))
//! ```
//!
//! 0 is a perfect prediction, 1 the worst (e.g. ŷ = −(y − b), or one of them zero);
//! below ≈ 0.25–0.3 is the usual acceptance guideline (Jategaonkar; Tischler & Remple).
//! The overall figure is the mean of the per-output TICs (the outputs have different
//! units, so their squares are not pooled).

use std::fmt;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use nalgebra::{DMatrix, DVector};

use super::model::Model;
use crate::frf::records::Record;

/// Why a model cannot be verified against a record.
#[derive(Clone, Debug, PartialEq)]
pub enum VerifyError {
    /// A control of the model is not among the record's inputs.
    MissingInput {
        /// The control.
        control: String,
        /// The record.
        source: String,
        /// The record's inputs.
        available: Vec<String>,
    },
    /// No output of the model is among the record's outputs.
    NoCommonOutput {
        /// The record.
        source: String,
        /// The model's outputs.
        model_outputs: Vec<String>,
    },
    /// The model's matrices do not fit its names, or M is singular.
    BadModel {
        /// What is wrong.
        reason: String,
    },
    /// The record is too short or its rate is not positive.
    BadRecord {
        /// The record.
        source: String,
        /// What is wrong.
        reason: String,
    },
    /// The simulation left the finite numbers (an unstable model ran away).
    Diverged {
        /// Sample index where the first non-finite value appeared.
        sample: usize,
    },
    /// The trim bias was asked for, but the record has no trim samples before its
    /// excitation.
    NoTrim {
        /// The record.
        source: String,
    },
    /// A plot could not be written.
    Plot {
        /// The file.
        path: PathBuf,
        /// The error.
        message: String,
    },
}

impl fmt::Display for VerifyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            VerifyError::MissingInput {
                control,
                source,
                available,
            } => write!(
                f,
                "model control `{control}` is not an input of {source} (inputs: {})",
                available.join(" ")
            ),
            VerifyError::NoCommonOutput {
                source,
                model_outputs,
            } => write!(
                f,
                "no output of the model ({}) is recorded in {source}",
                model_outputs.join(" ")
            ),
            VerifyError::BadModel { reason } => write!(f, "unusable model: {reason}"),
            VerifyError::BadRecord { source, reason } => write!(f, "{source}: {reason}"),
            VerifyError::Diverged { sample } => write!(
                f,
                "the simulated model diverged (non-finite at sample {sample})"
            ),
            VerifyError::NoTrim { source } => write!(
                f,
                "{source}: no trim samples before the excitation to take the output bias from \
                 (the fitted bias needs none)"
            ),
            VerifyError::Plot { path, message } => {
                write!(f, "cannot draw plot {}: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for VerifyError {}

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
    /// Sample interval h [s].
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
            return Err(VerifyError::BadModel {
                reason:
                    "the matrix exponential is not finite (model far too fast for the sample rate)"
                        .into(),
            });
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
            source: "inputs".into(),
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
    let discrete = DiscreteModel::new(model, 1.0 / sample_rate_hz)?;
    let length = inputs.first().map_or(0, Vec::len);
    if inputs.iter().any(|series| series.len() != length) {
        return Err(VerifyError::BadRecord {
            source: "inputs".into(),
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
    if let Some((_, bad)) = resets.iter().find(|(_, x)| x.len() != n) {
        return Err(VerifyError::BadModel {
            reason: format!("reset state of length {} for {n} states", bad.len()),
        });
    }
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

/// Where the constant b removed from each measured output (its trim value plus any sensor
/// bias) comes from; see the module documentation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BiasMode {
    /// b = the output's mean over the record's trim samples before the excitation; the
    /// inputs are taken from their mean over the same samples.
    #[default]
    Trim,
    /// b = mean(y − ŷ) over the record (least squares); the inputs from their first
    /// sample.
    Fitted,
}

impl BiasMode {
    /// `trim` or `fitted` (as in JSON).
    pub fn name(self) -> &'static str {
        match self {
            BiasMode::Trim => "trim",
            BiasMode::Fitted => "fitted",
        }
    }
}

impl fmt::Display for BiasMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The fit of one output.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OutputScore {
    /// Output name.
    pub output: String,
    /// The constant b removed from the measurement: the output's trim mean
    /// ([`BiasMode::Trim`]) or the least-squares mean(y − ŷ) ([`BiasMode::Fitted`]).
    pub bias: f64,
    /// RMS of the residual y − b − ŷ.
    pub rms_error: f64,
    /// RMS of the measured perturbation y − b.
    pub rms_measured: f64,
    /// RMS of the prediction ŷ.
    pub rms_predicted: f64,
    /// Theil's inequality coefficient.
    pub theil: f64,
}

/// Verification of a model on one record.
#[derive(Clone, Debug, PartialEq)]
pub struct Verification {
    /// The record's source.
    pub source: String,
    /// Sample rate [Hz].
    pub sample_rate_hz: f64,
    /// Samples compared.
    pub samples: usize,
    /// Where the output biases came from.
    pub bias: BiasMode,
    /// Samples averaged for the trim biases (the record's trim samples); 0 with
    /// [`BiasMode::Fitted`].
    pub trim_samples: usize,
    /// Per compared output (model outputs recorded in the record), model order.
    pub outputs: Vec<OutputScore>,
    /// Model outputs the record does not have.
    pub not_recorded: Vec<String>,
    /// Mean of the per-output TICs.
    pub theil_mean: f64,
    /// Time [s] at which the simulated model overflowed (an unstable model running away):
    /// every output then scores TIC = 1, the worst value (the limit as ŷ → ∞).
    pub diverged_at_s: Option<f64>,
    /// Measured series (with the bias removed), per compared output.
    pub measured: Vec<Vec<f64>>,
    /// Predicted series, per compared output.
    pub predicted: Vec<Vec<f64>>,
}

fn rms(values: impl Iterator<Item = f64>, n: usize) -> f64 {
    (values.map(|v| v * v).sum::<f64>() / n as f64).sqrt()
}

/// Score a prediction against a measurement of one output with the bias fitted by least
/// squares, `b = mean(y − ŷ)` ([`BiasMode::Fitted`]), then the TIC.
pub fn score_output(name: &str, measured: &[f64], predicted: &[f64]) -> OutputScore {
    let n = measured.len().min(predicted.len()).max(1);
    let bias = measured
        .iter()
        .zip(predicted)
        .map(|(y, p)| y - p)
        .sum::<f64>()
        / n as f64;
    score_output_with_bias(name, measured, predicted, bias)
}

/// Score a prediction against a measurement of one output with a given bias b (e.g. the
/// output's trim): the RMS of `y − b − ŷ`, `y − b` and ŷ, and the TIC.
pub fn score_output_with_bias(
    name: &str,
    measured: &[f64],
    predicted: &[f64],
    bias: f64,
) -> OutputScore {
    let n = measured.len().min(predicted.len()).max(1);
    let rms_error = rms(measured.iter().zip(predicted).map(|(y, p)| y - bias - p), n);
    let rms_measured = rms(measured.iter().map(|y| y - bias), n);
    let rms_predicted = rms(predicted.iter().copied(), n);
    let denominator = rms_measured + rms_predicted;
    // A prediction that overflowed the sums is the limit ŷ → ∞: TIC → 1.
    let theil = if !(rms_error.is_finite() && denominator.is_finite()) {
        1.0
    } else if denominator > 0.0 {
        rms_error / denominator
    } else {
        0.0
    };
    OutputScore {
        output: name.to_string(),
        bias,
        rms_error,
        rms_measured,
        rms_predicted,
        theil,
    }
}

/// Verify `model` on `record` over the whole record from trim: simulate it on the
/// record's inputs (perturbations from their trim) and score every model output the
/// record has, with the bias from the trim ([`BiasMode::Trim`]).
pub fn verify_record(model: &Model, record: &Record) -> Result<Verification, VerifyError> {
    verify_record_in_segments(model, record, None, BiasMode::default())
}

/// With the fitted bias, seconds of the record's start averaged for the trim values of
/// the measured states the segments restart from.
const TRIM_AVERAGE_S: f64 = 1.0;

/// Mean of the first `n` (≥ 1) values.
fn mean_of_first(values: &[f64], n: usize) -> f64 {
    values[..n].iter().sum::<f64>() / n as f64
}

/// [`verify_record`], optionally restarting the simulation every `segment_s` seconds from
/// the measured state. A hover helicopter is unstable (the Bo-105's phugoid-like pair
/// doubles in ≈ 2 s), so an open-loop prediction over a 90 s record runs away whatever
/// the model; VERIFID-style checks use records of a few seconds. Each model state named
/// like a recorded output (u v w p q r phi theta) restarts at its measured value minus
/// its trim (the mean over the record's trim samples with [`BiasMode::Trim`]; over its
/// first second, where the firmware captured trim, with [`BiasMode::Fitted`]); other
/// states (flapping) restart at 0. One bias per output over the whole record, as `bias`
/// says.
pub fn verify_record_in_segments(
    model: &Model,
    record: &Record,
    segment_s: Option<f64>,
    bias: BiasMode,
) -> Result<Verification, VerifyError> {
    if let Some(segment) = segment_s {
        if !(segment.is_finite() && segment * record.sample_rate_hz >= 2.0) {
            return Err(VerifyError::BadRecord {
                source: record.source.clone(),
                reason: format!("segment of {segment} s is shorter than 2 samples"),
            });
        }
    }
    if !(record.sample_rate_hz.is_finite() && record.sample_rate_hz > 0.0) {
        return Err(VerifyError::BadRecord {
            source: record.source.clone(),
            reason: format!("sample rate {} Hz", record.sample_rate_hz),
        });
    }
    if record.len() < 2 {
        return Err(VerifyError::BadRecord {
            source: record.source.clone(),
            reason: format!("{} samples, need at least 2", record.len()),
        });
    }
    let mut recorded_inputs = Vec::with_capacity(model.controls.len());
    for control in &model.controls {
        let series = record
            .input(control)
            .ok_or_else(|| VerifyError::MissingInput {
                control: control.clone(),
                source: record.source.clone(),
                available: record.inputs.iter().map(|c| c.name.clone()).collect(),
            })?;
        recorded_inputs.push(series);
    }
    let compared: Vec<(usize, &[f64])> = model
        .outputs
        .iter()
        .enumerate()
        .filter_map(|(i, name)| record.output(name).map(|series| (i, series)))
        .collect();
    if compared.is_empty() {
        return Err(VerifyError::NoCommonOutput {
            source: record.source.clone(),
            model_outputs: model.outputs.clone(),
        });
    }
    let not_recorded = model
        .outputs
        .iter()
        .filter(|name| record.output(name).is_none())
        .cloned()
        .collect();
    // Samples whose means are the trims (biases), with the trim bias.
    let trim_samples = match bias {
        BiasMode::Fitted => None,
        BiasMode::Trim if record.trim_samples == 0 => {
            return Err(VerifyError::NoTrim {
                source: record.source.clone(),
            })
        }
        BiasMode::Trim if record.trim_samples > record.len() => {
            return Err(VerifyError::BadRecord {
                source: record.source.clone(),
                reason: format!(
                    "{} trim samples in a record of {}",
                    record.trim_samples,
                    record.len()
                ),
            })
        }
        BiasMode::Trim => Some(record.trim_samples),
    };
    let inputs: Vec<Vec<f64>> = recorded_inputs
        .iter()
        .map(|series| {
            let trim = trim_samples.map_or(series[0], |n| mean_of_first(series, n));
            series.iter().map(|v| v - trim).collect()
        })
        .collect();
    let mut resets = Vec::new();
    if let Some(segment) = segment_s {
        let length = (segment * record.sample_rate_hz).round() as usize;
        let averaged = trim_samples.unwrap_or_else(|| {
            ((TRIM_AVERAGE_S * record.sample_rate_hz) as usize).clamp(1, record.len())
        });
        let measured_states: Vec<Option<(&[f64], f64)>> = model
            .states
            .iter()
            .map(|name| {
                record
                    .output(name)
                    .map(|series| (series, mean_of_first(series, averaged)))
            })
            .collect();
        for start in (0..record.len()).step_by(length.max(2)) {
            let state = DVector::from_fn(model.states.len(), |i, _| {
                measured_states[i].map_or(0.0, |(series, trim)| series[start] - trim)
            });
            resets.push((start, state));
        }
    }
    let simulated = match simulate_with_resets(model, &inputs, record.sample_rate_hz, &resets) {
        Ok(simulated) => simulated,
        Err(VerifyError::Diverged { sample }) => {
            let outputs = compared
                .iter()
                .map(|(index, series)| OutputScore {
                    output: model.outputs[*index].clone(),
                    bias: trim_samples.map_or(f64::NAN, |n| mean_of_first(series, n)),
                    rms_error: f64::INFINITY,
                    rms_measured: f64::NAN,
                    rms_predicted: f64::INFINITY,
                    theil: 1.0,
                })
                .collect();
            return Ok(Verification {
                source: record.source.clone(),
                sample_rate_hz: record.sample_rate_hz,
                samples: record.len(),
                bias,
                trim_samples: trim_samples.unwrap_or(0),
                outputs,
                not_recorded,
                theil_mean: 1.0,
                diverged_at_s: Some(sample as f64 / record.sample_rate_hz),
                measured: Vec::new(),
                predicted: Vec::new(),
            });
        }
        Err(other) => return Err(other),
    };
    let mut outputs = Vec::with_capacity(compared.len());
    let mut measured = Vec::with_capacity(compared.len());
    let mut predicted = Vec::with_capacity(compared.len());
    for (index, series) in &compared {
        let name = &model.outputs[*index];
        let score = match trim_samples {
            Some(n) => {
                score_output_with_bias(name, series, &simulated[*index], mean_of_first(series, n))
            }
            None => score_output(name, series, &simulated[*index]),
        };
        measured.push(series.iter().map(|y| y - score.bias).collect());
        predicted.push(simulated[*index].clone());
        outputs.push(score);
    }
    let theil_mean = outputs.iter().map(|o| o.theil).sum::<f64>() / outputs.len() as f64;
    Ok(Verification {
        source: record.source.clone(),
        sample_rate_hz: record.sample_rate_hz,
        samples: record.len(),
        bias,
        trim_samples: trim_samples.unwrap_or(0),
        not_recorded,
        outputs,
        theil_mean,
        diverged_at_s: None,
        measured,
        predicted,
    })
}

/// File-name-safe form of a name.
fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// One SVG per compared output, as `(file name, SVG text)`: measured (bias removed) and
/// predicted against time, named `<record stem>-<output>.svg`. The caller writes them
/// (the CLI writes each file whole, atomically).
pub fn render_verification_plots(
    verification: &Verification,
) -> Result<Vec<(String, String)>, VerifyError> {
    let plot_error = |path: &Path, e: &dyn fmt::Display| VerifyError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let stem = Path::new(&verification.source).file_stem().map_or_else(
        || "record".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let mut plots = Vec::new();
    let h = 1.0 / verification.sample_rate_hz;
    for ((score, measured), predicted) in verification
        .outputs
        .iter()
        .zip(&verification.measured)
        .zip(&verification.predicted)
    {
        let name = format!("{}-{}.svg", file_stem(&stem), file_stem(&score.output));
        let path = PathBuf::from(&name);
        let mut svg = String::new();
        let root = SVGBackend::with_string(&mut svg, (1000, 400)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_error(&path, &e))?;
        let (lo, hi) = measured
            .iter()
            .chain(predicted)
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let (lo, hi) = if lo.is_finite() && hi > lo {
            (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
        } else {
            (-1.0, 1.0)
        };
        let end = measured.len().max(2) as f64 * h;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "{}: {} measured vs predicted (TIC {:.3})",
                    stem, score.output, score.theil
                ),
                ("sans-serif", 18),
            )
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..end, lo..hi)
            .map_err(|e| plot_error(&path, &e))?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .y_desc(format!("{} (perturbation)", score.output))
            .draw()
            .map_err(|e| plot_error(&path, &e))?;
        for (series, label, color) in [
            (measured, "measured", BLACK.to_rgba()),
            (predicted, "predicted", RED.to_rgba()),
        ] {
            let points = series.iter().enumerate().map(|(k, v)| (k as f64 * h, *v));
            chart
                .draw_series(LineSeries::new(points, color.stroke_width(1)))
                .map_err(|e| plot_error(&path, &e))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| plot_error(&path, &e))?;
        root.present().map_err(|e| plot_error(&path, &e))?;
        drop(chart);
        drop(root);
        plots.push((name, svg));
    }
    Ok(plots)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frf::records::Channel;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    /// ẋ = −a x + b u(t − τ), y = x (and y2 = ẋ through H1).
    fn lag(a: f64, b: f64, delay: f64) -> Model {
        let mut model = Model::zeros(names(&["x"]), names(&["lat"]), names(&["p", "pdot"]));
        model.m[(0, 0)] = 1.0;
        model.f[(0, 0)] = -a;
        model.g[(0, 0)] = b;
        model.h0[(0, 0)] = 1.0;
        model.h1[(1, 0)] = 1.0;
        model.delays[0] = delay;
        model
    }

    #[test]
    fn ramp_response_is_exact() {
        // u = t: x(t) = (b/a)(t − (1 − e^{−at})/a), ẋ = (b/a)(1 − e^{−at}).
        let (a, b, rate) = (3.0, 2.0, 50.0);
        let times: Vec<f64> = (0..200).map(|k| k as f64 / rate).collect();
        let model = lag(a, b, 0.0);
        let y = simulate(&model, std::slice::from_ref(&times), rate).unwrap();
        for (k, t) in times.iter().enumerate() {
            let x = b / a * (t - (1.0 - (-a * t).exp()) / a);
            let xdot = b / a * (1.0 - (-a * t).exp());
            assert!((y[0][k] - x).abs() < 1e-12, "{k}: {} vs {x}", y[0][k]);
            assert!((y[1][k] - xdot).abs() < 1e-12, "{k}: {} vs {xdot}", y[1][k]);
        }
    }

    #[test]
    fn delay_shifts_by_fractional_samples() {
        let (a, b, rate) = (3.0, 2.0, 50.0);
        let tau = 0.047; // 2.35 samples
        let times: Vec<f64> = (0..200).map(|k| k as f64 / rate).collect();
        let y = simulate(&lag(a, b, tau), std::slice::from_ref(&times), rate).unwrap();
        for (k, t) in times.iter().enumerate() {
            let shifted = (t - tau).max(0.0);
            let x = b / a * (shifted - (1.0 - (-a * shifted).exp()) / a);
            // The delayed ramp is exact except its kink at t = τ, which falls between
            // samples and is smoothed over that interval: the input error there is at
            // most 0.35·0.65·h, worth ≤ b·h·0.23·h ≈ 1.8e-4 of x, decaying with e^{−at}.
            let tolerance = if *t < 1.0 { 2e-4 } else { 1e-5 };
            assert!((y[0][k] - x).abs() < tolerance, "{k}: {} vs {x}", y[0][k]);
        }
        assert_eq!(delayed(&[1.0, 2.0, 3.0], 0.5), vec![0.5, 1.5, 2.5]);
        assert_eq!(delayed(&[1.0, 2.0, 3.0], 1.0), vec![0.0, 1.0, 2.0]);
    }

    fn two_axis_model() -> Model {
        // A lightly damped oscillator and a first-order lag, coupled, with a mass matrix
        // that is not the identity and a delay.
        let mut model = Model::zeros(
            names(&["p", "phi", "q"]),
            names(&["lat", "lon"]),
            names(&["p", "q", "phi", "ay"]),
        );
        model.m = DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5]);
        model.f = DMatrix::from_row_slice(3, 3, &[-2.0, -9.0, 0.3, 1.0, 0.0, 0.0, 0.0, 0.0, -1.5]);
        model.g = DMatrix::from_row_slice(3, 2, &[10.0, 1.0, 0.0, 0.0, 0.5, 4.0]);
        model.h0[(0, 0)] = 1.0;
        model.h0[(1, 2)] = 1.0;
        model.h0[(2, 1)] = 1.0;
        model.h1[(3, 0)] = 0.3;
        model.h0[(3, 1)] = -9.8;
        model.delays = vec![0.02, 0.013];
        model
    }

    fn record_of(model: &Model, noise: f64) -> Record {
        let rate = 100.0;
        let n = 3000;
        let trim = [0.1, -0.2];
        // Perturbations that start at 0, as verify takes them (recorded minus first sample).
        let inputs: Vec<Vec<f64>> = (0..2)
            .map(|j| {
                let raw: Vec<f64> = (0..n)
                    .map(|k| {
                        let t = k as f64 / rate;
                        0.05 * (t * (0.5 + 0.1 * t) + j as f64).sin()
                            + 0.02 * (7.0 * t + 0.3 * j as f64).sin()
                    })
                    .collect();
                raw.iter().map(|v| v - raw[0]).collect()
            })
            .collect();
        let clean = simulate(model, &inputs, rate).unwrap();
        // Deterministic pseudo-noise, scaled to `noise` × RMS.
        let mut random = crate::random::SplitMix64::new(0x9e37_79b9_7f4a_7c15);
        let mut next = || random.symmetric();
        let outputs = model
            .outputs
            .iter()
            .zip(&clean)
            .enumerate()
            .map(|(i, (name, series))| {
                let level = noise * rms(series.iter().copied(), series.len()) * 3f64.sqrt();
                // A trim offset per output, which the bias must absorb.
                let offset = 0.7 * i as f64 - 1.0;
                Channel::new(
                    name.clone(),
                    series.iter().map(|v| v + offset + level * next()).collect(),
                )
            })
            .collect();
        Record {
            source: "synthetic".into(),
            sample_rate_hz: rate,
            primary: "lat".into(),
            primary_guessed: false,
            sweep_band: None,
            inputs: inputs
                .iter()
                .zip(["lat", "lon"])
                .zip(trim)
                .map(|((series, name), t)| {
                    Channel::new(name, series.iter().map(|v| v + t).collect())
                })
                .collect(),
            outputs,
            references: Vec::new(),
            notes: Vec::new(),
            trim_samples: 0,
        }
    }

    /// The verification with the fitted bias, as it was before the trim bias existed.
    fn verify_fitted(model: &Model, record: &Record) -> Result<Verification, VerifyError> {
        verify_record_in_segments(model, record, None, BiasMode::Fitted)
    }

    #[test]
    fn self_generated_data_scores_zero_and_noise_raises_the_tic() {
        let model = two_axis_model();
        let clean_record = record_of(&model, 0.0);
        let exact = verify_fitted(&model, &clean_record).unwrap();
        assert_eq!(exact.outputs.len(), 4);
        for score in &exact.outputs {
            assert!(score.theil < 1e-9, "{}: {}", score.output, score.theil);
            let offset = 0.7 * model.output_index(&score.output).unwrap() as f64 - 1.0;
            assert!((score.bias - offset).abs() < 1e-9, "{score:?}");
        }
        let mut previous = exact.theil_mean;
        for noise in [0.05, 0.2, 0.5] {
            let noisy = verify_fitted(&model, &record_of(&model, noise)).unwrap();
            assert!(
                noisy.theil_mean > previous,
                "noise {noise}: {} after {previous}",
                noisy.theil_mean
            );
            previous = noisy.theil_mean;
        }
        assert!(previous > 0.1 && previous < 1.0, "{previous}");
        // A wrong model scores clearly worse than the right one on clean data.
        let mut wrong = model.clone();
        wrong.g.scale_mut(-1.0);
        let bad = verify_fitted(&wrong, &clean_record).unwrap();
        // (A pure sign flip would give 1; the fitted bias takes out the means.)
        assert!(bad.theil_mean > 0.7, "{}", bad.theil_mean);
    }

    #[test]
    fn segments_restart_an_unstable_model_from_the_measured_state() {
        // The q lag made unstable (pole +0.6 /s): the data come from it, the model to
        // verify has the pole at +0.8 /s. Over the whole 30 s record the small error
        // grows without bound; restarted every 3 s from the measured state it cannot.
        let mut truth = two_axis_model();
        truth.f[(2, 2)] = 0.3; // M[q,q] = 0.5: pole +0.6
        let record = record_of(&truth, 0.0);
        let mut wrong = truth.clone();
        wrong.f[(2, 2)] = 0.4;
        let whole = verify_fitted(&wrong, &record).unwrap();
        let segmented =
            verify_record_in_segments(&wrong, &record, Some(3.0), BiasMode::Fitted).unwrap();
        let q_whole = whole
            .outputs
            .iter()
            .find(|o| o.output == "q")
            .unwrap()
            .theil;
        let q_segmented = segmented
            .outputs
            .iter()
            .find(|o| o.output == "q")
            .unwrap()
            .theil;
        assert!(q_whole > 0.2, "{q_whole}");
        assert!(q_segmented < 0.5 * q_whole, "{q_segmented} vs {q_whole}");
        // The right model restarted from measured states still predicts well (the
        // restarts use trim estimated from the first second, so not exactly).
        let right =
            verify_record_in_segments(&truth, &record, Some(3.0), BiasMode::Fitted).unwrap();
        assert!(right.theil_mean < 0.1, "{}", right.theil_mean);
        let error =
            verify_record_in_segments(&truth, &record, Some(0.001), BiasMode::Fitted).unwrap_err();
        assert!(error.to_string().contains("segment"), "{error}");
    }

    #[test]
    fn mismatches_are_reported() {
        let model = two_axis_model();
        let mut record = record_of(&model, 0.0);
        record.inputs.retain(|c| c.name != "lon");
        let error = verify_fitted(&model, &record).unwrap_err();
        assert!(matches!(error, VerifyError::MissingInput { ref control, .. } if control == "lon"));
        assert!(error.to_string().contains("`lon`"), "{error}");

        let mut record = record_of(&model, 0.0);
        for channel in &mut record.outputs {
            channel.name = format!("other_{}", channel.name);
        }
        let error = verify_fitted(&model, &record).unwrap_err();
        assert!(
            matches!(error, VerifyError::NoCommonOutput { .. }),
            "{error}"
        );

        let mut singular = model.clone();
        singular.m[(2, 2)] = 0.0;
        let error = verify_fitted(&singular, &record_of(&model, 0.0)).unwrap_err();
        assert!(error.to_string().contains("singular"), "{error}");

        let mut short = record_of(&model, 0.0);
        for channel in short.inputs.iter_mut().chain(short.outputs.iter_mut()) {
            channel.values.truncate(1);
        }
        let error = verify_fitted(&model, &short).unwrap_err();
        assert!(matches!(error, VerifyError::BadRecord { .. }), "{error}");

        // A model that runs away is a result (TIC 1 everywhere), not an error.
        let mut unstable = model.clone();
        unstable.f[(2, 2)] = 50.0;
        let result = verify_fitted(&unstable, &record_of(&model, 0.0)).unwrap();
        let at = result.diverged_at_s.expect("diverged");
        assert!(at > 0.0 && at < 30.0, "{at}");
        assert!(result.outputs.iter().all(|o| o.theil == 1.0));
        assert!(result.measured.is_empty());

        // An output missing from the record is listed, not an error.
        let mut partial = record_of(&model, 0.0);
        partial.outputs.retain(|c| c.name != "ay");
        let result = verify_fitted(&model, &partial).unwrap();
        assert_eq!(result.not_recorded, vec!["ay".to_string()]);
        assert_eq!(result.outputs.len(), 3);
    }

    /// Trim samples at 100 Hz in front of the excitation of [`record_with_trim`].
    const TRIM: usize = 150;

    /// `model` flown from trim: `TRIM` samples with the sticks at `stick_trim` (plus
    /// `stick_trim_wobble`, one value per trim sample and control, which the caller keeps at
    /// zero mean), then 28.5 s of excitation; each output is the model's response to the
    /// sticks minus their trim mean, plus the offset 0.7·i − 1 (its trim value). Returns
    /// the record and the perturbation inputs the outputs were simulated with.
    fn record_with_trim(
        model: &Model,
        stick_trim_wobble: &dyn Fn(usize, usize) -> f64,
    ) -> (Record, Vec<Vec<f64>>) {
        let rate = 100.0;
        let n = 3000;
        let stick_trim = [0.1, -0.2];
        let perturbations: Vec<Vec<f64>> = (0..2)
            .map(|j| {
                (0..n)
                    .map(|k| {
                        if k < TRIM {
                            return stick_trim_wobble(k, j);
                        }
                        // Starts at 0 when the excitation starts.
                        let t = (k - TRIM) as f64 / rate;
                        0.05 * (t * (0.5 + 0.1 * t) + j as f64).sin() - 0.05 * (j as f64).sin()
                            + 0.02 * (7.0 * t).sin()
                    })
                    .collect()
            })
            .collect();
        let clean = simulate(model, &perturbations, rate).unwrap();
        let outputs = model
            .outputs
            .iter()
            .zip(&clean)
            .enumerate()
            .map(|(i, (name, series))| {
                let offset = 0.7 * i as f64 - 1.0;
                Channel::new(name.clone(), series.iter().map(|v| v + offset).collect())
            })
            .collect();
        let record = Record {
            source: "trimmed".into(),
            sample_rate_hz: rate,
            primary: "lat".into(),
            primary_guessed: false,
            sweep_band: None,
            inputs: perturbations
                .iter()
                .zip(["lat", "lon"])
                .zip(stick_trim)
                .map(|((series, name), t)| {
                    Channel::new(name, series.iter().map(|v| v + t).collect())
                })
                .collect(),
            outputs,
            references: Vec::new(),
            notes: Vec::new(),
            trim_samples: TRIM,
        };
        (record, perturbations)
    }

    #[test]
    fn the_trim_bias_is_the_mean_before_the_excitation() {
        let model = two_axis_model();
        let (record, _) = record_with_trim(&model, &|_, _| 0.0);
        let exact = verify_record(&model, &record).unwrap();
        assert_eq!(exact.bias, BiasMode::Trim);
        assert_eq!(exact.trim_samples, TRIM);
        assert_eq!(exact.outputs.len(), 4);
        for score in &exact.outputs {
            let offset = 0.7 * model.output_index(&score.output).unwrap() as f64 - 1.0;
            assert!((score.bias - offset).abs() < 1e-12, "{score:?}");
            assert!(score.theil < 1e-9, "{}: {}", score.output, score.theil);
        }
        // The fitted bias finds the same offsets on exact data.
        let fitted = verify_fitted(&model, &record).unwrap();
        assert_eq!(fitted.bias, BiasMode::Fitted);
        assert_eq!(fitted.trim_samples, 0);
        assert!(fitted.theil_mean < 1e-9, "{}", fitted.theil_mean);

        // An error the model makes as a constant during the excitation (here: the
        // measured q settles 0.02 rad/s higher than predicted once the excitation starts).
        // The trim bias counts it; the fitted bias takes most of it out.
        let mut offset_q = record.clone();
        let q = offset_q.outputs.iter_mut().find(|c| c.name == "q").unwrap();
        for value in &mut q.values[TRIM..] {
            *value += 0.02;
        }
        let tic_q = |v: &Verification| v.outputs.iter().find(|o| o.output == "q").unwrap().theil;
        let trim = verify_record(&model, &offset_q).unwrap();
        let fitted = verify_fitted(&model, &offset_q).unwrap();
        assert!(tic_q(&trim) > 0.05, "{}", tic_q(&trim));
        assert!(
            tic_q(&fitted) < 0.5 * tic_q(&trim),
            "{} vs {}",
            tic_q(&fitted),
            tic_q(&trim)
        );
        // The other outputs are untouched either way.
        for v in [&trim, &fitted] {
            for o in v.outputs.iter().filter(|o| o.output != "q") {
                assert!(o.theil < 1e-9, "{o:?}");
            }
        }
    }

    #[test]
    fn inputs_are_taken_from_the_same_trim_as_the_outputs() {
        // The sticks wobble during the trim capture (zero mean): the first sample is
        // 0.01 off the trim. The outputs were simulated on the sticks minus their trim
        // mean, so that is what the model must be driven with.
        let wobble = |k: usize, _: usize| {
            if k == 0 {
                0.01
            } else {
                -0.01 / (TRIM - 1) as f64
            }
        };
        let model = two_axis_model();
        let (record, perturbations) = record_with_trim(&model, &wobble);
        let verification = verify_record(&model, &record).unwrap();
        let expected = simulate(&model, &perturbations, record.sample_rate_hz).unwrap();
        for (score, predicted) in verification.outputs.iter().zip(&verification.predicted) {
            let index = model.output_index(&score.output).unwrap();
            for (a, b) in predicted.iter().zip(&expected[index]) {
                assert!((a - b).abs() < 1e-12, "{}: {a} vs {b}", score.output);
            }
            // The bias is the measured trim mean: the offset plus the (small) response
            // to the wobble over the trim samples; what is left is that constant.
            let offset = 0.7 * index as f64 - 1.0;
            let response = expected[index][..TRIM].iter().sum::<f64>() / TRIM as f64;
            assert!(
                (score.bias - offset - response).abs() < 1e-12,
                "{}: {} vs {}",
                score.output,
                score.bias,
                offset + response
            );
        }
        // Driven from the first sample instead, the model sees a 0.01 step held over the
        // whole record, and misses: the fitted bias (which takes its inputs from there)
        // scores worse although it fits the constant.
        let fitted = verify_fitted(&model, &record).unwrap();
        assert!(
            fitted.theil_mean > 10.0 * verification.theil_mean,
            "{} vs {}",
            fitted.theil_mean,
            verification.theil_mean
        );
    }

    #[test]
    fn the_trim_bias_needs_trim_samples() {
        let model = two_axis_model();
        let record = record_of(&model, 0.0);
        let error = verify_record(&model, &record).unwrap_err();
        assert_eq!(
            error,
            VerifyError::NoTrim {
                source: "synthetic".into()
            }
        );
        assert!(
            error.to_string().starts_with("synthetic: no trim samples"),
            "{error}"
        );
        let mut overlong = record;
        overlong.trim_samples = overlong.len() + 1;
        let error = verify_record(&model, &overlong).unwrap_err();
        assert!(matches!(error, VerifyError::BadRecord { .. }), "{error}");
    }
}
