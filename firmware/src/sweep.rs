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
//! of ω·dt drifts without bound. Two evaluations of the same signal:
//!
//! * [`SweepSignal::sample`] at any time t: the closed form in `f64` (libm's `expm1`,
//!   which stays accurate near t = 0 where `e^x − 1` would cancel), reduced modulo 2π in
//!   `f64`, and only the reduced angle in [0, 2π) goes to `f32` `sinf`. The reference, for
//!   tests and the host.
//! * [`SweepTicker::sample`] at the loop's ticks, what the flight controller runs: no
//!   `f64` per tick (soft-float on the Cortex-M4F, ~7 000 instructions a tick). The phase
//!   is a 0.64 fixed-point fraction of a turn ([`Turns`]: wrapping addition is exact
//!   reduction modulo 2π) advanced by an exact integer recurrence, anchored on the closed
//!   form when the ticker is built; it stays within 10⁻⁹ rad of the closed form over a
//!   whole record (tests below).
//!
//! Never `sin(ω(t)·t)`: its instantaneous frequency is not ω(t) (the SIDPAC `mkfswp`
//! mistake).

use core::f64::consts::TAU;

use crate::excitation_sample::{ExcitationSample, Segment};
use crate::turns::{sin_turns, Turns};

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

    /// Where [`SweepTicker`] switches segments and how it steps, for a loop at `rate_hz`.
    pub fn ticker(&self, rate_hz: u16) -> SweepTicker {
        SweepTicker::new(*self, rate_hz)
    }
}

/// The first tick n ≥ 0 with n/rate ≥ `time_s`, decided with the same `f64` comparison
/// the time-based [`SweepSignal::sample`] makes at t = n/rate, so both agree on every
/// segment boundary. Construction only (`f64`).
pub(crate) fn first_tick_at_or_after(time_s: f64, rate_hz: f64) -> u32 {
    let at = |n: u32| f64::from(n) / rate_hz;
    let guess = libm::ceil(time_s * rate_hz);
    let mut n = if guess.is_nan() || guess <= 0.0 {
        0
    } else if guess >= f64::from(u32::MAX) {
        u32::MAX
    } else {
        guess as u32
    };
    // The guess is off by at most one either way (rounding of time·rate).
    while n > 0 && at(n - 1) >= time_s {
        n -= 1;
    }
    while n < u32::MAX && at(n) < time_s {
        n += 1;
    }
    n
}

/// Round-to-nearest high half of the 128-bit product: ⌊(a·b + 2⁶³) / 2⁶⁴⌋, i.e. a·b for
/// two 0.64 fixed-point fractions.
fn multiply_fractions(a: u64, b: u64) -> u64 {
    let product = u128::from(a) * u128::from(b) + (1u128 << 63);
    (product >> 64) as u64
}

/// The sweep excitation at the loop's ticks t = n/rate, n = 0, 1, 2, …, without `f64` on
/// the way: the same signal as [`SweepSignal::sample`] (same segments at the same ticks,
/// the phase within 10⁻⁹ rad of the closed form over a whole record), at a fraction of
/// its cost on a Cortex-M4F, where every `f64` operation is a soft-float call.
///
/// # Method
///
/// The phase is kept in [`Turns`] (0.64 fixed point, wrapping = modulo 2π, exact). In
/// the lead-in and the tail the phase is linear in n: θ(n) = θ(n₀) + (n − n₀)·ω/rate.
/// In the record, with h = 1/rate, a = C1/T_rec, Δω = ω_max − ω_min and τ the record
/// time of tick n, the closed form gives the per-tick increment
///
/// ```text
/// θ(τ+h) − θ(τ) = (ω_min − C2 Δω) h  +  C2 Δω (T_rec/C1) e^{aτ} (e^{ah} − 1)
///               =        L          +                G(τ)
/// G(τ+h) = G(τ) · e^{ah} = G(τ) + G(τ)·expm1(ah)
/// ```
///
/// so one tick costs two 64-bit additions and one 64×64→128 multiplication: φ ← φ + L + G,
/// G ← G + G·g with g = expm1(ah) in 0.64 fixed point. The only rounding is in L, g and
/// that product, one part in 2⁶⁴ each; over the 18 000 ticks of a 90 s record at 200 Hz
/// the phase error stays below 10⁻⁹ rad (tests below: against the `f64` closed form at
/// every tick). The state at the record's first tick comes from the closed form in `f64`
/// when the ticker is built (a Configure, not a tick). The instantaneous frequency
/// ω = ω_min − C2 Δω + C2 Δω e^{aτ} is affine in G: ω = ω₀ + G·k, in `f32` (relative
/// error ~10⁻⁷, it is telemetry).
///
/// Ticks must come in order (n, n + 1, …) for the recurrence; any other tick re-anchors
/// the record's state on the closed form (`f64`, correct but slow).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepTicker {
    amplitude: f32,
    /// First tick of the record, of the tail and past the end.
    record_start: u32,
    tail_start: u32,
    finished: u32,
    /// First tick after the fade-in (0 without fades).
    fade_in_end: u32,
    /// Phase step in the lead-in (ω_min·h) and in the tail (ω_max·h).
    lead_in_step: Turns,
    tail_step: Turns,
    /// Phase at `tail_start`.
    tail_anchor: Turns,
    /// Record state at `record_start`: phase and G.
    record_anchor: RecordState,
    /// L = (ω_min − C2 Δω) h, the constant part of the record's phase step.
    record_linear_step: Turns,
    /// g = expm1(ah) in 0.64 fixed point.
    growth_rate: u64,
    /// ω = ω₀ + (G ≫ 32)·k in the record.
    omega_offset: f32,
    omega_per_growth: f32,
    omega_min: f32,
    omega_max: f32,
    /// x = n·k_in in the fade-in, x = (n − tail_start)·k_out + x₀ in the fade-out.
    fade_per_tick: f32,
    fade_out_offset: f32,
    has_fades: bool,
    /// The closed form, for re-anchoring on an out-of-order tick.
    signal: SweepSignal,
    rate_hz: f64,
    /// Record state of the tick `next_tick` (valid when it is in the record).
    next_tick: u32,
    state: RecordState,
    /// Phase and envelope of the last sample, for [`quadrature`](Self::quadrature).
    last_phase: Turns,
    last_envelope: f32,
}

/// The record's recurrence state at one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct RecordState {
    /// Phase θ.
    phase: Turns,
    /// G = θ(τ+h) − θ(τ) − L, in turns, 0.64 fixed point (below ω_max·h < ½ turn).
    growth: u64,
}

/// 2⁶⁴ and 2³² as `f64` (exact).
const TWO_POW_64: f64 = 18_446_744_073_709_551_616.0;
const TWO_POW_32: f64 = 4_294_967_296.0;

impl SweepTicker {
    /// The ticker of `signal` for a loop at `rate_hz` (validated: 50–1000 Hz, so every
    /// per-tick phase step is below half a turn). Construction uses `f64`.
    pub fn new(signal: SweepSignal, rate_hz: u16) -> SweepTicker {
        let rate = f64::from(rate_hz.max(1));
        let h = 1.0 / rate;
        let sweep = signal.sweep;
        let record_end = signal.lead_in_s + sweep.t_rec;
        let record_start = first_tick_at_or_after(signal.lead_in_s, rate);
        let tail_start = first_tick_at_or_after(record_end, rate);
        let finished = first_tick_at_or_after(record_end + signal.fade_s, rate);
        let fade_in_end = first_tick_at_or_after(signal.fade_s, rate);
        let delta_omega = sweep.omega_max - sweep.omega_min;
        let a = C1 / sweep.t_rec;
        let growth_rate = libm::expm1(a * h);
        // G = C2 Δω (T_rec/C1) e^{aτ} expm1(ah) [rad] = e^{aτ}·scale [turns · 2⁶⁴].
        let growth_scale =
            sweep.c2 * delta_omega / a * growth_rate / core::f64::consts::TAU * TWO_POW_64;
        let tail_time = f64::from(tail_start) / rate - record_end;
        let tail_anchor =
            Turns::from_radians(signal.phase_at_record_end + sweep.omega_max * tail_time);
        let fade_s = signal.fade_s;
        let (fade_per_tick, fade_out_offset) = if fade_s > 0.0 {
            ((h / fade_s) as f32, (tail_time / fade_s) as f32)
        } else {
            (0.0, 0.0)
        };
        let mut ticker = SweepTicker {
            amplitude: signal.amplitude,
            record_start,
            tail_start,
            finished,
            fade_in_end,
            lead_in_step: Turns::from_radians(sweep.omega_min * h),
            tail_step: Turns::from_radians(sweep.omega_max * h),
            tail_anchor,
            record_anchor: RecordState {
                phase: Turns::ZERO,
                growth: 0,
            },
            record_linear_step: Turns::from_radians((sweep.omega_min - sweep.c2 * delta_omega) * h),
            growth_rate: (growth_rate * TWO_POW_64) as u64,
            // ω = ω_min − C2Δω + C2Δω·e^{aτ}, e^{aτ} = G / scale, G = (G ≫ 32)·2³².
            omega_offset: (sweep.omega_min - sweep.c2 * delta_omega) as f32,
            omega_per_growth: (sweep.c2 * delta_omega * TWO_POW_32 / growth_scale) as f32,
            omega_min: sweep.omega_min as f32,
            omega_max: sweep.omega_max as f32,
            fade_per_tick,
            fade_out_offset,
            has_fades: fade_s > 0.0,
            signal,
            rate_hz: rate,
            next_tick: u32::MAX,
            state: RecordState {
                phase: Turns::ZERO,
                growth: 0,
            },
            last_phase: Turns::ZERO,
            last_envelope: 0.0,
        };
        ticker.record_anchor = ticker.closed_form_state(record_start);
        ticker.next_tick = record_start;
        ticker.state = ticker.record_anchor;
        ticker
    }

    /// The record's state at tick `n` from the closed form (`f64`).
    fn closed_form_state(&self, n: u32) -> RecordState {
        let signal = &self.signal;
        let sweep = &signal.sweep;
        let tau = f64::from(n) / self.rate_hz - signal.lead_in_s;
        let h = 1.0 / self.rate_hz;
        let a = C1 / sweep.t_rec;
        let delta_omega = sweep.omega_max - sweep.omega_min;
        let growth = sweep.c2 * delta_omega / a * libm::exp(a * tau) * libm::expm1(a * h)
            / core::f64::consts::TAU;
        RecordState {
            phase: Turns::from_radians(signal.phase_at_record_start + sweep.phase(tau)),
            growth: (growth * TWO_POW_64) as u64,
        }
    }

    /// Phase θ of tick `n` and the instantaneous frequency; the record's state advances
    /// when `n` is the tick after the previous call's.
    fn phase_and_omega(&mut self, segment: Segment, n: u32) -> (Turns, f32) {
        match segment {
            Segment::LeadIn => (self.lead_in_step.wrapping_mul(u64::from(n)), self.omega_min),
            Segment::Main => {
                if n != self.next_tick {
                    self.state = if n == self.record_start {
                        self.record_anchor
                    } else {
                        self.closed_form_state(n)
                    };
                }
                let RecordState { phase, growth } = self.state;
                // G < ½ turn, so its high word fits a u32, and converts exactly enough
                // (24 of its ≥ 21 significant bits).
                let omega =
                    self.omega_offset + (growth >> 32) as u32 as f32 * self.omega_per_growth;
                self.state = RecordState {
                    phase: phase
                        .wrapping_add(self.record_linear_step)
                        .wrapping_add(Turns(growth)),
                    growth: growth.wrapping_add(multiply_fractions(growth, self.growth_rate)),
                };
                self.next_tick = n.wrapping_add(1);
                (phase, omega)
            }
            Segment::Tail => (
                self.tail_anchor
                    .wrapping_add(self.tail_step.wrapping_mul(u64::from(n - self.tail_start))),
                self.omega_max,
            ),
            Segment::Finished => (Turns::ZERO, 0.0),
        }
    }

    /// The segment tick `n` falls in.
    fn segment(&self, n: u32) -> Segment {
        if n < self.record_start {
            Segment::LeadIn
        } else if n < self.tail_start {
            Segment::Main
        } else if n < self.finished {
            Segment::Tail
        } else {
            Segment::Finished
        }
    }

    /// The raised-cosine envelope at tick `n` (see [`SweepSignal`]), with
    /// ½ ∓ ½cos(πx) = ½ ∓ ½cos(2π·x/2) from [`sin_turns`] on x/2 in 0.32 fixed point.
    fn envelope(&self, segment: Segment, n: u32) -> f32 {
        // x ∈ [0, 1] → x/2 turn in units of 2π/2³²; the float-to-int cast saturates.
        let half_turns = |x: f32| (x * 2_147_483_648.0) as u32;
        const QUARTER: u32 = 1 << 30;
        if !self.has_fades {
            return 1.0;
        }
        match segment {
            Segment::LeadIn if n < self.fade_in_end => {
                let x = n as f32 * self.fade_per_tick;
                0.5 - 0.5 * sin_turns(half_turns(x).wrapping_add(QUARTER))
            }
            Segment::Tail => {
                let x = (n - self.tail_start) as f32 * self.fade_per_tick + self.fade_out_offset;
                0.5 + 0.5 * sin_turns(half_turns(x).wrapping_add(QUARTER))
            }
            Segment::Finished => 0.0,
            _ => 1.0,
        }
    }

    /// The excitation at tick `n` (t = n/rate since it started). Cheapest when called
    /// for n = 0, 1, 2, … in order.
    pub fn sample(&mut self, n: u32) -> ExcitationSample {
        let segment = self.segment(n);
        if segment == Segment::Finished {
            return ExcitationSample::FINISHED;
        }
        let (phase, omega) = self.phase_and_omega(segment, n);
        let envelope = self.envelope(segment, n);
        self.last_phase = phase;
        self.last_envelope = envelope;
        ExcitationSample {
            segment,
            value: self.amplitude * envelope * phase.sin(),
            omega,
            envelope,
        }
    }

    /// The quadrature A·e·cos θ of the last [`sample`](Self::sample) (whose value is
    /// A·e·sin θ): with it the adaptive amplitude measures the response at the sweep's
    /// frequency in phase and in quadrature.
    pub fn quadrature(&self) -> f32 {
        self.amplitude * self.last_envelope * self.last_phase.cos()
    }

    /// Phase θ of tick `n` reduced to [0, 2π) (`f64`, for tests and diagnostics); the
    /// same stepping as [`sample`](Self::sample).
    pub fn phase_radians(&mut self, n: u32) -> f64 {
        let segment = self.segment(n);
        self.phase_and_omega(segment, n).0.to_radians()
    }
}

#[cfg(test)]
#[path = "sweep_tests.rs"]
mod tests;
