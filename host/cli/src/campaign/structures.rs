//! The model structures a campaign fits and `sweephold fit --model NAME` resolves: the
//! structures shipped in sysid ([`sysid::models`]), with the flown vehicle's numbers put in
//! where the file carries the Bo-105's.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{anyhow, Context};
use sweephold_protocol::{Decoder, Event, Frame};

use sysid::fit::structure::ParameterKind;
use sysid::fit::{ModelStructure, StructureError};
use sysid::models::{self, ShippedStructure, VehicleData};

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
    let vehicle: bo105::Vehicle = shipped
        .vehicle
        .parse()
        .map_err(|e| anyhow!("{}: {e}", shipped.name))?;
    let trim = bo105::trim(&vehicle.helicopter(), 0.0)
        .map_err(|e| anyhow!("{} does not trim in hover: {e}", vehicle.name()))?;
    let trim = TrimAttitude {
        phi: trim.phi,
        theta: trim.theta,
    };
    Ok(with_vehicle_data(shipped, vehicle, Some(trim), overrides)?)
}

/// The trim attitude a flight controller captured before its excitation \[rad\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrimAttitude {
    /// Roll φ0.
    pub phi: f64,
    /// Pitch θ0.
    pub theta: f64,
}

impl TrimAttitude {
    /// The mean of the `TrimCaptured` events in `dumps` (one per record), or None when no
    /// dump has one. What the flight-test engineer has: the aircraft's own trim, not the
    /// simulator's.
    pub fn captured(dumps: &[impl AsRef<Path>]) -> anyhow::Result<Option<TrimAttitude>> {
        let (mut sum, mut count) = ([0.0; 2], 0usize);
        for path in dumps {
            let path = path.as_ref();
            let bytes =
                std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
            let mut decoder = Decoder::new();
            let trim = decoder.feed(&bytes).find_map(|frame| match frame {
                Ok(Frame::Event(Event::TrimCaptured { phi, theta, .. })) => Some((phi, theta)),
                _ => None,
            });
            if let Some((phi, theta)) = trim {
                sum[0] += f64::from(phi);
                sum[1] += f64::from(theta);
                count += 1;
            }
        }
        Ok((count > 0).then(|| TrimAttitude {
            phi: sum[0] / count as f64,
            theta: sum[1] / count as f64,
        }))
    }

    /// The structure file's constants for this attitude: the sines, cosines and tangent
    /// its Euler kinematics and gravity terms are written with.
    fn constants(&self) -> [(&'static str, f64); 5] {
        [
            ("sin_phi0", self.phi.sin()),
            ("cos_phi0", self.phi.cos()),
            ("sin_theta0", self.theta.sin()),
            ("cos_theta0", self.theta.cos()),
            ("tan_theta0", self.theta.tan()),
        ]
    }
}

/// The 9-DOF hybrid structure (both vehicles), with the data of `vehicle` in it: the file
/// is written for the Bo-105 — its geometry constants (`hub_height`, `hub_forward`,
/// `shaft_tilt_sine`), gravity, its hover trim attitude, and the flap cross-coupling
/// `Kcs` it fixes from rotor theory — and another vehicle gets its own
/// ([`bo105::Rotor::flap_cross_coupling`], the hub position and shaft tilt of its main
/// rotor). `trim`: the captured trim attitude, when known (else the file's).
pub fn nine_dof_hybrid(
    vehicle: bo105::Vehicle,
    trim: Option<TrimAttitude>,
) -> Result<ModelStructure, StructureError> {
    with_vehicle_data(&models::BO105_9DOF_HYBRID, vehicle, trim, &BTreeMap::new())
}

/// A shipped structure with the data of `vehicle` in it: of the constants `hub_height`,
/// `hub_forward`, `shaft_tilt_sine`, `gravity` and (with `trim`) the trim attitude's, those
/// the file declares; a fixed `Kcs` (the flap cross-coupling, rotor data) if it has one;
/// then `overrides` of its constants. A file without any of them (the 6-DOF) is unchanged.
pub fn with_vehicle_data(
    shipped: &ShippedStructure,
    vehicle: bo105::Vehicle,
    trim: Option<TrimAttitude>,
    overrides: &BTreeMap<String, f64>,
) -> Result<ModelStructure, StructureError> {
    let declared = shipped.parse()?.constants;
    let helicopter = vehicle.helicopter();
    // The hub is at body (x, z) = (hub[0], hub[2]) from the CG, z down: its height above
    // the CG is −hub[2].
    let hub = helicopter.main_rotor.hub;
    let mut constants = BTreeMap::from([
        ("hub_height".to_string(), -hub[2]),
        ("hub_forward".to_string(), hub[0]),
        ("shaft_tilt_sine".to_string(), helicopter.shaft_tilt.sin()),
        ("gravity".to_string(), helicopter.gravity),
    ]);
    if let Some(trim) = trim {
        for (name, value) in trim.constants() {
            constants.insert(name.to_string(), value);
        }
    }
    constants.retain(|name, _| declared.contains_key(name));
    constants.extend(overrides.iter().map(|(name, &value)| (name.clone(), value)));
    let mut structure = shipped.parse_with_constants(&constants)?;
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
        let nine = nine_dof_hybrid(bo105::Vehicle::Bo105, None).unwrap();
        assert!(nine.states.len() > six.states.len());
        assert!(nine.states.iter().any(|s| s == "b1s"));
    }

    #[test]
    fn the_flap_cross_coupling_is_the_flown_vehicles_rotor_value() {
        let kcs = |vehicle| {
            let structure = nine_dof_hybrid(vehicle, None).unwrap();
            let index = structure.parameter_index("Kcs").unwrap();
            assert_eq!(structure.parameters[index].kind, ParameterKind::Fixed);
            structure.parameters[index].value
        };
        let file = models::BO105_9DOF_HYBRID.parse().unwrap();
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
        let heli = bo105::Helicopter::trex700l();
        let hover = bo105::trim(&heli, 0.0).unwrap();
        let campaign = nine_dof_hybrid(
            bo105::Vehicle::Trex700l,
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

    /// A dump holding a corrupt run of bytes and then one `TrimCaptured` event.
    fn dump_with_trim(dir: &Path, name: &str, phi: f32, theta: f32) -> std::path::PathBuf {
        use sweephold_protocol::codec::encode_to_vec;
        use sweephold_protocol::Controls;
        let event = Frame::Event(Event::TrimCaptured {
            tick: 210,
            sticks: Controls::from_array([0.0; 4]),
            phi,
            theta,
            psi: 0.0,
        });
        let mut bytes = vec![0x55, 0x13, 0x00];
        bytes.extend_from_slice(encode_to_vec(&event).unwrap().as_bytes());
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn the_trim_attitude_is_the_mean_of_the_dumps_captures() {
        let dir = std::env::temp_dir().join(format!("sweephold-trim-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let dumps = [
            dump_with_trim(&dir, "a.bin", -0.04, 0.03),
            dump_with_trim(&dir, "b.bin", -0.06, 0.05),
        ];
        let trim = TrimAttitude::captured(&dumps).unwrap().unwrap();
        assert!((trim.phi + 0.05).abs() < 1e-7, "{trim:?}");
        assert!((trim.theta - 0.04).abs() < 1e-7, "{trim:?}");
        // A dump without a capture contributes nothing; none at all gives None.
        let empty = dir.join("empty.bin");
        std::fs::write(&empty, [0u8; 16]).unwrap();
        assert_eq!(TrimAttitude::captured(&[&empty]).unwrap(), None);
        // A missing file is an error naming it.
        let missing = dir.join("missing.bin");
        let error = TrimAttitude::captured(&[&missing]).unwrap_err();
        assert!(error.to_string().contains("missing.bin"), "{error}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_captured_trim_attitude_sets_the_kinematics() {
        let trim = TrimAttitude {
            phi: -0.1,
            theta: 0.2,
        };
        let structure = nine_dof_hybrid(bo105::Vehicle::Bo105, Some(trim)).unwrap();
        assert_eq!(structure.constants["sin_phi0"], (-0.1f64).sin());
        assert_eq!(structure.constants["tan_theta0"], 0.2f64.tan());
        let model = structure.model(&structure.values()).unwrap();
        let state = |name: &str| structure.states.iter().position(|s| s == name).unwrap();
        // θ̇ = cos φ0 q − sin φ0 r and v̇ ∋ g cos φ0 cos θ0 φ.
        let f = |row: &str, column: &str| model.f[(state(row), state(column))];
        assert!((f("theta", "r") - 0.1f64.sin()).abs() < 1e-15);
        let g = bo105::Helicopter::bo105().gravity;
        assert!((f("v", "phi") - g * 0.1f64.cos() * 0.2f64.cos()).abs() < 1e-12);
        // Without one, the file's Bo-105 hover trim stays.
        let file = nine_dof_hybrid(bo105::Vehicle::Bo105, None).unwrap();
        assert_eq!(file.constants["sin_phi0"], -0.0460);
    }

    #[test]
    fn the_geometry_constants_are_the_flown_vehicles() {
        let file = models::BO105_9DOF_HYBRID.parse().unwrap();
        let bo105 = nine_dof_hybrid(bo105::Vehicle::Bo105, None).unwrap();
        let trex = nine_dof_hybrid(bo105::Vehicle::Trex700l, None).unwrap();
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
