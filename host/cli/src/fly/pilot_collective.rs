//! The simulated pilot's collective stick: a height hold, and a step (`--collective-step`).
//!
//! # Height hold
//!
//! When the flight logic leaves the collective with the pilot during a test
//! (`[flight_controller] collective = "pilot"`), the pilot of `fly` keeps the height the
//! record started at with the collective stick, until the test ends.
//!
//! ```text
//! col = col_trim + (ω²·(h₀ − h) − 2ζω·ḣ) / |Z_col|
//! ```
//!
//! with h the simulator's height (−down) and ḣ its climb rate (the change of the height
//! over the tick), Z_col the aircraft's quasi-static heave per collective stick at the
//! hover trim (Bo-105 −14.6, TREX 700L −59.7 m/s² per stick), ω = 0.5 rad/s and
//! ζ = 0.7: the vertical axis behaves as a second-order loop with a 2π/0.5 ≈ 13 s period
//! and little overshoot, a human pilot's slow hand on the collective that does not
//! chase the sweep's small height disturbances at frequencies above about 1 rad/s
//! (the Bo-105: 0.017 stick per m, 0.048 stick per m/s; the TREX: 0.0042 and 0.012).
//! The correction is limited to ±0.3 stick: a pilot does not slam the collective.

/// `--collective-step DELTA@AT_S`: from record time `at_s` on (while the test runs), the
/// pilot's collective stick is `delta` (fraction of travel) off where the pilot holds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollectiveStep {
    /// The stick's offset \[fraction of travel\].
    pub delta: f64,
    /// Record time of the step \[s\].
    pub at_s: f64,
}

impl CollectiveStep {
    /// Parse `DELTA@AT_S`: DELTA in [−2, 2], AT_S ≥ 0.
    pub fn parse(text: &str) -> Result<CollectiveStep, String> {
        let expected = || format!("`{text}`: expected DELTA@AT_S (e.g. -0.8@10)");
        let (delta, at) = text.split_once('@').ok_or_else(expected)?;
        let delta: f64 = delta.trim().parse().map_err(|_| expected())?;
        let at_s: f64 = at.trim().parse().map_err(|_| expected())?;
        if !(delta.is_finite() && (-2.0..=2.0).contains(&delta)) {
            return Err(format!(
                "`{text}`: DELTA must be from -2 to 2 (stick travel)"
            ));
        }
        if !(at_s.is_finite() && at_s >= 0.0) {
            return Err(format!("`{text}`: AT_S must be a record time >= 0 s"));
        }
        Ok(CollectiveStep { delta, at_s })
    }
}

/// Natural frequency of the height loop \[rad/s\].
const OMEGA_RAD_S: f64 = 0.5;
/// Damping ratio of the height loop.
const ZETA: f64 = 0.7;
/// Largest correction from the trim collective \[stick\].
const MAX_CORRECTION: f64 = 0.3;

/// The height hold's gains and state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightHold {
    /// Stick per m of height error.
    height_gain: f64,
    /// Stick per m/s of climb rate.
    climb_gain: f64,
    /// The height held \[m\] (the first one seen).
    reference: Option<f64>,
    /// The height of the tick before \[m\].
    last: Option<f64>,
}

impl HeightHold {
    /// A height hold for an aircraft whose collective gives `z_col` m/s² of heave per
    /// stick (negative: up); `None` for a collective without heave authority.
    pub fn new(z_col: f64) -> Option<Self> {
        let authority = z_col.abs();
        (authority.is_finite() && authority > 1e-3).then(|| HeightHold {
            height_gain: OMEGA_RAD_S * OMEGA_RAD_S / authority,
            climb_gain: 2.0 * ZETA * OMEGA_RAD_S / authority,
            reference: None,
            last: None,
        })
    }

    /// The stick gains: (per m of height error, per m/s of climb).
    pub fn gains(&self) -> (f64, f64) {
        (self.height_gain, self.climb_gain)
    }

    /// The collective correction \[stick\] for the height `height` \[m\] after `dt` \[s\]
    /// since the last call.
    pub fn correction(&mut self, height: f64, dt: f64) -> f64 {
        let reference = *self.reference.get_or_insert(height);
        let climb = match self.last {
            Some(last) if dt > 0.0 => (height - last) / dt,
            _ => 0.0,
        };
        self.last = Some(height);
        let correction = self.height_gain * (reference - height) - self.climb_gain * climb;
        if correction.is_finite() {
            correction.clamp(-MAX_CORRECTION, MAX_CORRECTION)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the vertical axis ḧ = |Z_col|·δ (no heave damping), the hold brings a climb
    /// of 0.5 m/s back to the held height: the peak about v₀/ω·e^(−ζ…) ≈ 0.5 m, an
    /// undershoot under 5 % of it, within 5 cm after 30 s.
    #[test]
    fn the_loop_on_a_pure_heave_model_returns_to_the_held_height() {
        let z_col = -14.6;
        let mut hold = HeightHold::new(z_col).unwrap();
        let dt = 0.005;
        let (mut h, mut climb) = (0.0, 0.5);
        let (mut peak, mut low): (f64, f64) = (0.0, 0.0);
        for _ in 0..(30.0 / dt) as usize {
            let delta = hold.correction(h, dt);
            climb += -z_col * delta * dt;
            h += climb * dt;
            peak = peak.max(h);
            low = low.min(h);
        }
        assert!(peak > 0.3 && peak < 0.7, "peak {peak} m");
        assert!(-low < 0.05 * peak, "undershoot {low} m");
        assert!(h.abs() < 0.05, "after 30 s: {h} m");
    }

    #[test]
    fn the_gains_follow_the_collective_authority() {
        let hold = HeightHold::new(-14.6).unwrap();
        let (height, climb) = hold.gains();
        assert!((height - 0.25 / 14.6).abs() < 1e-12);
        assert!((climb - 0.7 / 14.6).abs() < 1e-12);
        assert_eq!(HeightHold::new(0.0), None);
        assert_eq!(HeightHold::new(f64::NAN), None);
    }

    #[test]
    fn collective_steps_parse() {
        assert_eq!(
            CollectiveStep::parse("-0.8@10"),
            Ok(CollectiveStep {
                delta: -0.8,
                at_s: 10.0
            })
        );
        for bad in ["0.1", "x@1", "0.1@-1", "3@1", "nan@1", "0.1@inf"] {
            assert!(CollectiveStep::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_correction_is_limited() {
        let mut hold = HeightHold::new(-14.6).unwrap();
        hold.correction(0.0, 0.005);
        assert_eq!(hold.correction(-1000.0, 0.005), MAX_CORRECTION);
    }
}
