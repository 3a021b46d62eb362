//! Conditional attitude hold: the per-axis hysteresis of paper §IV.B.
//!
//! ```text
//! |angle| > engage             → Engaged   (the attitude-hold controller drives the axis)
//! release ≤ |angle| ≤ engage   → prior form kept (Engaged stays Engaged, Released stays
//!                                Released) — or, with `freeze_in_band`, Frozen: the last
//!                                command is held constant until the angle leaves the band
//! |angle| < release            → Released  (the axis gets its excitation again)
//! ```
//!
//! The angle is the deviation from the captured trim attitude (φ − φ_trim, θ − θ_trim,
//! wrapped ψ − ψ_trim), so a helicopter that trims at 2–3° of pitch starts in the middle
//! of the released region rather than near the band.

use sweephold_protocol::HoldState;

/// Engage and release thresholds of the hysteresis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldThresholds {
    /// Deviation above which the controller engages \[rad\] (paper: 6°).
    pub engage_rad: f32,
    /// Deviation below which the controller releases \[rad\] (paper: 4°).
    pub release_rad: f32,
    /// Freeze the last command inside the band instead of keeping the prior form.
    pub freeze_in_band: bool,
}

/// The hold state after observing `deviation` \[rad\], given the state before.
///
/// A non-finite deviation compares false both ways and keeps the prior state; the
/// safety checks abort the test on such a sample in the same tick anyway.
pub fn next_hold_state(
    previous: HoldState,
    deviation: f32,
    thresholds: &HoldThresholds,
) -> HoldState {
    let magnitude = deviation.abs();
    if magnitude > thresholds.engage_rad {
        HoldState::Engaged
    } else if magnitude < thresholds.release_rad {
        HoldState::Released
    } else if thresholds.freeze_in_band {
        HoldState::Frozen
    } else {
        previous
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEG: f32 = core::f32::consts::PI / 180.0;

    fn paper(freeze: bool) -> HoldThresholds {
        HoldThresholds {
            engage_rad: 6.0 * DEG,
            release_rad: 4.0 * DEG,
            freeze_in_band: freeze,
        }
    }

    fn run(freeze: bool, angles_deg: &[f32]) -> Vec<HoldState> {
        let mut state = HoldState::Released;
        angles_deg
            .iter()
            .map(|&a| {
                state = next_hold_state(state, a * DEG, &paper(freeze));
                state
            })
            .collect()
    }

    #[test]
    fn engages_above_six_degrees_either_sign() {
        use HoldState::*;
        assert_eq!(run(false, &[0.0, 5.9, 6.1]), [Released, Released, Engaged]);
        assert_eq!(
            run(false, &[0.0, -5.9, -6.1]),
            [Released, Released, Engaged]
        );
    }

    #[test]
    fn keeps_the_prior_form_inside_the_band_in_both_directions() {
        use HoldState::*;
        // Rising through the band: stays released until 6° is exceeded.
        assert_eq!(run(false, &[3.0, 4.0, 5.0, 6.0]), [Released; 4]);
        // Falling through the band after an engagement: stays engaged down to 4°.
        assert_eq!(
            run(false, &[7.0, 6.0, 5.0, 4.0, 3.9]),
            [Engaged, Engaged, Engaged, Engaged, Released]
        );
        // Turning back inside the band keeps whatever was there.
        assert_eq!(
            run(false, &[7.0, 5.0, 5.9, 4.5, 5.5]),
            [Engaged, Engaged, Engaged, Engaged, Engaged]
        );
    }

    #[test]
    fn releases_below_four_degrees() {
        use HoldState::*;
        assert_eq!(run(false, &[10.0, 3.99]), [Engaged, Released]);
        assert_eq!(run(false, &[-10.0, -3.0]), [Engaged, Released]);
    }

    #[test]
    fn freeze_option_freezes_inside_the_band() {
        use HoldState::*;
        assert_eq!(
            run(true, &[3.0, 5.0, 7.0, 5.0, 3.0]),
            [Released, Frozen, Engaged, Frozen, Released]
        );
    }

    #[test]
    fn non_finite_deviation_keeps_the_state() {
        let engaged = next_hold_state(HoldState::Engaged, f32::NAN, &paper(false));
        assert_eq!(engaged, HoldState::Engaged);
    }
}
