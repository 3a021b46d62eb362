//! The board application's modes and the transition rule between them: a pure function
//! of the current mode and this tick's [`Conditions`], so that every transition can be
//! tested by itself.
//!
//! ```text
//!                     arm off→on, pre-arm checks pass
//!        ┌──────────┐ ───────────────────────────────▶ ┌───────┐ test off→on, checks pass ┌──────┐
//!        │ Disarmed │                                  │ Pilot │ ───────────────────────▶ │ Test │
//!        └──────────┘ ◀── arm switch off (any armed    └───────┘ ◀─────────────────────── └──────┘
//!          ▲    ▲          mode; a test is aborted)      ▲   ▲    Done / sequencer abort /    │
//!          │    │                                        │   │    attitude invalid / landed  │
//!          │    │ receiver lost ≥ rc_cut_s               │   │                               │
//!          │  ┌────────────┐ ◀── receiver lost ──────────┘   │     receiver lost (abort)     │
//!          │  │ RcFailsafe │ ◀─────────────────────────────────┼───────────────────────────────┤
//!          │  └────────────┘ ── regained (rc_regain_s) ──▶ Pilot                             │
//!          │     ▲       │ IMU fault                         │                               │
//!          │     │       ▼                                   │ IMU fault                     │
//!          │  ┌─────────────┐ ◀──────────────────────────────┘◀──── IMU fault (abort) ───────┘
//!          └──│ ImuFailsafe │ ── recovered: Pilot if the receiver is regained, else RcFailsafe
//!             └─────────────┘
//! ```
//!
//! Precedence in an armed mode, first match wins: arm switch off in a valid frame →
//! Disarmed; receiver lost for `rc_cut_s` → Disarmed; IMU fault → ImuFailsafe;
//! receiver lost → RcFailsafe; then the mode's own exits. The pilot's throttle hold
//! comes first; an IMU fault before a receiver loss because without rates no loop can
//! hold the trim the receiver failsafe would fly. The test's own end (Done, or an abort
//! by the sequencer's checks, including the test switch released) is seen after the
//! sequencer's step: the application then returns to Pilot (see `BoardApp::tick`).

use sweephold_protocol::AbortReason;

use super::arming::{CheckFailure, Refusal};

/// The board application's mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// Throttle cut, servos safe (swash level at mid collective, tail centred), test
    /// logic idle; the host link may be obeyed.
    Disarmed,
    /// Armed, stabilised pilot mode.
    Pilot,
    /// Armed, the sequencer flies a test.
    Test,
    /// Armed, receiver lost: stabilised about the trim, collective and throttle held.
    RcFailsafe,
    /// Armed, IMU unusable: trim plus reduced direct pilot inputs, no loops.
    ImuFailsafe,
}

impl Mode {
    /// Whether the mode runs the motor (every mode but Disarmed).
    pub const fn is_armed(self) -> bool {
        !matches!(self, Mode::Disarmed)
    }

    /// Short snake_case name.
    pub const fn name(self) -> &'static str {
        match self {
            Mode::Disarmed => "disarmed",
            Mode::Pilot => "pilot",
            Mode::Test => "test",
            Mode::RcFailsafe => "rc_failsafe",
            Mode::ImuFailsafe => "imu_failsafe",
        }
    }
}

/// What the transition rule reads this tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Conditions {
    /// This tick's receiver frame is valid.
    pub rc_valid: bool,
    /// Valid frames for `rc_regain_s` in a row and no loss pending.
    pub rc_regained: bool,
    /// The receiver has been lost for `rc_cut_s`.
    pub rc_loss_expired: bool,
    /// Arm switch on (meaningful in a valid frame).
    pub arm_on: bool,
    /// Arm switch went off → on this tick.
    pub arm_rising: bool,
    /// Test switch went off → on this tick.
    pub test_rising: bool,
    /// IMU healthy this tick.
    pub imu_healthy: bool,
    /// IMU healthy for `imu_recover_s` in a row.
    pub imu_recovered: bool,
    /// Attitude estimate valid.
    pub attitude_valid: bool,
    /// The airborne rule's landed condition (see [`super::airborne`]).
    pub landed: bool,
    /// The pre-arm checks' verdict.
    pub pre_arm: Result<(), CheckFailure>,
    /// The test-entry checks' verdict.
    pub test_ready: Result<(), CheckFailure>,
}

/// The rule's answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Transition {
    /// The mode for this tick.
    pub to: Mode,
    /// A running test must be aborted with this reason (the application's own aborts).
    pub abort: Option<AbortReason>,
    /// A request refused this tick.
    pub refused: Option<Refusal>,
}

impl Transition {
    const fn to(mode: Mode) -> Self {
        Transition {
            to: mode,
            abort: None,
            refused: None,
        }
    }

    const fn aborting(mode: Mode, reason: AbortReason) -> Self {
        Transition {
            to: mode,
            abort: Some(reason),
            refused: None,
        }
    }
}

/// The mode for this tick, from the mode of the last tick and this tick's conditions.
pub fn next(from: Mode, c: &Conditions) -> Transition {
    if from == Mode::Disarmed {
        if !c.arm_rising {
            return Transition::to(Mode::Disarmed);
        }
        return match c.pre_arm {
            Ok(()) => Transition::to(Mode::Pilot),
            Err(failure) => Transition {
                to: Mode::Disarmed,
                abort: None,
                refused: Some(Refusal::Arm(failure)),
            },
        };
    }
    // Ends a running test with `reason` if the mode was Test.
    let leave = |to: Mode, reason: AbortReason| {
        if from == Mode::Test {
            Transition::aborting(to, reason)
        } else {
            Transition::to(to)
        }
    };
    if c.rc_valid && !c.arm_on {
        return leave(Mode::Disarmed, AbortReason::Disarmed);
    }
    if !c.rc_valid && c.rc_loss_expired {
        return leave(Mode::Disarmed, AbortReason::RcLost);
    }
    if from == Mode::ImuFailsafe {
        // Healthy is not enough: the IMU must have stayed healthy for imu_recover_s.
        return Transition::to(match (c.imu_recovered, c.rc_regained) {
            (false, _) => Mode::ImuFailsafe,
            (true, true) => Mode::Pilot,
            (true, false) => Mode::RcFailsafe,
        });
    }
    if !c.imu_healthy {
        return leave(Mode::ImuFailsafe, AbortReason::ImuFault);
    }
    if !c.rc_valid {
        return leave(Mode::RcFailsafe, AbortReason::RcLost);
    }
    match from {
        Mode::Test if !c.attitude_valid => leave(Mode::Pilot, AbortReason::ImuFault),
        Mode::Test if c.landed => leave(Mode::Pilot, AbortReason::Landed),
        Mode::Pilot if c.test_rising => match c.test_ready {
            Ok(()) => Transition::to(Mode::Test),
            Err(failure) => Transition {
                to: Mode::Pilot,
                abort: None,
                refused: Some(Refusal::Test(failure)),
            },
        },
        Mode::RcFailsafe if c.rc_regained => Transition::to(Mode::Pilot),
        other => Transition::to(other),
    }
}
