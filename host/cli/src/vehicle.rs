//! The flown aircraft, and everything the command line takes from it: a shipped aircraft
//! (`bo105`, `trex700l`, `fbl700`) or an aircraft file (`docs/formats.md`, "Aircraft files"), read
//! once when the command line is. The simulator flies its physical description; the
//! flight controller flies the firmware preset it names with the settings the file states
//! in its place (hold gains and thresholds, excitation scale, slew, abort limits); the
//! campaign takes its sweep
//! bands, 9-DOF structure, trim balance and valid-range source from it. This is the one
//! place of the tool that turns an aircraft into those settings: the verbs ask it and do
//! not branch on vehicles.

use std::fmt;
use std::sync::Arc;

use aircraft::{Aircraft, TrimBalance, ValidRanges};
use rotorsim::{ActuatorModel, Helicopter};
use sweephold_firmware::{CollectiveSource, Config, HoldReference};
use sweephold_protocol::{Axis, VehicleId};
use sysid::frf::RangeSource;

/// An aircraft as given on the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct Vehicle {
    /// What was given: a shipped name or a file's path (passed on as it was).
    given: String,
    aircraft: Arc<Aircraft>,
    preset: VehicleId,
}

impl Vehicle {
    /// Read `--vehicle NAME|FILE` (clap value parser): the aircraft, checked, with a firmware
    /// preset and a shipped hybrid structure it can be identified with.
    pub fn parse(given: &str) -> Result<Vehicle, String> {
        let aircraft = aircraft::resolve(given).map_err(|e| e.to_string())?;
        let where_ = || format!("aircraft `{}`", aircraft.name);
        let preset = match aircraft.flight_controller.preset.as_str() {
            "bo105" => VehicleId::Bo105,
            "trex700l" => VehicleId::Trex700l,
            other => return Err(format!("{}: no firmware preset `{other}`", where_())),
        };
        let structure = &aircraft.identification.structure;
        if !truth::hybrid_structures().any(|file| file.name == structure) {
            return Err(format!(
                "{}: identification.structure `{structure}` is not a shipped 9-DOF hybrid \
                 ({})",
                where_(),
                truth::hybrid_structures()
                    .map(|file| file.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        let vehicle = Vehicle {
            given: given.to_string(),
            aircraft: Arc::new(aircraft),
            preset,
        };
        // The file's settings are checked one by one when it is read; here, with the
        // preset's in the places it leaves, as the firmware will check them.
        for axis in Axis::ALL {
            if let Err(error) = vehicle.firmware_config(axis).validate() {
                return Err(format!(
                    "aircraft `{}`: flight_controller: with preset `{}`'s other settings: \
                     {error}",
                    vehicle.name(),
                    vehicle.aircraft.flight_controller.preset
                ));
            }
        }
        Ok(vehicle)
    }

    /// A shipped aircraft (`bo105`, `trex700l`, `fbl700`).
    ///
    /// # Panics
    /// When `name` is not shipped: for names written in the code.
    pub fn shipped(name: &str) -> Vehicle {
        Vehicle::parse(name).expect("a shipped aircraft")
    }

    /// Its name (`trex700l`), in files and JSON.
    pub fn name(&self) -> &str {
        &self.aircraft.name
    }

    /// What was given on the command line, to pass on to a stage.
    pub fn given(&self) -> &str {
        &self.given
    }

    /// The aircraft file's contents.
    pub fn aircraft(&self) -> &Aircraft {
        &self.aircraft
    }

    /// The simulator's parameter set.
    pub fn helicopter(&self) -> Helicopter {
        Helicopter::from_aircraft(&self.aircraft)
    }

    /// The simulator's servos.
    pub fn servos(&self) -> ActuatorModel {
        ActuatorModel::from_aircraft(&self.aircraft)
    }

    /// The firmware preset the flight controller flies (and the Header names).
    pub fn preset(&self) -> VehicleId {
        self.preset
    }

    /// The firmware's configuration for a test of `axis`: its preset, with each setting the
    /// file's `[flight_controller]` states in place of the preset's (the settings the file
    /// leaves out stay the preset's to the bit).
    pub fn firmware_config(&self, axis: Axis) -> Config {
        let mut config = Config::preset(self.preset, axis);
        let file = &self.aircraft.flight_controller;
        let set = |slot: &mut f32, value: Option<f64>| {
            if let Some(value) = value {
                *slot = value as f32;
            }
        };
        if let Some(reference) = file.hold_reference {
            config.hold_reference = match reference {
                aircraft::HoldReference::Level => HoldReference::Level,
                aircraft::HoldReference::Trim => HoldReference::Trim,
            };
        }
        if let Some(source) = file.collective {
            config.collective = match source {
                aircraft::CollectiveSource::Trim => CollectiveSource::Trim,
                aircraft::CollectiveSource::Pilot => CollectiveSource::Pilot,
            };
        }
        set(&mut config.test.hold_engage_rad, file.hold_engage);
        set(&mut config.test.hold_release_rad, file.hold_release);
        set(&mut config.test.pulse.width_s, file.pulse_width);
        if let Some(scale) = file.excitation_scale {
            config.excitation_scale.per_axis = scale.map(|s| s as f32);
        }
        if let Some(slew) = file.command_slew {
            config.slew.per_s = slew.map(|rate| rate.map_or(f32::INFINITY, |r| r as f32));
        }
        if let Some(slew) = file.hold_slew {
            config.hold_slew.per_s = slew.map(|rate| rate.map_or(f32::INFINITY, |r| r as f32));
        }
        set(&mut config.safety.attitude_limit_rad, file.attitude_limit);
        if let Some(limits) = file.rate_limits {
            config.safety.rate_limit_rad_s = limits.map(|l| l as f32);
        }
        set(&mut config.safety.pilot_override, file.pilot_override);
        let held = [
            &mut config.gains.lat,
            &mut config.gains.lon,
            &mut config.gains.ped,
        ];
        for (gains, stated) in held.into_iter().zip(&file.hold) {
            set(&mut gains.kp, stated.kp);
            set(&mut gains.ki, stated.ki);
            set(&mut gains.kd, stated.kd);
            set(&mut gains.output_limit, stated.output_limit);
            set(&mut gains.integrator_limit, stated.integrator_limit);
            set(&mut gains.bumpless_time_s, stated.bumpless_time);
            set(&mut gains.release_time_s, stated.release_time);
            if let Some(reversed) = stated.reversed {
                gains.reversed = reversed;
            }
        }
        config
    }

    /// The two sweep bands flown per axis [rad/s].
    pub fn sweep_bands(&self) -> [(f64, f64); 2] {
        self.aircraft
            .identification
            .sweep_bands
            .map(|[low, high]| (low, high))
    }

    /// The a-priori constants the 9-DOF structure takes from the file, with their σ.
    pub fn file_constants(&self) -> anyhow::Result<Vec<truth::FileConstant>> {
        let structure = self.structure();
        let shipped = truth::hybrid_structures()
            .find(|file| file.name == structure)
            .ok_or_else(|| anyhow::anyhow!("no shipped 9-DOF hybrid `{structure}`"))?;
        Ok(truth::file_constants(shipped, &self.aircraft)?)
    }

    /// The shipped 9-DOF hybrid structure the campaign fits.
    pub fn structure(&self) -> &str {
        &self.aircraft.identification.structure
    }

    /// How the campaign's 9-DOF fit takes the trim points by default.
    pub fn trim_balance(&self) -> TrimBalance {
        self.aircraft.identification.trim_balance
    }

    /// Where the campaign's valid frequency ranges come from.
    pub fn range_source(&self) -> RangeSource {
        match self.aircraft.identification.valid_ranges {
            ValidRanges::Estimate => RangeSource::Estimate,
            ValidRanges::SweepReference => RangeSource::SweepReference,
        }
    }
}

impl Default for Vehicle {
    /// The Bo-105.
    fn default() -> Vehicle {
        Vehicle::shipped("bo105")
    }
}

impl fmt::Display for Vehicle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_aircraft_give_the_settings_they_were_compiled_with() {
        let bo105 = Vehicle::shipped("bo105");
        assert_eq!(bo105.preset(), VehicleId::Bo105);
        assert_eq!(bo105.sweep_bands(), crate::fly::plan::PAPER_BANDS);
        assert_eq!(
            bo105.firmware_config(Axis::Lat),
            Config::bo105_default(Axis::Lat)
        );
        assert_eq!(bo105.structure(), sysid::models::BO105_9DOF_HYBRID.name);
        assert_eq!(bo105.trim_balance(), TrimBalance::Hold);
        assert_eq!(bo105.range_source(), RangeSource::SweepReference);
        let trex = Vehicle::shipped("trex700l");
        assert_eq!(trex.preset(), VehicleId::Trex700l);
        assert_eq!(trex.sweep_bands(), crate::fly::plan::TREX700L_BANDS);
        assert_eq!(
            trex.firmware_config(Axis::Ped),
            Config::trex700l_default(Axis::Ped)
        );
        assert_eq!(trex.structure(), sysid::models::TREX700L_9DOF_HYBRID.name);
        assert_eq!(trex.trim_balance(), TrimBalance::Joint);
        assert_eq!(trex.range_source(), RangeSource::Estimate);
        assert_eq!(trex.servos(), rotorsim::SimOptions::default().actuator);
        // The third flies the TREX's preset with the gains, cyclic excitation, slew
        // limits (the holds' share limited, the whole command not), hysteresis and
        // release fades its file states, and the preset's everything else.
        let fbl = Vehicle::shipped("fbl700");
        assert_eq!(fbl.preset(), VehicleId::Trex700l);
        let own = fbl.firmware_config(Axis::Lat);
        let mut expected = Config::trex700l_default(Axis::Lat);
        expected.excitation_scale.per_axis = [0.7, 0.7, 0.2, 1.0];
        expected.slew = sweephold_firmware::slew::CommandSlew::NONE;
        expected.hold_slew.per_s = [3.6, 3.6, 4.0];
        expected.test.hold_engage_rad = 6.0_f32.to_radians();
        expected.test.hold_release_rad = 4.0_f32.to_radians();
        expected.gains.lat.release_time_s = 0.3;
        expected.gains.lon.release_time_s = 0.3;
        for (gains, [kp, ki, kd]) in [
            (&mut expected.gains.lat, [2.12, 0.07, 0.113]),
            (&mut expected.gains.lon, [2.94, 0.074, 0.22]),
            (&mut expected.gains.ped, [0.545, 0.045, 0.109]),
        ] {
            (gains.kp, gains.ki, gains.kd) = (kp, ki, kd);
        }
        assert_eq!(own, expected);
    }

    #[test]
    fn a_files_flight_settings_replace_the_presets_and_only_those() {
        let dir = std::env::temp_dir().join(format!("vehicle-fc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let trex = aircraft::SHIPPED[1].1;
        let preset = "preset = \"trex700l\"\n";
        let settings = "hold_engage = \"5 deg\"\nexcitation_scale = [0.8, 0.9, 0.2, 1.0]\n\
             command_slew = { lon = \"3 /s\" }\nhold_slew = { ped = \"2 /s\" }\nrate_limits = [\"3 rad/s\", \"3 rad/s\", \"4 rad/s\"]\n\
             hold.lon = { kp = \"2.5 /rad\", release_time = \"0.2 s\" }\n";
        let path = dir.join("tuned.toml");
        std::fs::write(&path, trex.replace(preset, &format!("{preset}{settings}"))).unwrap();
        let tuned = Vehicle::parse(path.to_str().unwrap()).unwrap();
        let got = tuned.firmware_config(Axis::Lon);
        let mut expected = Config::trex700l_default(Axis::Lon);
        expected.test.hold_engage_rad = (5.0 * std::f64::consts::PI / 180.0) as f32;
        expected.excitation_scale.per_axis = [0.8, 0.9, 0.2, 1.0];
        expected.slew.per_s = [f32::INFINITY, 3.0, f32::INFINITY, f32::INFINITY];
        expected.hold_slew.per_s = [f32::INFINITY, f32::INFINITY, 2.0];
        expected.safety.rate_limit_rad_s = [3.0, 3.0, 4.0];
        expected.gains.lon.kp = 2.5;
        expected.gains.lon.release_time_s = 0.2;
        assert_eq!(got, expected);
        // A setting that is valid alone but not with the preset's others: one line.
        let clash = "hold.lat = { integrator_limit = 0.5 }\n";
        std::fs::write(&path, trex.replace(preset, &format!("{preset}{clash}"))).unwrap();
        let error = Vehicle::parse(path.to_str().unwrap()).unwrap_err();
        assert!(
            error.contains(
                "flight_controller: with preset `trex700l`'s other settings: \
                 attitude-hold gains or limits invalid"
            ),
            "{error}"
        );
        assert!(!error.contains('\n'));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_file_names_a_preset_and_a_structure_that_exist() {
        let dir = std::env::temp_dir().join(format!("vehicle-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let trex = aircraft::SHIPPED[1].1;
        for (from, to, expected) in [
            (
                "structure = \"trex700l-9dof-hybrid\"",
                "structure = \"bo105-6dof\"",
                "identification.structure `bo105-6dof` is not a shipped 9-DOF hybrid",
            ),
            (
                "preset = \"trex700l\"",
                "preset = \"ec135\"",
                "flight_controller.preset: `ec135` is not a firmware preset",
            ),
        ] {
            let path = dir.join("variant.toml");
            std::fs::write(&path, trex.replace(from, to)).unwrap();
            let error = Vehicle::parse(path.to_str().unwrap()).unwrap_err();
            assert!(error.contains(expected), "{error}");
        }
        let path = dir.join("same.toml");
        std::fs::write(&path, trex).unwrap();
        let read = Vehicle::parse(path.to_str().unwrap()).unwrap();
        assert_eq!(read.given(), path.to_str().unwrap());
        assert_eq!(read.aircraft(), Vehicle::shipped("trex700l").aircraft());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
