//! The fit on a structure it was never tuned on: the Yamaha R-50 hover model
//! (`docs/published_model/`: 13 states, five of them unmeasured rotor, stabilizer-bar and
//! yaw-damper states, 32 free parameters), fitted from the structure file's round start
//! values to the model's exact responses. With no estimation error the published values
//! are the global minimum (J_ave 0); what the fit reaches measures the search.
//!
//! The simulated-sweep half (CSV → `frf` → `fit`, noise-free and three noise seeds) needs
//! Python to make its data and runs outside the suite: `docs/published_model/run_fit.py`,
//! figures in `docs/decisions/2026-11-27-published-model-fit.md`.

use sysid::fit::synthetic::{exact_frf_document, SyntheticGrid};
use sysid::fit::{fit, FitOptions, ModelStructure, PairBand};

const STRUCTURE: &str = include_str!("../../../docs/published_model/r50-hover.toml");
const PUBLISHED: &str = include_str!("../../../docs/published_model/published_values.csv");

/// The published free values, by name.
fn published() -> Vec<(String, f64)> {
    PUBLISHED
        .lines()
        .filter(|line| !line.starts_with('#') && !line.starts_with("name,"))
        .map(|line| {
            let (name, value) = line.split_once(',').unwrap();
            (name.to_string(), value.parse().unwrap())
        })
        .collect()
}

/// The structure, and its base-parameter values with every free one at its published value.
fn structure_and_truth() -> (ModelStructure, Vec<f64>) {
    let structure = ModelStructure::parse(STRUCTURE, "r50-hover.toml").unwrap();
    let mut values = structure.values();
    let published = published();
    assert_eq!(published.len(), structure.free_indices().len());
    for (name, value) in &published {
        values[structure.parameter_index(name).unwrap()] = *value;
    }
    (structure, values)
}

/// Exact responses of the published model over 0.3–40 rad/s for the structure's pairs.
fn exact_responses(structure: &ModelStructure, truth: &[f64]) -> sysid::document::FrfDocument {
    let model = structure.model(truth).unwrap();
    let bands: Vec<PairBand> = structure
        .pairs
        .iter()
        .map(|pair| PairBand {
            input: pair.input.clone(),
            output: pair.output.clone(),
            range: [0.3, 40.0],
        })
        .collect();
    exact_frf_document(&model, &bands, SyntheticGrid::FitPoints(20))
}

/// Free parameters within 10 % of the published values.
fn within_ten_percent(structure: &ModelStructure, fitted: &[f64]) -> Vec<String> {
    published()
        .into_iter()
        .filter(|(name, value)| {
            let got = fitted[structure.parameter_index(name).unwrap()];
            (got - value).abs() <= 0.1 * value.abs()
        })
        .map(|(name, _)| name)
        .collect()
}

/// The default (local) search, from the file's round starts: every one of the 32 free
/// parameters within 10 % (measured: all within 0.1 %, J_ave < 0.01).
#[test]
fn the_published_model_is_found_from_round_starts() {
    let (structure, truth) = structure_and_truth();
    let data = exact_responses(&structure, &truth);
    let result = fit(&structure, &data, &FitOptions::default()).unwrap();
    let within = within_ten_percent(&structure, &result.values);
    assert!(result.average_cost < 0.1, "J_ave {}", result.average_cost);
    assert_eq!(within.len(), 32, "within 10 %: {within:?}");
}

/// The global search spends its whole budget (8 starts, where the local search stops at
/// the second hit) and finds the same minimum.
#[test]
fn the_global_search_spends_its_budget_and_finds_the_same_minimum() {
    let (structure, truth) = structure_and_truth();
    let data = exact_responses(&structure, &truth);
    let options = FitOptions {
        max_starts: 8,
        global_search: true,
        ..FitOptions::default()
    };
    let result = fit(&structure, &data, &options).unwrap();
    assert_eq!(result.starts.len(), 8);
    let within = within_ten_percent(&structure, &result.values);
    assert!(result.average_cost < 0.1, "J_ave {}", result.average_cost);
    assert_eq!(within.len(), 32, "within 10 %: {within:?}");
}
