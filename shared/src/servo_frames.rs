//! Servo test frames (protocol 1.8): a host moves one servo on the bench
//! ([`Frame::ServoTest`](crate::Frame::ServoTest), answered by
//! [`Frame::ServoTestReply`](crate::Frame::ServoTestReply)).
//!
//! * A [`ServoTest`] for servo 1–4 puts that servo at its target (its centre, its lowest
//!   or highest pulse, or a pulse, clamped to its limits) for `hold_ms`; the other
//!   servos stay at the disarmed output. Each request is answered with
//!   [`ServoTestStatus::Moving`] and the pulse applied, and starts `hold_ms` afresh: a
//!   host keeps a servo where it is by repeating the request.
//! * When `hold_ms` passes without another request (the host went quiet), the servo goes
//!   back to the disarmed output and the board says [`ServoTestEnd::TimedOut`].
//! * Servo 0 ends a running test at once ([`ServoTestEnd::Stopped`]).
//! * Armed, nothing moves: every request is refused with [`ServoTestRefusal::Armed`], and
//!   a test running when the board arms ends on that tick ([`ServoTestEnd::Armed`]).
//!   So is a request without a valid parameter set, in the loop, for another servo
//!   number, or with a hold outside 1 … [`MAX_SERVO_HOLD_MS`].

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

/// Longest hold of one request \[ms\]: a host that goes quiet leaves a servo off the
/// disarmed output for at most this long.
pub const MAX_SERVO_HOLD_MS: u16 = 2000;

/// Where a servo test puts the servo.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoTarget {
    /// The servo's centre pulse (its `*_MID`).
    Centre,
    /// Its lowest pulse (`*_MIN`).
    Min,
    /// Its highest pulse (`*_MAX`).
    Max,
    /// This pulse \[µs\], clamped to the servo's limits.
    PulseUs(u16),
}

/// Host → flight controller (1.8): move one servo while disarmed.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoTest {
    /// The servo, 1–4 (swash servos 1, 2, 3, tail); 0 ends a running test.
    pub servo: u8,
    /// Where to put it.
    pub target: ServoTarget,
    /// How long to hold it without another request \[ms\], 1 … [`MAX_SERVO_HOLD_MS`].
    pub hold_ms: u16,
}

/// Why a servo test ended.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoTestEnd {
    /// The host asked (servo 0).
    Stopped,
    /// No request within the hold: the link went quiet.
    TimedOut,
    /// The board armed.
    Armed,
}

/// Why a servo test request was refused.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoTestRefusal {
    /// The board is armed.
    Armed,
    /// No valid parameter set in use (the servo limits are not known to be the aircraft's).
    ParamsInvalid,
    /// A host flies the board in the loop.
    InTheLoop,
    /// No servo of that number.
    NoSuchServo,
    /// `hold_ms` is 0 or above [`MAX_SERVO_HOLD_MS`].
    HoldOutOfRange,
}

/// What happened to a servo test.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoTestStatus {
    /// The servo is at the reply's pulse.
    Moving,
    /// The test ended: every servo at the disarmed output.
    Ended(ServoTestEnd),
    /// The request was refused: nothing moved.
    Refused(ServoTestRefusal),
}

/// Flight controller → host (1.8): the answer to a [`ServoTest`], and the end of a test.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoTestReply {
    /// The servo (1–4; 0 for a stop or a refused request naming none).
    pub servo: u8,
    /// The pulse the servo is at \[µs\] (while Moving), else 0.
    pub pulse_us: u16,
    /// What happened.
    pub status: ServoTestStatus,
}

impl ServoTestEnd {
    /// Short snake_case name.
    pub const fn name(self) -> &'static str {
        match self {
            ServoTestEnd::Stopped => "stopped",
            ServoTestEnd::TimedOut => "timed_out",
            ServoTestEnd::Armed => "armed",
        }
    }
}

impl ServoTestRefusal {
    /// Short snake_case name.
    pub const fn name(self) -> &'static str {
        match self {
            ServoTestRefusal::Armed => "armed",
            ServoTestRefusal::ParamsInvalid => "params_invalid",
            ServoTestRefusal::InTheLoop => "in_the_loop",
            ServoTestRefusal::NoSuchServo => "no_such_servo",
            ServoTestRefusal::HoldOutOfRange => "hold_out_of_range",
        }
    }
}
