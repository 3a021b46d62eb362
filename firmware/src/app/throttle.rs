//! The throttle (ESC) channel: cut when disarmed, the pilot's throttle when armed, raised
//! no faster than the soft-start rate.
//!
//! The ESC runs its own governor (head speed); the throttle channel is its set point.
//! The board only decides *whether* the motor may run and how fast the set point may
//! rise:
//!
//! * Disarmed: the output is 0 and the pulse is [`ThrottleSettings::esc_min_us`], the
//!   pulse every ESC reads as motor off.
//! * Armed: the output follows the stick down at once (the pilot may always reduce
//!   power) and up by at most `1 / soft_start_s` per second. After arming the output
//!   starts at 0, so this is the soft start: a governor set point of 0.8 is reached in
//!   0.8 · soft_start_s. Later it only slows a stick raised faster than that.
//! * Receiver lost while armed: the output is held (see the failsafe policy).

use crate::attitude_hold::clamp_finite;

/// Throttle channel settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThrottleSettings {
    /// Pulse for throttle 0 (motor off) \[µs\].
    pub esc_min_us: u16,
    /// Pulse for throttle 1 \[µs\].
    pub esc_max_us: u16,
    /// Time for the output to rise from 0 to 1 \[s\] (the soft start).
    pub soft_start_s: f32,
    /// Arming needs the throttle stick at or below this (fraction).
    pub arm_max: f32,
    /// At or above this output the rotor is taken to be under power: the rate-loop
    /// integrators run; below it they leak away (see `pilot_mode`).
    pub spooled_min: f32,
}

impl ThrottleSettings {
    /// Defaults for an electric helicopter with a governor ESC: 1000–2000 µs (the
    /// standard ESC range; calibrate the ESC's end points to it), soft start 0→1 in 5 s
    /// (a 700 rotor of ~0.4 kg·m² comes up to head speed without a current spike and the
    /// pilot sees it spool), arm below 5 % (a stick at the bottom, with margin for trim
    /// and noise), rotor under power from 20 % (below any governor set point a 700 flies
    /// on, above a ground idle).
    pub const fn standard() -> Self {
        ThrottleSettings {
            esc_min_us: 1000,
            esc_max_us: 2000,
            soft_start_s: 5.0,
            arm_max: 0.05,
            spooled_min: 0.2,
        }
    }

    /// Whether the pulses are ordered and the fractions and the soft-start time finite
    /// and in range.
    pub fn is_valid(&self) -> bool {
        self.esc_min_us < self.esc_max_us
            && self.soft_start_s.is_finite()
            && self.soft_start_s > 0.0
            && (0.0..1.0).contains(&self.arm_max)
            && (0.0..=1.0).contains(&self.spooled_min)
    }

    /// ESC pulse for `throttle` in [0, 1] (clamped; NaN → motor off).
    pub fn pulse_us(&self, throttle: f32) -> u16 {
        let fraction = unit_fraction(throttle);
        let min = f32::from(self.esc_min_us);
        let span = f32::from(self.esc_max_us) - min;
        // In [min, max] ⊂ [0, 65 535]: + ½ and truncation round to nearest; `as`
        // saturates anyway.
        (min + fraction * span + 0.5) as u16
    }
}

/// `value` clamped to [0, 1]; NaN maps to 0.
pub(crate) fn unit_fraction(value: f32) -> f32 {
    if value.is_nan() {
        return 0.0;
    }
    clamp_finite(value - 0.5, 0.5) + 0.5
}

/// The throttle output's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Throttle {
    output: f32,
}

impl Throttle {
    /// The current output in [0, 1].
    pub fn output(&self) -> f32 {
        self.output
    }

    /// Motor off.
    pub fn cut(&mut self) {
        self.output = 0.0;
    }

    /// Follow `stick`: down at once, up by at most `max_rise` per call. Returns the new
    /// output.
    pub fn follow(&mut self, stick: f32, max_rise: f32) -> f32 {
        let wanted = unit_fraction(stick);
        let ceiling = self.output + max_rise.max(0.0);
        self.output = if wanted <= ceiling { wanted } else { ceiling };
        self.output
    }

    /// Set the output (a held value), clamped to [0, 1].
    pub fn hold(&mut self, value: f32) -> f32 {
        self.output = unit_fraction(value);
        self.output
    }

    /// The output has reached `stick` (the soft start no longer limits it).
    pub fn settled(&self, stick: f32) -> bool {
        self.output >= unit_fraction(stick) - 1e-6
    }
}
