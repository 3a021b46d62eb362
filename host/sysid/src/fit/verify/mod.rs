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
//! units, so their squares are not pooled). Only measured outputs are scored: a model
//! output the record lacks, or holds as zeros throughout ([`measured_output`]: a board
//! without air data logs u = v = w = 0), is listed as not measured, outside the TICs and
//! their mean.
//!
//! The submodules hold the parts: `simulate` (the discrete model and the simulation),
//! `score` (bias and TIC of one output), `error` ([`VerifyError`]); their items are
//! re-exported here.

use std::fmt;

use nalgebra::DVector;

use super::model::Model;
use crate::records::Record;

mod error;
mod score;
mod simulate;

pub use error::VerifyError;
pub use score::{score_output, score_output_with_bias, OutputScore};
pub use simulate::{delayed, simulate, simulate_with_resets, DiscreteModel};

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

/// Verification of a model on one record.
#[derive(Clone, Debug, PartialEq)]
pub struct Verification {
    /// The record's source.
    pub source: String,
    /// Sample rate \[Hz\].
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
    /// Model outputs the record does not measure ([`measured_output`]): not compared, and
    /// not in [`Self::theil_mean`].
    pub not_measured: Vec<String>,
    /// Mean of the per-output TICs.
    pub theil_mean: f64,
    /// Time \[s\] at which the simulated model overflowed (an unstable model running away):
    /// every output then scores TIC = 1, the worst value (the limit as ŷ → ∞).
    pub diverged_at_s: Option<f64>,
    /// Measured series (with the bias removed), per compared output.
    pub measured: Vec<Vec<f64>>,
    /// Predicted series, per compared output.
    pub predicted: Vec<Vec<f64>>,
}

/// The series of output `name` when `record` measures it: a channel the record holds
/// that is not exactly zero throughout. A logger writes zeros for what its board has no
/// sensor for (a flight controller's u, v, w without air data); no sensor reads exactly
/// 0.0 on every sample of a flight, so such a channel is no measurement to score.
pub fn measured_output<'a>(record: &'a Record, name: &str) -> Option<&'a [f64]> {
    record
        .output(name)
        .filter(|series| series.iter().any(|&value| value != 0.0))
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
                record: record.source.clone(),
                reason: format!("segment of {segment} s is shorter than 2 samples"),
            });
        }
    }
    if !(record.sample_rate_hz.is_finite() && record.sample_rate_hz > 0.0) {
        return Err(VerifyError::BadRecord {
            record: record.source.clone(),
            reason: format!("sample rate {} Hz", record.sample_rate_hz),
        });
    }
    if record.len() < 2 {
        return Err(VerifyError::BadRecord {
            record: record.source.clone(),
            reason: format!("{} samples, need at least 2", record.len()),
        });
    }
    let mut recorded_inputs = Vec::with_capacity(model.controls.len());
    for control in &model.controls {
        let series = record
            .input(control)
            .ok_or_else(|| VerifyError::MissingInput {
                control: control.clone(),
                record: record.source.clone(),
                available: record.inputs.iter().map(|c| c.name.clone()).collect(),
            })?;
        recorded_inputs.push(series);
    }
    let compared: Vec<(usize, &[f64])> = model
        .outputs
        .iter()
        .enumerate()
        .filter_map(|(i, name)| measured_output(record, name).map(|series| (i, series)))
        .collect();
    if compared.is_empty() {
        return Err(VerifyError::NoCommonOutput {
            record: record.source.clone(),
            model_outputs: model.outputs.clone(),
        });
    }
    let not_measured = model
        .outputs
        .iter()
        .filter(|name| measured_output(record, name).is_none())
        .cloned()
        .collect();
    // Samples whose means are the trims (biases), with the trim bias.
    let trim_samples = match bias {
        BiasMode::Fitted => None,
        BiasMode::Trim if record.trim_samples == 0 => {
            return Err(VerifyError::NoTrim {
                record: record.source.clone(),
            })
        }
        BiasMode::Trim if record.trim_samples > record.len() => {
            return Err(VerifyError::BadRecord {
                record: record.source.clone(),
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
                measured_output(record, name)
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
                not_measured,
                theil_mean: 1.0,
                diverged_at_s: Some(sample as f64 / record.sample_rate_hz),
                measured: Vec::new(),
                predicted: Vec::new(),
            });
        }
        Err(other) => return Err(other),
    };
    // The logged outputs went through the flight controller's filter: so do the model's
    // before they are compared (its rate divides the filter's for every board dump; a
    // record where it does not is compared unfiltered).
    let simulated: Vec<Vec<f64>> = match &record.measurement_filter {
        Some(filter) => simulated
            .into_iter()
            .zip(&model.outputs)
            .map(|(series, name)| {
                if filter.acts_on(name) {
                    filter
                        .apply(&series, record.sample_rate_hz)
                        .unwrap_or(series)
                } else {
                    series
                }
            })
            .collect(),
        None => simulated,
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
        not_measured,
        outputs,
        theil_mean,
        diverged_at_s: None,
        measured,
        predicted,
    })
}

#[cfg(test)]
mod tests;
