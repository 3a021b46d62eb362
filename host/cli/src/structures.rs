//! The model structures a campaign fits and `sweephold fit --model NAME` resolves: the
//! structures shipped in sysid ([`sysid::models`]), with the flown vehicle's numbers put in
//! where the file carries the Bo-105's ([`truth::with_vehicle_data`]).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{anyhow, Context};
use sweephold_protocol::{Decoder, Event, Frame};

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

/// The trim attitude as the flight controller captured it, read from its dumps (the
/// `truth` crate, where [`TrimAttitude`] lives, does not read telemetry).
pub trait CapturedTrim: Sized {
    /// The mean of the `TrimCaptured` events in `dumps` (one per record), or None when no
    /// dump has one. What the flight-test engineer has: the aircraft's own trim, not the
    /// simulator's.
    fn captured(dumps: &[impl AsRef<Path>]) -> anyhow::Result<Option<Self>>;
}

impl CapturedTrim for TrimAttitude {
    fn captured(dumps: &[impl AsRef<Path>]) -> anyhow::Result<Option<TrimAttitude>> {
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
}
