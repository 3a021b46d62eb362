//! Swashplate mixing plus the tail servo: commands in stick fractions to servo pulse
//! widths in µs. A pure function.
//!
//! The cyclic command is first limited to the cyclic ring, then the [`SwashGeometry`]
//! gives each swash output its height ([`crate::swash`]: 120°, 135°, 140° CCPM or a
//! mechanically mixed H1 head, a phase angle and the lead servo). With the default
//! geometry (CCPM-120, servo 1 front at 0°, servo 2 right-rear at 120°, servo 3
//! left-rear at 240°, azimuths clockwise from the nose seen from above) the height each
//! servo must produce is
//!
//! ```text
//! hᵢ = c₀ + k_col·δ_col + k_cyc·(δ_lon·cos ψᵢ − δ_lat·sin ψᵢ)
//! front:      k_col·col + k_cyc·lon
//! right-rear: k_col·col − k_cyc·(½·lon + (√3/2)·lat)
//! left-rear:  k_col·col − k_cyc·(½·lon − (√3/2)·lat)
//! ```
//!
//! (c₀ the collective offset, 0 by default) so collective raises all three equally,
//! positive lon raises the front against the rear (tilting the plate aft, nose up) and
//! positive lat lowers the right side (roll right). Each servo then maps height to pulse
//! width: `centre ± throw·h` (sign from `reversed`), rounded and clamped to its
//! `[min, max]`. The tail servo gets `k_ped·δ_ped`.

use sweephold_protocol::Controls;

use crate::swash::{limit_to_ring, SwashGeometry};

/// Largest accepted cyclic ring \[stick fraction\]; it is also the default, which never
/// limits commands within ±1 (|(1, 1)| = √2 < 1.5).
pub const MAX_CYCLIC_RING: f32 = 1.5;
/// Smallest accepted cyclic ring \[stick fraction\].
pub const MIN_CYCLIC_RING: f32 = 0.1;

/// One servo's pulse mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoConfig {
    /// Pulse width at zero height (the servo trim) \[µs\].
    pub centre_us: u16,
    /// Pulse width per unit height \[µs\].
    pub throw_us: f32,
    /// Lowest pulse width ever sent \[µs\].
    pub min_us: u16,
    /// Highest pulse width ever sent \[µs\].
    pub max_us: u16,
    /// The servo moves the other way (mounted mirrored).
    pub reversed: bool,
}

impl ServoConfig {
    /// A standard 1520 µs-centre servo, ±400 µs per unit height, limited to 1100–1940 µs.
    pub const STANDARD: ServoConfig = ServoConfig {
        centre_us: 1520,
        throw_us: 400.0,
        min_us: 1100,
        max_us: 1940,
        reversed: false,
    };

    /// Whether min < max, the centre lies between them and the throw is finite and ≥ 0.
    pub fn is_valid(&self) -> bool {
        self.min_us < self.max_us
            && (self.min_us..=self.max_us).contains(&self.centre_us)
            && self.throw_us.is_finite()
            && self.throw_us >= 0.0
    }

    /// Pulse width for `height`, clamped to the limits; NaN maps to the centre.
    pub fn pulse_us(&self, height: f32) -> u16 {
        let sign = if self.reversed { -1.0 } else { 1.0 };
        let offset = if height.is_nan() {
            0.0
        } else {
            sign * self.throw_us * height
        };
        let raw = f32::from(self.centre_us) + offset;
        // Clamp, then round to the nearest µs. max-then-min rather than `f32::clamp`,
        // which panics on reversed bounds (an unvalidated config), and written as
        // comparisons: on the Cortex-M4 `max`/`min` are fmaxf/fminf calls. NaN fails
        // `>=` and becomes the minimum. Clamping first is the same as rounding first
        // (the bounds are integers and rounding is monotonic), and it leaves a value in
        // [0, 65 535], where x + ½ is exact in f32 and truncating it rounds half away
        // from zero like `roundf`, without the libm call. `as` saturates.
        let (min, max) = (f32::from(self.min_us), f32::from(self.max_us));
        let at_least_min = if raw >= min { raw } else { min };
        let clamped = if at_least_min <= max {
            at_least_min
        } else {
            max
        };
        (clamped + 0.5) as u16
    }
}

/// Mixer settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MixerConfig {
    /// Swash outputs 1, 2, 3 (with the default geometry: front, right-rear, left-rear).
    pub swash: [ServoConfig; 3],
    /// Where the swash servos sit (type, phase angle, lead servo).
    pub geometry: SwashGeometry,
    /// Tail-rotor pitch servo.
    pub tail: ServoConfig,
    /// Height per unit collective command.
    pub collective_scale: f32,
    /// Height at zero collective command (the middle of the collective range).
    pub collective_offset: f32,
    /// Radius the cyclic command (lat, lon) is limited to \[stick fraction\].
    pub cyclic_ring: f32,
    /// Height per unit cyclic command.
    pub cyclic_scale: f32,
    /// Tail height per unit pedal command.
    pub pedal_scale: f32,
}

impl MixerConfig {
    /// Defaults: CCPM-120 with servo 1 in front, no cyclic ring, standard servos, half
    /// of the throw to collective and half to cyclic (so
    /// full collective plus full cyclic just reaches ±400 µs), full throw to the tail.
    pub const fn trex700l() -> Self {
        MixerConfig {
            swash: [ServoConfig::STANDARD; 3],
            geometry: SwashGeometry::H3_120,
            tail: ServoConfig::STANDARD,
            collective_scale: 0.5,
            collective_offset: 0.0,
            cyclic_ring: MAX_CYCLIC_RING,
            cyclic_scale: 0.5,
            pedal_scale: 1.0,
        }
    }

    /// Whether every servo is valid, the scales are finite and ≥ 0, the collective
    /// offset finite and the cyclic ring within [`MIN_CYCLIC_RING`, `MAX_CYCLIC_RING`].
    pub fn is_valid(&self) -> bool {
        let scale_ok = |v: f32| v.is_finite() && v >= 0.0;
        self.swash.iter().all(ServoConfig::is_valid)
            && self.tail.is_valid()
            && scale_ok(self.collective_scale)
            && scale_ok(self.cyclic_scale)
            && scale_ok(self.pedal_scale)
            && self.collective_offset.is_finite()
            && (MIN_CYCLIC_RING..=MAX_CYCLIC_RING).contains(&self.cyclic_ring)
    }
}

/// Servo pulse widths \[µs\] for `command`: swash outputs 1–3, then the tail.
pub fn mix(config: &MixerConfig, command: &Controls) -> [u16; 4] {
    let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
    let (lat, lon, ped, col) = (
        finite(command.lat),
        finite(command.lon),
        finite(command.ped),
        finite(command.col),
    );
    let (lat, lon) = limit_to_ring(lat, lon, config.cyclic_ring);
    let collective = config.collective_scale * col + config.collective_offset;
    let heights = config
        .geometry
        .heights(lat, lon, config.cyclic_scale, collective);
    let mut out = [0u16; 4];
    for ((pulse, servo), height) in out.iter_mut().zip(config.swash.iter()).zip(heights) {
        *pulse = servo.pulse_us(height);
    }
    let [front, right, left, _] = out;
    [
        front,
        right,
        left,
        config.tail.pulse_us(config.pedal_scale * ped),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swash::SwashType;
    use proptest::prelude::*;

    fn servos(lat: f32, lon: f32, ped: f32, col: f32) -> [i32; 4] {
        mix(&MixerConfig::trex700l(), &Controls { lat, lon, ped, col }).map(i32::from)
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
        const SWASH_COS_SIN: [(f32, f32); 3] =
            [(1.0, 0.0), (-0.5, 0.866_025_4), (-0.5, -0.866_025_4)];
        let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
        let (lat, lon, ped, col) = (
            finite(command.lat),
            finite(command.lon),
            finite(command.ped),
            finite(command.col),
        );
        let mut out = [0u16; 4];
        for ((pulse, servo), (cos, sin)) in
            out.iter_mut().zip(config.swash.iter()).zip(SWASH_COS_SIN)
        {
            let height =
                config.collective_scale * col + config.cyclic_scale * (lon * cos - lat * sin);
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
}
