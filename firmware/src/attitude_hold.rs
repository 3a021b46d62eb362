//! The attitude-hold controller of one axis: PID on the attitude error with rate damping
//! from the measured body rate, output and integrator limits, anti-windup, bumpless
//! engagement and integrator reset on release.
//!
//! ```text
//! s = −1 if reversed else +1        (sign convention below)
//! u = −s·(Kp·e + Kd·ω) + I + B,     I[n+1] = clamp(I[n] − s·Ki·e·dt, ±I_max)
//! B[n+1] = B[n]·e^{−dt/τ_b}          (bumpless-transfer term, see below)
//! output = clamp(u, ±u_max)
//! ```
//!
//! `e` is the attitude deviation from trim \[rad\] and `ω` the matching body rate (p, q or
//! r) [rad/s], used instead of de/dt because it is measured directly and has no
//! derivative kick. Sign convention: a positive command produces a positive moment about
//! the held axis (lat → +roll, lon → +pitch (nose up), ped → +yaw (nose right)); set
//! `reversed` for an axis wired the other way.
//!
//! Anti-windup is conditional integration: the integrator does not grow while the output
//! is saturated in the direction it would grow.
//!
//! Bumpless engagement sets the transfer term B so that the first output equals the
//! perturbation the axis carried in the previous tick; B then decays with time constant
//! τ_b (`bumpless_time_s`), handing the axis over to the PID within a few τ_b. Loading
//! the offset into the integrator instead (the textbook bumpless transfer) would cancel
//! the proportional action at the very moment the attitude has crossed the engage
//! threshold, and with the small Ki of an attitude hold it would take tens of seconds to
//! bleed off. The integrator starts empty at each engagement.

/// Gains and limits of one axis. Units: stick fraction per rad, per rad/s, per rad·s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisGains {
    /// Proportional gain on the attitude error [stick/rad].
    pub kp: f32,
    /// Integral gain [stick/(rad·s)].
    pub ki: f32,
    /// Rate-damping gain on the body rate [stick/(rad/s)].
    pub kd: f32,
    /// Output limit, fraction of stick travel (the controller's authority around trim).
    pub output_limit: f32,
    /// Integrator limit, fraction of stick travel.
    pub integrator_limit: f32,
    /// The axis' positive command produces a negative moment.
    pub reversed: bool,
    /// Time constant τ_b of the bumpless-transfer decay \[s\]; 0 hands over at once.
    pub bumpless_time_s: f32,
    /// Time constant τ_r \[s\] with which the controller's last output fades out after a
    /// release, while the excitation resumes at once; 0 drops it in one tick (the
    /// paper's rule taken literally). See `controller` for why a fade is the default.
    pub release_time_s: f32,
}

impl AxisGains {
    /// Whether every field is finite and in range: gains ≥ 0, output limit in (0, 1],
    /// integrator limit in [0, output limit], bumpless time ≥ 0.
    pub fn is_valid(&self) -> bool {
        let finite = [
            self.kp,
            self.ki,
            self.kd,
            self.output_limit,
            self.integrator_limit,
            self.bumpless_time_s,
            self.release_time_s,
        ]
        .iter()
        .all(|v| v.is_finite());
        finite
            && self.kp >= 0.0
            && self.ki >= 0.0
            && self.kd >= 0.0
            && self.output_limit > 0.0
            && self.output_limit <= 1.0
            && self.integrator_limit >= 0.0
            && self.integrator_limit <= self.output_limit
            && self.bumpless_time_s >= 0.0
            && self.release_time_s >= 0.0
    }
}

/// Gains of the three held axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// Lateral cyclic on roll φ, damped by p.
    pub lat: AxisGains,
    /// Longitudinal cyclic on pitch θ, damped by q.
    pub lon: AxisGains,
    /// Pedal on heading error ψ − ψ_trim, damped by r.
    pub ped: AxisGains,
}

impl Gains {
    /// Starting values for the Bo-105 simulator, to be tuned against it (integration).
    ///
    /// Sizing, hover, quasi-static, with the simulator's gearing (lat ±8° θ1c, lon ±10°
    /// θ1s, ped ±16.5° tail pitch per unit stick; positive stick → positive moment):
    /// roll: L_θ1c ≈ −170 /s² per rad → ~24 rad/s² per stick, L_p ≈ −14 /s. Kp 2.0,
    /// Kd 0.3: φ̈ + 21φ̇ + 47φ = 0 → poles ≈ −2.6, −18.5 /s.
    /// pitch: M_θ1s ≈ 45 → ~7.9 rad/s² per stick, M_q ≈ −3.7 /s. Kp 3.0, Kd 1.0:
    /// θ̈ + 11.6θ̇ + 23.6θ = 0 → poles ≈ −2.6, −9.0 /s.
    /// yaw: N_θ0tr ≈ −15.5 per rad → ~4.5 rad/s² per stick, N_r ≈ −0.3 /s. Kp 3.0,
    /// Kd 1.5: ω_n ≈ 3.7 rad/s, ζ ≈ 0.96.
    /// Small integral gains trim out offsets over tens of seconds; authority ±0.3 of
    /// stick around trim; bumpless hand-over in τ_b = 0.1 s.
    ///
    /// Release fade τ_r = 2 s (see `controller`). Tuned against `host/rotorsim` in hover
    /// with sensor noise, pilot sticks at trim, the paper's two sweeps per axis in CAH
    /// mode with off-axis noise RMS 0.03 (`sweephold fly`, seeds 1–3): no abort, |φ| and
    /// |θ| at most 9°, the hold engaged ~10–15 % of the excitation on the lateral records.
    /// Without the release fade the hold chattered (engaged ~30 %, peaks ~11–12°).
    pub const fn bo105() -> Self {
        Gains {
            lat: AxisGains {
                kp: 2.0,
                ki: 0.05,
                kd: 0.3,
                output_limit: 0.3,
                integrator_limit: 0.3,
                reversed: false,
                bumpless_time_s: 0.1,
                release_time_s: 2.0,
            },
            lon: AxisGains {
                kp: 3.0,
                ki: 0.1,
                kd: 1.0,
                output_limit: 0.3,
                integrator_limit: 0.3,
                reversed: false,
                bumpless_time_s: 0.1,
                release_time_s: 2.0,
            },
            ped: AxisGains {
                kp: 3.0,
                ki: 0.05,
                kd: 1.5,
                output_limit: 0.3,
                integrator_limit: 0.3,
                reversed: false,
                bumpless_time_s: 0.1,
                release_time_s: 2.0,
            },
        }
    }

    /// Gains for a TREX 700L-class flybarless helicopter, tuned against the host
    /// simulator's `trex700l` (an approximation: no identified model of the real
    /// aircraft exists). Its roll control power (L_lat ≈ 350 rad/s² per stick, L_p ≈
    /// −67 /s) is an order of magnitude above the Bo-105's and its hover phugoid
    /// doubles in under a second (0.84 ± 1.12i), so the attitude loop must be stiff:
    /// Kp 1.5 gives φ poles near −8 and −70 /s. With these, `sweephold fly --vehicle
    /// trex700l` flies every default record without an abort. Re-tune on the real
    /// aircraft before flight.
    ///
    /// Release fade τ_r = 0.8 s on roll and pitch: the output a hold leaves behind at
    /// release is mostly its restoring command. A short fade (0.3 s) hands the steps the
    /// cross-control coherence measures back into both held axes (cah lat–lon 0.279 over
    /// seeds 1–10); a long one alone carried the aircraft through trim and beyond the
    /// engage angle on the other side (1 s: excursions to 10.6° from trim). With the
    /// preset's narrower hysteresis (engage 4.5°, release 3°) and the holds' share slewed
    /// at 3.6 /s ([`crate::config::TREX700L_HOLD_SLEW`]), 0.8 s gives 0.240 with every
    /// excursion within 9.2°
    /// (docs/decisions/2026-11-27-trex-cah-coherence-release.md).
    ///
    /// Heading: N_ped ≈ 80 rad/s² per stick, and the pedal slews at 4 /s. With Kp 1.5,
    /// Kd 0.3 and ±0.3 of authority the heading hold needed 0.15 s to reverse its
    /// output, longer than its own loop's half period, and it limit-cycled at ±25–35°
    /// whenever it engaged. Kp 0.6, Kd 0.12 (ψ̈ ≈ −80·(0.6ψ + 0.12r): ω_n ≈ 6.9 rad/s,
    /// ζ ≈ 0.7) within ±0.12 reverse in 0.06 s and hold the heading within 12°
    /// (docs/decisions/2026-11-25-trex700l-pedal-and-release.md).
    pub const fn trex700l() -> Self {
        Gains {
            lat: AxisGains {
                kp: 1.5,
                ki: 0.05,
                kd: 0.08,
                output_limit: 0.3,
                integrator_limit: 0.3,
                reversed: false,
                bumpless_time_s: 0.05,
                release_time_s: 0.8,
            },
            lon: AxisGains {
                kp: 2.0,
                ki: 0.05,
                kd: 0.15,
                output_limit: 0.3,
                integrator_limit: 0.3,
                reversed: false,
                bumpless_time_s: 0.05,
                release_time_s: 0.8,
            },
            ped: AxisGains {
                kp: 0.6,
                ki: 0.05,
                kd: 0.12,
                output_limit: 0.12,
                integrator_limit: 0.12,
                reversed: false,
                bumpless_time_s: 0.05,
                release_time_s: 1.0,
            },
        }
    }

    /// The three axes in order lat, lon, ped.
    pub const fn to_array(&self) -> [AxisGains; 3] {
        [self.lat, self.lon, self.ped]
    }
}

/// Largest bumpless-transfer offset \[stick\]: commands and trims lie in [−1, 1].
const MAX_TRANSFER: f32 = 2.0;

/// State of one axis' attitude-hold controller: the integrator and the decaying
/// bumpless-transfer term, both in stick units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AttitudeController {
    integral: f32,
    transfer: f32,
}

impl AttitudeController {
    /// A controller with an empty integrator.
    pub const ZERO: AttitudeController = AttitudeController {
        integral: 0.0,
        transfer: 0.0,
    };

    fn sign(gains: &AxisGains) -> f32 {
        if gains.reversed {
            -1.0
        } else {
            1.0
        }
    }

    /// The proportional and rate terms −s·(Kp·e + Kd·ω).
    fn proportional_and_damping(gains: &AxisGains, error: f32, rate: f32) -> f32 {
        -Self::sign(gains) * (gains.kp * error + gains.kd * rate)
    }

    /// Bumpless engagement: empty the integrator and set the transfer term so that the
    /// output for (`error`, `rate`) equals `previous_output` (the perturbation the axis
    /// carried last tick).
    pub fn engage(&mut self, gains: &AxisGains, error: f32, rate: f32, previous_output: f32) {
        self.integral = 0.0;
        let needed = previous_output - Self::proportional_and_damping(gains, error, rate);
        self.transfer = if gains.bumpless_time_s > 0.0 {
            clamp_finite(needed, MAX_TRANSFER)
        } else {
            0.0
        };
    }

    /// Forget the integrator and the transfer term (on release).
    pub fn reset(&mut self) {
        *self = Self::ZERO;
    }

    /// The remaining bumpless-transfer offset \[stick\].
    pub fn transfer(&self) -> f32 {
        self.transfer
    }

    /// The integrator's current contribution \[stick\].
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// One control step: the output for this tick, then the integrator update.
    pub fn update(&mut self, gains: &AxisGains, error: f32, rate: f32, dt: f32) -> f32 {
        self.update_with_decay(gains, error, rate, dt, Self::transfer_decay(gains, dt))
    }

    /// e^{−dt/τ_b}, the per-tick factor of the bumpless-transfer term (0 without one). A
    /// decay rate needs no libm precision: micromath's fast exp (≈1e-3 relative) does.
    pub fn transfer_decay(gains: &AxisGains, dt: f32) -> f32 {
        if gains.bumpless_time_s > 0.0 {
            micromath::F32Ext::exp(-dt / gains.bumpless_time_s)
        } else {
            0.0
        }
    }

    /// [`update`](Self::update) with the transfer decay computed once for the
    /// configuration ([`transfer_decay`](Self::transfer_decay)), not every tick.
    pub fn update_with_decay(
        &mut self,
        gains: &AxisGains,
        error: f32,
        rate: f32,
        dt: f32,
        transfer_decay: f32,
    ) -> f32 {
        let unsaturated =
            Self::proportional_and_damping(gains, error, rate) + self.integral + self.transfer;
        let output = clamp_finite(unsaturated, gains.output_limit);
        // B ← B·e^{−dt/τ_b}: continuous at engagement, gone after a few τ_b.
        self.transfer = if gains.bumpless_time_s > 0.0 {
            clamp_finite(self.transfer * transfer_decay, MAX_TRANSFER)
        } else {
            0.0
        };
        let increment = -Self::sign(gains) * gains.ki * error * dt;
        // Conditional integration: no growth further into a saturated output.
        let winding_up = (unsaturated >= gains.output_limit && increment > 0.0)
            || (unsaturated <= -gains.output_limit && increment < 0.0);
        if !winding_up {
            self.integral = clamp_finite(self.integral + increment, gains.integrator_limit);
        }
        output
    }
}

/// `value` clamped to ±|`limit`|; NaN maps to 0 (a NaN limit counts as 0).
///
/// Not `f32::clamp`, which panics when its bounds are NaN or reversed: gains reach this
/// through public functions that cannot assume a validated configuration.
pub(crate) fn clamp_finite(value: f32, limit: f32) -> f32 {
    let limit = if limit.is_nan() { 0.0 } else { limit.abs() };
    // Comparisons, not `max`/`min` (fmaxf/fminf calls on the Cortex-M4); same result
    // for the non-NaN value and limit here.
    if value.is_nan() {
        0.0
    } else if value < -limit {
        -limit
    } else if value > limit {
        limit
    } else {
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f32 = 0.005;

    #[test]
    fn presets_are_valid() {
        for gains in [Gains::bo105(), Gains::trex700l()] {
            assert!(gains.to_array().iter().all(AxisGains::is_valid));
        }
    }

    #[test]
    fn opposes_a_positive_error_and_a_positive_rate() {
        let gains = Gains::bo105().lat;
        let mut controller = AttitudeController::default();
        assert!(controller.update(&gains, 0.1, 0.0, DT) < 0.0);
        controller.reset();
        assert!(controller.update(&gains, 0.0, 0.5, DT) < 0.0);
        let reversed = AxisGains {
            reversed: true,
            ..gains
        };
        controller.reset();
        assert!(controller.update(&reversed, 0.1, 0.0, DT) > 0.0);
    }

    #[test]
    fn output_is_limited_and_the_integrator_does_not_wind_up() {
        let gains = Gains::bo105().lat;
        let mut controller = AttitudeController::default();
        for _ in 0..100_000 {
            let out = controller.update(&gains, 1.0, 0.0, DT);
            assert!(out.abs() <= gains.output_limit);
        }
        // Saturated by the P term alone: the integrator must not have grown.
        assert_eq!(controller.integral(), 0.0);
        // Not saturated: the integrator grows but stays within its limit.
        for _ in 0..100_000 {
            controller.update(&gains, 0.01, 0.0, DT);
        }
        assert!(controller.integral() < 0.0);
        assert!(controller.integral() >= -gains.integrator_limit);
    }

    #[test]
    fn engagement_is_bumpless_and_release_resets() {
        let gains = Gains::bo105().lon;
        let mut controller = AttitudeController::default();
        controller.engage(&gains, 0.11, 0.02, 0.04);
        let initial_transfer = controller.transfer();
        assert!(initial_transfer > 0.0);
        let first = controller.update(&gains, 0.11, 0.02, DT);
        assert!((first - 0.04).abs() < 1e-6, "first output {first}");
        // After 5 τ_b the transfer has bled off and the PID acts against the error.
        let ticks = (5.0 * gains.bumpless_time_s / DT) as usize;
        let mut last = first;
        for _ in 0..ticks {
            last = controller.update(&gains, 0.11, 0.02, DT);
        }
        // e^{−5} ≈ 0.7 %: the transfer term is practically gone.
        assert!(controller.transfer().abs() < 0.01 * initial_transfer);
        assert!(last < -0.1, "output after hand-over {last}");
        controller.reset();
        assert_eq!(controller.integral(), 0.0);
        assert_eq!(controller.transfer(), 0.0);
    }

    #[test]
    fn invalid_limits_do_not_panic() {
        let mut gains = Gains::bo105().lat;
        gains.output_limit = f32::NAN;
        gains.integrator_limit = -1.0;
        let mut controller = AttitudeController::default();
        assert_eq!(controller.update(&gains, 0.1, 0.1, DT), 0.0);
        assert_eq!(clamp_finite(5.0, -2.0), 2.0);
    }

    #[test]
    fn nan_inputs_give_a_finite_output() {
        let gains = Gains::bo105().ped;
        let mut controller = AttitudeController::default();
        let out = controller.update(&gains, f32::NAN, f32::INFINITY, DT);
        assert!(out.is_finite());
        assert!(controller.integral().is_finite());
    }
}
