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

/// The command the pulses [`mix`] gives for `command` express: the pulses turned back
/// through the servos and the plate (the inverse of each step of `mix`).
///
/// It is what the rotor gets, and so what the telemetry logs as the applied command. It
/// differs from `command` by the cyclic ring, the servo limits and the pulses' whole µs:
/// a 1 µs step is `1/(throw·scale)` of a unit command, 0.005 of the pedal with a
/// narrow-band tail servo of 200 µs per unit height. That error is not white: while a
/// command varies slowly the rounding holds one sign for seconds, a steady yaw moment
/// the pedal's weak damping integrates into a drift a model driven by the unrounded
/// command does not have. An axis the pulses do not determine (a zero scale or throw)
/// keeps the command's own value. [`PulseInverse`] is the same map computed once.
pub fn expressed(config: &MixerConfig, command: &Controls) -> Controls {
    PulseInverse::new(config).command(mix(config, command), command)
}

/// The mixer turned around: the command a set of pulses expresses ([`expressed`]), as
/// one affine map per axis computed once per mixer.
///
/// Each servo's height is affine in its pulse, `hᵢ = sᵢ·(pᵢ − centreᵢ)/throwᵢ` (sᵢ = −1
/// when reversed), and the plate's inverse ([`SwashGeometry::unmix`]) is linear in the
/// heights, so each of lat, lon and col is `Σᵢ kᵢ·pᵢ + k₀`: the columns of the plate's
/// inverse are its images of the unit heights, scaled by `sᵢ/throwᵢ` and by the axis's
/// scale. Per tick that is nine multiply-adds and the tail's one, where turning the
/// pulses back step by step takes eleven divisions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulseInverse {
    /// Per swash axis (lat, lon, col): the factors on pulses 1–3 and the constant, or
    /// `None` when the pulses do not determine the axis.
    swash: [Option<([f32; 3], f32)>; 3],
    /// The tail pulse's factor and constant for the pedal, or `None`.
    tail: Option<(f32, f32)>,
}

impl PulseInverse {
    /// The inverse of `config`'s mixer.
    pub fn new(config: &MixerConfig) -> Self {
        // Height per µs and the height at 0 µs of one servo, if its throw allows.
        let affine = |servo: &ServoConfig| {
            let sign = if servo.reversed { -1.0 } else { 1.0 };
            let gain = sign / servo.throw_us;
            let at_zero = -gain * f32::from(servo.centre_us);
            (gain.is_finite() && at_zero.is_finite()).then_some((gain, at_zero))
        };
        let servos = config.swash.each_ref().map(affine);
        let columns =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|h| config.geometry.unmix(h));
        // Each swash axis: its scale, its offset (command = (value − offset)/scale) and
        // its part of the plate's inverse.
        type Pick = fn((f32, f32, f32)) -> f32;
        let axes: [(f32, f32, Pick); 3] = [
            (config.cyclic_scale, 0.0, |(lat, _, _)| lat),
            (config.cyclic_scale, 0.0, |(_, lon, _)| lon),
            (
                config.collective_scale,
                config.collective_offset,
                |(_, _, col)| col,
            ),
        ];
        let swash = axes.map(|(scale, offset, pick)| {
            let mut factors = [0.0; 3];
            let mut constant = -offset;
            for ((factor, column), servo) in factors.iter_mut().zip(columns).zip(servos) {
                let (Some(column), Some((gain, at_zero))) = (column, servo) else {
                    return None;
                };
                let u = pick(column);
                *factor = u * gain / scale;
                constant += u * at_zero;
            }
            let constant = constant / scale;
            (constant.is_finite() && factors.iter().all(|f| f.is_finite()))
                .then_some((factors, constant))
        });
        let tail = affine(&config.tail).and_then(|(gain, at_zero)| {
            let factor = gain / config.pedal_scale;
            let constant = at_zero / config.pedal_scale;
            (factor.is_finite() && constant.is_finite()).then_some((factor, constant))
        });
        PulseInverse { swash, tail }
    }

    /// The command `pulses` (swash 1–3, tail) express; an axis they do not determine
    /// keeps `command`'s value.
    pub fn command(&self, pulses: [u16; 4], command: &Controls) -> Controls {
        let [p1, p2, p3, tail] = pulses.map(f32::from);
        let swash = |axis: Option<([f32; 3], f32)>, own: f32| {
            axis.map_or(own, |([a, b, c], k)| a * p1 + b * p2 + c * p3 + k)
        };
        let [lat, lon, col] = self.swash;
        Controls {
            lat: swash(lat, command.lat),
            lon: swash(lon, command.lon),
            col: swash(col, command.col),
            ped: self.tail.map_or(command.ped, |(a, k)| a * tail + k),
        }
    }
}

#[cfg(test)]
#[path = "mixer_tests.rs"]
mod tests;
