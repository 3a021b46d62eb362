//! The model structures a campaign fits, compiled into the binary so that `sweephold
//! campaign` works from any directory.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Context;
use sweephold_protocol::{Decoder, Event, Frame};

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
        let file = ModelStructure::parse(NINE_DOF_HYBRID_TOML, "file").unwrap();
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
