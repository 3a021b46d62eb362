//! What an excitation yields at one instant — which segment of it the instant falls in,
//! the perturbation, the instantaneous frequency and the envelope — shared by the sweep
//! ([`crate::sweep`]), the multisteps ([`crate::pulse`]) and the interface over both
//! ([`crate::excitation`]).

use sweephold_protocol::Phase;

/// Which part of the excitation a time falls in; maps one to one onto the sequencer's
/// FadeIn / Sweep / FadeOut phases.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Segment {
    /// Fade-in and ω_min hold (sweep) or quiet lead-in (pulses).
    LeadIn,
    /// The sweep record or the pulses.
    Main,
    /// Fade-out (sweep) or quiet tail (pulses).
    Tail,
    /// Past the end.
    Finished,
}

impl Segment {
    /// The sequencer phase of this segment; `None` once finished.
    pub const fn phase(self) -> Option<Phase> {
        match self {
            Segment::LeadIn => Some(Phase::FadeIn),
            Segment::Main => Some(Phase::Sweep),
            Segment::Tail => Some(Phase::FadeOut),
            Segment::Finished => None,
        }
    }
}

/// One excitation sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExcitationSample {
    /// Where in the excitation.
    pub segment: Segment,
    /// Primary-axis perturbation, fraction of stick travel.
    pub value: f32,
    /// Instantaneous frequency dθ/dt [rad/s] of a sweep; 0 for pulses and when finished.
    pub omega: f32,
    /// Envelope in [0, 1] applied to the excitation and to the off-axis noise.
    pub envelope: f32,
}

impl ExcitationSample {
    /// The sample past the end of the excitation.
    pub const FINISHED: ExcitationSample = ExcitationSample {
        segment: Segment::Finished,
        value: 0.0,
        omega: 0.0,
        envelope: 0.0,
    };
}
