//! The model structures a campaign fits and `sweephold fit --model NAME` resolves: the
//! structures shipped in sysid ([`sysid::models`]), with the flown vehicle's numbers put in
//! where the file carries the Bo-105's ([`truth::with_vehicle_data`]).

use std::collections::BTreeMap;

use anyhow::anyhow;

use sysid::fit::{ModelStructure, StructureError};
use sysid::models::{self, ShippedStructure, VehicleData};
pub use truth::{nine_dof_hybrid, with_vehicle_data, TrimAttitude};

/// The outputs only air data measures (the body velocities): a flight controller's IMU
/// measures the rates, the attitude and the specific force, not these.
pub const AIR_DATA_OUTPUTS: [&str; 3] = ["u", "v", "w"];

/// `structure` for records without air data: its pairs of the [`AIR_DATA_OUTPUTS`] left
/// out (the states stay: the accelerometer pairs and the trim points still see them).
pub fn without_air_data(mut structure: ModelStructure) -> ModelStructure {
    structure
        .pairs
        .retain(|pair| !AIR_DATA_OUTPUTS.contains(&pair.output.as_str()));
    structure
}

/// The quasi-steady 6-DOF structure (both vehicles: it has no vehicle constants).
pub fn six_dof() -> Result<ModelStructure, StructureError> {
    models::BO105_6DOF.parse()
}

/// The shipped structure called `name` (see [`sysid::models::SHIPPED`]) with
/// `overrides` of its constants applied last, or None when no structure has that name.
/// A `trex700l-*` structure gets the TREX's numbers ([`with_vehicle_data`]) and its
/// simulator's hover trim attitude, the file's Bo-105 numbers being of no use for it.
pub fn shipped(
    name: &str,
    overrides: &BTreeMap<String, f64>,
) -> Option<anyhow::Result<ModelStructure>> {
    let shipped = models::shipped(name)?;
    Some(match shipped.vehicle_data {
        VehicleData::InFile => shipped.parse_with_constants(overrides).map_err(Into::into),
        VehicleData::FromCaller => shipped_for_its_vehicle(shipped, overrides),
    })
}

fn shipped_for_its_vehicle(
    shipped: &ShippedStructure,
    overrides: &BTreeMap<String, f64>,
) -> anyhow::Result<ModelStructure> {
    let vehicle = aircraft::shipped(shipped.vehicle)
        .ok_or_else(|| anyhow!("{}: no aircraft `{}`", shipped.name, shipped.vehicle))?;
    let trim = rotorsim::trim(&rotorsim::Helicopter::from_aircraft(&vehicle), 0.0)
        .map_err(|e| anyhow!("{} does not trim in hover: {e}", vehicle.name))?;
    let trim = TrimAttitude {
        phi: trim.phi,
        theta: trim.theta,
    };
    Ok(with_vehicle_data(shipped, &vehicle, Some(trim), overrides)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_air_data_keeps_the_imu_pairs_only() {
        let full = nine_dof_hybrid(&aircraft::shipped("bo105").unwrap(), None).unwrap();
        let imu = without_air_data(full.clone());
        assert_eq!(imu.states, full.states);
        assert_eq!(imu.parameters, full.parameters);
        assert!(imu
            .pairs
            .iter()
            .all(|p| !AIR_DATA_OUTPUTS.contains(&p.output.as_str())));
        let dropped = full.pairs.len() - imu.pairs.len();
        let air = full
            .pairs
            .iter()
            .filter(|p| AIR_DATA_OUTPUTS.contains(&p.output.as_str()))
            .count();
        assert_eq!(dropped, air);
        assert!(air > 0 && !imu.pairs.is_empty());
    }

    #[test]
    fn built_in_structures_parse() {
        let six = six_dof().unwrap();
        let nine = nine_dof_hybrid(&aircraft::shipped("bo105").unwrap(), None).unwrap();
        assert!(nine.states.len() > six.states.len());
        assert!(nine.states.iter().any(|s| s == "b1s"));
    }

    #[test]
    fn shipped_names_resolve_to_the_structures_the_campaign_fits() {
        let none = BTreeMap::new();
        let by_name = |name: &str| shipped(name, &none).unwrap().unwrap();
        assert_eq!(by_name("bo105-6dof"), six_dof().unwrap());
        assert_eq!(by_name("trex700l-6dof"), six_dof().unwrap());
        assert_eq!(
            by_name("bo105-9dof-hybrid"),
            models::BO105_9DOF_HYBRID.parse().unwrap()
        );
        assert!(shipped("bo105-7dof", &none).is_none());

        // The TREX's hybrid: its geometry and rotor, and its simulator's hover trim.
        let trex = by_name("trex700l-9dof-hybrid");
        let heli = rotorsim::Helicopter::trex700l();
        let hover = rotorsim::trim(&heli, 0.0).unwrap();
        let campaign = nine_dof_hybrid(
            &aircraft::shipped("trex700l").unwrap(),
            Some(TrimAttitude {
                phi: hover.phi,
                theta: hover.theta,
            }),
        )
        .unwrap();
        assert_eq!(trex, campaign);
        assert_eq!(trex.constants["hub_height"], -heli.main_rotor.hub[2]);
        assert_eq!(trex.constants["sin_phi0"], hover.phi.sin());
        assert!(
            (trex.constants["sin_phi0"] - by_name("bo105-9dof-hybrid").constants["sin_phi0"]).abs()
                > 0.01
        );
        let kcs = trex.parameters[trex.parameter_index("Kcs").unwrap()].value;
        assert_eq!(kcs, heli.flap_cross_coupling());

        // --constant overrides come last, and must name a declared constant.
        let overrides = BTreeMap::from([("hub_height".to_string(), 0.5)]);
        for name in ["bo105-9dof-hybrid", "trex700l-9dof-hybrid"] {
            let structure = shipped(name, &overrides).unwrap().unwrap();
            assert_eq!(structure.constants["hub_height"], 0.5, "{name}");
        }
        let error = shipped("trex700l-6dof", &overrides).unwrap().unwrap_err();
        assert!(
            error.to_string().contains("unknown constant `hub_height`"),
            "{error}"
        );
    }
}
