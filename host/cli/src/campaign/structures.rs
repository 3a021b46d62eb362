//! The model structures a campaign fits, compiled into the binary so that `sweephold
//! campaign` works from any directory.

use std::collections::BTreeMap;

use sysid::fit::structure::ParameterKind;
use sysid::fit::{ModelStructure, StructureError};

/// `host/sysid/models/bo105-6dof.toml`: the quasi-steady 6-DOF structure.
pub const SIX_DOF_TOML: &str = include_str!("../../../sysid/models/bo105-6dof.toml");

/// `host/sysid/models/bo105-9dof-hybrid.toml`: the paper's Table 2 hybrid structure.
pub const NINE_DOF_HYBRID_TOML: &str = include_str!("../../../sysid/models/bo105-9dof-hybrid.toml");

/// The quasi-steady 6-DOF structure (both vehicles: no TREX-specific structure exists).
pub fn six_dof() -> Result<ModelStructure, StructureError> {
    ModelStructure::parse(SIX_DOF_TOML, "bo105-6dof.toml (built in)")
}

/// The 9-DOF hybrid structure (both vehicles), with the rotor data of `vehicle` in it:
/// the file is written for the Bo-105 — its geometry constants (`hub_height`,
/// `hub_forward`, `shaft_tilt_sine`) and the flap cross-coupling `Kcs` it fixes from rotor
/// theory — and another vehicle gets its own ([`bo105::Rotor::flap_cross_coupling`], the
/// hub position and shaft tilt of its main rotor).
pub fn nine_dof_hybrid(vehicle: bo105::Vehicle) -> Result<ModelStructure, StructureError> {
    let helicopter = vehicle.helicopter();
    // The hub is at body (x, z) = (hub[0], hub[2]) from the CG, z down: its height above
    // the CG is −hub[2].
    let hub = helicopter.main_rotor.hub;
    let constants = BTreeMap::from([
        ("hub_height".to_string(), -hub[2]),
        ("hub_forward".to_string(), hub[0]),
        ("shaft_tilt_sine".to_string(), helicopter.shaft_tilt.sin()),
    ]);
    let mut structure = ModelStructure::parse_with_constants(
        NINE_DOF_HYBRID_TOML,
        "bo105-9dof-hybrid.toml (built in)",
        &constants,
    )?;
    if let Some(index) = structure.parameter_index("Kcs") {
        let parameter = &mut structure.parameters[index];
        // Only a fixed entry is a rotor-data prior; a free one stays the fit's to find.
        if parameter.kind == ParameterKind::Fixed {
            parameter.value = helicopter.flap_cross_coupling();
        }
    }
    Ok(structure)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_structures_parse() {
        let six = six_dof().unwrap();
        let nine = nine_dof_hybrid(bo105::Vehicle::Bo105).unwrap();
        assert!(nine.states.len() > six.states.len());
        assert!(nine.states.iter().any(|s| s == "b1s"));
    }

    #[test]
    fn the_flap_cross_coupling_is_the_flown_vehicles_rotor_value() {
        let kcs = |vehicle| {
            let structure = nine_dof_hybrid(vehicle).unwrap();
            let index = structure.parameter_index("Kcs").unwrap();
            assert_eq!(structure.parameters[index].kind, ParameterKind::Fixed);
            structure.parameters[index].value
        };
        let file = ModelStructure::parse(NINE_DOF_HYBRID_TOML, "file").unwrap();
        let in_file = file.parameters[file.parameter_index("Kcs").unwrap()].value;
        let bo105_rotor = bo105::Helicopter::bo105().flap_cross_coupling();
        // The file's number is the Bo-105 rotor's, rounded to the digits written.
        assert!(
            (in_file - bo105_rotor).abs() < 5e-5,
            "{in_file} vs {bo105_rotor}"
        );
        assert_eq!(kcs(bo105::Vehicle::Bo105), bo105_rotor);
        let trex = bo105::Helicopter::trex700l().flap_cross_coupling();
        assert_eq!(kcs(bo105::Vehicle::Trex700l), trex);
        assert!(
            (trex - bo105_rotor).abs() > 0.01,
            "TREX {trex}, Bo-105 {bo105_rotor}"
        );
    }

    #[test]
    fn the_geometry_constants_are_the_flown_vehicles() {
        let file = ModelStructure::parse(NINE_DOF_HYBRID_TOML, "file").unwrap();
        let bo105 = nine_dof_hybrid(bo105::Vehicle::Bo105).unwrap();
        let trex = nine_dof_hybrid(bo105::Vehicle::Trex700l).unwrap();
        // The file's numbers are the Bo-105's geometry (to the digits written).
        let bo105_data = bo105::Helicopter::bo105();
        for (name, value) in [
            ("hub_height", -bo105_data.main_rotor.hub[2]),
            ("hub_forward", bo105_data.main_rotor.hub[0]),
            ("shaft_tilt_sine", bo105_data.shaft_tilt.sin()),
        ] {
            assert!((file.constants[name] - value).abs() < 5e-4, "{name}");
            assert_eq!(bo105.constants[name], value, "{name}");
        }
        let trex_hub = -bo105::Helicopter::trex700l().main_rotor.hub[2];
        assert_eq!(trex.constants["hub_height"], trex_hub);
        assert!(trex_hub > 0.0 && trex_hub < 0.5, "{trex_hub}");
        // It reaches the model: Kpq = hub_height·Lfu.
        let kpq = |s: &ModelStructure| s.parameter_value("Kpq", &s.values()).unwrap();
        let lfu = |s: &ModelStructure| s.parameter_value("Lfu", &s.values()).unwrap();
        assert!((kpq(&trex) - trex_hub * lfu(&trex)).abs() < 1e-15);
        assert!((kpq(&bo105) - 1.48 * lfu(&bo105)).abs() < 1e-15);
    }
}
