//! A structure reduced to the outputs the data hold: a flight controller without air
//! data measures no body velocities (u, v, w), so its frequency responses have no pair of
//! them, and a structure written for a vehicle that does would otherwise refuse to fit.
//!
//! The rule: an output of which the frequency-response document holds no pair at all is
//! not measured, and the structure's pairs of it are left out. Its states, parameters and
//! other pairs stay (the accelerometer pairs and the trim points still see the velocity
//! states). An output the document does hold keeps every pair the structure lists, so a
//! pair missing for one control of a measured output is still the error it was
//! ([`super::FitError::MissingPair`]). A control left with no pair
//! is an error naming it: nothing in the data would identify its derivatives.

use std::collections::BTreeSet;

use super::error::FitError;
use super::structure::ModelStructure;
use crate::document::FrfDocument;

/// The outputs of which `data` holds at least one pair.
pub fn measured_outputs(data: &FrfDocument) -> BTreeSet<String> {
    data.pairs.iter().map(|pair| pair.output.clone()).collect()
}

/// `structure` without the pairs of outputs not in `measured`, and the names of those
/// outputs in the structure's output order (empty when nothing was left out).
pub fn reduce_to_measured(
    mut structure: ModelStructure,
    measured: &BTreeSet<String>,
) -> Result<(ModelStructure, Vec<String>), FitError> {
    let unmeasured: Vec<String> = structure
        .outputs
        .iter()
        .filter(|output| {
            !measured.contains(*output) && structure.pairs.iter().any(|p| &p.output == *output)
        })
        .cloned()
        .collect();
    if unmeasured.is_empty() {
        return Ok((structure, unmeasured));
    }
    for control in &structure.controls {
        let of_control: Vec<&str> = structure
            .pairs
            .iter()
            .filter(|pair| &pair.input == control)
            .map(|pair| pair.output.as_str())
            .collect();
        if !of_control.is_empty() && of_control.iter().all(|o| !measured.contains(*o)) {
            return Err(FitError::NoMeasuredPairOfControl {
                structure: structure.name.clone(),
                control: control.clone(),
                outputs: of_control.join(" "),
            });
        }
    }
    structure
        .pairs
        .retain(|pair| measured.contains(&pair.output));
    Ok((structure, unmeasured))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models;

    fn names(list: &[&str]) -> BTreeSet<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn leaves_out_the_pairs_of_outputs_the_data_do_not_hold() {
        let full = models::BO105_6DOF.parse().unwrap();
        let all: BTreeSet<String> = full.outputs.iter().cloned().collect();
        let (same, dropped) = reduce_to_measured(full.clone(), &all).unwrap();
        assert_eq!(same, full);
        assert!(dropped.is_empty());

        let imu: BTreeSet<String> = all
            .iter()
            .filter(|o| !["u", "v", "w"].contains(&o.as_str()))
            .cloned()
            .collect();
        let (reduced, dropped) = reduce_to_measured(full.clone(), &imu).unwrap();
        assert_eq!(dropped, ["u", "v", "w"]);
        assert_eq!(reduced.states, full.states);
        assert_eq!(reduced.parameters, full.parameters);
        assert!(reduced.pairs.iter().all(|p| imu.contains(&p.output)));
        let air = full
            .pairs
            .iter()
            .filter(|p| !imu.contains(&p.output))
            .count();
        assert!(air > 0);
        assert_eq!(reduced.pairs.len() + air, full.pairs.len());
    }

    #[test]
    fn a_control_left_without_pairs_is_named() {
        // Only q measured: the collective has no q pair in the 6-DOF structure.
        let full = models::BO105_6DOF.parse().unwrap();
        let error = reduce_to_measured(full, &names(&["q"])).unwrap_err();
        let text = error.to_string();
        assert!(
            matches!(&error, FitError::NoMeasuredPairOfControl { control, .. } if control == "col"),
            "{text}"
        );
        assert!(text.contains("no pair of control `col` left"), "{text}");
    }
}
