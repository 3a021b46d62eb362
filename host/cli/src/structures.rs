//! The model structures a campaign fits and `sweephold fit --model NAME` resolves: the
//! structures shipped in sysid ([`sysid::models`]), with the flown vehicle's numbers put in
//! where the file carries the Bo-105's ([`truth::with_vehicle_data`]).

use std::collections::BTreeMap;

use anyhow::anyhow;

use sysid::fit::{ModelStructure, StructureError};
use sysid::models::{self, ShippedStructure, VehicleData};
pub use truth::{nine_dof_hybrid, with_vehicle_data, TrimAttitude};

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
