use super::*;
use crate::fit::test_support::{shipped, values_with, SHIPPED_NAMES};

#[test]
fn every_shipped_structure_starts_inside_the_physical_ranges() {
    for name in SHIPPED_NAMES {
        let structure = shipped(name);
        let found = implausible_parameters(&structure, &structure.values());
        assert!(found.is_empty(), "{name}: {found:?}");
    }
}

#[test]
fn the_degenerate_six_dof_minima_are_outside_worst_first() {
    // Values of the default Bo-105 campaign's 6-DOF fit (seed 1) and the L_v.
    let structure = shipped("bo105-6dof");
    let values = values_with(
        &structure,
        &[
            ("Zped", -1.1448676e7),
            ("Xped", 1.946e6),
            ("Lv", 1.6e4),
            ("Llat", 50.2),
        ],
    );
    let found = implausible_parameters(&structure, &values);
    let names: Vec<&str> = found.iter().map(|p| p.name.as_str()).collect();
    // Worst first by how far outside: 1.1·10⁴, 1.9·10³, 160 times the limit.
    assert_eq!(names, ["Zped", "Xped", "Lv"], "{found:?}");
    assert_eq!(found[0].limit, LARGEST_ACCELERATION);
    assert_eq!(found[0].dimension, "m/s² per stick");
    assert_eq!(found[2].limit, 100.0);
    assert_eq!(found[2].dimension, "rad/s² per m/s");
    let line = describe(&found);
    assert!(
        line.starts_with("`Zped` = -1.145e7 (|value| <= 1000 m/s² per stick), `Xped`"),
        "{line}"
    );
    // At the limit it is still plausible; a hair beyond it is not.
    let at = values_with(&structure, &[("Lv", -100.0)]);
    assert!(implausible_parameters(&structure, &at).is_empty());
    let beyond = values_with(&structure, &[("Lv", -100.001)]);
    assert_eq!(implausible_parameters(&structure, &beyond).len(), 1);
}

#[test]
fn a_value_that_is_not_finite_is_always_implausible_and_fixed_ones_are_not_judged() {
    let mut structure = shipped("bo105-6dof");
    let values = values_with(&structure, &[("Mu", f64::NAN)]);
    let found = implausible_parameters(&structure, &values);
    assert_eq!(found.len(), 1);
    assert!(found[0].excess().is_infinite());
    let index = structure.parameter_index("Mu").unwrap();
    structure.parameters[index].kind = ParameterKind::Fixed;
    assert!(implausible_parameters(&structure, &values).is_empty());
}

#[test]
fn a_parameter_is_judged_by_the_part_it_contributes_to_each_entry() {
    // Kpq = h·Lfu and the others enter with coefficients: the hybrid's flapping
    // stiffness L_b1s (rate per angle) may reach Ω², its roll damping only Ω.
    let structure = shipped("bo105-9dof-hybrid");
    let fine = values_with(&structure, &[("Lb1s", 5e4)]);
    assert!(implausible_parameters(&structure, &fine).is_empty());
    let stiff = values_with(&structure, &[("Lb1s", 1e5)]);
    let found = implausible_parameters(&structure, &stiff);
    assert_eq!(found[0].name, "Lb1s");
    assert_eq!(found[0].limit, FASTEST_RATE * FASTEST_RATE);
}

#[test]
fn a_time_constant_in_m_is_never_dropped() {
    let structure = shipped("bo105-9dof-hybrid");
    assert!(!droppable(&structure, "tau_f"));
    assert!(droppable(&structure, "Lb1s"));
    assert!(!droppable(&structure, "Kcs"), "fixed");
    assert!(!droppable(&structure, "nothing"));
}
