//! The table: names, ranges, defaults from the presets, set and get, refusals, and the
//! typed view.

use super::*;
use crate::board_stack::StackConfig;
use sweephold_protocol::Axis;

const VEHICLES: [VehicleId; 2] = [VehicleId::Trex700l, VehicleId::Bo105];

#[test]
fn names_are_short_upper_case_and_unique() {
    for (i, def) in DEFS.iter().enumerate() {
        assert!(
            !def.name.is_empty() && def.name.len() <= MAX_NAME_LEN,
            "{}",
            def.name
        );
        assert!(
            def.name
                .bytes()
                .all(|b| b.is_ascii_uppercase() || b.is_ascii_digit() || b == b'_'),
            "{}",
            def.name
        );
        assert!(def.min <= def.max, "{}", def.name);
        for other in DEFS.iter().skip(i + 1) {
            assert_ne!(def.name, other.name);
        }
        let id = ParamId::from_name(def.name).unwrap();
        assert_eq!(id.index(), i);
        assert_eq!(ParamId::from_index(i), Some(id));
        if let ParamKind::OneOf(choices) = def.kind {
            assert!(choices.iter().all(|c| (def.min..=def.max).contains(c)));
        }
    }
    assert_eq!(ParamId::from_index(COUNT), None);
}

#[test]
fn the_defaults_are_the_presets_bit_for_bit() {
    for vehicle in VEHICLES {
        let table = ParamTable::defaults(vehicle);
        // Every default passes its own definition.
        assert_eq!(ParamTable::from_values(*table.values()), Ok(table));
        let params = table.params().unwrap();
        assert_eq!(params, Params::preset(vehicle));
        // The application's preset, but for the collective: the pilot's on the board.
        let mut app = crate::app::AppConfig::preset(vehicle, Axis::Lat);
        assert_eq!(app.flight.collective, crate::CollectiveSource::Trim);
        app.flight.collective = crate::CollectiveSource::Pilot;
        assert_eq!(params.stack, StackConfig::with_app(app));
    }
    let table = ParamTable::defaults(VehicleId::Trex700l);
    // A few defaults by name, from the TREX 700L preset.
    for (name, value) in [
        ("SWASH_TYPE", 120.0),
        ("SERVO1_MID", 1520.0),
        ("COLL_MIN", -0.5),
        ("COLL_MAX", 0.5),
        ("CYC_RING", 1.5),
        ("HEAD_RPM", 2100.0),
        ("TAIL_RPM", 9600.0),
        ("HOLD_ENGAGE", 4.5),
        ("ABORT_RATE_Y", 250.0),
        ("RC_MODE", 8.0),
        ("IMU_ROT", 0.0),
        ("SERVO_RATE", 333.0),
        ("TAIL_RATE", 333.0),
        ("TEST_COL_SRC", 1.0),
        ("AIR_COL_MIN", -0.2),
        ("AIR_TIME", 1.0),
    ] {
        assert_eq!(table.get_by_name(name), Ok(value), "{name}");
    }
}

#[test]
fn every_parameter_reaches_the_configuration_and_reads_back() {
    let base = ParamTable::defaults(VehicleId::Trex700l);
    let base_params = base.params().unwrap();
    for id in ParamId::ALL {
        let def = id.def();
        let current = base.get(id);
        // Another valid value: the other end of the range, another choice, or for
        // values whose other end breaks the set, a nearby value.
        let candidates: &[f32] = match def.kind {
            ParamKind::OneOf(choices) => choices,
            _ => &[
                def.min,
                def.max,
                current + 1.0,
                current - 1.0,
                current * 0.9,
                current * 1.1,
            ],
        };
        let changed = candidates.iter().copied().find_map(|value| {
            let mut table = base;
            (value != current && table.set(id, value).is_ok())
                .then_some(table)
                .and_then(|t| t.params().ok().map(|p| (t, p)))
        });
        let (table, params) =
            changed.unwrap_or_else(|| panic!("{}: no other valid value", def.name));
        assert_ne!(params, base_params, "{} changes nothing", def.name);
        assert_eq!(
            typed::values_of(&params),
            *table.values(),
            "{} does not read back",
            def.name
        );
    }
}

#[test]
fn set_refuses_bad_values_and_leaves_the_table_unchanged() {
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    let before = table;
    assert_eq!(
        table.set_by_name("NO_SUCH_PARAM", 1.0),
        Err(SetError::UnknownName)
    );
    assert_eq!(
        table.set_by_name("swash_type", 140.0),
        Err(SetError::UnknownName)
    );
    assert_eq!(
        table.set_by_name("SWASH_PHASE", f32::NAN),
        Err(SetError::NotFinite)
    );
    assert_eq!(
        table.set_by_name("SWASH_PHASE", f32::INFINITY),
        Err(SetError::NotFinite)
    );
    assert_eq!(
        table.set_by_name("SWASH_PHASE", 180.5),
        Err(SetError::OutOfRange)
    );
    assert_eq!(
        table.set_by_name("SERVO1_MID", 1520.5),
        Err(SetError::NotAnInteger)
    );
    assert_eq!(
        table.set_by_name("SWASH_TYPE", 90.0),
        Err(SetError::NotAChoice)
    );
    assert_eq!(table.set_by_name("IMU_ROT", 1.0), Err(SetError::NotAChoice));
    assert_eq!(
        table.set_by_name("SERVO2_DIR", 0.0),
        Err(SetError::NotAChoice)
    );
    assert_eq!(table, before);
    // Each parameter's range, at both ends.
    for id in ParamId::ALL {
        let def = id.def();
        let below = def.min - 1.0f32.max(def.min.abs() * 0.01);
        let above = def.max + 1.0f32.max(def.max.abs() * 0.01);
        assert_eq!(
            table.set(id, below),
            Err(SetError::OutOfRange),
            "{}",
            def.name
        );
        assert_eq!(
            table.set(id, above),
            Err(SetError::OutOfRange),
            "{}",
            def.name
        );
        assert_eq!(
            table.set(id, f32::NAN),
            Err(SetError::NotFinite),
            "{}",
            def.name
        );
    }
    assert_eq!(table, before);
}

#[test]
fn a_set_round_trips_by_name() {
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    for (name, value) in [
        ("SWASH_TYPE", 140.0),
        ("SWASH_PHASE", -12.5),
        ("SERVO2_DIR", -1.0),
        ("TAIL_MID", 760.0),
        ("TAIL_MIN", 560.0),
        ("TAIL_MAX", 960.0),
        ("SERVO_RATE", 200.0),
        ("TAIL_RATE", 50.0),
        ("IMU_ROT", 27.0),
    ] {
        table.set_by_name(name, value).unwrap();
        assert_eq!(table.get_by_name(name), Ok(value));
    }
    let params = table.params().unwrap();
    let mixer = params.stack.app.flight.mixer;
    assert_eq!(mixer.geometry.kind(), crate::swash::SwashType::H3_140);
    assert!(mixer.swash[1].reversed && !mixer.swash[0].reversed);
    assert_eq!(mixer.tail.centre_us, 760);
    assert_eq!((params.swash_frame_hz, params.tail_frame_hz), (200, 50));
    // ArduPilot's PITCH_180_YAW_270 is ROLL_180_YAW_90.
    assert_eq!(params.imu_rotation, crate::imu::ImuRotation::Roll180Yaw90);
    assert_eq!(
        params.stack.orientation,
        crate::imu::ImuRotation::Roll180Yaw90.orientation()
    );
}

#[test]
fn an_inconsistent_set_gives_no_configuration() {
    let refused = |changes: &[(&str, f32)]| {
        let mut table = ParamTable::defaults(VehicleId::Trex700l);
        for (name, value) in changes {
            table.set_by_name(name, *value).unwrap();
        }
        table.params().unwrap_err()
    };
    assert_eq!(refused(&[("SERVO1_MIN", 1600.0)]), ParamsError::Mixer);
    assert!(matches!(
        refused(&[("RC_LON", 1.0)]),
        ParamsError::ChannelMap(_)
    ));
    assert!(matches!(
        refused(&[("RC_MID", 100.0)]),
        ParamsError::ChannelMap(_)
    ));
    assert!(matches!(
        refused(&[("HOLD_RELEASE", 10.0)]),
        ParamsError::Flight(crate::config::ConfigError::HoldThresholdsInvalid)
    ));
    assert!(matches!(
        refused(&[("SWP_WMIN", 40.0)]),
        ParamsError::Flight(_)
    ));
    // A tail notch above the IMU's Nyquist frequency (20 000 rpm = 333 Hz is fine;
    // the 2/rev of a 4000 rpm head is 133 Hz): the filters still design.
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    table.set_by_name("TAIL_RPM", 20_000.0).unwrap();
    assert!(table.params().is_ok());
}

/// The README's parameter table row of `id`: name, unit, range, kind, TREX 700L and
/// Bo-105 defaults, meaning.
fn readme_row(id: ParamId) -> String {
    let def = id.def();
    let kind = match def.kind {
        ParamKind::Real => String::from("real"),
        ParamKind::Integer => String::from("integer"),
        ParamKind::OneOf(choices) => choices
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join(", "),
    };
    let trex = ParamTable::defaults(VehicleId::Trex700l).get(id);
    let bo105 = ParamTable::defaults(VehicleId::Bo105).get(id);
    format!(
        "| `{}` | {} | {} … {} | {} | {} | {} | {} |",
        def.name,
        if def.unit.is_empty() { "—" } else { def.unit },
        def.min,
        def.max,
        kind,
        trex,
        bo105,
        def.doc
    )
}

#[test]
fn the_readme_lists_every_parameter_as_defined() {
    let readme = include_str!("../../README.md");
    let missing: Vec<String> = ParamId::ALL
        .iter()
        .map(|id| readme_row(*id))
        .filter(|row| !readme.lines().any(|line| line == row))
        .collect();
    assert!(
        missing.is_empty(),
        "firmware/README.md lacks or differs in these rows:\n{}",
        missing.join("\n")
    );
}

/// Prints the README table (`cargo test -p sweephold-firmware --lib print_readme_table
/// -- --ignored --nocapture`).
#[test]
#[ignore]
fn print_readme_table() {
    for id in ParamId::ALL {
        println!("{}", readme_row(id));
    }
}

#[test]
fn frame_names_the_preset_under_the_table() {
    // FRAME came right after the first table's 80 parameters: a table only ever grows
    // at its end, each growth a new version.
    assert_eq!(ParamId::ALL[80], ParamId::Frame);
    // Version 4 appended the collective source and the airborne rule after version 3's
    // last parameter.
    assert_eq!(
        ParamId::ALL[ParamId::HoldPedRev.index() + 1..ParamId::AirTime.index() + 1],
        [ParamId::TestColSrc, ParamId::AirColMin, ParamId::AirTime]
    );
    // Version 5 appended the test list after them, version 6 the holds' slew limits,
    // version 7 the pilot mode's gains.
    assert_eq!(TABLE_VERSION, 7);
    assert_eq!(
        ParamId::ALL[ParamId::AirTime.index() + 1],
        ParamId::TestSelCh
    );
    assert_eq!(
        ParamId::ALL[ParamId::Test12Amp.index() + 1..ParamId::HoldSlewPed.index() + 1],
        [
            ParamId::HoldSlewLat,
            ParamId::HoldSlewLon,
            ParamId::HoldSlewPed
        ]
    );
    assert_eq!(
        ParamId::ALL[ParamId::HoldSlewPed.index() + 1..],
        [
            ParamId::PilotRollKp,
            ParamId::PilotRollKi,
            ParamId::PilotPitchKp,
            ParamId::PilotPitchKi,
            ParamId::PilotYawKp,
            ParamId::PilotYawKi,
            ParamId::PilotLevelGain,
            ParamId::PilotHeadingGain
        ]
    );
    for vehicle in VEHICLES {
        let table = ParamTable::defaults(vehicle);
        assert_eq!(table.get(ParamId::Frame), frame_code(vehicle));
        assert_eq!(table.frame(), vehicle);
        assert_eq!(frame_vehicle(frame_code(vehicle)), Some(vehicle));
    }
    assert_eq!(frame_vehicle(0.5), None);
    // FRAME 1 on the TREX 700L values: the Bo-105 preset under the same values.
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    table.set_by_name("FRAME", 1.0).unwrap();
    let params = table.params().unwrap();
    assert_eq!(params.stack.app.flight.vehicle, VehicleId::Bo105);
    assert_eq!(typed::values_of(&params), *table.values());
    assert_eq!(table.set_by_name("FRAME", 2.0), Err(SetError::OutOfRange));
}
