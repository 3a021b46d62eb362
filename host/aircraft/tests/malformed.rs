//! Malformed aircraft files: each is the shipped TREX 700L file with one change, and each
//! must be refused with one line that names the file, the line and the field.

const TREX: &str = aircraft::SHIPPED[1].1;

/// (what is wrong, text replaced, replacement, fragment the message must hold)
const CASES: &[(&str, &str, &str, &str)] = &[
    (
        "missing field",
        "mass = \"5.0 kg\"\n",
        "",
        "missing field `mass`",
    ),
    (
        "missing table",
        "[servos]",
        "[servo_data]",
        "unknown field `servo_data`",
    ),
    (
        "unknown key",
        "ixz = \"0 kg*m^2\"",
        "ixz = \"0 kg*m^2\"\niyz = \"0 kg*m^2\"",
        "unknown field `iyz`",
    ),
    (
        "misspelt key",
        "head_speed =",
        "headspeed =",
        "unknown field `headspeed`",
    ),
    (
        "mass in metres",
        "mass = \"5.0 kg\"",
        "mass = \"5.0 m\"",
        "airframe.mass: `5.0 m`: unit `m` is not one of kg, g",
    ),
    (
        "mass without unit",
        "mass = \"5.0 kg\"",
        "mass = 5.0",
        "airframe.mass: `5` has no unit",
    ),
    (
        "zero mass",
        "mass = \"5.0 kg\"",
        "mass = \"0 kg\"",
        "airframe.mass: 0 must be positive",
    ),
    (
        "negative inertia",
        "ixx = \"0.12 kg*m^2\"",
        "ixx = \"-0.12 kg*m^2\"",
        "airframe.ixx: -0.12 must be positive",
    ),
    (
        "NaN radius",
        "radius = \"0.78 m\"",
        "radius = \"nan m\"",
        "main_rotor.radius: the value is not a finite number",
    ),
    (
        "NaN as a TOML float",
        "damping = 0.7",
        "damping = nan",
        "servos.damping: the value is not a finite number",
    ),
    (
        "infinite chord",
        "chord = \"0.062 m\"",
        "chord = \"inf m\"",
        "main_rotor.chord: the value is not a finite number",
    ),
    (
        "sigma above the value",
        "iyy = \"0.40 kg*m^2\"",
        "iyy = \"0.40 ± 0.5 kg*m^2\"",
        "airframe.iyy: the uncertainty 0.5 is not smaller than the value 0.4",
    ),
    (
        "negative sigma",
        "izz = \"0.35 kg*m^2\"",
        "izz = \"0.35 +- -0.01 kg*m^2\"",
        "airframe.izz: `0.35 +- -0.01 kg*m^2`: the uncertainty must not be negative",
    ),
    (
        "head speed in rad/s written as rpm",
        "head_speed = \"1900 rpm\"",
        "head_speed = \"1900 rad/s\"",
        "main_rotor.head_speed: 1900 must be positive and at most 500 rad/s",
    ),
    (
        "supersonic tip",
        "head_speed = \"1900 rpm\"",
        "head_speed = \"4000 rpm\"",
        "main_rotor.head_speed: tip speed 327 m/s is above Mach 0.9",
    ),
    (
        "half a blade",
        "blades = 2\nchord = \"0.062 m\"",
        "blades = 2.5\nchord = \"0.062 m\"",
        "main_rotor.blades: 2.5 is not a whole number of blades",
    ),
    (
        "one-bladed main rotor",
        "blades = 2\nchord = \"0.062 m\"",
        "blades = 1\nchord = \"0.062 m\"",
        "main_rotor.blades: a main rotor has at least 2 blades",
    ),
    (
        "inertias no body has",
        "izz = \"0.35 kg*m^2\"",
        "izz = \"0.60 kg*m^2\"",
        "airframe.izz: 0.6 kg*m^2 exceeds the sum of the other two inertias",
    ),
    (
        "product of inertia too large",
        "ixz = \"0 kg*m^2\"",
        "ixz = \"0.3 kg*m^2\"",
        "airframe.ixz: I_xz² must be smaller than I_xx·I_zz",
    ),
    (
        "tail rotor larger than the main rotor",
        "radius = \"0.135 m\"",
        "radius = \"0.9 m\"",
        "tail_rotor.radius: 0.9 m is not smaller than the main rotor's 0.78 m",
    ),
    (
        "tail rotor ahead of the CG",
        "hub = [\"-0.95 m\"",
        "hub = [\"0.95 m\"",
        "tail_rotor.hub[0]: the tail rotor must be behind the CG",
    ),
    (
        "tail speed twice",
        "speed = \"8930 rpm\"",
        "speed = \"8930 rpm\"\ngear_ratio = 4.7",
        "tail_rotor.speed: give speed or gear_ratio, not both",
    ),
    (
        "tail speed missing",
        "speed = \"8930 rpm\"\n",
        "",
        "tail_rotor.speed: missing: give speed or gear_ratio",
    ),
    (
        "position with two coordinates",
        "position = [\"-0.90 m\", \"0 m\", \"-0.05 m\"]",
        "position = [\"-0.90 m\", \"0 m\"]",
        "fin.position: expected 3 values, found 2",
    ),
    (
        "gearing that moves nothing",
        "per_stick = \"8 deg\"",
        "per_stick = \"0 deg\"",
        "controls.lon.per_stick: must not be zero",
    ),
    (
        "gearing in a unit of length",
        "per_stick = \"-25 deg\"",
        "per_stick = \"-25 mm\"",
        "controls.ped.per_stick: `-25 mm`: unit `mm` is not one of rad, deg, °",
    ),
    (
        "clockwise rotor",
        "rotation = \"counterclockwise\"",
        "rotation = \"clockwise\"",
        "main_rotor.rotation: the simulator models rotors turning counterclockwise",
    ),
    (
        "unknown rotation",
        "rotation = \"counterclockwise\"",
        "rotation = \"sideways\"",
        "main_rotor.rotation: `sideways`: expected counterclockwise or clockwise",
    ),
    (
        "servo damping with a unit",
        "damping = 0.7",
        "damping = \"0.7 s\"",
        "servos.damping: `0.7 s`: a dimensionless value takes no unit",
    ),
    (
        "servo rate of zero",
        "rate_limit = \"4 /s\"",
        "rate_limit = \"0 /s\"",
        "servos.rate_limit: 0 must be positive",
    ),
    (
        "air on the moon",
        "gravity = \"9.80665 m/s^2\"",
        "gravity = \"1.62 m/s^2\"",
        "environment.gravity: 1.62 must be between 9.7 and 9.9",
    ),
    (
        "profile drag out of range",
        "profile_drag = [0.012, 0.0]\nhub = [\"0 m\"",
        "profile_drag = [0.5, 0.0]\nhub = [\"0 m\"",
        "main_rotor.profile_drag[0]: δ0 = 0.5 must be at most 0.1",
    ),
    (
        "name with a space",
        "name = \"trex700l\"",
        "name = \"trex 700l\"",
        "name: must be a non-empty word",
    ),
    ("not TOML", "[airframe]", "[airframe", "unclosed table"),
    (
        "text where a number belongs",
        "blades = 2\nchord = \"0.032 m\"",
        "blades = \"two\"\nchord = \"0.032 m\"",
        "tail_rotor.blades: `two`: `two` is not a number",
    ),
];

#[test]
fn every_malformed_file_is_refused_on_one_line_naming_the_field() {
    assert!(CASES.len() >= 20);
    for (what, from, to, expected) in CASES {
        assert!(
            TREX.contains(from),
            "{what}: `{from}` is not in the shipped file"
        );
        let text = TREX.replacen(from, to, 1);
        let error = aircraft::parse(&text, "variant.toml")
            .err()
            .unwrap_or_else(|| panic!("{what}: accepted"))
            .to_string();
        assert!(
            error.contains(expected),
            "{what}: `{error}` lacks `{expected}`"
        );
        assert!(!error.contains('\n'), "{what}: more than one line: {error}");
        assert!(error.starts_with("variant.toml:"), "{what}: {error}");
    }
}

#[test]
fn a_field_error_names_the_line_of_the_value() {
    let text = TREX.replace("mass = \"5.0 kg\"", "mass = \"-5 kg\"");
    let line = 1 + text.lines().position(|l| l.starts_with("mass =")).unwrap();
    let error = aircraft::parse(&text, "variant.toml")
        .unwrap_err()
        .to_string();
    assert!(
        error.starts_with(&format!("variant.toml:{line}: airframe.mass:")),
        "{error}"
    );
}

#[test]
fn the_shipped_files_read_and_a_file_on_disk_reads_like_its_text() {
    for (name, text) in aircraft::SHIPPED {
        let parsed = aircraft::parse(text, name).unwrap();
        assert_eq!(parsed.name, name);
        assert_eq!(aircraft::shipped(name).unwrap(), parsed);
    }
    let dir = std::env::temp_dir().join(format!("aircraft-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("heavier.toml");
    let text = TREX
        .replace("name = \"trex700l\"", "name = \"heavier\"")
        .replace("mass = \"5.0 kg\"", "mass = \"5.6 ± 0.1 kg\"");
    std::fs::write(&path, &text).unwrap();
    let read = aircraft::resolve(path.to_str().unwrap()).unwrap();
    assert_eq!(read.name, "heavier");
    assert_eq!(
        read.airframe.mass,
        aircraft::Quantity {
            value: 5.6,
            sigma: Some(0.1)
        }
    );
    let missing = aircraft::resolve(dir.join("none.toml").to_str().unwrap()).unwrap_err();
    assert!(missing.to_string().contains("none.toml"), "{missing}");
    let unknown = aircraft::resolve("ec135").unwrap_err().to_string();
    assert_eq!(
        unknown,
        "unknown vehicle `ec135`: expected bo105, trex700l, fbl700 or the path of an aircraft file"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// (what is wrong, the `[flight_controller]` setting added after `preset`, fragment the
/// message must hold)
const SETTING_CASES: &[(&str, &str, &str)] = &[
    (
        "gain in the wrong unit",
        "hold.lat = { kp = \"1.5 s/rad\" }",
        "flight_controller.hold.lat.kp: `1.5 s/rad`: unit `s/rad` is not one of /rad, 1/rad",
    ),
    (
        "gain without unit",
        "hold.lon = { kd = 0.2 }",
        "flight_controller.hold.lon.kd: `0.2` has no unit",
    ),
    (
        "negative gain",
        "hold.ped = { ki = \"-0.05 /(rad*s)\" }",
        "flight_controller.hold.ped.ki: -0.05 must be between 0 and 100",
    ),
    (
        "NaN gain",
        "hold.lat = { kp = \"nan /rad\" }",
        "flight_controller.hold.lat.kp: the value is not a finite number",
    ),
    (
        "authority above full travel",
        "hold.lat = { output_limit = 1.5 }",
        "flight_controller.hold.lat.output_limit: 1.5 must be positive and at most 1",
    ),
    (
        "integrator above the authority",
        "hold.lon = { output_limit = 0.2, integrator_limit = 0.3 }",
        "flight_controller.hold.lon.integrator_limit: must not exceed output_limit",
    ),
    (
        "a gain with an uncertainty",
        "hold.lat = { kp = \"1.5 ± 0.1 /rad\" }",
        "flight_controller.hold.lat.kp: a flight-controller setting is chosen",
    ),
    (
        "unknown hold key",
        "hold.lat = { kf = \"1 /rad\" }",
        "unknown field `kf`",
    ),
    (
        "unknown held axis",
        "hold.col = { kp = \"1 /rad\" }",
        "unknown field `col`",
    ),
    (
        "unknown setting",
        "sweep_gain = 2",
        "unknown field `sweep_gain`",
    ),
    (
        "engage angle of zero",
        "hold_engage = \"0 deg\"",
        "flight_controller.hold_engage: 0 must be positive",
    ),
    (
        "engage angle in metres",
        "hold_engage = \"6 m\"",
        "flight_controller.hold_engage: `6 m`: unit `m` is not one of rad, deg",
    ),
    (
        "release beyond engage",
        "hold_engage = \"5 deg\"\nhold_release = \"6 deg\"",
        "flight_controller.hold_release: must not exceed hold_engage",
    ),
    (
        "unknown hold reference",
        "hold_reference = \"horizon\"",
        "flight_controller.hold_reference: `horizon`: expected level or trim",
    ),
    (
        "unknown collective source",
        "collective = \"autopilot\"",
        "flight_controller.collective: `autopilot`: expected pilot or trim",
    ),
    (
        "excitation scale above one",
        "excitation_scale = [1.0, 1.2, 0.2, 1.0]",
        "flight_controller.excitation_scale[1]: 1.2 must be positive and at most 1",
    ),
    (
        "excitation scale of zero",
        "excitation_scale = [1.0, 1.0, 0.0, 1.0]",
        "flight_controller.excitation_scale[2]: 0 must be positive",
    ),
    (
        "three excitation scales",
        "excitation_scale = [1.0, 1.0, 0.2]",
        "flight_controller.excitation_scale: expected 4 values, found 3",
    ),
    (
        "slew without a rate unit",
        "command_slew = { ped = \"4 s\" }",
        "flight_controller.command_slew.ped: `4 s`: unit `s` is not one of /s, 1/s",
    ),
    (
        "hold slew on the collective, which has no hold",
        "hold_slew = { col = \"4 /s\" }",
        "unknown field `col`",
    ),
    (
        "hold slew of zero",
        "hold_slew = { lon = \"0 /s\" }",
        "flight_controller.hold_slew.lon",
    ),
    (
        "negative rate limit",
        "rate_limits = [\"200 deg/s\", \"-200 deg/s\", \"250 deg/s\"]",
        "flight_controller.rate_limits[1]: -3.49",
    ),
    (
        "pulse width of a minute and more",
        "pulse_width = \"61 s\"",
        "flight_controller.pulse_width: 61 must be positive and at most 60",
    ),
    (
        "attitude limit beyond 90 degrees",
        "attitude_limit = \"100 deg\"",
        "flight_controller.attitude_limit: 1.745",
    ),
    (
        "negative fade",
        "hold.lat = { release_time = \"-0.3 s\" }",
        "flight_controller.hold.lat.release_time: -0.3 must be between 0 and 10",
    ),
];

#[test]
fn every_malformed_flight_controller_setting_is_refused_on_its_line() {
    assert!(SETTING_CASES.len() >= 20);
    let preset = "preset = \"trex700l\"\n";
    assert!(TREX.contains(preset));
    for (what, setting, expected) in SETTING_CASES {
        let text = TREX.replacen(preset, &format!("{preset}{setting}\n"), 1);
        let error = aircraft::parse(&text, "variant.toml")
            .err()
            .unwrap_or_else(|| panic!("{what}: accepted"))
            .to_string();
        assert!(
            error.contains(expected),
            "{what}: `{error}` lacks `{expected}`"
        );
        assert!(!error.contains('\n'), "{what}: more than one line: {error}");
        // The line named is one of the lines added (after the preset's).
        let first = 1 + text
            .lines()
            .position(|l| l.starts_with("preset ="))
            .unwrap();
        let added = first + 1..=first + setting.lines().count();
        let line: usize = error.split(':').nth(1).unwrap().parse().unwrap();
        assert!(added.contains(&line), "{what}: line {line} of {added:?}");
    }
}

#[test]
fn flight_controller_settings_read_in_si_and_default_to_none() {
    let settings = "preset = \"trex700l\"\nhold_reference = \"level\"\ncollective = \"pilot\"\n\
         hold_engage = \"5 deg\"\n\
         hold_release = \"3 deg\"\npulse_width = \"300 ms\"\n\
         excitation_scale = [0.9, 0.8, 0.2, 1.0]\ncommand_slew = { ped = \"4 /s\" }\n\
         hold_slew = { lat = \"3.6 /s\", lon = \"3 1/s\" }\n\
         attitude_limit = \"20 deg\"\nrate_limits = [\"180 deg/s\", \"3 rad/s\", \"250 deg/s\"]\n\
         pilot_override = 0.1\n\
         hold.lon = { kp = \"2.5 /rad\", ki = \"0.1 /(rad s)\", kd = \"0.2 s/rad\", reversed = true }\n";
    let text = TREX.replacen("preset = \"trex700l\"\n", settings, 1);
    let read = aircraft::parse(&text, "variant.toml")
        .unwrap()
        .flight_controller;
    let deg = std::f64::consts::PI / 180.0;
    assert_eq!(read.hold_reference, Some(aircraft::HoldReference::Level));
    assert_eq!(read.collective, Some(aircraft::CollectiveSource::Pilot));
    assert_eq!(read.hold_engage, Some(5.0 * deg));
    assert_eq!(read.hold_release, Some(3.0 * deg));
    assert_eq!(read.pulse_width, Some(0.3));
    assert_eq!(read.excitation_scale, Some([0.9, 0.8, 0.2, 1.0]));
    assert_eq!(read.command_slew, Some([None, None, Some(4.0), None]));
    assert_eq!(read.hold_slew, Some([Some(3.6), Some(3.0), None]));
    assert_eq!(read.rate_limits, Some([180.0 * deg, 3.0, 250.0 * deg]));
    assert_eq!(read.pilot_override, Some(0.1));
    let lon = read.hold[1];
    assert_eq!(
        (lon.kp, lon.ki, lon.kd, lon.reversed),
        (Some(2.5), Some(0.1), Some(0.2), Some(true))
    );
    assert_eq!(lon.output_limit, None);
    assert_eq!(read.hold[0], aircraft::HoldGains::default());
    assert!(read.states_settings());
    let shipped = aircraft::shipped("trex700l").unwrap().flight_controller;
    assert!(!shipped.states_settings());
    assert_eq!(shipped.preset, "trex700l");
}

const FBL700: &str = aircraft::SHIPPED[2].1;

/// (what is wrong, text of the FBL700 file's `[swash]` table replaced, replacement,
/// fragment the message must hold)
const SWASH_CASES: &[(&str, &str, &str, &str)] = &[
    (
        "unknown plate angle",
        "type = 140",
        "type = 130",
        "swash.type: `130`: expected 120, 135, 140 or \"H1\"",
    ),
    (
        "plate type misspelt",
        "type = 140",
        "type = \"h1\"",
        "swash.type: `\"h1\"`: expected 120, 135, 140 or \"H1\"",
    ),
    (
        "phase beyond 180 deg",
        "phase = \"0 deg\"",
        "phase = \"190 deg\"",
        "swash.phase: 3.316",
    ),
    (
        "phase without unit",
        "phase = \"0 deg\"",
        "phase = 0",
        "swash.phase: `0` has no unit",
    ),
    (
        "lead servo 4",
        "lead = 1",
        "lead = 4",
        "swash.lead: 4 must be between 1 and 3",
    ),
    (
        "lead servo not whole",
        "lead = 1",
        "lead = 1.5",
        "swash.lead: 1.5 is not a whole number",
    ),
    (
        "two swash servos",
        "  { centre = \"1520 us\", throw = \"400 us\", min = \"1100 us\", max = \"1940 us\" },\n]",
        "]",
        "swash.servos: expected 3 servos (outputs 1, 2, 3), found 2",
    ),
    (
        "centre in ms",
        "tail = { centre = \"760 us\"",
        "tail = { centre = \"0.76 ms\"",
        "swash.tail.centre: `0.76 ms`: unit `ms` is not one of us, µs",
    ),
    (
        "centre beyond the pulse range",
        "tail = { centre = \"760 us\"",
        "tail = { centre = \"3000 us\"",
        "swash.tail.centre: 3000 must be between 500 and 2500 us",
    ),
    (
        "centre not a whole µs",
        "tail = { centre = \"760 us\"",
        "tail = { centre = \"760.5 us\"",
        "swash.tail.centre: 760.5 is not a whole number",
    ),
    (
        "zero throw",
        "tail = { centre = \"760 us\", throw = \"200 us\"",
        "tail = { centre = \"760 us\", throw = \"0 us\"",
        "swash.tail.throw: 0 must be positive and at most 1000 us",
    ),
    (
        "760 us tail with the standard limits",
        ", min = \"550 us\", max = \"970 us\" }",
        " }",
        "swash.tail: min 1100 µs, centre 760 µs, max 1940 µs: the limits must surround",
    ),
    (
        "limits reversed",
        "min = \"550 us\", max = \"970 us\"",
        "min = \"970 us\", max = \"550 us\"",
        "swash.tail: min 970 µs, centre 760 µs, max 550 µs",
    ),
    (
        "frame rate above 333 Hz",
        "frame_rate = \"333 Hz\"\ntail",
        "frame_rate = \"400 Hz\"\ntail",
        "swash.frame_rate: 400 must be between 50 and 333 Hz",
    ),
    (
        "frame rate with an uncertainty",
        "tail_frame_rate = \"333 Hz\"",
        "tail_frame_rate = \"333 ± 1 Hz\"",
        "swash.tail_frame_rate: the servo geometry is set, not measured",
    ),
    (
        "direction as a number",
        "{ reversed = true,",
        "{ reversed = -1,",
        "invalid type: integer `-1`, expected a boolean",
    ),
    (
        "unknown servo key",
        "{ reversed = true,",
        "{ reverse = true,",
        "unknown field `reverse`",
    ),
];

#[test]
fn every_malformed_swash_table_is_refused_on_one_line() {
    for (what, old, new, expected) in SWASH_CASES {
        assert!(FBL700.contains(old), "{what}: `{old}` not in fbl700.toml");
        let text = FBL700.replacen(old, new, 1);
        let error = aircraft::parse(&text, "variant.toml")
            .err()
            .unwrap_or_else(|| panic!("{what}: accepted"))
            .to_string();
        assert!(
            error.contains(expected),
            "{what}: `{error}` lacks `{expected}`"
        );
        assert!(!error.contains('\n'), "{what}: more than one line: {error}");
        assert!(error.starts_with("variant.toml:"), "{what}: {error}");
    }
}

#[test]
fn the_swash_table_reads_and_defaults_to_the_presets_geometry() {
    let fbl = aircraft::shipped("fbl700").unwrap().swash;
    assert_eq!(fbl.kind, aircraft::SwashKind::H3_140);
    assert_eq!(fbl.kind.code(), 140);
    assert_eq!((fbl.phase, fbl.lead), (0.0, 1));
    let reversed: Vec<bool> = fbl.servos.iter().map(|s| s.reversed).collect();
    assert_eq!(reversed, [false, true, false]);
    assert_eq!(
        fbl.tail,
        aircraft::ServoOutput {
            reversed: false,
            centre_us: 760.0,
            throw_us: 200.0,
            min_us: 550.0,
            max_us: 970.0
        }
    );
    assert_eq!(
        (fbl.frame_rate, fbl.tail_frame_rate),
        (Some(333.0), Some(333.0))
    );
    for name in ["bo105", "trex700l"] {
        let swash = aircraft::shipped(name).unwrap().swash;
        assert_eq!(swash, aircraft::Swash::default(), "{name}");
    }
    let default = aircraft::Swash::default();
    assert_eq!(default.kind, aircraft::SwashKind::H3_120);
    assert_eq!(default.servos, [aircraft::ServoOutput::STANDARD; 3]);
    // A servo left partly unstated takes the standard servo's other fields; H1 and a
    // phase angle read.
    let text = FBL700
        .replacen("type = 140", "type = \"H1\"", 1)
        .replacen("phase = \"0 deg\"", "phase = \"-30 deg\"", 1)
        .replacen(
            "{ reversed = true, centre = \"1520 us\", throw = \"400 us\", min = \"1100 us\", max = \"1940 us\" }",
            "{ reversed = true, centre = \"1500 µs\" }",
            1,
        );
    let read = aircraft::parse(&text, "variant.toml").unwrap().swash;
    assert_eq!(read.kind, aircraft::SwashKind::H1);
    assert_eq!(read.phase, -30.0 * (std::f64::consts::PI / 180.0));
    assert_eq!(
        read.servos[1],
        aircraft::ServoOutput {
            reversed: true,
            centre_us: 1500.0,
            ..aircraft::ServoOutput::STANDARD
        }
    );
}
