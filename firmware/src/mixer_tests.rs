//! Tests of the mixer.
use super::*;
use crate::swash::SwashType;
use proptest::prelude::*;

fn servos(lat: f32, lon: f32, ped: f32, col: f32) -> [i32; 4] {
    mix(&MixerConfig::trex700l(), &Controls { lat, lon, ped, col }).map(i32::from)
}

#[test]
fn the_expressed_command_is_what_the_limits_and_the_ring_leave() {
    let mut config = MixerConfig::trex700l();
    // Beyond the tail servo's travel: the pedal the servo's limit expresses.
    let full = expressed(
        &config,
        &Controls {
            lat: 0.0,
            lon: 0.0,
            ped: 2.0,
            col: 0.0,
        },
    );
    assert_eq!(full.ped, (1940.0 - 1520.0) / 400.0);
    // Limited to the ring: the command on the ring, to the pulses' rounding.
    config.cyclic_ring = 0.5;
    let ringed = expressed(
        &config,
        &Controls {
            lat: 0.6,
            lon: 0.8,
            ped: 0.0,
            col: 0.0,
        },
    );
    assert!((ringed.lat - 0.3).abs() < 0.01 && (ringed.lon - 0.4).abs() < 0.01);
    // A pedal the pulses cannot express (no tail throw) keeps the command's.
    config.tail.throw_us = 0.0;
    let kept = expressed(
        &config,
        &Controls {
            lat: 0.0,
            lon: 0.0,
            ped: 0.3,
            col: 0.0,
        },
    );
    assert_eq!(kept.ped, 0.3);
    // Not finite in, finite out: the pulses of a non-finite command are the centre's.
    let odd = expressed(
        &MixerConfig::trex700l(),
        &Controls {
            lat: f32::NAN,
            lon: f32::INFINITY,
            ped: f32::NAN,
            col: f32::NAN,
        },
    );
    assert_eq!(
        odd,
        Controls {
            lat: 0.0,
            lon: 0.0,
            ped: 0.0,
            col: 0.0
        }
    );
}

/// The 1 µs steps of a narrow-band tail servo: a pedal command between two steps
/// is expressed as the nearer step.
#[test]
fn a_pedal_between_two_microseconds_is_expressed_as_the_nearer() {
    let mut config = MixerConfig::trex700l();
    config.tail = ServoConfig {
        centre_us: 760,
        throw_us: 200.0,
        min_us: 550,
        max_us: 970,
        reversed: false,
    };
    // 0.0197 of a unit pedal is 3.94 µs: the servo gets 764 µs, 0.02.
    let e = expressed(
        &config,
        &Controls {
            lat: 0.0,
            lon: 0.0,
            ped: 0.0197,
            col: 0.0,
        },
    );
    assert_eq!(
        mix(
            &config,
            &Controls {
                lat: 0.0,
                lon: 0.0,
                ped: 0.0197,
                col: 0.0
            }
        )[3],
        764
    );
    assert!((e.ped - 0.02).abs() < 1e-6, "{e:?}");
}

#[test]
fn neutral_is_centre() {
    assert_eq!(servos(0.0, 0.0, 0.0, 0.0), [1520; 4]);
}

#[test]
fn pure_collective_moves_all_swash_servos_equally() {
    let s = servos(0.0, 0.0, 0.0, 0.5);
    assert_eq!(s, [1620, 1620, 1620, 1520]);
}

#[test]
fn pure_lon_moves_front_opposite_to_the_two_rear() {
    let s = servos(0.0, 0.4, 0.0, 0.0);
    assert_eq!(s[0] - 1520, 80);
    assert_eq!(s[1] - 1520, -40);
    assert_eq!(s[2] - 1520, -40);
    assert_eq!(s[3], 1520);
}

#[test]
fn pure_lat_moves_the_rear_servos_opposite_and_leaves_the_front() {
    let s = servos(0.4, 0.0, 0.0, 0.0);
    assert_eq!(s[0], 1520);
    assert_eq!(s[1] - 1520, -69);
    assert_eq!(s[2] - 1520, 69);
}

#[test]
fn pedal_moves_only_the_tail_and_reversal_flips_it() {
    let mut config = MixerConfig::trex700l();
    assert_eq!(servos(0.0, 0.0, 0.25, 0.0), [1520, 1520, 1520, 1620]);
    config.tail.reversed = true;
    let s = mix(
        &config,
        &Controls {
            ped: 0.25,
            ..Controls::default()
        },
    );
    assert_eq!(s[3], 1420);
}

#[test]
fn an_unvalidated_config_with_reversed_limits_does_not_panic() {
    let mut config = MixerConfig::trex700l();
    config.tail.min_us = 1900;
    config.tail.max_us = 1100;
    config.cyclic_scale = f32::NAN;
    assert!(!config.is_valid());
    let s = mix(
        &config,
        &Controls {
            lat: 0.3,
            lon: 0.2,
            ped: 0.1,
            col: 0.0,
        },
    );
    assert_eq!(s[3], 1100);
    assert_eq!(s[0], 1520);
}

#[test]
fn outputs_are_clamped_to_the_limits() {
    // Within the default limits full travel reaches centre ± 400 µs.
    assert_eq!(servos(0.0, 1.0, 1.0, 1.0), [1920, 1620, 1620, 1920]);
    let mut config = MixerConfig::trex700l();
    config.swash = [ServoConfig {
        throw_us: 600.0,
        ..ServoConfig::STANDARD
    }; 3];
    config.tail.max_us = 1700;
    let high = mix(
        &config,
        &Controls {
            lon: 1.0,
            ped: 1.0,
            col: 1.0,
            lat: 0.0,
        },
    );
    assert_eq!(high, [1940, 1670, 1670, 1700]);
    let low = mix(
        &config,
        &Controls {
            lon: -1.0,
            ped: 0.0,
            col: -1.0,
            lat: 0.0,
        },
    );
    assert_eq!(low[0], 1100);
}

/// The CCPM-120 mixer before swash types, phase, lead servo and cyclic ring existed,
/// kept verbatim to pin the default path's outputs.
fn mix_before_swash_types(config: &MixerConfig, command: &Controls) -> [u16; 4] {
    const SWASH_COS_SIN: [(f32, f32); 3] = [(1.0, 0.0), (-0.5, 0.866_025_4), (-0.5, -0.866_025_4)];
    let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
    let (lat, lon, ped, col) = (
        finite(command.lat),
        finite(command.lon),
        finite(command.ped),
        finite(command.col),
    );
    let mut out = [0u16; 4];
    for ((pulse, servo), (cos, sin)) in out.iter_mut().zip(config.swash.iter()).zip(SWASH_COS_SIN) {
        let height = config.collective_scale * col + config.cyclic_scale * (lon * cos - lat * sin);
        *pulse = servo.pulse_us(height);
    }
    out[3] = config.tail.pulse_us(config.pedal_scale * ped);
    out
}

fn with_geometry(kind: SwashType, phase: f32, lead: u8) -> MixerConfig {
    MixerConfig {
        geometry: SwashGeometry::new(kind, phase, lead).unwrap(),
        ..MixerConfig::trex700l()
    }
}

#[test]
fn a_140_plate_mixes_by_its_geometry() {
    // Fore-aft 0.4 at k_cyc 0.5, throw 400 µs: the lead servo +80 µs, each side
    // servo −80·cos 40° = −61.28 µs → 1459 (rounded); lateral 0.4: the side servos
    // ∓80·sin 40° = ∓51.42 µs → 1469 / 1571, the lead servo still.
    let config = with_geometry(SwashType::H3_140, 0.0, 1);
    let lon = mix(
        &config,
        &Controls {
            lon: 0.4,
            ..Controls::default()
        },
    );
    assert_eq!(lon, [1600, 1459, 1459, 1520]);
    let lat = mix(
        &config,
        &Controls {
            lat: 0.4,
            ..Controls::default()
        },
    );
    assert_eq!(lat, [1520, 1469, 1571, 1520]);
    // 135°: ∓80·cos 45° = ∓56.57 µs.
    let config = with_geometry(SwashType::H3_135, 0.0, 1);
    let lon = mix(
        &config,
        &Controls {
            lon: 0.4,
            ..Controls::default()
        },
    );
    assert_eq!(lon, [1600, 1463, 1463, 1520]);
}

#[test]
fn a_reversed_output_mirrors_about_its_centre() {
    let mut config = with_geometry(SwashType::H3_140, 0.0, 1);
    config.swash[1].reversed = true;
    let lon = mix(
        &config,
        &Controls {
            lon: 0.4,
            ..Controls::default()
        },
    );
    assert_eq!(lon, [1600, 1581, 1459, 1520]);
}

#[test]
fn h1_and_the_collective_offset_reach_their_outputs() {
    let mut config = with_geometry(SwashType::H1, 0.0, 1);
    config.collective_offset = 0.1;
    let out = mix(
        &config,
        &Controls {
            lat: 0.2,
            lon: -0.4,
            col: 0.5,
            ped: 0.0,
        },
    );
    // lat 0.2·0.5·400 = +40, lon −0.4·0.5·400 = −80, (0.1 + 0.5·0.5)·400 = +140.
    assert_eq!(out, [1560, 1440, 1660, 1520]);
}

#[test]
fn the_cyclic_ring_limits_a_corner_stick() {
    let mut config = MixerConfig::trex700l();
    config.cyclic_ring = 1.0;
    // (1, 1) scaled to (0.7071, 0.7071): front +0.7071·200 = +141.4 µs.
    let out = mix(
        &config,
        &Controls {
            lat: 1.0,
            lon: 1.0,
            ..Controls::default()
        },
    );
    assert_eq!(out[0], 1661);
    config.cyclic_ring = 0.05;
    assert!(!config.is_valid());
}

/// The libm formulation the comparison version replaced: round, then clamp.
fn pulse_by_roundf(servo: &ServoConfig, height: f32) -> u16 {
    let sign = if servo.reversed { -1.0 } else { 1.0 };
    let offset = if height.is_nan() {
        0.0
    } else {
        sign * servo.throw_us * height
    };
    let raw = libm::roundf(f32::from(servo.centre_us) + offset);
    raw.max(f32::from(servo.min_us))
        .min(f32::from(servo.max_us)) as u16
}

proptest! {
    /// Clamp-then-round without libm gives the same pulse as round-then-clamp, ties
    /// (x.5) and reversed limits included.
    #[test]
    fn pulse_matches_round_then_clamp(
        height in proptest::num::f32::ANY,
        tie in -2000i32..2000,
        min_us in 0u16..3000,
        max_us in 0u16..3000,
        throw_us in 0.0f32..1000.0,
    ) {
        let servo = ServoConfig { min_us, max_us, throw_us, ..ServoConfig::STANDARD };
        prop_assert_eq!(servo.pulse_us(height), pulse_by_roundf(&servo, height));
        let unit = ServoConfig { min_us, max_us, throw_us: 1.0, ..ServoConfig::STANDARD };
        for h in [tie as f32 + 0.5, tie as f32 - 0.5, tie as f32 + 0.499_999_97] {
            prop_assert_eq!(unit.pulse_us(h), pulse_by_roundf(&unit, h));
        }
    }

    /// The default mixer gives the pulses of the mixer before swash types, bit for
    /// bit, for every command the controller can send (clamped to ±1) and for
    /// non-finite ones, on both presets' mixer.
    #[test]
    fn the_default_path_is_bit_identical_to_the_ccpm_120_mixer_of_before(
        lat in -1.0f32..=1.0,
        lon in -1.0f32..=1.0,
        ped in -1.0f32..=1.0,
        col in -1.0f32..=1.0,
        odd in prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY)],
    ) {
        let config = MixerConfig::trex700l();
        let command = Controls { lat, lon, ped, col };
        prop_assert_eq!(mix(&config, &command), mix_before_swash_types(&config, &command));
        let odd_command = Controls { lat: odd, lon, ped, col: odd };
        prop_assert_eq!(
            mix(&config, &odd_command),
            mix_before_swash_types(&config, &odd_command)
        );
    }

    /// Every plate (type, phase, lead, reversed servos, narrow-band tail): the
    /// expressed command gives the same pulses as the command, and differs from it by
    /// at most the half µs each pulse was rounded by, carried through the plate's
    /// inverse (for commands the ring and the limits leave alone).
    #[test]
    fn the_expressed_command_is_the_command_to_the_pulses_rounding(
        lat in -0.8f32..=0.8,
        lon in -0.8f32..=0.8,
        ped in -0.8f32..=0.8,
        col in -0.5f32..=0.5,
        kind in prop_oneof![
            Just(SwashType::H3_120), Just(SwashType::H3_135),
            Just(SwashType::H3_140), Just(SwashType::H1)
        ],
        phase_deg in -45.0f32..45.0,
        lead in 1u8..=3,
        reversed in proptest::array::uniform3(proptest::bool::ANY),
    ) {
        let mut config = MixerConfig::trex700l();
        config.geometry = SwashGeometry::new(kind, phase_deg, lead).unwrap();
        for (servo, reversed) in config.swash.iter_mut().zip(reversed) {
            servo.reversed = reversed;
        }
        config.tail = ServoConfig {
            centre_us: 760, throw_us: 200.0, min_us: 550, max_us: 970, reversed: true,
        };
        let command = Controls { lat, lon, ped, col };
        let expressed = expressed(&config, &command);
        prop_assert_eq!(mix(&config, &expressed), mix(&config, &command));
        // Half a µs of each swash servo through the inverse: the largest absolute row
        // sum of a plate's inverse is 1.556 (140°, lat'), √2 for an H1 head's turn.
        let swash_step = 0.5 / 400.0 * 1.56 / 0.5 + 1e-6;
        prop_assert!((expressed.lat - lat).abs() <= swash_step, "lat {expressed:?}");
        prop_assert!((expressed.lon - lon).abs() <= swash_step, "lon {expressed:?}");
        prop_assert!((expressed.col - col).abs() <= swash_step, "col {expressed:?}");
        prop_assert!((expressed.ped - ped).abs() <= 0.5 / 200.0 + 1e-6, "ped {expressed:?}");
    }

    #[test]
    fn any_command_stays_within_every_servo_limit(
        lat in proptest::num::f32::ANY,
        lon in proptest::num::f32::ANY,
        ped in proptest::num::f32::ANY,
        col in proptest::num::f32::ANY,
    ) {
        let config = MixerConfig::trex700l();
        let s = mix(&config, &Controls { lat, lon, ped, col });
        for (pulse, servo) in s.iter().zip(config.swash.iter().chain([&config.tail])) {
            prop_assert!((servo.min_us..=servo.max_us).contains(pulse));
        }
    }
}
