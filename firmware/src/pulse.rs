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

use crate::excitation::{ExcitationSample, Segment};

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

#[cfg(test)]
mod tests {
    use super::*;

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
