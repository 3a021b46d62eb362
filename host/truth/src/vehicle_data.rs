//! A shipped structure with the flown vehicle's data in it: the files are written for the
//! Bo-105 (its geometry, gravity, hover trim attitude and rotor's flap cross-coupling),
//! and a structure fitted to, or scored against, another vehicle needs that vehicle's
//! numbers.

use std::collections::BTreeMap;

use aircraft::Aircraft;
use rotorsim::{ActuatorModel, Helicopter};
use sysid::fit::structure::ParameterKind;
use sysid::fit::{ModelStructure, StructureError};
use sysid::models::{self, ShippedStructure};

use crate::Error;

/// The trim attitude a structure's Euler kinematics and gravity terms are written about
/// \[rad\]: the one a flight controller captured before its excitation, or a simulator's
/// hover trim.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrimAttitude {
    /// Roll φ0.
    pub phi: f64,
    /// Pitch θ0.
    pub theta: f64,
}

impl TrimAttitude {
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

/// The aircraft's 9-DOF hybrid structure (its file's `identification.structure`:
/// `bo105-9dof-hybrid`, or `trex700l-9dof-hybrid` with its servos), with the data of
/// `aircraft` in it — its geometry
/// constants (`hub_height`, `hub_forward`, `shaft_tilt_sine`), gravity, the servos' ω_n
/// and ζ where the file models them, the flap cross-coupling `Kcs` the file fixes from
/// rotor theory ([`rotorsim::Rotor::flap_cross_coupling`]) — and `trim`: the captured trim
/// attitude, when known (else the file's).
pub fn nine_dof_hybrid(
    aircraft: &Aircraft,
    trim: Option<TrimAttitude>,
) -> Result<ModelStructure, Error> {
    let name = &aircraft.identification.structure;
    let file = hybrid_structures()
        .find(|file| file.name == name)
        .ok_or_else(|| Error::UnknownStructure(name.clone()))?;
    Ok(with_vehicle_data(file, aircraft, trim, &BTreeMap::new())?)
}

/// The shipped structures an aircraft can be identified with: the 9-DOF hybrids, whose
/// files declare the vehicle's geometry (`hub_height`) for [`with_vehicle_data`] to put in.
pub fn hybrid_structures() -> impl Iterator<Item = &'static ShippedStructure> {
    models::SHIPPED.iter().filter(|file| {
        file.parse()
            .is_ok_and(|structure| structure.constants.contains_key("hub_height"))
    })
}

/// A shipped structure with the data of `aircraft` in it: of the constants `hub_height`,
/// `hub_forward`, `shaft_tilt_sine`, `gravity`, `servo_natural_frequency`,
/// `servo_damping`, `inertia_xz_over_zz`, `tail_arm`, `tail_height`, `izz_over_ixx`,
/// `mass_over_iyy` and (with `trim`) the trim attitude's, those
/// the file declares; a fixed `Kcs` (the flap cross-coupling, rotor data) if it has one;
/// then `overrides` of its constants. A file without any of them (the 6-DOF) is unchanged.
pub fn with_vehicle_data(
    shipped: &ShippedStructure,
    aircraft: &Aircraft,
    trim: Option<TrimAttitude>,
    overrides: &BTreeMap<String, f64>,
) -> Result<ModelStructure, StructureError> {
    let declared = shipped.parse()?.constants;
    let helicopter = Helicopter::from_aircraft(aircraft);
    let mut constants = vehicle_constants(aircraft);
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

/// σ of a servo's natural frequency when the aircraft file states none, relative to the
/// value: a data sheet gives the servo unloaded, and under a rotor's loads and another
/// supply voltage its bandwidth is commonly 10–20 % lower; 20 % keeps a wrong data-sheet
/// value within 1σ, so that the responses, which inform ω_n well (Cramér–Rao about
/// 1–2 % on the TREX), decide.
pub const SERVO_NATURAL_FREQUENCY_DEFAULT_RELATIVE_SIGMA: f64 = 0.2;

/// σ of a servo's damping ratio when the file states none: servo data sheets do not
/// state it, and hobby servos' step responses range from about 0.5 to 0.9.
pub const SERVO_DAMPING_DEFAULT_SIGMA: f64 = 0.2;

/// The constants a structure may declare that come from the aircraft file, by name, as
/// [`with_vehicle_data`] puts them in (the trim attitude's and `Kcs` aside).
pub(crate) fn vehicle_constants(aircraft: &Aircraft) -> BTreeMap<String, f64> {
    let helicopter = Helicopter::from_aircraft(aircraft);
    // The hub is at body (x, z) = (hub[0], hub[2]) from the CG, z down: its height above
    // the CG is −hub[2].
    let hub = helicopter.main_rotor.hub;
    // The servos of the aircraft file, which `sweephold fly` flies with too.
    let servo = ActuatorModel::from_aircraft(aircraft);
    BTreeMap::from([
        ("hub_height".to_string(), -hub[2]),
        ("hub_forward".to_string(), hub[0]),
        ("shaft_tilt_sine".to_string(), helicopter.shaft_tilt.sin()),
        ("gravity".to_string(), helicopter.gravity),
        // A structure file with `[actuators]` declares these.
        (
            "servo_natural_frequency".to_string(),
            servo.natural_frequency_rad_s,
        ),
        ("servo_damping".to_string(), servo.damping),
        // The priors' σ of the servos (a structure that identifies them declares these):
        // the file's, else the default of their kind.
        (
            "servo_natural_frequency_sigma".to_string(),
            aircraft.servos.natural_frequency.sigma.unwrap_or(
                SERVO_NATURAL_FREQUENCY_DEFAULT_RELATIVE_SIGMA * servo.natural_frequency_rad_s,
            ),
        ),
        (
            "servo_damping_sigma".to_string(),
            aircraft
                .servos
                .damping
                .sigma
                .unwrap_or(SERVO_DAMPING_DEFAULT_SIGMA),
        ),
        (
            "inertia_xz_over_zz".to_string(),
            helicopter.ixz / helicopter.izz,
        ),
        // The tail rotor's hub behind and above the CG (body x forward, z down).
        ("tail_arm".to_string(), -helicopter.tail_rotor.hub[0]),
        ("tail_height".to_string(), -helicopter.tail_rotor.hub[2]),
        ("izz_over_ixx".to_string(), helicopter.izz / helicopter.ixx),
        (
            "mass_over_iyy".to_string(),
            helicopter.mass / helicopter.iyy,
        ),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bo105_aircraft() -> Aircraft {
        aircraft::shipped("bo105").unwrap()
    }

    fn trex_aircraft() -> Aircraft {
        aircraft::shipped("trex700l").unwrap()
    }

    #[test]
    fn the_flap_cross_coupling_is_the_flown_vehicles_rotor_value() {
        let kcs = |vehicle: &Aircraft| {
            let structure = nine_dof_hybrid(vehicle, None).unwrap();
            let index = structure.parameter_index("Kcs").unwrap();
            assert_eq!(structure.parameters[index].kind, ParameterKind::Fixed);
            structure.parameters[index].value
        };
        let file = models::BO105_9DOF_HYBRID.parse().unwrap();
        let in_file = file.parameters[file.parameter_index("Kcs").unwrap()].value;
        let bo105_rotor = rotorsim::Helicopter::bo105().flap_cross_coupling();
        // The file's number is the Bo-105 rotor's, rounded to the digits written.
        assert!(
            (in_file - bo105_rotor).abs() < 5e-5,
            "{in_file} vs {bo105_rotor}"
        );
        assert_eq!(kcs(&bo105_aircraft()), bo105_rotor);
        let trex = rotorsim::Helicopter::trex700l().flap_cross_coupling();
        assert_eq!(kcs(&trex_aircraft()), trex);
        assert!(
            (trex - bo105_rotor).abs() > 0.01,
            "TREX {trex}, Bo-105 {bo105_rotor}"
        );
    }

    #[test]
    fn a_captured_trim_attitude_sets_the_kinematics() {
        let trim = TrimAttitude {
            phi: -0.1,
            theta: 0.2,
        };
        let structure = nine_dof_hybrid(&bo105_aircraft(), Some(trim)).unwrap();
        assert_eq!(structure.constants["sin_phi0"], (-0.1f64).sin());
        assert_eq!(structure.constants["tan_theta0"], 0.2f64.tan());
        let model = structure.model(&structure.values()).unwrap();
        let state = |name: &str| structure.states.iter().position(|s| s == name).unwrap();
        // θ̇ = cos φ0 q − sin φ0 r and v̇ ∋ g cos φ0 cos θ0 φ.
        let f = |row: &str, column: &str| model.f[(state(row), state(column))];
        assert!((f("theta", "r") - 0.1f64.sin()).abs() < 1e-15);
        let g = rotorsim::Helicopter::bo105().gravity;
        assert!((f("v", "phi") - g * 0.1f64.cos() * 0.2f64.cos()).abs() < 1e-12);
        // Without one, the file's Bo-105 hover trim stays.
        let file = nine_dof_hybrid(&bo105_aircraft(), None).unwrap();
        assert_eq!(file.constants["sin_phi0"], -0.0460);
    }

    #[test]
    fn the_geometry_constants_are_the_flown_vehicles() {
        let file = models::BO105_9DOF_HYBRID.parse().unwrap();
        let bo105 = nine_dof_hybrid(&bo105_aircraft(), None).unwrap();
        let trex = nine_dof_hybrid(&trex_aircraft(), None).unwrap();
        // The file's numbers are the Bo-105's geometry (to the digits written).
        let bo105_data = rotorsim::Helicopter::bo105();
        for (name, value) in [
            ("hub_height", -bo105_data.main_rotor.hub[2]),
            ("hub_forward", bo105_data.main_rotor.hub[0]),
            ("shaft_tilt_sine", bo105_data.shaft_tilt.sin()),
        ] {
            assert!((file.constants[name] - value).abs() < 5e-4, "{name}");
            assert_eq!(bo105.constants[name], value, "{name}");
        }
        let trex_hub = -rotorsim::Helicopter::trex700l().main_rotor.hub[2];
        assert_eq!(trex.constants["hub_height"], trex_hub);
        assert!(trex_hub > 0.0 && trex_hub < 0.5, "{trex_hub}");
        // It reaches the model: Kpq = hub_height·Lfu.
        let kpq = |s: &ModelStructure| s.parameter_value("Kpq", &s.values()).unwrap();
        let lfu = |s: &ModelStructure| s.parameter_value("Lfu", &s.values()).unwrap();
        assert!((kpq(&trex) - trex_hub * lfu(&trex)).abs() < 1e-15);
        assert!((kpq(&bo105) - 1.48 * lfu(&bo105)).abs() < 1e-15);
    }

    #[test]
    fn the_trex_yaw_flap_coupling_follows_its_product_of_inertia() {
        let nb1s = |s: &ModelStructure| s.parameter_value("Nb1s", &s.values()).unwrap();
        let lb1s = |s: &ModelStructure| s.parameter_value("Lb1s", &s.values()).unwrap();
        let trex = nine_dof_hybrid(&trex_aircraft(), None).unwrap();
        let data = rotorsim::Helicopter::trex700l();
        assert_eq!(trex.constants["inertia_xz_over_zz"], data.ixz / data.izz);
        // Derived, not a base parameter the fit could move.
        assert!(trex.parameter_index("Nb1s").is_none());
        assert!(trex.derived.iter().any(|d| d.name == "Nb1s"));
        assert_eq!(nb1s(&trex), data.ixz / data.izz * lb1s(&trex));
        // Another airframe's product of inertia reaches the model through the constant.
        let overrides = BTreeMap::from([("inertia_xz_over_zz".to_string(), 0.05)]);
        let file = &models::TREX700L_9DOF_HYBRID;
        let tilted = with_vehicle_data(file, &trex_aircraft(), None, &overrides).unwrap();
        assert!((nb1s(&tilted) - 0.05 * lb1s(&tilted)).abs() < 1e-12);
        assert!(nb1s(&tilted) > 0.0);
        // The Bo-105's file keeps N_b1s free and declares no such constant.
        let bo105 = nine_dof_hybrid(&bo105_aircraft(), None).unwrap();
        assert!(!bo105.constants.contains_key("inertia_xz_over_zz"));
        let index = bo105.parameter_index("Nb1s").unwrap();
        assert_eq!(bo105.parameters[index].kind, ParameterKind::Free);
    }

    #[test]
    fn the_servo_natural_frequency_is_estimated_under_the_aircraft_files_prior() {
        use sysid::fit::structure::Prior;
        let prior = |aircraft: &Aircraft| {
            let structure = nine_dof_hybrid(aircraft, None).unwrap();
            let index = structure.parameter_index("servo_omega").unwrap();
            let parameter = &structure.parameters[index];
            assert_eq!(parameter.kind, ParameterKind::Free);
            assert_eq!(
                parameter.value,
                parameter.prior.unwrap().value,
                "starts at it"
            );
            // The four actuators take their ω_n from it; ζ stays the file's constant.
            assert!(structure
                .actuator_parameters
                .iter()
                .all(|&[w, z]| w == Some(index) && z.is_none()));
            parameter.prior.unwrap()
        };
        // The TREX's file states no σ: the default of the kind, 20 % of 60 rad/s.
        assert_eq!(
            prior(&trex_aircraft()),
            Prior {
                value: 60.0,
                sigma: 12.0
            }
        );
        // The fbl700's states "48 ± 5 rad/s".
        let fbl = aircraft::shipped("fbl700").unwrap();
        assert_eq!(
            prior(&fbl),
            Prior {
                value: 48.0,
                sigma: 5.0
            }
        );
        // The Bo-105's structure has no identified servo (its delays stand for it).
        let bo105 = nine_dof_hybrid(&bo105_aircraft(), None).unwrap();
        assert!(bo105.parameters.iter().all(|p| p.prior.is_none()));
    }

    /// The TREX file ties its body terms to the tail rotor, the shaft and the hub (its
    /// header). Checked here against the simulator's hover linearization, which knows
    /// nothing of those ties: each relation holds there within 5 %.
    #[test]
    fn the_trex_body_terms_are_its_tail_rotors_shafts_and_hubs_in_the_simulator() {
        let truth = crate::VehicleTruth::at_hover(&trex_aircraft()).unwrap();
        let structure = nine_dof_hybrid(&trex_aircraft(), None).unwrap();
        let c = |name: &str| structure.constants[name];
        let a = |row: &str, column: &str| truth.a(row, column).unwrap();
        let b = |row: &str, control: &str| truth.b(row, control).unwrap();
        let close = |what: &str, value: f64, expected: f64| {
            assert!(
                (value - expected).abs() <= 0.05 * expected.abs(),
                "{what}: simulator {value}, tie {expected}"
            );
        };
        let (arm, height) = (c("tail_arm"), c("tail_height"));
        assert!(arm > 0.5 && height > 0.0, "{arm} {height}");
        close("Y_p", a("v", "p"), height * a("v", "v"));
        close("Y_r", a("v", "r"), -arm * a("v", "v"));
        close("N_p", a("r", "p"), height * a("r", "v"));
        close("N_r", a("r", "r"), -arm * a("r", "v"));
        close("L_r", a("p", "r"), height * c("izz_over_ixx") * a("r", "v"));
        let data = rotorsim::Helicopter::trex700l();
        close(
            "N_v",
            a("r", "v"),
            -arm * data.mass / data.izz * a("v", "v"),
        );
        // Upright shaft, hub over the CG: no x force or pitching moment from thrust, and
        // nothing gives X_r or M_v in hover.
        assert_eq!((c("shaft_tilt_sine"), c("hub_forward")), (0.0, 0.0));
        for (value, what) in [
            (a("u", "w"), "X_w"),
            (b("u", "col"), "X_col"),
            (b("q", "col"), "M_col"),
            (a("u", "r"), "X_r"),
            (a("q", "v"), "M_v"),
        ] {
            assert!(value.abs() < 1e-6, "{what} = {value}");
        }
    }
}
