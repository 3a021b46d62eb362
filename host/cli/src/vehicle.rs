//! The flown aircraft, and everything the command line takes from it: a shipped aircraft
//! (`bo105`, `trex700l`, `fbl700`) or an aircraft file (`docs/formats.md`, "Aircraft files"), read
//! once when the command line is. The simulator flies its physical description; the
//! flight controller flies the firmware preset it names; the campaign takes its sweep
//! bands, 9-DOF structure, trim balance and valid-range source from it. This is the one
//! place of the tool that turns an aircraft into those settings: the verbs ask it and do
//! not branch on vehicles.

use std::fmt;
use std::sync::Arc;

use aircraft::{Aircraft, TrimBalance, ValidRanges};
use bo105::{ActuatorModel, Helicopter};
use sweephold_firmware::Config;
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
        Ok(Vehicle {
            given: given.to_string(),
            aircraft: Arc::new(aircraft),
            preset,
        })
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

    /// The firmware's configuration for a test of `axis`: its preset.
    pub fn firmware_config(&self, axis: Axis) -> Config {
        Config::preset(self.preset, axis)
    }

    /// The two sweep bands flown per axis [rad/s].
    pub fn sweep_bands(&self) -> [(f64, f64); 2] {
        self.aircraft
            .identification
            .sweep_bands
            .map(|[low, high]| (low, high))
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
        assert_eq!(trex.servos(), bo105::SimOptions::default().actuator);
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
