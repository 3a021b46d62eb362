//! What one tick of the board application commands and reports: [`TickOutput`], the
//! answer of [`BoardApp::tick`](super::BoardApp::tick) to a
//! [`TickInput`](super::TickInput).

use sweephold_protocol::{AbortReason, Controls, Phase};

use super::arming::Refusal;
use super::modes::Mode;
use super::pilot_mode::StickMode;

/// What one tick commands and reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickOutput {
    /// The mode whose logic produced this tick's command (on the tick a test ends, the
    /// sequencer's [`Mode::Test`]; the next tick carries the mode it ended into).
    pub mode: Mode,
    /// The pilot-mode loops' stick interpretation when they produced the command
    /// (Pilot, receiver failsafe, and a test before its excitation); `None` otherwise.
    pub stick_mode: Option<StickMode>,
    /// The sequencer's phase after the tick.
    pub phase: Phase,
    /// The command, each value in [−1, 1] and finite.
    pub command: Controls,
    /// Servo pulse widths \[µs\] from the CCPM mixer: swash servos 1 (front), 2
    /// (right-rear), 3 (left-rear), tail.
    pub servo_us: [u16; 4],
    /// Throttle sent to the ESC, in [0, 1].
    pub throttle: f32,
    /// ESC pulse width \[µs\].
    pub esc_us: u16,
    /// The host link (hardware in the loop) may be obeyed: only while disarmed.
    pub host_link_allowed: bool,
    /// Set on the tick a test ended with an abort: why.
    pub abort: Option<AbortReason>,
    /// Set on the tick an arm or test request was refused: which check failed.
    pub refused: Option<Refusal>,
}
