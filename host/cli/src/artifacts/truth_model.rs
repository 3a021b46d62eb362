//! `truth-model9.json`: the final structure evaluated at the simulator's truth values (the
//! "truth model" J is measured against), so that the report can draw the truth's Bode
//! curves from the campaign folder alone.

use serde::{Deserialize, Serialize};
use sysid::fit::model::Actuator;
use sysid::fit::report::{no_actuators, ModelMatrices};
use sysid::fit::Model;

/// A truth model on file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthModelDocument {
    /// Vehicle linearized (at hover trim).
    pub vehicle: String,
    /// Structure evaluated at the truth values.
    pub structure: String,
    /// State names.
    pub states: Vec<String>,
    /// Control names.
    pub controls: Vec<String>,
    /// Output names.
    pub outputs: Vec<String>,
    /// M F G H0 H1, row-major.
    pub matrices: ModelMatrices,
    /// Delay per control \[s\].
    pub delays: Vec<f64>,
    /// Known actuator per control (as `model.json`'s; left out when none has one).
    #[serde(default, skip_serializing_if = "no_actuators")]
    pub actuators: Vec<Option<Actuator>>,
}

impl TruthModelDocument {
    /// The document of `model`.
    pub fn new(vehicle: &str, structure: &str, model: &Model) -> Self {
        TruthModelDocument {
            vehicle: vehicle.to_string(),
            structure: structure.to_string(),
            states: model.states.clone(),
            controls: model.controls.clone(),
            outputs: model.outputs.clone(),
            matrices: ModelMatrices::from_model(model),
            delays: model.delays.clone(),
            actuators: model.actuators.clone(),
        }
    }

    /// The numeric model; `None` when a matrix does not fit the names.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_through_json() {
        let mut model = Model::zeros(vec!["p".into()], vec!["lat".into()], vec!["p".into()]);
        model.m[(0, 0)] = 1.0;
        model.f[(0, 0)] = -2.0;
        model.g[(0, 0)] = 3.0;
        model.h0[(0, 0)] = 1.0;
        model.delays[0] = 0.05;
        let document = TruthModelDocument::new("bo105", "lag", &model);
        let text = serde_json::to_string(&document).unwrap();
        let back: TruthModelDocument = serde_json::from_str(&text).unwrap();
        let again = back.model().unwrap();
        assert_eq!(again.f, model.f);
        assert_eq!(again.delays, model.delays);
        let mut broken = back;
        broken.delays.clear();
        assert!(broken.model().is_none());
    }
}
