//! The model structures shipped with sysid (`host/sysid/models/*.toml`), compiled in so that
//! a program can fit them by name from any directory.
//!
//! The `bo105-*` files are written for the Bo-105: their `[constants]` (hub position, shaft
//! tilt, gravity, hover trim attitude) and the rotor-data parameter they fix (`Kcs`) are
//! its numbers. `trex700l-9dof-hybrid` is the TREX 700L's own file (its numbers, start
//! values of its size, its servos as known actuators); `trex700l-6dof` is the 6-DOF file,
//! which has no vehicle numbers. For both TREX entries the caller puts in the flown
//! vehicle's numbers over the file's ([`VehicleData::FromCaller`]; `sweephold` does so
//! from its simulator's data and the captured trim), since this crate knows no vehicle
//! data.
//!
//! ```
//! let hybrid = sysid::models::shipped("bo105-9dof-hybrid").unwrap();
//! let structure = hybrid.parse().unwrap();
//! assert_eq!(structure.name, "bo105-9dof-hybrid");
//! assert!(sysid::models::shipped("bo105-12dof").is_none());
//! ```

use std::collections::BTreeMap;

use crate::fit::{ModelStructure, StructureError};

/// `host/sysid/models/bo105-6dof.toml`: the quasi-steady 6-DOF structure.
pub const BO105_6DOF_TOML: &str = include_str!("../models/bo105-6dof.toml");

/// `host/sysid/models/bo105-9dof-hybrid.toml`: the paper's Table 2 hybrid structure with
/// the hingeless rotor's flap couplings.
pub const BO105_9DOF_HYBRID_TOML: &str = include_str!("../models/bo105-9dof-hybrid.toml");

/// `host/sysid/models/trex700l-9dof-hybrid.toml`: the hybrid for the TREX 700L, with its
/// servos as known actuators.
pub const TREX700L_9DOF_HYBRID_TOML: &str = include_str!("../models/trex700l-9dof-hybrid.toml");

/// Where a shipped structure's vehicle numbers come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VehicleData {
    /// The file's own numbers are this vehicle's: parse it as it is.
    InFile,
    /// The caller replaces the constants the file declares (geometry, gravity, trim
    /// attitude, servos) and its fixed rotor-data parameters (`Kcs`) with the flown
    /// vehicle's, e.g. through [`ShippedStructure::parse_with_constants`]; the file's own
    /// numbers are defaults (the Bo-105's in a `bo105-*` file).
    FromCaller,
}

/// A structure compiled into this crate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShippedStructure {
    /// The name to ask for it by (`bo105-9dof-hybrid`, `trex700l-6dof`, …).
    pub name: &'static str,
    /// One line on what it is.
    pub description: &'static str,
    /// The file it is, under `host/sysid/models/` (the TOML's own `name` is the file's).
    pub file: &'static str,
    /// The file's text.
    pub toml: &'static str,
    /// The vehicle it is for (`bo105`, `trex700l`).
    pub vehicle: &'static str,
    /// Whether the file's numbers are that vehicle's.
    pub vehicle_data: VehicleData,
}

/// `bo105-6dof`: the 6-DOF file as it is.
pub const BO105_6DOF: ShippedStructure = ShippedStructure {
    name: "bo105-6dof",
    description: "quasi-steady 6-DOF with equivalent delays (gives the 9-DOF start values)",
    file: "bo105-6dof.toml",
    toml: BO105_6DOF_TOML,
    vehicle: "bo105",
    vehicle_data: VehicleData::InFile,
};

/// `bo105-9dof-hybrid`: the 9-DOF hybrid file as it is.
pub const BO105_9DOF_HYBRID: ShippedStructure = ShippedStructure {
    name: "bo105-9dof-hybrid",
    description: "9-DOF hybrid: rigid body + first-order flapping (paper Table 2)",
    file: "bo105-9dof-hybrid.toml",
    toml: BO105_9DOF_HYBRID_TOML,
    vehicle: "bo105",
    vehicle_data: VehicleData::InFile,
};

/// `trex700l-6dof`: the 6-DOF file, which has no vehicle numbers, for the TREX 700L.
pub const TREX700L_6DOF: ShippedStructure = ShippedStructure {
    name: "trex700l-6dof",
    description: "the 6-DOF file for the TREX 700L (it has no vehicle constants)",
    file: "bo105-6dof.toml",
    toml: BO105_6DOF_TOML,
    vehicle: "trex700l",
    vehicle_data: VehicleData::FromCaller,
};

/// `trex700l-9dof-hybrid`: the TREX 700L's hybrid (its numbers, its servos), the flown
/// vehicle's numbers put in by the caller.
pub const TREX700L_9DOF_HYBRID: ShippedStructure = ShippedStructure {
    name: "trex700l-9dof-hybrid",
    description: "9-DOF hybrid for the TREX 700L: its geometry, flap cross-coupling, hover \
                  trim and servos (known second-order actuators)",
    file: "trex700l-9dof-hybrid.toml",
    toml: TREX700L_9DOF_HYBRID_TOML,
    vehicle: "trex700l",
    vehicle_data: VehicleData::FromCaller,
};

/// Every shipped structure, in the order `sweephold fit --help` lists them.
pub const SHIPPED: &[ShippedStructure] = &[
    BO105_6DOF,
    BO105_9DOF_HYBRID,
    TREX700L_6DOF,
    TREX700L_9DOF_HYBRID,
];

/// The shipped structure called `name`, if any.
pub fn shipped(name: &str) -> Option<&'static ShippedStructure> {
    SHIPPED.iter().find(|structure| structure.name == name)
}

/// The names of [`SHIPPED`], comma-separated (for messages and help texts).
pub fn shipped_names() -> String {
    SHIPPED
        .iter()
        .map(|structure| structure.name)
        .collect::<Vec<_>>()
        .join(", ")
}

impl ShippedStructure {
    /// The name its parse errors carry: `bo105-6dof.toml (built in)`.
    pub fn source_name(&self) -> String {
        format!("{} (built in)", self.file)
    }

    /// The structure with the file's own numbers (the Bo-105's; see [`VehicleData`]).
    pub fn parse(&self) -> Result<ModelStructure, StructureError> {
        self.parse_with_constants(&BTreeMap::new())
    }

    /// The structure with some of the file's `[constants]` replaced (see
    /// [`ModelStructure::parse_with_constants`]).
    pub fn parse_with_constants(
        &self,
        overrides: &BTreeMap<String, f64>,
    ) -> Result<ModelStructure, StructureError> {
        ModelStructure::parse_with_constants(self.toml, &self.source_name(), overrides)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::ParameterKind;

    #[test]
    fn every_shipped_structure_parses_under_its_files_name() {
        for shipped in SHIPPED {
            let structure = shipped.parse().unwrap();
            assert_eq!(format!("{}.toml", structure.name), shipped.file);
            assert!(!structure.pairs.is_empty(), "{}", shipped.name);
            assert!(
                shipped.name.starts_with(shipped.vehicle),
                "{}",
                shipped.name
            );
        }
        let names: Vec<&str> = SHIPPED.iter().map(|s| s.name).collect();
        assert_eq!(
            names,
            [
                "bo105-6dof",
                "bo105-9dof-hybrid",
                "trex700l-6dof",
                "trex700l-9dof-hybrid"
            ]
        );
        assert_eq!(shipped_names(), names.join(", "));
    }

    #[test]
    fn the_texts_are_the_files_in_models() {
        let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
        for shipped in SHIPPED {
            let on_disk = std::fs::read_to_string(folder.join(shipped.file)).unwrap();
            assert_eq!(shipped.toml, on_disk, "{}", shipped.file);
        }
    }

    #[test]
    fn the_dampings_of_both_hybrids_are_bounded_at_zero() {
        // Z_w on both (heave damping); X_u and Y_v on the TREX's, whose drag dampings are
        // below what its sweeps resolve (its file's header).
        let upper = |shipped: &ShippedStructure, name: &str| {
            let structure = shipped.parse().unwrap();
            let index = structure.parameter_index(name).unwrap();
            let parameter = &structure.parameters[index];
            assert_eq!(parameter.kind, ParameterKind::Free, "{name}");
            assert!(
                parameter.value < 0.0,
                "{name} starts at {}",
                parameter.value
            );
            parameter.upper
        };
        for name in ["Xu", "Yv", "Zw"] {
            assert_eq!(upper(&TREX700L_9DOF_HYBRID, name), Some(0.0), "{name}");
        }
        assert_eq!(upper(&BO105_9DOF_HYBRID, "Zw"), Some(0.0));
    }

    #[test]
    fn lookup_by_name() {
        assert_eq!(
            shipped("trex700l-9dof-hybrid").map(|s| s.vehicle_data),
            Some(VehicleData::FromCaller)
        );
        assert_eq!(
            shipped("bo105-6dof").map(|s| s.vehicle_data),
            Some(VehicleData::InFile)
        );
        assert!(shipped("bo105-6dof.toml").is_none());
        assert!(shipped("").is_none());
        let error = shipped("bo105-9dof-hybrid")
            .unwrap()
            .parse_with_constants(&BTreeMap::from([("hub_heigth".to_string(), 1.0)]))
            .unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("bo105-9dof-hybrid.toml (built in): unknown constant `hub_heigth`"),
            "{error}"
        );
    }
}
