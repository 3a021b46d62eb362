//! Tischler's exponential frequency sweep (paper Eq. 19–23; Tischler & Remple), with the
//! closed-form phase, an optional hold at ω_min and raised-cosine fades.
//!
//! ```text
//! ω(t) = ω_min + K(t)(ω_max − ω_min),   K(t) = C2 (e^{C1 t/T_rec} − 1)
//! C1 = 4,  C2 = 1/(e^4 − 1)             (so ω(0) = ω_min, ω(T_rec) = ω_max)
//! θ(t) = ∫₀ᵗ ω dt = ω_min t + (ω_max − ω_min) C2 [ (T_rec/C1)(e^{C1 t/T_rec} − 1) − t ]
//! δ(t) = A sin θ(t)
//! ```
//!
//! The phase reaches several hundred radians over a 90 s record. An `f32` carries only
//! ~7 digits, so at θ ≈ 700 rad its spacing is ~6·10⁻⁵ rad and an `f32` *accumulation*
//! of ω·dt drifts without bound. The phase is therefore evaluated in closed form in `f64`
//! (libm's `expm1`, which stays accurate near t = 0 where `e^x − 1` would cancel), reduced
//! modulo 2π in `f64`, and only the reduced angle in [0, 2π) goes to `f32` `sinf`.
//! Never `sin(ω(t)·t)`: its instantaneous frequency is not ω(t) (the SIDPAC `mkfswp`
//! mistake).

use core::f64::consts::TAU;

use crate::excitation::{ExcitationSample, Segment};

/// Exponent constant C1 of the sweep.
pub const C1: f64 = 4.0;

/// C2 = 1/(e^{C1} − 1), so that K(T_rec) = 1 and the sweep ends exactly at ω_max.
pub fn c2() -> f64 {
    1.0 / libm::expm1(C1)
}

/// The frequency law and closed-form phase of one exponential sweep record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExponentialSweep {
    omega_min: f64,
    omega_max: f64,
    t_rec: f64,
    c2: f64,
}

impl ExponentialSweep {
    /// A sweep from `omega_min` to `omega_max` [rad/s] over `t_rec` \[s\]. The arguments are
    /// assumed validated (finite, 0 < ω_min < ω_max, T_rec > 0); see `Config::validate`.
    pub fn new(omega_min: f64, omega_max: f64, t_rec: f64) -> Self {
        ExponentialSweep {
            omega_min,
            omega_max,
            t_rec,
            c2: c2(),
        }
    }

    /// Record length T_rec \[s\].
    pub fn record_length(&self) -> f64 {
        self.t_rec
    }

    /// Instantaneous frequency ω(t) = ω_min + C2 (e^{C1 t/T_rec} − 1)(ω_max − ω_min) [rad/s].
    pub fn omega(&self, t: f64) -> f64 {
        let k = self.c2 * libm::expm1(C1 * t / self.t_rec);
        self.omega_min + k * (self.omega_max - self.omega_min)
    }

    /// Phase θ(t) = ω_min t + (ω_max − ω_min) C2 [(T_rec/C1)(e^{C1 t/T_rec} − 1) − t] \[rad\],
    /// the exact integral of [`omega`](Self::omega) from 0 to t.
    pub fn phase(&self, t: f64) -> f64 {
        let growth = (self.t_rec / C1) * libm::expm1(C1 * t / self.t_rec) - t;
        self.omega_min * t + (self.omega_max - self.omega_min) * self.c2 * growth
    }
}

/// The complete sweep excitation: fade-in and ω_min hold (lead-in), the sweep record, and
/// the fade-out, as a pure function of the time since the excitation started.
///
/// ```text
/// segment   time span                      phase θ                          envelope
/// lead-in   [0, T_fade + T_hold)           ω_min t                          ½ − ½cos(πt/T_fade), then 1
/// main      [T_lead, T_lead + T_rec)       θ_lead + θ_sweep(t − T_lead)     1
/// tail      [T_main_end, + T_fade)         θ_end + ω_max (t − T_main_end)    ½ + ½cos(πτ/T_fade)
/// ```
///
/// The phase is continuous across the segments, and the instantaneous frequency is ω_min
/// in the lead-in, ω(t) in the record and ω_max in the tail, so the full record T_rec runs
/// at full amplitude and the fades and the hold come on top (as `SweepSettings` says).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepSignal {
    sweep: ExponentialSweep,
    amplitude: f32,
    fade_s: f64,
    lead_in_s: f64,
    phase_at_record_start: f64,
    phase_at_record_end: f64,
}

impl SweepSignal {
    /// Build from validated settings: amplitude A, ω range [rad/s], record length \[s\],
    /// fade length \[s\] (0 disables) and the number of ω_min cycles held before the record.
    pub fn new(
        amplitude: f32,
        omega_min: f64,
        omega_max: f64,
        t_rec: f64,
        fade_s: f64,
        start_hold_cycles: u8,
    ) -> Self {
        let sweep = ExponentialSweep::new(omega_min, omega_max, t_rec);
        // N cycles at ω_min last N·2π/ω_min.
        let hold_s = f64::from(start_hold_cycles) * TAU / omega_min;
        let lead_in_s = fade_s + hold_s;
        let phase_at_record_start = omega_min * lead_in_s;
        SweepSignal {
            sweep,
            amplitude,
            fade_s,
            lead_in_s,
            phase_at_record_start,
            phase_at_record_end: phase_at_record_start + sweep.phase(t_rec),
        }
    }

    /// The sweep record's frequency law.
    pub fn sweep(&self) -> &ExponentialSweep {
        &self.sweep
    }

    /// Total length of the excitation, lead-in + record + tail \[s\].
    pub fn duration_s(&self) -> f64 {
        self.lead_in_s + self.sweep.t_rec + self.fade_s
    }

    /// Continuous phase θ \[rad\] and instantaneous frequency [rad/s] at time `t` since the
    /// excitation started, with the segment `t` falls in.
    pub fn phase_and_omega(&self, t: f64) -> (Segment, f64, f64) {
        let record_end = self.lead_in_s + self.sweep.t_rec;
        if t < self.lead_in_s {
            (
                Segment::LeadIn,
                self.sweep.omega_min * t,
                self.sweep.omega_min,
            )
        } else if t < record_end {
            let tau = t - self.lead_in_s;
            (
                Segment::Main,
                self.phase_at_record_start + self.sweep.phase(tau),
                self.sweep.omega(tau),
            )
        } else if t < record_end + self.fade_s {
            let tau = t - record_end;
            (
                Segment::Tail,
                self.phase_at_record_end + self.sweep.omega_max * tau,
                self.sweep.omega_max,
            )
        } else {
            (Segment::Finished, self.phase_at_record_end, 0.0)
        }
    }

    /// The raised-cosine envelope at time `t` (1 outside the fades).
    fn envelope(&self, segment: Segment, t: f64) -> f32 {
        if self.fade_s <= 0.0 {
            return 1.0;
        }
        match segment {
            Segment::LeadIn if t < self.fade_s => {
                // ½ − ½ cos(π t / T_fade): 0 → 1 with zero slope at both ends.
                let x = (t / self.fade_s) as f32;
                0.5 - 0.5 * libm::cosf(core::f32::consts::PI * x)
            }
            Segment::Tail => {
                let tau = t - self.lead_in_s - self.sweep.t_rec;
                let x = (tau / self.fade_s) as f32;
                0.5 + 0.5 * libm::cosf(core::f32::consts::PI * x)
            }
            Segment::Finished => 0.0,
            _ => 1.0,
        }
    }

    /// The excitation at time `t` \[s\] since it started.
    pub fn sample(&self, t: f64) -> ExcitationSample {
        let (segment, theta, omega) = self.phase_and_omega(t);
        if segment == Segment::Finished {
            return ExcitationSample::FINISHED;
        }
        // Reduce in f64 first: the f32 sine then sees an angle in [0, 2π) where its
        // absolute error is ~1e-7, instead of a ~700 rad argument that f32 cannot resolve.
        let reduced = libm::fmod(theta, TAU) as f32;
        let envelope = self.envelope(segment, t);
        ExcitationSample {
            segment,
            value: self.amplitude * envelope * libm::sinf(reduced),
            omega: omega as f32,
            envelope,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper_sweep() -> ExponentialSweep {
        ExponentialSweep::new(0.3, 31.4, 90.0)
    }

    #[test]
    fn c2_makes_the_sweep_end_at_omega_max() {
        assert!((c2() - 0.018_657_1).abs() < 1e-6);
        let sweep = paper_sweep();
        assert!((sweep.omega(0.0) - 0.3).abs() < 1e-12);
        assert!((sweep.omega(90.0) - 31.4).abs() < 1e-9);
    }

    #[test]
    fn numerical_derivative_of_phase_matches_omega_over_the_whole_record() {
        // Central difference dθ/dt ≈ (θ(t+h) − θ(t−h)) / 2h; the truncation error
        // θ'''h²/6 and the rounding error ε·θ/h are both far below 0.1 %.
        let sweep = paper_sweep();
        let h = 1e-4;
        let steps = 9000;
        let mut worst = 0.0f64;
        for i in 0..=steps {
            let t = 90.0 * f64::from(i) / f64::from(steps);
            let derivative = if i == 0 {
                (sweep.phase(t + h) - sweep.phase(t)) / h
            } else if i == steps {
                (sweep.phase(t) - sweep.phase(t - h)) / h
            } else {
                (sweep.phase(t + h) - sweep.phase(t - h)) / (2.0 * h)
            };
            let relative = (derivative - sweep.omega(t)).abs() / sweep.omega(t);
            worst = worst.max(relative);
        }
        assert!(worst < 1e-3, "worst relative frequency error {worst}");
        // And the frequency actually runs from ω_min to ω_max.
        let start = (sweep.phase(h) - sweep.phase(0.0)) / h;
        let end = (sweep.phase(90.0) - sweep.phase(90.0 - h)) / h;
        assert!((start - 0.3).abs() / 0.3 < 1e-3, "start {start}");
        assert!((end - 31.4).abs() / 31.4 < 1e-3, "end {end}");
    }

    #[test]
    fn sampled_signal_frequency_matches_omega_from_zero_crossings() {
        // Independent check on the emitted samples: the count of zero crossings of the
        // sampled signal over the record equals θ(T_rec)/π to within one crossing.
        let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 0.0, 0);
        let rate = 1000.0;
        let mut crossings = 0u32;
        let mut previous = signal.sample(0.5 / rate).value;
        for n in 1..90_000u32 {
            let value = signal.sample((f64::from(n) + 0.5) / rate).value;
            if (value > 0.0) != (previous > 0.0) {
                crossings += 1;
            }
            previous = value;
        }
        let expected = signal.sweep().phase(90.0) / core::f64::consts::PI;
        assert!(
            (f64::from(crossings) - expected).abs() <= 2.0,
            "{crossings} vs {expected}"
        );
    }

    #[test]
    fn phase_is_continuous_across_segments_and_fades_shape_the_envelope() {
        let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 2.0, 1);
        let hold = TAU / 0.3;
        let lead = 2.0 + hold;
        let eps = 1e-9;
        for boundary in [lead, lead + 90.0] {
            let (_, before, _) = signal.phase_and_omega(boundary - eps);
            let (_, after, _) = signal.phase_and_omega(boundary);
            assert!((after - before).abs() < 1e-6, "jump at {boundary}");
        }
        assert_eq!(signal.sample(0.0).envelope, 0.0);
        assert!((signal.sample(1.0).envelope - 0.5).abs() < 1e-6);
        assert_eq!(signal.sample(2.5).envelope, 1.0);
        assert_eq!(signal.sample(lead + 1.0).segment, Segment::Main);
        assert!((signal.sample(lead + 90.0 + 1.0).envelope - 0.5).abs() < 1e-6);
        assert_eq!(signal.sample(lead + 90.0 + 1.0).omega, 31.4);
        assert_eq!(signal.sample(lead + 92.0).segment, Segment::Finished);
        assert!((signal.duration_s() - (lead + 92.0)).abs() < 1e-12);
    }

    #[test]
    fn amplitude_bounds_the_signal() {
        let signal = SweepSignal::new(0.05, 0.3, 31.4, 90.0, 2.0, 0);
        let mut peak = 0.0f32;
        for n in 0..94_000u32 {
            let sample = signal.sample(f64::from(n) / 1000.0);
            peak = peak.max(sample.value.abs());
        }
        assert!(peak <= 0.05 && peak > 0.0499, "peak {peak}");
    }
}
