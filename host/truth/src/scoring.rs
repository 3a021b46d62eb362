//! A fit scored against the simulator's truth: each parameter against its truth value,
//! J per fitted pair against the structure's truth model, and the modes paired.

use sysid::fit::modes::{compare_modes, ModeComparison, ModeError};
use sysid::fit::report::{TruthParameter, TruthSection};
use sysid::fit::PairFit;
use sysid::fit::{cost_between_models, FitResult, ModelComparison};

use crate::structure_truth::{structure_truth, StructureTruth};
use crate::vehicle_truth::VehicleTruth;
use crate::Error;

/// Fit points per pair when an identified model is scored against the truth (n_ω).
pub const TRUTH_POINTS_PER_PAIR: usize = 20;

/// A fit scored against the simulator's truth, everything [`score_fit_with_modes`] finds.
#[derive(Clone, Debug)]
pub struct ScoredFit {
    /// The `truth` section of `model.json` (its `modes`: the truth's modes with their
    /// identified counterparts, empty when `modes` is an error).
    pub section: TruthSection,
    /// The structure at the truth values.
    pub mapped: StructureTruth,
    /// The identified model's modes against the truth model's (both the fitted structure,
    /// so that both have the same states and the same naming rules); an error, not a
    /// failure of the scoring, when either model has no eigenvalues (a singular M, a NaN).
    pub modes: Result<ModeComparison, ModeError>,
}

/// Score a fit against the simulator's truth: every parameter with its truth value and
/// error, and J per fitted pair of the identified model against the structure's truth
/// model (the `truth` section of `model.json`), with the modes compared as in
/// [`score_fit_with_modes`].
pub fn score_fit(result: &FitResult, truth: &VehicleTruth) -> Result<TruthSection, Error> {
    Ok(score_fit_with_modes(result, truth)?.section)
}

/// [`score_fit`], and the identified model's modes against those of the fitted structure
/// at the truth values ([`sysid::fit::modes::compare_modes`]). The simulator's own
/// eigenvalues (`linearization.eigenvalues`, 11 states with ψ and the unscaled flapping)
/// are not used: the structure at the truth values has the identified model's states, so
/// the same naming rules apply to both sides.
pub fn score_fit_with_modes(result: &FitResult, truth: &VehicleTruth) -> Result<ScoredFit, Error> {
    let mapped = structure_truth(&result.structure, truth)?;
    let modes = compare_modes(&result.model, &mapped.model);
    let parameters = result
        .parameters
        .iter()
        .map(|p| {
            let truth = mapped.values.get(&p.name).copied();
            TruthParameter {
                name: p.name.clone(),
                value: p.value,
                truth,
                error_percent: truth
                    .filter(|t| *t != 0.0)
                    .map(|t| 100.0 * (p.value - t) / t.abs()),
            }
        })
        .collect();
    let comparison: ModelComparison = cost_between_models(
        &mapped.model,
        &result.model,
        &result.bands(),
        TRUTH_POINTS_PER_PAIR,
    )?;
    let section = TruthSection {
        vehicle: truth.aircraft.name.clone(),
        parameters,
        pairs: comparison
            .bands
            .iter()
            .zip(&comparison.costs)
            .map(|(band, cost)| PairFit {
                input: band.input.clone(),
                output: band.output.clone(),
                range: band.range,
                cost: *cost,
            })
            .collect(),
        average_cost: comparison.average,
        unmapped: mapped.unmapped.clone(),
        modes: modes
            .as_ref()
            .map(|compared| compared.truth.clone())
            .unwrap_or_default(),
    };
    Ok(ScoredFit {
        section,
        mapped,
        modes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::shipped;

    #[test]
    fn fit_to_the_truth_responses_recovers_the_truth_and_scores_zero() {
        use sysid::fit::report::ScoredModelDocument;
        use sysid::fit::structure::ParameterKind;
        use sysid::fit::synthetic::{exact_frf_document, SyntheticGrid};
        use sysid::fit::{fit, FitOptions, ModelDocument};

        let truth = VehicleTruth::at_hover(&aircraft::shipped("bo105").unwrap()).unwrap();
        let structure = shipped("bo105-6dof.toml");
        let mapped = structure_truth(&structure, &truth).unwrap();
        // Everything at its truth and fixed, except Lp and Llat, started 30 % off.
        let mut start = structure.with_values(&mapped.base_values).unwrap();
        for parameter in &mut start.parameters {
            if parameter.name == "Lp" || parameter.name == "Llat" {
                parameter.value *= 1.3;
            } else {
                parameter.kind = ParameterKind::Fixed;
            }
        }
        let bands: Vec<sysid::fit::PairBand> = [("p", "lat"), ("q", "lon"), ("r", "ped")]
            .iter()
            .map(|(output, input)| sysid::fit::PairBand {
                input: input.to_string(),
                output: output.to_string(),
                range: [0.5, 12.0],
            })
            .collect();
        start.pairs.retain(|p| {
            bands
                .iter()
                .any(|b| b.input == p.input && b.output == p.output)
        });
        let data = exact_frf_document(&mapped.model, &bands, SyntheticGrid::FitPoints(20));
        let options = FitOptions {
            max_starts: 2,
            ..FitOptions::default()
        };
        let result = fit(&start, &data, &options).unwrap();
        let section = score_fit(&result, &truth).unwrap();
        assert_eq!(section.vehicle, "bo105");
        for name in ["Lp", "Llat"] {
            let row = section.parameters.iter().find(|p| p.name == name).unwrap();
            assert!(row.error_percent.unwrap().abs() < 0.01, "{row:?}");
        }
        assert_eq!(section.pairs.len(), 3);
        assert!(section.average_cost < 1e-6, "{}", section.average_cost);
        // model.json round-trips with and without truth.
        let document = ScoredModelDocument {
            model: result.to_document(),
            truth: Some(section.clone()),
            modes: Vec::new(),
        };
        let json = serde_json::to_string(&document).unwrap();
        // (serde_json's default float parsing may differ in the last bit: compare closely.)
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300);
        let back: ScoredModelDocument = serde_json::from_str(&json).unwrap();
        let back_truth = back.truth.expect("truth section read back");
        assert_eq!(back_truth.parameters.len(), section.parameters.len());
        for (a, b) in back_truth.parameters.iter().zip(&section.parameters) {
            assert_eq!(a.name, b.name);
            assert!(close(a.value, b.value), "{a:?} {b:?}");
            assert_eq!(a.truth.is_some(), b.truth.is_some());
        }
        assert_eq!(back_truth.pairs.len(), 3);
        let plain: ModelDocument = serde_json::from_str(&json).unwrap();
        assert_eq!(plain.parameters.len(), document.model.parameters.len());
        assert_eq!(plain.structure, document.model.structure);
        let without = serde_json::to_string(&document.model).unwrap();
        assert!(!without.contains("\"truth\""));
        let back: ScoredModelDocument = serde_json::from_str(&without).unwrap();
        assert!(back.truth.is_none());
    }

    #[test]
    fn a_perfect_fit_scores_zero_against_the_truth() {
        let truth = VehicleTruth::at_hover(&aircraft::shipped("bo105").unwrap()).unwrap();
        let structure = shipped("bo105-6dof.toml");
        let mapped = structure_truth(&structure, &truth).unwrap();
        let bands = vec![sysid::fit::PairBand {
            input: "lat".into(),
            output: "p".into(),
            range: [0.5, 10.0],
        }];
        let same = cost_between_models(&mapped.model, &mapped.model, &bands, 20).unwrap();
        assert!(same.average < 1e-12, "{}", same.average);
        let mut off = mapped.model.clone();
        off.g.scale_mut(1.5);
        let worse = cost_between_models(&mapped.model, &off, &bands, 20).unwrap();
        assert!(worse.average > 1.0, "{}", worse.average);
    }
}
