//! Fit reports: the `model.json` document (layout in `host/sysid/models/README.md`), with
//! its truth section. The text tables `sweephold fit` prints from them are the
//! command-line program's.

use serde::{Deserialize, Serialize};

use super::model::{Actuator, Model, RowMajor};
use super::modes::{ModeRecord, TruthModeRecord};
use super::result::{FitResult, PairFit, ParameterReport, ReductionStep, StartOutcome};

/// Version of the `model.json` layout.
pub const MODEL_DOCUMENT_VERSION: u32 = 1;

/// The matrices of the model, row-major.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelMatrices {
    /// M, states × states.
    #[serde(rename = "M")]
    pub m: RowMajor,
    /// F, states × states.
    #[serde(rename = "F")]
    pub f: RowMajor,
    /// G, states × controls.
    #[serde(rename = "G")]
    pub g: RowMajor,
    /// H0, outputs × states.
    #[serde(rename = "H0")]
    pub h0: RowMajor,
    /// H1, outputs × states.
    #[serde(rename = "H1")]
    pub h1: RowMajor,
}

impl ModelMatrices {
    /// The matrices of `model`.
    pub fn from_model(model: &Model) -> ModelMatrices {
        ModelMatrices {
            m: RowMajor::from_matrix(&model.m),
            f: RowMajor::from_matrix(&model.f),
            g: RowMajor::from_matrix(&model.g),
            h0: RowMajor::from_matrix(&model.h0),
            h1: RowMajor::from_matrix(&model.h1),
        }
    }

    /// The numeric model with these names, delays and actuators (empty: none); `None`
    /// when a matrix does not fit the names, the delays or actuators do not match the
    /// controls, or an actuator is not valid.
    pub fn to_model(
        &self,
        states: &[String],
        controls: &[String],
        outputs: &[String],
        delays: &[f64],
        actuators: &[Option<Actuator>],
    ) -> Option<Model> {
        let (n, m, p) = (states.len(), controls.len(), outputs.len());
        let sized = |matrix: &RowMajor, rows: usize, cols: usize| {
            (matrix.rows == rows && matrix.cols == cols)
                .then(|| matrix.to_matrix())
                .flatten()
        };
        (delays.len() == m).then_some(())?;
        let actuators = match actuators.len() {
            0 => vec![None; m],
            k if k == m && actuators.iter().flatten().all(Actuator::is_valid) => actuators.to_vec(),
            _ => return None,
        };
        Some(Model {
            actuators,
            m: sized(&self.m, n, n)?,
            f: sized(&self.f, n, n)?,
            g: sized(&self.g, n, m)?,
            h0: sized(&self.h0, p, n)?,
            h1: sized(&self.h1, p, n)?,
            delays: delays.to_vec(),
            states: states.to_vec(),
            controls: controls.to_vec(),
            outputs: outputs.to_vec(),
        })
    }
}

/// The correlation matrix of the free parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CorrelationMatrix {
    /// Free-parameter names: rows and columns, in order.
    pub names: Vec<String>,
    /// Coefficients, row-major, names.len()².
    pub values: Vec<f64>,
}

/// The `model.json` document `sweephold fit --out` writes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelDocument {
    /// Layout version ([`MODEL_DOCUMENT_VERSION`]).
    pub version: u32,
    /// Structure name.
    pub structure: String,
    /// Structure description.
    pub description: String,
    /// State names.
    pub states: Vec<String>,
    /// Control names.
    pub controls: Vec<String>,
    /// Output names.
    pub outputs: Vec<String>,
    /// M F G H0 H1, row-major.
    pub matrices: ModelMatrices,
    /// Delay per control \[s\], in `controls` order.
    pub delays: Vec<f64>,
    /// Known actuator per control, in `controls` order (`null`: none); left out when no
    /// control has one.
    #[serde(default, skip_serializing_if = "no_actuators")]
    pub actuators: Vec<Option<Actuator>>,
    /// Base parameters in structure order, then constrained ones.
    pub parameters: Vec<ParameterReport>,
    /// J per pair.
    pub pairs: Vec<PairFit>,
    /// Mean J over the pairs.
    pub average_cost: f64,
    /// Correlation of the free parameters; null when the Hessian is singular.
    pub correlation: Option<CorrelationMatrix>,
    /// Every optimizer start.
    pub starts: Vec<StartOutcome>,
    /// Whether two starts reached the best minimum.
    pub minimum_confirmed: bool,
    /// Reduction steps (empty without `--reduce`).
    pub reduction: Vec<ReductionStep>,
    /// `auto` pairs left out of the fit, and why.
    #[serde(default)]
    pub skipped_pairs: Vec<super::result::SkippedPair>,
    /// Parameters derived from trim points (absent without them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trim: Option<super::trim::TrimOutcome>,
    /// Parameters held at the structure file's values because a degenerate minimum put them
    /// outside their physical range, with the values it gave them ([`super::plausible`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub implausible_held: Vec<super::plausible::HeldParameter>,
    /// Parameters this model keeps outside their physical range (a degenerate minimum
    /// written as it is, never as a usable model: the campaign's 6-DOF start, which
    /// only starts the hybrid; [`super::plausible`]). Left out when there are none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outside_physical_range: Vec<super::plausible::HeldParameter>,
    /// Why this model is degenerate ([`super::degenerate`]): parameters outside their
    /// physical range or free parameters on a range bound of the structure file, after
    /// the fit's restarts elsewhere. Never a usable model; left out when there are none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub degenerate: Vec<super::degenerate::DegenerateReason>,
    /// The seeds of the searches the fit ran again because its minimum was degenerate
    /// ([`super::degenerate`]); left out when there were none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub degenerate_restarts: Vec<u64>,
}

/// `model.json` with its optional `truth` section and the model's `modes`: the
/// [`ModelDocument`] keys at the top level plus `"truth"` when the fit was scored against
/// a simulator (`sweephold fit --truth`) and `"modes"` (absent from files written before
/// it existed: read as empty). A [`ModelDocument`] reads such a file too (it ignores the
/// extra keys); the sections are kept apart so that existing code building a
/// `ModelDocument` is unaffected.
///
/// Deserialization goes through a `serde_json::Value` rather than `#[serde(flatten)]`:
/// flatten buffers the numbers in serde's internal `Content`, which cannot hold
/// serde_json's arbitrary-precision numbers — a feature another crate of the same build
/// (defmt-decoder) switches on for everyone.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScoredModelDocument {
    /// The model document.
    #[serde(flatten)]
    pub model: ModelDocument,
    /// Scoring against a simulator's truth; absent without `--truth`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth: Option<TruthSection>,
    /// The modes of the model (eigenvalues of M⁻¹F, named: [`super::modes`]), each with
    /// its truth mode and error when scored against a truth.
    #[serde(default)]
    pub modes: Vec<ModeRecord>,
}

impl<'de> Deserialize<'de> for ScoredModelDocument {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut value = serde_json::Value::deserialize(deserializer)?;
        let truth = match value.as_object_mut().and_then(|map| map.remove("truth")) {
            None | Some(serde_json::Value::Null) => None,
            Some(section) => Some(serde_json::from_value(section).map_err(D::Error::custom)?),
        };
        let modes = match value.as_object_mut().and_then(|map| map.remove("modes")) {
            None | Some(serde_json::Value::Null) => Vec::new(),
            Some(list) => serde_json::from_value(list).map_err(D::Error::custom)?,
        };
        let model = serde_json::from_value(value).map_err(D::Error::custom)?;
        Ok(ScoredModelDocument {
            model,
            truth,
            modes,
        })
    }
}

/// One parameter compared with the value the simulator's linearization implies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthParameter {
    /// Parameter name.
    pub name: String,
    /// Identified value.
    pub value: f64,
    /// Truth value; null when the truth mapping does not know the parameter.
    pub truth: Option<f64>,
    /// 100·(value − truth)/|truth|; null without a (non-zero) truth.
    pub error_percent: Option<f64>,
}

/// The `truth` section of `model.json`: the fit scored against a simulator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthSection {
    /// Simulated vehicle (`bo105`, `trex700l`), linearized at hover trim.
    pub vehicle: String,
    /// Every parameter of the fit with its truth and error.
    pub parameters: Vec<TruthParameter>,
    /// J against the truth model per fitted pair.
    pub pairs: Vec<PairFit>,
    /// Mean of the pair costs.
    pub average_cost: f64,
    /// Structure parameters the truth mapping does not know (held at 0 in the truth model).
    #[serde(default)]
    pub unmapped: Vec<String>,
    /// The truth model's modes, each with the identified mode paired with it
    /// ([`super::modes::compare_modes`]); empty in files written before it existed.
    #[serde(default)]
    pub modes: Vec<TruthModeRecord>,
}

fn finite(value: Option<f64>) -> Option<f64> {
    value.filter(|v| v.is_finite())
}

impl FitResult {
    /// The `model.json` form.
    pub fn to_document(&self) -> ModelDocument {
        ModelDocument::from_result(self)
    }
}

impl ModelDocument {
    /// The document of a fit result.
    pub fn from_result(result: &FitResult) -> Self {
        let model = &result.model;
        let correlation_values: Vec<f64> = RowMajor::from_matrix(&result.correlation).data;
        Self {
            version: MODEL_DOCUMENT_VERSION,
            structure: result.structure.name.clone(),
            description: result.structure.description.clone(),
            states: model.states.clone(),
            controls: model.controls.clone(),
            outputs: model.outputs.clone(),
            matrices: ModelMatrices::from_model(model),
            delays: model.delays.clone(),
            actuators: model.actuators.clone(),
            parameters: result
                .parameters
                .iter()
                .map(|p| ParameterReport {
                    cramer_rao_percent: finite(p.cramer_rao_percent),
                    insensitivity_percent: finite(p.insensitivity_percent),
                    ..p.clone()
                })
                .collect(),
            pairs: result.pairs.clone(),
            average_cost: result.average_cost,
            correlation: (!result.hessian_singular
                && correlation_values.iter().all(|v| v.is_finite()))
            .then(|| CorrelationMatrix {
                names: result.correlation_names.clone(),
                values: correlation_values,
            }),
            starts: result.starts.clone(),
            minimum_confirmed: result.minimum_confirmed,
            reduction: result.reduction.clone(),
            skipped_pairs: result.skipped_pairs.clone(),
            trim: result.trim.clone(),
            implausible_held: result.implausible_held.clone(),
            degenerate: result.degenerate.clone(),
            degenerate_restarts: result.degenerate_restarts.clone(),
            outside_physical_range: Vec::new(),
        }
    }

    /// Value of a parameter by name.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    }

    /// The numeric model; `None` when a matrix has the wrong size.
    pub fn model(&self) -> Option<Model> {
        self.matrices.to_model(
            &self.states,
            &self.controls,
            &self.outputs,
            &self.delays,
            &self.actuators,
        )
    }
}

/// Whether no control has an actuator (the field is then left out of the JSON).
pub fn no_actuators(actuators: &[Option<Actuator>]) -> bool {
    actuators.iter().all(Option::is_none)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::test_support::*;
    use crate::fit::{fit, AccuracyFlag, FitOptions};

    #[test]
    fn document_round_trips_through_json_and_rebuilds_the_model() {
        let structure = first_order_structure();
        let document_data = synthetic_document(
            &structure.model(&structure.values()).unwrap(),
            &structure,
            40,
        );
        let result = fit(&structure, &document_data, &FitOptions::default()).unwrap();
        let document = result.to_document();
        let json = serde_json::to_string_pretty(&document).unwrap();
        let back: ModelDocument = serde_json::from_str(&json).unwrap();
        assert_eq!(back.parameters.len(), document.parameters.len());
        assert_eq!(back.model().unwrap(), result.model);
        assert_eq!(back.parameter("b"), result.parameter("b"));
        let correlation = back.correlation.unwrap();
        assert_eq!(correlation.values.len(), correlation.names.len().pow(2));
    }

    #[test]
    fn scored_document_with_flags_round_trips_under_arbitrary_precision() {
        // This test crate builds serde_json with `arbitrary_precision` (dev-dependency),
        // as the `sweephold` binary does: flatten and internal tagging broke there.
        let structure = first_order_structure();
        let data = synthetic_document(
            &structure.model(&structure.values()).unwrap(),
            &structure,
            20,
        );
        let result = fit(&structure, &data, &FitOptions::default()).unwrap();
        let mut model = result.to_document();
        model.parameters[0].flags = vec![
            AccuracyFlag::CramerRao,
            AccuracyFlag::Insensitive,
            AccuracyFlag::Correlated {
                with: "b".into(),
                correlation: -0.93,
            },
        ];
        let truth = TruthSection {
            vehicle: "bo105".into(),
            parameters: vec![TruthParameter {
                name: "a".into(),
                value: -1.0,
                truth: Some(-1.1),
                error_percent: Some(9.09),
            }],
            pairs: Vec::new(),
            average_cost: 0.5,
            unmapped: Vec::new(),
            modes: vec![TruthModeRecord {
                name: "heave".into(),
                eigenvalue: [-0.5, 0.0],
                omega_n: Some(0.5),
                zeta: None,
                hover: true,
                identified: Some([-0.25, 0.0]),
                identified_name: Some("heave".into()),
                error_percent: Some(50.0),
            }],
        };
        let modes = crate::fit::modes::mode_records(&result.model).unwrap();
        assert_eq!(modes.len(), 1);
        for truth in [Some(truth), None] {
            let document = ScoredModelDocument {
                model: model.clone(),
                truth,
                modes: modes.clone(),
            };
            let json = serde_json::to_string_pretty(&document).unwrap();
            assert!(json.contains(r#""flag": "correlated""#), "{json}");
            // serde_json's default float parser may miss by one ulp (no `float_roundtrip`),
            // so numbers are compared to 1e-14, everything else exactly.
            let close = |a: &ModelDocument, b: &ModelDocument| {
                a.parameters.iter().zip(&b.parameters).all(|(x, y)| {
                    x.name == y.name
                        && x.flags == y.flags
                        && (x.value - y.value).abs() <= 1e-14 * y.value.abs()
                        && x.cramer_rao_percent
                            .zip(y.cramer_rao_percent)
                            .is_none_or(|(x, y)| (x - y).abs() <= 1e-14 * y.abs())
                }) && a.model().is_some()
                    && a.structure == b.structure
            };
            let back: ScoredModelDocument = serde_json::from_str(&json).unwrap();
            assert!(close(&back.model, &model));
            assert_eq!(back.truth, document.truth);
            assert_eq!(back.modes.len(), 1);
            assert_eq!(back.modes[0].name, modes[0].name);
            let plain: ModelDocument = serde_json::from_str(&json).unwrap();
            assert!(close(&plain, &model));
            // A file written before `modes` and the truth's modes existed still reads.
            let mut older: serde_json::Value = serde_json::from_str(&json).unwrap();
            let map = older.as_object_mut().unwrap();
            map.remove("modes");
            if let Some(section) = map.get_mut("truth") {
                section.as_object_mut().unwrap().remove("modes");
            }
            let back: ScoredModelDocument = serde_json::from_value(older).unwrap();
            assert!(back.modes.is_empty());
            assert!(back.truth.is_none_or(|t| t.modes.is_empty()));
        }
        let unknown = r#"{"flag": "bogus"}"#;
        assert!(serde_json::from_str::<AccuracyFlag>(unknown).is_err());
    }
}
