//! The truth stage: the final fit scored against the simulator's linearization at hover —
//! `truth-model9.json`, the truth section of `model9.json`, and the truth figures of the
//! summary's `fit` section.

use crate::mode_text::hover_summary;
use sysid::fit::report::ScoredModelDocument;
use sysid::fit::FitResult;

use super::Campaign;
use crate::artifacts::aircraft_constants::write_model;
use crate::artifacts::files;
use crate::artifacts::truth_model::TruthModelDocument;
use crate::identify::stages::speed_derivatives;
use crate::output::write_json;

impl Campaign<'_> {
    /// The truth stage for the final fit `nine`.
    pub(super) fn score(&mut self, nine: &FitResult) -> anyhow::Result<((), String)> {
        let vehicle = &self.args.vehicle;
        let truth = truth::VehicleTruth::at_hover(vehicle.aircraft())?;
        let scored = truth::score_fit_with_modes(nine, &truth)?;
        let (section, mapped) = (scored.section, scored.mapped);
        write_json(
            &self.dir().join(files::TRUTH_MODEL_9DOF),
            &TruthModelDocument::new(vehicle.name(), &nine.structure.name, &mapped.model),
        )?;
        let modes_line = match &scored.modes {
            Ok(compared) => hover_summary(&compared.hover, compared.poles_at_origin),
            // Reported, not fatal: the model and its scoring are still worth the report.
            Err(error) => format!("modes not computed: {error}"),
        };
        let line = format!(
            "J_ave against the truth {:.1}; {modes_line}",
            section.average_cost
        );
        if let Some(fit) = self.summary.fit.as_mut() {
            match &scored.modes {
                Ok(compared) => {
                    fit.modes = compared.identified.clone();
                    fit.truth_modes = compared.truth.clone();
                    fit.hover_modes_matched = Some(compared.hover);
                    fit.poles_at_origin = Some(compared.poles_at_origin);
                }
                Err(_) => {
                    fit.modes.clear();
                    fit.truth_modes.clear();
                    fit.hover_modes_matched = None;
                    fit.poles_at_origin = None;
                }
            }
            fit.truth_cost_ave = Some(section.average_cost);
            fit.speed_derivatives = speed_derivatives(&nine.model, Some(&mapped.model));
            for pair in &mut fit.pairs {
                pair.truth_cost = section
                    .pairs
                    .iter()
                    .find(|t| t.input == pair.input && t.output == pair.output)
                    .map(|t| t.cost);
            }
            for param in &mut fit.params {
                if let Some(t) = section.parameters.iter().find(|t| t.name == param.name) {
                    param.truth = t.truth;
                    param.error_percent = t.error_percent;
                }
            }
        }
        let document = ScoredModelDocument {
            model: nine.to_document(),
            truth: Some(section),
            modes: scored
                .modes
                .map(|compared| compared.identified)
                .unwrap_or_default(),
        };
        write_model(
            &self.dir().join(files::MODEL_9DOF),
            &document,
            &self.args.priors_vehicle().file_constants()?,
        )?;
        Ok(((), line))
    }
}
