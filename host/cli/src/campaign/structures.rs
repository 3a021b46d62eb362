//! The model structures a campaign fits, compiled into the binary so that `sweephold
//! campaign` works from any directory.

use sysid::fit::{ModelStructure, StructureError};

/// `host/sysid/models/bo105-6dof.toml`: the quasi-steady 6-DOF structure.
pub const SIX_DOF_TOML: &str = include_str!("../../../sysid/models/bo105-6dof.toml");

/// `host/sysid/models/bo105-9dof-hybrid.toml`: the paper's Table 2 hybrid structure.
pub const NINE_DOF_HYBRID_TOML: &str = include_str!("../../../sysid/models/bo105-9dof-hybrid.toml");

/// The quasi-steady 6-DOF structure (both vehicles: no TREX-specific structure exists).
pub fn six_dof() -> Result<ModelStructure, StructureError> {
    ModelStructure::parse(SIX_DOF_TOML, "bo105-6dof.toml (built in)")
}

/// The 9-DOF hybrid structure (both vehicles).
pub fn nine_dof_hybrid() -> Result<ModelStructure, StructureError> {
    ModelStructure::parse(NINE_DOF_HYBRID_TOML, "bo105-9dof-hybrid.toml (built in)")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_structures_parse() {
        let six = six_dof().unwrap();
        let nine = nine_dof_hybrid().unwrap();
        assert!(nine.states.len() > six.states.len());
        assert!(nine.states.iter().any(|s| s == "b1s"));
    }
}
