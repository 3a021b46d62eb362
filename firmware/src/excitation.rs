//! The primary-axis excitation: a sweep or a multistep, behind one interface the
//! sequencer drives with the time since the excitation started.

use sweephold_protocol::{InputKind, TestConfig};

pub use crate::excitation_sample::{ExcitationSample, Segment};
use crate::pulse::{PulsePattern, PulseSignal, PulseTicker};
use crate::sweep::{SweepSignal, SweepTicker};

/// The configured primary-axis excitation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Excitation {
    /// Exponential sweep with fades and ω_min hold.
    Sweep(SweepSignal),
    /// Doublet or 3-2-1-1.
    Pulse(PulseSignal),
}

impl Excitation {
    /// Build from a validated test configuration.
    pub fn from_test(test: &TestConfig) -> Self {
        let fade_s = f64::from(test.sweep.fade_s);
        match test.input {
            InputKind::Sweep | InputKind::AdaptiveSweep | InputKind::LoopSweep => {
                Excitation::Sweep(SweepSignal::new(
                    test.sweep.amplitude,
                    f64::from(test.sweep.omega_min),
                    f64::from(test.sweep.omega_max),
                    f64::from(test.sweep.t_rec_s),
                    fade_s,
                    test.sweep.start_hold_cycles,
                ))
            }
            InputKind::Doublet => Excitation::Pulse(PulseSignal::new(
                PulsePattern::Doublet,
                test.pulse.amplitude,
                f64::from(test.pulse.width_s),
                fade_s,
            )),
            InputKind::ThreeTwoOneOne => Excitation::Pulse(PulseSignal::new(
                PulsePattern::ThreeTwoOneOne,
                test.pulse.amplitude,
                f64::from(test.pulse.width_s),
                fade_s,
            )),
        }
    }

    /// The excitation at time `t` \[s\] since it started.
    pub fn sample(&self, t: f64) -> ExcitationSample {
        match self {
            Excitation::Sweep(sweep) => sweep.sample(t),
            Excitation::Pulse(pulse) => pulse.sample(t),
        }
    }

    /// Total length \[s\] (lead-in, main part and tail).
    pub fn duration_s(&self) -> f64 {
        match self {
            Excitation::Sweep(sweep) => sweep.duration_s(),
            Excitation::Pulse(pulse) => pulse.duration_s(),
        }
    }
}

/// The configured excitation at the loop's ticks, without `f64` on the tick path (see
/// [`SweepTicker`] and [`PulseTicker`]); same samples as [`Excitation::sample`] at
/// t = n/rate (the sweep's to `f32` rounding).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExcitationTicker {
    /// Exponential sweep.
    Sweep(SweepTicker),
    /// Doublet or 3-2-1-1.
    Pulse(PulseTicker),
}

impl Excitation {
    /// This excitation sampled at `rate_hz` (construction uses `f64`).
    pub fn ticker(&self, rate_hz: u16) -> ExcitationTicker {
        match self {
            Excitation::Sweep(sweep) => ExcitationTicker::Sweep(sweep.ticker(rate_hz)),
            Excitation::Pulse(pulse) => ExcitationTicker::Pulse(pulse.ticker(rate_hz)),
        }
    }
}

impl ExcitationTicker {
    /// A·e·cos θ of the last sample of a sweep ([`SweepTicker::quadrature`]); 0 for pulses.
    pub fn quadrature(&self) -> f32 {
        match self {
            ExcitationTicker::Sweep(sweep) => sweep.quadrature(),
            ExcitationTicker::Pulse(_) => 0.0,
        }
    }

    /// The excitation at tick `n` since it started (t = n/rate). Cheapest in order.
    pub fn sample(&mut self, n: u32) -> ExcitationSample {
        match self {
            ExcitationTicker::Sweep(sweep) => sweep.sample(n),
            ExcitationTicker::Pulse(pulse) => pulse.sample(n),
        }
    }
}
