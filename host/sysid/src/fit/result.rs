//! What a fit produces: the fitted model with a report per parameter (value, status,
//! Cramér–Rao bound, insensitivity, guideline flags), the cost per pair, every start of
//! the optimizer, the steps of the reduction and the pairs left out. Its `model.json`
//! form is [`super::report`]'s.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::accuracy::{self, AccuracyAnalysis};
use super::cost::PairBand;
use super::model::Model;
use super::options::FitOptions;
use super::structure::{ModelStructure, ParameterKind};
use super::trim;

/// How a parameter entered the fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ParameterStatus {
    /// Identified.
    Free,
    /// Held at its value (by the file, or dropped by the reduction at zero).
    Fixed,
    /// Derived from trim points and held ([`trim`]).
    Trim,
    /// A linear expression of other parameters.
    Constrained,
}

/// A warning on an identified parameter (guidelines of the paper and Tischler & Remple).
/// In JSON: `{"flag": "cramer_rao"}`, `{"flag": "insensitive"}`,
/// `{"flag": "correlated", "with": "Lp", "correlation": 0.93}`,
/// `{"flag": "needed", "reason": "…"}` — read and written through
/// [`FlagRecord`], not serde's internal tagging, whose buffering cannot hold serde_json's
/// arbitrary-precision numbers (switched on by another crate of the build).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(into = "FlagRecord", try_from = "FlagRecord")]
pub enum AccuracyFlag {
    /// Cramér–Rao bound above the limit (20 %).
    CramerRao,
    /// Insensitivity above the limit (10 %).
    Insensitive,
    /// |correlation| with another parameter above the limit (0.9).
    Correlated {
        /// The other parameter.
        with: String,
        /// The correlation coefficient.
        correlation: f64,
    },
    /// Kept above the Cramér–Rao or insensitivity guideline because the reduction found
    /// the fit needs it: dropping it raised J_ave too much, moved a hover mode, slid into
    /// another minimum or left no usable model. Shown beside the guideline flags it
    /// excuses (the paper keeps L_f(β1c) that way).
    Needed {
        /// Why, from the reduction step that restored it, e.g. `moves the heave mode
        /// −0.309 → −0.0012`.
        reason: String,
    },
}

impl AccuracyFlag {
    /// Whether this flag is a guideline violation (Cramér–Rao or insensitivity).
    pub fn is_guideline_violation(&self) -> bool {
        matches!(self, AccuracyFlag::CramerRao | AccuracyFlag::Insensitive)
    }
}

/// The JSON form of an [`AccuracyFlag`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FlagRecord {
    /// `cramer_rao`, `insensitive` or `correlated`.
    pub flag: String,
    /// The other parameter (`correlated` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub with: Option<String>,
    /// The correlation coefficient (`correlated` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correlation: Option<f64>,
    /// Why the fit needs the parameter (`needed` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

impl From<AccuracyFlag> for FlagRecord {
    fn from(flag: AccuracyFlag) -> FlagRecord {
        let (name, with, correlation, reason) = match flag {
            AccuracyFlag::CramerRao => ("cramer_rao", None, None, None),
            AccuracyFlag::Insensitive => ("insensitive", None, None, None),
            AccuracyFlag::Correlated { with, correlation } => {
                ("correlated", Some(with), Some(correlation), None)
            }
            AccuracyFlag::Needed { reason } => ("needed", None, None, Some(reason)),
        };
        FlagRecord {
            flag: name.to_string(),
            with,
            correlation,
            reason,
        }
    }
}

impl TryFrom<FlagRecord> for AccuracyFlag {
    type Error = String;

    fn try_from(record: FlagRecord) -> Result<AccuracyFlag, String> {
        match (record.flag.as_str(), record.with, record.correlation) {
            ("cramer_rao", _, _) => Ok(AccuracyFlag::CramerRao),
            ("insensitive", _, _) => Ok(AccuracyFlag::Insensitive),
            ("correlated", Some(with), Some(correlation)) => {
                Ok(AccuracyFlag::Correlated { with, correlation })
            }
            ("correlated", _, _) => {
                Err("a `correlated` flag needs `with` and `correlation`".into())
            }
            ("needed", _, _) => Ok(AccuracyFlag::Needed {
                reason: record.reason.unwrap_or_default(),
            }),
            (other, _, _) => Err(format!("unknown accuracy flag `{other}`")),
        }
    }
}

/// One parameter of the fitted model, as reported and as written in `model.json`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ParameterReport {
    /// Engineering name.
    pub name: String,
    /// Value (SI, controls per unit stick fraction).
    pub value: f64,
    /// Free, fixed or constrained.
    pub status: ParameterStatus,
    /// Cramér–Rao bound in % of |value| (free parameters only; null in `model.json`
    /// when infinite).
    pub cramer_rao_percent: Option<f64>,
    /// Insensitivity in % of |value| (free parameters only; null in `model.json` when
    /// infinite).
    pub insensitivity_percent: Option<f64>,
    /// Guideline violations.
    pub flags: Vec<AccuracyFlag>,
    /// The structure's prior of the parameter (value ± σ), when it has one; absent in
    /// `model.json` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prior: Option<super::prior::Prior>,
}

/// The cost of one pair at the fitted model.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairFit {
    /// Control name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Range fitted [rad/s].
    pub range: [f64; 2],
    /// J of the pair.
    pub cost: f64,
}

/// What one start of the optimizer reached.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StartOutcome {
    /// J_ave at the end of the run (None when the start could not be evaluated).
    pub average_cost: Option<f64>,
    /// Iterations used.
    pub iterations: usize,
    /// Why it stopped (debug form of [`StopReason`]), or the error.
    ///
    /// [`StopReason`]: super::StopReason
    pub stop: String,
}

/// Everything a fit produces.
#[derive(Clone, Debug, PartialEq)]
pub struct FitResult {
    /// The structure with the fitted values as its values (and, after a reduction, the
    /// dropped parameters fixed at zero).
    pub structure: ModelStructure,
    /// Base-parameter values (free and fixed), in structure order.
    pub values: Vec<f64>,
    /// The fitted numeric model.
    pub model: Model,
    /// Base parameters in structure order, then the constrained ones.
    pub parameters: Vec<ParameterReport>,
    /// J per pair.
    pub pairs: Vec<PairFit>,
    /// J_ave: mean J over the pairs.
    pub average_cost: f64,
    /// Free-parameter names: the rows/columns of `correlation`.
    pub correlation_names: Vec<String>,
    /// Correlation matrix of the free parameters (NaN when the Hessian is singular).
    pub correlation: DMatrix<f64>,
    /// True when the Hessian could not be inverted.
    pub hessian_singular: bool,
    /// Every start tried, in order.
    pub starts: Vec<StartOutcome>,
    /// True when two starts reached the best minimum.
    pub minimum_confirmed: bool,
    /// Reduction steps (empty without `reduce`).
    pub reduction: Vec<ReductionStep>,
    /// `auto` pairs left out because their data support no usable range.
    pub skipped_pairs: Vec<SkippedPair>,
    /// What the trim points gave (None without trim points or `trim_derived`).
    pub trim: Option<trim::TrimOutcome>,
    /// Parameters a degenerate minimum put outside their physical range, with the values
    /// it gave them; the fit was repeated with them held at the structure file's values
    /// ([`super::plausible`]; empty when none).
    pub implausible_held: Vec<super::plausible::HeldParameter>,
    /// Why the model is degenerate ([`super::degenerate`]), after the fit's restarts
    /// elsewhere and recovery: empty for a model that is not.
    pub degenerate: Vec<super::degenerate::DegenerateReason>,
    /// The restarts elsewhere the fit made because its minimum was degenerate: the
    /// seeds of the searches run again, in order (empty when none was needed).
    pub degenerate_restarts: Vec<u64>,
    /// The trim balances' share of the cost, Σ e² ([`trim::joint`]; 0 when the cost does
    /// not carry them).
    pub balance_cost: f64,
}

impl FitResult {
    /// What the fit minimised, per pair: J_ave plus the trim balances' and the priors'
    /// shares ([`Self::balance_cost`], [`Self::prior_cost`]) over the number of pairs.
    /// J_ave without them.
    pub fn objective(&self) -> f64 {
        let extra = self.balance_cost + self.prior_cost();
        if extra == 0.0 || self.pairs.is_empty() {
            self.average_cost
        } else {
            self.average_cost + extra / self.pairs.len() as f64
        }
    }

    /// The priors' share of the cost, Σ ((θ − θ_p)/σ)² over the free parameters with a
    /// prior ([`super::prior`]; 0 without).
    pub fn prior_cost(&self) -> f64 {
        super::prior::cost(&self.structure, &self.values)
    }

    /// Value of a parameter (base or constrained) by name.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    }

    /// The pairs and ranges fitted, e.g. to score the model against a truth model with
    /// [`cost_between_models`].
    ///
    /// [`cost_between_models`]: super::cost_between_models
    pub fn bands(&self) -> Vec<PairBand> {
        self.pairs
            .iter()
            .map(|pair| PairBand {
                input: pair.input.clone(),
                output: pair.output.clone(),
                range: pair.range,
            })
            .collect()
    }
}

/// One reduction step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReductionStep {
    /// The parameter fixed at zero.
    pub dropped: String,
    /// Why it was chosen, e.g. `insensitivity 35.2 %`.
    pub reason: String,
    /// J_ave before the step.
    pub average_cost_before: f64,
    /// J_ave after refitting without the parameter; infinite (`null` in JSON) when the
    /// model without it cannot be evaluated or is no state-space model (M singular).
    #[serde(with = "infinite_as_null")]
    pub average_cost_after: f64,
    /// Whether the smaller model was kept.
    pub accepted: bool,
    /// The refit moved another parameter by more than
    /// [`FitOptions::reduce_max_shift_cramer_rao`] of its Cramér–Rao bounds (so the step
    /// was undone whatever its cost; the reason names the parameter).
    #[serde(default)]
    pub left_the_minimum: bool,
    /// The refit moved a hover mode beyond
    /// [`FitOptions::reduce_max_hover_mode_shift_percent`] or added a pole at the origin
    /// (so the step was undone whatever its cost): which mode, from where to where.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moved_hover_mode: Option<String>,
    /// The refit moved a remaining parameter that it identifies within the Cramér–Rao
    /// guideline by more than [`FitOptions::reduce_max_shift_percent`] of its value (so
    /// the step was undone whatever its cost: that parameter made up for the dropped
    /// one): which, from where to where.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compensated_by: Option<String>,
}

impl ReductionStep {
    /// Why an undone step's parameter is needed, in words (None for an accepted step).
    pub fn needed_because(&self) -> Option<String> {
        if self.accepted {
            return None;
        }
        Some(if let Some(mode) = &self.moved_hover_mode {
            format!("without it the refit {mode}")
        } else if let Some(compensation) = &self.compensated_by {
            format!("without it the refit moves {compensation} to make up for it")
        } else if self.left_the_minimum {
            "without it the refit leaves the minimum".to_string()
        } else if self.average_cost_after.is_finite() {
            format!(
                "without it J_ave rises {:.2} -> {:.2}",
                self.average_cost_before, self.average_cost_after
            )
        } else {
            "without it the model is unusable".to_string()
        })
    }
}

/// JSON has no infinity: a non-finite J is written as `null` and read back as +∞
/// (serde_json would write `null` and then refuse to read it back into an f64).
mod infinite_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(value: &f64, serializer: S) -> Result<S::Ok, S::Error> {
        if value.is_finite() {
            serializer.serialize_f64(*value)
        } else {
            serializer.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(deserializer)?.unwrap_or(f64::INFINITY))
    }
}

/// A pair of the structure left out of the fit, and why.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SkippedPair {
    /// Control name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Line of the pair in the structure file.
    pub line: usize,
    /// Why it was left out.
    pub reason: String,
}

/// The cost a start set reached in [`fit_from_alternative_starts`], before reduction.
///
/// [`fit_from_alternative_starts`]: super::fit_from_alternative_starts
#[derive(Clone, Debug, PartialEq)]
pub struct StartSetOutcome {
    /// What the caller called this start set (e.g. "6-DOF model", "structure file").
    pub label: String,
    /// J_ave of its best start, or the error that stopped it.
    pub average_cost: Result<f64, String>,
}

/// The report of every parameter at `values`: the free ones (`free`, in order) with their
/// accuracy from `analysis` and the guideline flags `options` sets, then the fixed and
/// trim-derived ones, then the constrained ones.
pub(super) fn parameter_reports(
    structure: &ModelStructure,
    values: &[f64],
    free: &[usize],
    analysis: &AccuracyAnalysis,
    options: &FitOptions,
) -> Vec<ParameterReport> {
    let mut reports: Vec<ParameterReport> = structure
        .parameters
        .iter()
        .enumerate()
        .map(|(index, parameter)| {
            let value = values[index];
            match free.iter().position(|&i| i == index) {
                Some(k) => {
                    let accuracy = analysis.parameters[k];
                    let cramer_rao = accuracy::percent_of(accuracy.cramer_rao, value);
                    let insensitivity = accuracy::percent_of(accuracy.insensitivity, value);
                    let mut flags = Vec::new();
                    if cramer_rao.is_nan() || cramer_rao > options.cramer_rao_limit_percent {
                        flags.push(AccuracyFlag::CramerRao);
                    }
                    if insensitivity.is_nan() || insensitivity > options.insensitivity_limit_percent
                    {
                        flags.push(AccuracyFlag::Insensitive);
                    }
                    for (other, &other_index) in free.iter().enumerate() {
                        let rho = analysis.correlation[(k, other)];
                        if other != k && rho.abs() > options.correlation_limit {
                            flags.push(AccuracyFlag::Correlated {
                                with: structure.parameters[other_index].name.clone(),
                                correlation: rho,
                            });
                        }
                    }
                    ParameterReport {
                        name: parameter.name.clone(),
                        value,
                        status: ParameterStatus::Free,
                        cramer_rao_percent: Some(cramer_rao),
                        insensitivity_percent: Some(insensitivity),
                        flags,
                        prior: parameter.prior,
                    }
                }
                None => ParameterReport {
                    name: parameter.name.clone(),
                    value,
                    status: if parameter.kind == ParameterKind::Trim {
                        ParameterStatus::Trim
                    } else {
                        ParameterStatus::Fixed
                    },
                    cramer_rao_percent: None,
                    insensitivity_percent: None,
                    flags: Vec::new(),
                    prior: parameter.prior,
                },
            }
        })
        .collect();
    reports.extend(structure.derived.iter().map(|derived| ParameterReport {
        name: derived.name.clone(),
        value: derived.expression.evaluate(values),
        status: ParameterStatus::Constrained,
        cramer_rao_percent: None,
        insensitivity_percent: None,
        flags: Vec::new(),
        prior: None,
    }));
    reports
}
