//! A per-axis slew limit on the commands of the excitation phases: each command moves by
//! at most its axis' rate per second from the one applied the tick before.
//!
//! The servos have rate limits of their own (the simulator's: 4 stick fractions per
//! second). A command that moves faster than its servo can follow is recorded but not
//! flown: the blade sees the servo's ramp, the telemetry the step. With the slew limit at
//! (or just below) the servo's rate, the recorded command is one the servo achieves. The
//! limit is off (infinite) by default; a vehicle preset turns it on where its controller
//! drives a servo into its rate limit.

/// Per-axis slew limits \[stick fraction per second\] of `N` axes. Each is positive;
/// `f32::INFINITY` means no limit on that axis. Two uses: [`CommandSlew`] (the four
/// commands) and [`HoldSlew`] (the holds' share of the three held ones).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlewLimits<const N: usize> {
    /// Largest rate of change on each axis \[1/s\].
    pub per_s: [f32; N],
}

/// Slew limits of the four commands, in the order lat, lon, ped, col.
pub type CommandSlew = SlewLimits<4>;

/// Slew limits of the attitude holds' share of the lat, lon and ped commands: the part of
/// each command the hold controller (and its fade after a release) produces moves from
/// its own value of the tick before by at most its axis' rate per second; the sweep and
/// the off-axis noise are added as they are, and leave or rejoin an axis at once when its
/// hold engages or releases.
///
/// Why the hold's share alone: a hold's rate damping (`Kd·ω`) answers the rotor's fast
/// motion with commands faster than a slow servo follows, so the recorded command is not
/// the one flown; the sweep and the noise are designed within the servo's rate. Limiting
/// the whole command instead ([`CommandSlew`]) also slews the noise's steps at the holds'
/// engagements and releases into the command, which measured worse on the fbl700
/// (docs/decisions/2026-11-27-fbl700-servo-rate-limit.md). An infinite limit on an axis:
/// its command is bit for bit the one without the setting.
pub type HoldSlew = SlewLimits<3>;

impl<const N: usize> SlewLimits<N> {
    /// No limit on any axis.
    pub const NONE: Self = SlewLimits {
        per_s: [f32::INFINITY; N],
    };

    /// Every limit positive and not NaN (infinite allowed: no limit).
    pub fn is_valid(&self) -> bool {
        self.per_s.iter().all(|&rate| rate > 0.0)
    }

    /// The largest step per tick of each axis for a tick of `dt_s` seconds (infinite for an
    /// axis without a limit).
    pub fn steps(&self, dt_s: f32) -> [f32; N] {
        self.per_s.map(|rate| {
            if rate.is_finite() {
                rate * dt_s
            } else {
                f32::INFINITY
            }
        })
    }
}

impl CommandSlew {
    /// Only the pedal limited, to `per_s` \[1/s\].
    pub const fn pedal(per_s: f32) -> CommandSlew {
        SlewLimits {
            per_s: [f32::INFINITY, f32::INFINITY, per_s, f32::INFINITY],
        }
    }
}

impl<const N: usize> Default for SlewLimits<N> {
    fn default() -> Self {
        Self::NONE
    }
}

/// `target`, moved from `last` by at most `max_step`. An infinite (or NaN) `max_step`
/// returns `target` unchanged, bit for bit; a NaN `last` or `target` gives `last` or the
/// other finite value, never NaN when either is finite and `max_step` is finite.
pub fn limit(last: f32, target: f32, max_step: f32) -> f32 {
    if !max_step.is_finite() {
        return target;
    }
    if target.is_nan() {
        return last;
    }
    if last.is_nan() {
        return target;
    }
    let step = max_step.abs();
    let delta = target - last;
    // Comparisons, not `f32::clamp` (which panics on reversed or NaN bounds).
    if delta > step {
        last + step
    } else if delta < -step {
        last - step
    } else {
        target
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_limit_returns_the_target_bit_for_bit() {
        for target in [0.0, -0.0, 0.123_456_7, -1.0, 1.0] {
            let out = limit(0.5, target, f32::INFINITY);
            assert_eq!(out.to_bits(), target.to_bits());
        }
        assert_eq!(CommandSlew::NONE.steps(0.005), [f32::INFINITY; 4]);
        assert_eq!(CommandSlew::default(), CommandSlew::NONE);
    }

    #[test]
    fn a_step_is_cut_to_the_rate_and_a_small_move_passes() {
        let step = 4.0 * 0.005;
        assert_eq!(limit(0.0, 0.5, step), step);
        assert_eq!(limit(0.0, -0.5, step), -step);
        assert_eq!(limit(0.1, 0.11, step), 0.11);
        // A ramp towards a far target reaches it in ceil(distance / step) ticks.
        let mut command = 0.0;
        let mut ticks = 0;
        while command != 0.5 && ticks < 1000 {
            command = limit(command, 0.5, step);
            ticks += 1;
        }
        assert_eq!(ticks, 25);
    }

    #[test]
    fn nan_never_comes_out_of_finite_inputs() {
        assert_eq!(limit(0.2, f32::NAN, 0.02), 0.2);
        assert_eq!(limit(f32::NAN, 0.3, 0.02), 0.3);
        assert_eq!(limit(0.2, 0.9, f32::NAN), 0.9);
        // A negative step acts as its magnitude.
        assert!((limit(0.0, 1.0, -0.02) - 0.02).abs() < 1e-7);
        assert_eq!(limit(0.0, f32::INFINITY, 0.02), 0.02);
        assert_eq!(limit(0.0, f32::NEG_INFINITY, 0.02), -0.02);
    }

    #[test]
    fn validity_and_steps() {
        assert!(CommandSlew::NONE.is_valid());
        assert!(CommandSlew::pedal(4.0).is_valid());
        assert_eq!(CommandSlew::pedal(4.0).steps(0.005)[2], 0.02);
        for bad in [0.0, -1.0, f32::NAN, f32::NEG_INFINITY] {
            assert!(!CommandSlew::pedal(bad).is_valid(), "{bad}");
        }
    }
}
