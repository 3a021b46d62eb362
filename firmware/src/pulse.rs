//! Doublet and 3-2-1-1 multistep inputs.
//!
//! ```text
//! doublet:  +A for w, −A for w                      (2w)
//! 3-2-1-1:  +A for 3w, −A for 2w, +A for w, −A for w  (7w)
//! ```
//!
//! The pulses run on the same sequencer as the sweep. A faded pulse is no longer a pulse,
//! so there is no envelope: the fade phases become quiet periods of `T_fade` (zero input,
//! steady trim before the pulses, free response after them).

use crate::excitation_sample::{ExcitationSample, Segment};
use crate::sweep::first_tick_at_or_after;

/// One step of a multistep: sign and length in base widths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Step {
    sign: i8,
    widths: u8,
}

const DOUBLET: &[Step] = &[
    Step { sign: 1, widths: 1 },
    Step {
        sign: -1,
        widths: 1,
    },
];

const THREE_TWO_ONE_ONE: &[Step] = &[
    Step { sign: 1, widths: 3 },
    Step {
        sign: -1,
        widths: 2,
    },
    Step { sign: 1, widths: 1 },
    Step {
        sign: -1,
        widths: 1,
    },
];

/// Which multistep pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PulsePattern {
    /// +A w, −A w.
    Doublet,
    /// +A 3w, −A 2w, +A w, −A w.
    ThreeTwoOneOne,
}

impl PulsePattern {
    fn steps(self) -> &'static [Step] {
        match self {
            PulsePattern::Doublet => DOUBLET,
            PulsePattern::ThreeTwoOneOne => THREE_TWO_ONE_ONE,
        }
    }

    /// Length of the pattern in base pulse widths (2 or 7).
    pub fn total_widths(self) -> u32 {
        self.steps().iter().map(|step| u32::from(step.widths)).sum()
    }
}

/// A multistep excitation with quiet lead-in and tail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulseSignal {
    pattern: PulsePattern,
    amplitude: f32,
    width_s: f64,
    quiet_s: f64,
}

impl PulseSignal {
    /// Build from validated settings: pattern, amplitude, base width \[s\] and the quiet
    /// period before and after the pulses \[s\].
    pub fn new(pattern: PulsePattern, amplitude: f32, width_s: f64, quiet_s: f64) -> Self {
        PulseSignal {
            pattern,
            amplitude,
            width_s,
            quiet_s,
        }
    }

    fn pulses_s(&self) -> f64 {
        f64::from(self.pattern.total_widths()) * self.width_s
    }

    /// Total length: quiet lead-in + pulses + quiet tail \[s\].
    pub fn duration_s(&self) -> f64 {
        2.0 * self.quiet_s + self.pulses_s()
    }

    /// The excitation at time `t` \[s\] since it started. The envelope is 1 throughout (it
    /// scales the off-axis noise, which keeps running in the quiet periods).
    pub fn sample(&self, t: f64) -> ExcitationSample {
        let pulses_end = self.quiet_s + self.pulses_s();
        let segment = if t < self.quiet_s {
            Segment::LeadIn
        } else if t < pulses_end {
            Segment::Main
        } else if t < pulses_end + self.quiet_s {
            Segment::Tail
        } else {
            return ExcitationSample::FINISHED;
        };
        let mut value = 0.0;
        if segment == Segment::Main {
            // Walk the (at most four) steps to the one containing t.
            let mut step_end = self.quiet_s;
            for step in self.pattern.steps() {
                step_end += f64::from(step.widths) * self.width_s;
                if t < step_end {
                    value = f32::from(step.sign) * self.amplitude;
                    break;
                }
            }
        }
        ExcitationSample {
            segment,
            value,
            omega: 0.0,
            envelope: 1.0,
        }
    }
}

/// Most steps in a pattern.
const MAX_STEPS: usize = 4;

/// A [`PulseSignal`] at the loop's ticks t = n/rate: its segment and step boundaries as
/// tick numbers, found once with the same `f64` comparisons [`PulseSignal::sample`] makes
/// at t = n/rate, so both give the same sample at every tick, with integer comparisons
/// only on the tick path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulseTicker {
    /// First tick of the pulses, of the quiet tail, and past the end.
    pulses_start: u32,
    tail_start: u32,
    finished: u32,
    /// First tick past each step, and the step's value; unused entries end at 0.
    step_ends: [u32; MAX_STEPS],
    step_values: [f32; MAX_STEPS],
}

impl PulseSignal {
    /// The tick boundaries of this signal for a loop at `rate_hz` (construction, `f64`).
    pub fn ticker(&self, rate_hz: u16) -> PulseTicker {
        let rate = f64::from(rate_hz.max(1));
        let pulses_end = self.quiet_s + self.pulses_s();
        let mut step_ends = [0; MAX_STEPS];
        let mut step_values = [0.0; MAX_STEPS];
        let mut step_end = self.quiet_s;
        for ((step, end), value) in self
            .pattern
            .steps()
            .iter()
            .zip(step_ends.iter_mut())
            .zip(step_values.iter_mut())
        {
            step_end += f64::from(step.widths) * self.width_s;
            *end = first_tick_at_or_after(step_end, rate);
            *value = f32::from(step.sign) * self.amplitude;
        }
        PulseTicker {
            pulses_start: first_tick_at_or_after(self.quiet_s, rate),
            tail_start: first_tick_at_or_after(pulses_end, rate),
            finished: first_tick_at_or_after(pulses_end + self.quiet_s, rate),
            step_ends,
            step_values,
        }
    }
}

impl PulseTicker {
    /// The excitation at tick `n` (t = n/rate since it started).
    pub fn sample(&self, n: u32) -> ExcitationSample {
        let segment = if n < self.pulses_start {
            Segment::LeadIn
        } else if n < self.tail_start {
            Segment::Main
        } else if n < self.finished {
            Segment::Tail
        } else {
            return ExcitationSample::FINISHED;
        };
        let mut value = 0.0;
        if segment == Segment::Main {
            for (&end, &step_value) in self.step_ends.iter().zip(&self.step_values) {
                if n < end {
                    value = step_value;
                    break;
                }
            }
        }
        ExcitationSample {
            segment,
            value,
            omega: 0.0,
            envelope: 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tick path and time path agree at every tick, both patterns, awkward rates.
    #[test]
    fn ticker_matches_the_time_based_signal_at_every_tick() {
        for pattern in [PulsePattern::Doublet, PulsePattern::ThreeTwoOneOne] {
            for (rate, width, quiet) in [(200u16, 0.5, 2.0), (333, 0.33, 1.7), (50, 0.2, 0.0)] {
                let signal = PulseSignal::new(pattern, 0.1, width, quiet);
                let ticker = signal.ticker(rate);
                let end = (signal.duration_s() * f64::from(rate)) as u32 + 3;
                for n in 0..end {
                    let t = f64::from(n) / f64::from(rate);
                    assert_eq!(ticker.sample(n), signal.sample(t), "{pattern:?} tick {n}");
                }
            }
        }
    }

    fn values(signal: &PulseSignal, rate: f64) -> Vec<f32> {
        let n = (signal.duration_s() * rate).round() as u32;
        (0..n)
            .map(|i| signal.sample((f64::from(i) + 0.5) / rate).value)
            .collect()
    }

    #[test]
    fn doublet_is_plus_then_minus_one_width_each() {
        let signal = PulseSignal::new(PulsePattern::Doublet, 0.1, 0.5, 1.0);
        let v = values(&signal, 100.0);
        assert_eq!(v.len(), 300);
        assert!(v[..100].iter().all(|&x| x == 0.0));
        assert!(v[100..150].iter().all(|&x| x == 0.1));
        assert!(v[150..200].iter().all(|&x| x == -0.1));
        assert!(v[200..].iter().all(|&x| x == 0.0));
        assert_eq!(signal.sample(3.0).segment, Segment::Finished);
    }

    #[test]
    fn three_two_one_one_has_the_right_step_lengths() {
        let signal = PulseSignal::new(PulsePattern::ThreeTwoOneOne, 0.05, 0.2, 0.0);
        let v = values(&signal, 100.0);
        assert_eq!(v.len(), 140);
        assert!(v[..60].iter().all(|&x| x == 0.05));
        assert!(v[60..100].iter().all(|&x| x == -0.05));
        assert!(v[100..120].iter().all(|&x| x == 0.05));
        assert!(v[120..].iter().all(|&x| x == -0.05));
    }
}
