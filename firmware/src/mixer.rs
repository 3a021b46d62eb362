//! CCPM-120 swashplate mixing (TREX 700L) plus the tail servo: commands in stick
//! fractions to servo pulse widths in µs. A pure function.
//!
//! The three swash servos sit at azimuths ψᵢ measured clockwise from the nose seen from
//! above: servo 1 front (0°), servo 2 right-rear (120°), servo 3 left-rear (240°). The
//! swashplate height each servo must produce is
//!
//! ```text
//! hᵢ = k_col·δ_col + k_cyc·(δ_lon·cos ψᵢ − δ_lat·sin ψᵢ)
//! front:      k_col·col + k_cyc·lon
//! right-rear: k_col·col − k_cyc·(½·lon + (√3/2)·lat)
//! left-rear:  k_col·col − k_cyc·(½·lon − (√3/2)·lat)
//! ```
//!
//! so collective raises all three equally, positive lon raises the front against the rear
//! (tilting the plate aft, nose up) and positive lat lowers the right side (roll right).
//! Each servo then maps height to pulse width: `centre ± throw·h` (sign from `reversed`),
//! rounded and clamped to its `[min, max]`. The tail servo gets `k_ped·δ_ped`.

use sweephold_protocol::Controls;

/// cos ψ and sin ψ of the three swash servos (0°, 120°, 240°).
const SWASH_COS_SIN: [(f32, f32); 3] = [(1.0, 0.0), (-0.5, 0.866_025_4), (-0.5, -0.866_025_4)];

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
    /// Swash servos 1 (front), 2 (right-rear), 3 (left-rear).
    pub swash: [ServoConfig; 3],
    /// Tail-rotor pitch servo.
    pub tail: ServoConfig,
    /// Height per unit collective command.
    pub collective_scale: f32,
    /// Height per unit cyclic command.
    pub cyclic_scale: f32,
    /// Tail height per unit pedal command.
    pub pedal_scale: f32,
}

impl MixerConfig {
    /// Defaults: standard servos, half of the throw to collective and half to cyclic (so
    /// full collective plus full cyclic just reaches ±400 µs), full throw to the tail.
    pub const fn trex700l() -> Self {
        MixerConfig {
            swash: [ServoConfig::STANDARD; 3],
            tail: ServoConfig::STANDARD,
            collective_scale: 0.5,
            cyclic_scale: 0.5,
            pedal_scale: 1.0,
        }
    }

    /// Whether every servo is valid and the scales are finite and ≥ 0.
    pub fn is_valid(&self) -> bool {
        let scale_ok = |v: f32| v.is_finite() && v >= 0.0;
        self.swash.iter().all(ServoConfig::is_valid)
            && self.tail.is_valid()
            && scale_ok(self.collective_scale)
            && scale_ok(self.cyclic_scale)
            && scale_ok(self.pedal_scale)
    }
}

/// Servo pulse widths \[µs\] for `command`: swash servos 1–3, then the tail.
pub fn mix(config: &MixerConfig, command: &Controls) -> [u16; 4] {
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
