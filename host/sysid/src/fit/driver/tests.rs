//! Tests of the fit driver's hold of undetermined parameters.

use super::*;
use crate::fit::test_support::{shipped, values_with};

fn with_values(structure: &ModelStructure, changes: &[(&str, f64)]) -> ModelStructure {
    let mut changed = structure.clone();
    let values = values_with(structure, changes);
    for (parameter, value) in changed.parameters.iter_mut().zip(values) {
        parameter.value = value;
    }
    changed
}

#[test]
fn a_held_parameter_takes_the_a_priori_value_in_every_start_set() {
    let file = shipped("trex700l-9dof-hybrid");
    let value =
        |s: &ModelStructure, name: &str| s.parameters[s.parameter_index(name).unwrap()].value;
    // A start set from another fit: its N_col undetermined there (202 against the
    // file's 10), its N_ped determined.
    let from_six = with_values(&file, &[("Ncol", 202.5), ("Nped", 80.0)]);
    let names = ["Ncol".to_string()];
    for start in [&from_six, &file] {
        let held = held_at_a_priori(start, &names, &file);
        let index = held.parameter_index("Ncol").unwrap();
        assert_eq!(held.parameters[index].kind, ParameterKind::Fixed);
        assert_eq!(value(&held, "Ncol"), value(&file, "Ncol"));
        assert_eq!(
            value(&held, "Nped"),
            value(start, "Nped"),
            "not held: its own start"
        );
    }
    // An a-priori value outside the physical range is held at zero.
    let wild = with_values(&file, &[("Ncol", 1e7)]);
    let held = held_at_a_priori(&from_six, &names, &wild);
    assert_eq!(value(&held, "Ncol"), 0.0);
}
