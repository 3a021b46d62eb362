//! The airborne and landed rule: a test starts only in the air, and a landing ends it.
//!
//! The board has no height, no air data and no skid switch, and its accelerometer cannot
//! tell a hover from standing on the skids: in both the specific force is (0, 0, −g),
//! the rotor's thrust carrying the weight or the ground doing it. So the rule reads what
//! the pilot does, as ArduPilot's helicopter land detector does (it takes a helicopter
//! for landed while the collective is below `H_COL_LAND_MIN` or the rotor is not at
//! speed, and for airborne once the collective has been above it):
//!
//! * **airborne**: the throttle has finished its soft start, the throttle output is at
//!   or above `ThrottleSettings::spooled_min` (the rotor under power), and the
//!   collective stick has stayed at or above [`AirborneSettings::col_min`] for
//!   [`AirborneSettings::time_s`] without a break;
//! * **landed**: the collective stick has stayed below `col_min` for `time_s` without a
//!   break, or the throttle output is below `spooled_min` (throttle cut: no rotor to fly
//!   on, at once).
//!
//! Between the two (a collective lowered for less than `time_s`) the aircraft is neither:
//! no new test starts, and a running one goes on. A receiver frame that is not valid
//! restarts both counts (the failsafes handle the loss itself).

/// The airborne and landed rule's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirborneSettings {
    /// Collective stick threshold (fraction, [−1, 1]): at or above it counts towards
    /// airborne, below it towards landed. Below the hover collective, above the
    /// collective a pilot leaves on the ground.
    pub col_min: f32,
    /// How long the collective must stay on one side of `col_min` \[s\].
    pub time_s: f32,
}

impl AirborneSettings {
    /// TREX 700L: hover collective stick about +0.07 (the host simulator's trim), a
    /// collective on the ground at or below about −0.3 (the blades' zero to slightly
    /// negative pitch): threshold −0.2, 1 s.
    pub const fn trex700l() -> Self {
        AirborneSettings {
            col_min: -0.2,
            time_s: 1.0,
        }
    }

    /// Bo-105 (simulator): hover collective stick about +0.35 (the host simulator's
    /// trim): threshold 0, 1 s.
    pub const fn bo105() -> Self {
        AirborneSettings {
            col_min: 0.0,
            time_s: 1.0,
        }
    }

    /// Whether the threshold is a stick value and the time finite and ≥ 0.
    pub fn is_valid(&self) -> bool {
        self.col_min.is_finite()
            && (-1.0..=1.0).contains(&self.col_min)
            && self.time_s.is_finite()
            && self.time_s >= 0.0
    }
}

/// What the rule reads this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirborneInput {
    /// The collective stick, if this tick's receiver frame is valid.
    pub collective: Option<f32>,
    /// The throttle output is at or above `spooled_min`.
    pub spooled: bool,
    /// The soft start has finished (the output has reached the stick).
    pub soft_start_done: bool,
}

/// The rule's verdict this tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AirborneState {
    /// Airborne: a test may start.
    pub airborne: bool,
    /// Landed: a running test aborts.
    pub landed: bool,
}

/// Counts the ticks the collective has stayed on each side of the threshold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AirborneDetector {
    above: u32,
    below: u32,
}

impl AirborneDetector {
    /// Forget the counts (disarm).
    pub fn reset(&mut self) {
        *self = AirborneDetector::default();
    }

    /// Observe this tick; `needed_ticks` is `time_s` in ticks (at least 1).
    pub fn observe(
        &mut self,
        settings: &AirborneSettings,
        input: &AirborneInput,
        needed_ticks: u32,
    ) -> AirborneState {
        match input.collective {
            // NaN is neither above nor below: both counts restart.
            Some(col) if col >= settings.col_min => {
                self.above = self.above.saturating_add(1);
                self.below = 0;
            }
            Some(col) if col < settings.col_min => {
                self.below = self.below.saturating_add(1);
                self.above = 0;
            }
            _ => self.reset(),
        }
        AirborneState {
            airborne: input.spooled && input.soft_start_done && self.above >= needed_ticks,
            landed: !input.spooled || self.below >= needed_ticks,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SETTINGS: AirborneSettings = AirborneSettings {
        col_min: 0.0,
        time_s: 1.0,
    };

    fn flying(col: f32) -> AirborneInput {
        AirborneInput {
            collective: Some(col),
            spooled: true,
            soft_start_done: true,
        }
    }

    #[test]
    fn airborne_after_the_collective_stays_up_for_the_time() {
        let mut detector = AirborneDetector::default();
        for _ in 0..4 {
            let state = detector.observe(&SETTINGS, &flying(0.3), 5);
            assert!(!state.airborne && !state.landed);
        }
        assert!(detector.observe(&SETTINGS, &flying(0.3), 5).airborne);
        // One tick below restarts the count.
        let dip = detector.observe(&SETTINGS, &flying(-0.1), 5);
        assert!(!dip.airborne && !dip.landed);
        assert!(!detector.observe(&SETTINGS, &flying(0.3), 5).airborne);
    }

    #[test]
    fn never_airborne_while_spooling_or_without_power() {
        let mut detector = AirborneDetector::default();
        let spooling = AirborneInput {
            soft_start_done: false,
            ..flying(0.5)
        };
        for _ in 0..10 {
            assert!(!detector.observe(&SETTINGS, &spooling, 2).airborne);
        }
        let cut = AirborneInput {
            spooled: false,
            ..flying(0.5)
        };
        let state = detector.observe(&SETTINGS, &cut, 2);
        assert!(
            !state.airborne && state.landed,
            "throttle cut is landed at once"
        );
    }

    #[test]
    fn landed_after_the_collective_stays_down_for_the_time() {
        let mut detector = AirborneDetector::default();
        for _ in 0..2 {
            assert!(!detector.observe(&SETTINGS, &flying(-0.5), 3).landed);
        }
        assert!(detector.observe(&SETTINGS, &flying(-0.5), 3).landed);
    }

    #[test]
    fn an_invalid_or_non_finite_collective_restarts_both_counts() {
        let mut detector = AirborneDetector::default();
        detector.observe(&SETTINGS, &flying(-0.5), 2);
        let lost = AirborneInput {
            collective: None,
            ..flying(0.0)
        };
        assert!(!detector.observe(&SETTINGS, &lost, 2).landed);
        detector.observe(&SETTINGS, &flying(-0.5), 2);
        assert!(!detector.observe(&SETTINGS, &flying(f32::NAN), 2).landed);
        assert!(!detector.observe(&SETTINGS, &flying(-0.5), 2).landed);
        assert!(detector.observe(&SETTINGS, &flying(-0.5), 2).landed);
    }

    #[test]
    fn settings_are_checked() {
        assert!(AirborneSettings::trex700l().is_valid());
        assert!(AirborneSettings::bo105().is_valid());
        for bad in [
            AirborneSettings {
                col_min: 1.5,
                ..SETTINGS
            },
            AirborneSettings {
                time_s: -1.0,
                ..SETTINGS
            },
            AirborneSettings {
                time_s: f32::NAN,
                ..SETTINGS
            },
        ] {
            assert!(!bad.is_valid());
        }
    }
}
