//! The model structures a campaign fits, compiled into the binary so that `sweephold
//! campaign` works from any directory.

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
/// the file fixes the flap cross-coupling `Kcs` at the Bo-105's rotor-theory value, and
/// another vehicle gets its own ([`bo105::Rotor::flap_cross_coupling`]).
pub fn nine_dof_hybrid(vehicle: bo105::Vehicle) -> Result<ModelStructure, StructureError> {
    let mut structure =
        ModelStructure::parse(NINE_DOF_HYBRID_TOML, "bo105-9dof-hybrid.toml (built in)")?;
    let helicopter = vehicle.helicopter();
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
}
