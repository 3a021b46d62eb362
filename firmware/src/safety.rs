//! Abort checks, run in the same tick as the command they guard.
//!
//! Order of precedence when several faults coincide (the first one is reported):
//! switch released, sensor not finite, sensor stale, attitude limit, rate limit, pilot
//! override. The pilot's intent comes first; then the checks that say the sensor data
//! cannot be trusted, before any check that reads that data.

use sweephold_protocol::{AbortReason, Measurements, SensorIn};

/// Abort limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyLimits {
    /// |φ| or |θ| above this aborts \[rad\] (absolute attitude, not deviation from trim).
    pub attitude_limit_rad: f32,
    /// |p|, |q|, |r| above these abort [rad/s].
    pub rate_limit_rad_s: [f32; 3],
    /// A stick more than this far from its trim aborts (fraction of stick travel;
    /// 0.1 = 10 % of travel).
    pub pilot_override: f32,
    /// The sensor `seq` may stay unchanged for this many consecutive ticks; one more
    /// aborts.
    pub stale_limit_ticks: u8,
}

impl SafetyLimits {
    /// Defaults for the Bo-105: 20° attitude, 90°/s on every rate (a 5 % sweep moves the
    /// Bo-105 by a few °/s), 10 % stick override, 3 stale ticks.
    pub const fn bo105() -> Self {
        SafetyLimits {
            attitude_limit_rad: 20.0 * DEG,
            rate_limit_rad_s: [90.0 * DEG; 3],
            pilot_override: 0.1,
            stale_limit_ticks: 3,
        }
    }

    /// Defaults for a TREX 700L-class model: 20° attitude, 200°/s roll and pitch,
    /// 250°/s yaw (well below its aerobatic rates, well above a 5 % sweep's response).
    pub const fn trex700l() -> Self {
        SafetyLimits {
            attitude_limit_rad: 20.0 * DEG,
            rate_limit_rad_s: [200.0 * DEG, 200.0 * DEG, 250.0 * DEG],
            pilot_override: 0.1,
            stale_limit_ticks: 3,
        }
    }

    /// Whether every limit is finite and positive.
    pub fn is_valid(&self) -> bool {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        positive(self.attitude_limit_rad)
            && self.rate_limit_rad_s.iter().all(|&v| positive(v))
            && positive(self.pilot_override)
    }
}

const DEG: f32 = core::f32::consts::PI / 180.0;

/// Tracks how many consecutive ticks the sensor `seq` has not changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StaleTracker {
    last_seq: Option<u32>,
    unchanged: u32,
}

impl StaleTracker {
    /// Observe this tick's `seq`; returns the number of consecutive ticks (this one
    /// included) on which it equalled the previous tick's.
    pub fn observe(&mut self, seq: u32) -> u32 {
        if self.last_seq == Some(seq) {
            self.unchanged = self.unchanged.saturating_add(1);
        } else {
            self.unchanged = 0;
        }
        self.last_seq = Some(seq);
        self.unchanged
    }
}

/// Everything the checks look at in one tick.
#[derive(Clone, Copy, Debug)]
pub struct SafetyInput<'a> {
    /// This tick's sensor frame (measurements, pilot sticks and switch).
    pub sensor: &'a SensorIn,
    /// Consecutive unchanged `seq` ticks from [`StaleTracker::observe`].
    pub unchanged_seq_ticks: u32,
    /// The sticks the pilot must stay near: the trim, or the running average during trim
    /// capture; `None` skips the override check (the Armed tick).
    pub stick_reference: Option<[f32; 4]>,
}

fn measurements_finite(meas: &Measurements) -> bool {
    [
        meas.p, meas.q, meas.r, meas.phi, meas.theta, meas.psi, meas.u, meas.v, meas.w, meas.ax,
        meas.ay, meas.az,
    ]
    .iter()
    .all(|v| v.is_finite())
}

/// The first abort reason that applies this tick, if any.
///
/// Non-finite pilot sticks count as [`AbortReason::SensorNotFinite`]: the receiver is
/// the sensor of the pilot.
pub fn check(limits: &SafetyLimits, input: &SafetyInput<'_>) -> Option<AbortReason> {
    let sensor = input.sensor;
    let meas = &sensor.meas;
    let sticks = sensor.pilot.sticks.to_array();
    if !sensor.pilot.test_switch {
        return Some(AbortReason::SwitchReleased);
    }
    if !measurements_finite(meas) || !sticks.iter().all(|v| v.is_finite()) {
        return Some(AbortReason::SensorNotFinite);
    }
    if input.unchanged_seq_ticks > u32::from(limits.stale_limit_ticks) {
        return Some(AbortReason::SensorStale);
    }
    if meas.phi.abs() > limits.attitude_limit_rad || meas.theta.abs() > limits.attitude_limit_rad {
        return Some(AbortReason::AttitudeLimit);
    }
    let rates = [meas.p, meas.q, meas.r];
    if rates
        .iter()
        .zip(limits.rate_limit_rad_s.iter())
        .any(|(rate, limit)| rate.abs() > *limit)
    {
        return Some(AbortReason::RateLimit);
    }
    if let Some(reference) = input.stick_reference {
        if sticks
            .iter()
            .zip(reference.iter())
            .any(|(stick, trim)| (stick - trim).abs() > limits.pilot_override)
        {
            return Some(AbortReason::PilotOverride);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweephold_protocol::{Controls, PilotInput};

    fn calm() -> SensorIn {
        SensorIn {
            seq: 1,
            meas: Measurements {
                az: -9.81,
                ..Measurements::default()
            },
            pilot: PilotInput {
                sticks: Controls::default(),
                test_switch: true,
            },
        }
    }

    fn verdict(sensor: &SensorIn, unchanged: u32) -> Option<AbortReason> {
        check(
            &SafetyLimits::bo105(),
            &SafetyInput {
                sensor,
                unchanged_seq_ticks: unchanged,
                stick_reference: Some([0.0; 4]),
            },
        )
    }

    #[test]
    fn calm_flight_passes() {
        assert_eq!(verdict(&calm(), 0), None);
        assert_eq!(verdict(&calm(), 3), None);
    }

    #[test]
    fn stale_counts_consecutive_unchanged_ticks() {
        let mut tracker = StaleTracker::default();
        assert_eq!(tracker.observe(5), 0);
        assert_eq!(tracker.observe(5), 1);
        assert_eq!(tracker.observe(5), 2);
        assert_eq!(tracker.observe(6), 0);
        assert_eq!(verdict(&calm(), 4), Some(AbortReason::SensorStale));
    }

    #[test]
    fn the_switch_takes_precedence() {
        let mut sensor = calm();
        sensor.pilot.test_switch = false;
        sensor.meas.phi = f32::NAN;
        assert_eq!(verdict(&sensor, 0), Some(AbortReason::SwitchReleased));
    }

    #[test]
    fn non_finite_stick_is_a_sensor_fault() {
        let mut sensor = calm();
        sensor.pilot.sticks.col = f32::INFINITY;
        assert_eq!(verdict(&sensor, 0), Some(AbortReason::SensorNotFinite));
    }
}
