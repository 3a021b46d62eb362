//! The shipped structures' mode names and shares do not change with the naming of states
//! of other names (`sysid::fit::modes::state_kinds`): the Bo-105's and the TREX 700L's
//! fitted hybrids (the quick campaign's `model9.json`, seed 1, checked in for the
//! `control` crate) give the modes written in those files.

use sysid::fit::modes::modes;
use sysid::fit::ModelDocument;

const BO105: &str = include_str!("../../control/tests/fixtures/bo105-quick-seed1-model9.json");
const TREX: &str = include_str!("../../control/tests/fixtures/trex700l-quick-seed1-model9.json");

/// The modes of the model in `text` against the `modes` written in it: the same names in
/// the same order, the same shares.
fn assert_same_modes(text: &str) {
    let document: ModelDocument = serde_json::from_str(text).unwrap();
    let model = document
        .matrices
        .to_model(
            &document.states,
            &document.controls,
            &document.outputs,
            &document.delays,
            &document.actuators,
        )
        .unwrap();
    let written: serde_json::Value = serde_json::from_str(text).unwrap();
    let written = written["modes"].as_array().unwrap();
    let found = modes(&model).unwrap();
    assert_eq!(found.len(), written.len());
    for (mode, record) in found.iter().zip(written) {
        assert_eq!(mode.name.as_str(), record["name"].as_str().unwrap());
        let shares = record["shares"].as_object().unwrap();
        for (state, share) in document.states.iter().zip(&mode.shares) {
            let expected = shares.get(state).map_or(0.0, |v| v.as_f64().unwrap());
            // The file lists shares of at least 1 %.
            if expected > 0.0 {
                assert!(
                    (share - expected).abs() < 1e-9,
                    "{state}: {share} vs {expected}"
                );
            } else {
                assert!(*share < 0.01, "{state}: {share}");
            }
        }
    }
}

#[test]
fn the_bo105_hybrids_modes_are_unchanged() {
    assert_same_modes(BO105);
}

#[test]
fn the_trex700ls_hybrids_modes_are_unchanged() {
    assert_same_modes(TREX);
}
