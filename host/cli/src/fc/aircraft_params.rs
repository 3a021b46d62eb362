//! `fc params push AIRCRAFT.toml`: an aircraft file as board parameters. The board a
//! file describes is its firmware preset with the file's `[flight_controller]` settings
//! (the configuration `fly` and `campaign` build from it) and the mixer and servo frame
//! rates of its `[swash]` table; its values are the parameter table's
//! ([`sweephold_firmware::params::typed::values_of`]).
//!
//! Pushed are the parameters the file determines — swash type, phase and lead servo,
//! every servo's direction, centre, limits and throw, the frame rates, the mixer's
//! scales and ring, the hold's gains, limits, time constants, directions, reference and
//! thresholds, the abort limits, the pulse width, the excitation scale, the command
//! slew, the holds' slew, the pilot mode's gains (`PM_*`: the preset's; an aircraft file
//! states none, `sweephold tune --params` writes tuned ones to push after it) and the
//! test's collective source (`TEST_COL_SRC`: the board's table defaults to
//! `pilot`, an aircraft file that states no `collective` has its preset's `trim`, so
//! that a board set up from a file flies as `--fc board-sim` flies that file) — each the
//! file's value or, where the file states none, its preset's — and the head and tail
//! rotor speeds that place the vibration notches (`HEAD_RPM`, `TAIL_RPM`), from the
//! file's `main_rotor.head_speed` and `tail_rotor` speed when both lie in the table's
//! ranges ([`servo_plant::board_rotor_rpm`]; a full-size rotor such as the Bo-105's 424 rpm does not, and
//! keeps its preset's notches). Not pushed: the board's installation (receiver map and
//! ranges, IMU mounting), the airborne rule (`AIR_COL_MIN`, `AIR_TIME`: the pilot's
//! collective habits) and the test (chosen per record).

use sweephold_firmware::filters::FilterBankConfig;
use sweephold_firmware::params::{typed, ParamId, ParamTable, Params};
use sweephold_protocol::Axis;

use super::client::BoardValue;
use crate::fly::servo_plant;
use crate::vehicle::Vehicle;

/// The parameters an aircraft file does not set.
const NOT_FROM_THE_AIRCRAFT: [&str; 7] = [
    "RC_",
    "IMU_ROT",
    "TEST_",
    "SWP_",
    "PULSE_AMP",
    "NOISE_",
    "AIR_",
];

/// Whether `id` is one the aircraft file determines.
fn from_the_aircraft(id: ParamId, vehicle: &Vehicle) -> bool {
    if matches!(id, ParamId::HeadRpm | ParamId::TailRpm) {
        return servo_plant::board_rotor_rpm(vehicle.aircraft()).is_some();
    }
    if id == ParamId::TestColSrc {
        // A `TEST_` parameter, but the flight logic's, not the test's.
        return true;
    }
    let name = id.def().name;
    !NOT_FROM_THE_AIRCRAFT
        .iter()
        .any(|prefix| name.starts_with(prefix))
}

/// The typed parameters of a board set up for `vehicle`.
pub fn params(vehicle: &Vehicle) -> anyhow::Result<Params> {
    let swash = &vehicle.aircraft().swash;
    let mut flight = vehicle.firmware_config(Axis::Lat);
    flight.mixer = servo_plant::board_mixer(swash);
    let mut params = Params::preset(flight.vehicle);
    params.stack.app.flight = flight;
    [params.swash_frame_hz, params.tail_frame_hz] = servo_plant::board_frame_rates(swash);
    if let Some([head, tail]) = servo_plant::board_rotor_rpm(vehicle.aircraft()) {
        let filters = &mut params.stack.filters;
        *filters = FilterBankConfig::helicopter(filters.sample_rate_hz, head / 60.0, tail / 60.0);
    }
    // The table's own check: every value in range and the set consistent.
    let values = typed::values_of(&params);
    let table = ParamTable::from_values(values).map_err(|(id, error)| {
        anyhow::anyhow!(
            "aircraft `{}`: {} = {} cannot be a parameter: {}",
            vehicle.name(),
            id.def().name,
            values[id.index()],
            error.message()
        )
    })?;
    table.params().map_err(|e| {
        anyhow::anyhow!(
            "aircraft `{}` makes no consistent parameter set: {}",
            vehicle.name(),
            e.message()
        )
    })
}

/// The values `push` writes for `vehicle`, in table order.
pub fn values(vehicle: &Vehicle) -> anyhow::Result<Vec<BoardValue>> {
    let values = typed::values_of(&params(vehicle)?);
    Ok(ParamId::ALL
        .iter()
        .filter(|id| from_the_aircraft(**id, vehicle))
        .map(|id| BoardValue {
            name: id.def().name.to_string(),
            value: values[id.index()],
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweephold_firmware::CollectiveSource;

    #[test]
    fn the_file_s_collective_is_pushed() {
        let dir = std::env::temp_dir().join(format!("sweephold-col-src-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("trex-pilot-collective.toml");
        let text = aircraft::SHIPPED[1]
            .1
            .replacen("name = \"trex700l\"", "name = \"trex-pilot-collective\"", 1)
            .replacen(
                "preset = \"trex700l\"",
                "preset = \"trex700l\"\ncollective = \"pilot\"",
                1,
            );
        std::fs::write(&path, text).unwrap();
        let stated = Vehicle::parse(path.to_str().unwrap()).unwrap();
        let pushed = values(&stated).unwrap();
        let col_src: Vec<f32> = pushed
            .iter()
            .filter(|v| v.name == "TEST_COL_SRC")
            .map(|v| v.value)
            .collect();
        assert_eq!(col_src, [1.0]);
        assert_eq!(
            params(&stated).unwrap().stack.app.flight.collective,
            CollectiveSource::Pilot
        );
        // The board's own table defaults to the pilot's collective.
        assert_eq!(
            ParamTable::defaults(sweephold_protocol::VehicleId::Trex700l).get(ParamId::TestColSrc),
            1.0
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_fbl700_file_maps_onto_its_servo_geometry_and_settings() {
        let vehicle = Vehicle::shipped("fbl700");
        let values = values(&vehicle).unwrap();
        let get = |name: &str| {
            values
                .iter()
                .find(|v| v.name == name)
                .unwrap_or_else(|| panic!("{name} not pushed"))
                .value
        };
        assert_eq!(get("SWASH_TYPE"), 140.0);
        assert_eq!(get("SWASH_LEAD"), 1.0);
        assert_eq!(
            [get("SERVO1_DIR"), get("SERVO2_DIR"), get("SERVO3_DIR")],
            [1.0, -1.0, 1.0]
        );
        assert_eq!(
            [
                get("TAIL_MID"),
                get("TAIL_MIN"),
                get("TAIL_MAX"),
                get("TAIL_THROW")
            ],
            [760.0, 550.0, 970.0, 200.0]
        );
        assert_eq!([get("SERVO_RATE"), get("TAIL_RATE")], [333.0, 333.0]);
        assert_eq!(
            [
                get("EXC_SCALE_LAT"),
                get("EXC_SCALE_LON"),
                get("EXC_SCALE_PED"),
                get("EXC_SCALE_COL")
            ],
            [0.7, 0.7, 0.2, 1.0]
        );
        assert_eq!(
            [get("HOLD_LAT_P"), get("HOLD_LON_D"), get("HOLD_PED_I")],
            [2.12, 0.22, 0.045]
        );
        // 1800 rpm, the tail 4.5 times as fast: 30, 60 and 135 Hz notches.
        assert_eq!([get("HEAD_RPM"), get("TAIL_RPM")], [1800.0, 8100.0]);
        for name in [
            "RC_LAT",
            "IMU_ROT",
            "TEST_AXIS",
            "SWP_AMP",
            "NOISE_RMS",
            "AIR_COL_MIN",
            "AIR_TIME",
        ] {
            assert!(values.iter().all(|v| v.name != name), "{name} pushed");
        }
        // The typed set flies the configuration `fly` builds from the file.
        let params = params(&vehicle).unwrap();
        let mut expected = vehicle.firmware_config(Axis::Lat);
        expected.mixer = servo_plant::board_mixer(&vehicle.aircraft().swash);
        assert_eq!(params.stack.app.flight, expected);
        let notches = params.stack.filters.notches.map(|n| n.map(|n| n.centre_hz));
        assert_eq!(notches, [Some(30.0), Some(60.0), Some(135.0)]);
        assert_eq!(get("TEST_COL_SRC"), 0.0, "the preset's trim collective");
    }

    #[test]
    fn a_full_size_rotor_keeps_the_presets_notches_and_a_model_s_gets_its_own() {
        // The Bo-105 turns at 424 rpm, below HEAD_RPM's range.
        let bo105 = Vehicle::shipped("bo105");
        assert_eq!(servo_plant::board_rotor_rpm(bo105.aircraft()), None);
        assert!(values(&bo105)
            .unwrap()
            .iter()
            .all(|v| !v.name.ends_with("_RPM")));
        // The TREX 700L file says 1900 rpm and 8930 rpm, not the firmware preset's 2100.
        let trex = Vehicle::shipped("trex700l");
        let [head, tail] = servo_plant::board_rotor_rpm(trex.aircraft()).unwrap();
        assert!((head - 1900.0).abs() < 0.01 && (tail - 8930.0).abs() < 0.05);
    }

    #[test]
    fn the_presets_files_push_the_presets_mixer() {
        for name in ["bo105", "trex700l"] {
            let vehicle = Vehicle::shipped(name);
            let params = params(&vehicle).unwrap();
            assert_eq!(
                params.stack.app.flight.mixer,
                sweephold_firmware::mixer::MixerConfig::trex700l(),
                "{name}"
            );
        }
    }
}
