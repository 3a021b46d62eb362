//! Pre-arm and test-entry checks, and the switch edges that request them.
//!
//! Arming happens only on the tick the arm switch goes off → on, and only if every
//! pre-arm check passes then; a refused request needs the switch cycled again (an
//! aircraft must never spool up by itself because a check cleared later, e.g. when the
//! gyro calibration ends with the switch left on). The same holds for the test switch.
//!
//! Switch states are read from valid receiver frames only. At boot, and while the
//! receiver is lost, a switch counts as *on*: a switch already on at boot, or on when
//! the signal returns, must go off and on again before it requests anything.
//!
//! Pre-arm checks, in the order they are reported (the first failure is named):
//! IMU healthy (status Ok, fresh, finite), attitude estimate valid, the estimate within
//! [`MAX_ARM_TILT_DEG`] of level (a board standing tilted, or an IMU mounting that is
//! wrong by 90° or 180° about a horizontal axis), a valid parameter set in use,
//! receiver frame valid, throttle stick at or below `ThrottleSettings::arm_max`, test
//! switch off.
//! Test-entry checks (armed, in the pilot mode): IMU healthy, attitude valid, receiver
//! valid, the soft start finished (a sweep on a rotor still spooling up would measure a
//! changing aircraft), airborne by the rule of [`super::airborne`] (a test engaged on
//! the skids would excite an aircraft the ground holds), the sequencer idle, and a test
//! selected (with a selector channel, its slice's entry of the test list is not empty).

use super::failsafe::ImuProblem;
use super::inputs::RcInput;
pub use crate::imu::rotation::MAX_ARM_TILT_DEG;

/// A check that failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CheckFailure {
    /// The IMU is not healthy.
    Imu(ImuProblem),
    /// The attitude estimate is not valid.
    AttitudeInvalid,
    /// No valid receiver frame.
    ReceiverInvalid,
    /// The throttle stick is above the arming threshold.
    ThrottleHigh,
    /// The test switch is on.
    TestSwitchOn,
    /// The throttle has not finished its soft start.
    SoftStartRunning,
    /// The sequencer is not idle (a test's end is still being wound up).
    SequencerBusy,
    /// The parameter store held no valid set (the defaults are in use).
    ParamsInvalid,
    /// The attitude estimate is more than [`MAX_ARM_TILT_DEG`] from level.
    NotLevel,
    /// Not airborne by the rule of [`super::airborne`] (a test request on the ground).
    NotAirborne,
    /// The test selector points at an empty entry of the test list.
    NoTestSelected,
}

/// A request that was refused, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Refusal {
    /// The arm switch went on but a pre-arm check failed.
    Arm(CheckFailure),
    /// The test switch went on but a test-entry check failed.
    Test(CheckFailure),
}

/// Rising-edge detector of a switch read from the receiver; unknown counts as on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SwitchEdge {
    was_on: bool,
}

impl Default for SwitchEdge {
    /// At boot the switch counts as on.
    fn default() -> Self {
        SwitchEdge { was_on: true }
    }
}

impl SwitchEdge {
    /// Observe this tick's switch (`None`: no valid frame, state unknown); returns
    /// whether it went off → on.
    pub fn update(&mut self, on: Option<bool>) -> bool {
        let on_now = on.unwrap_or(true);
        let rising = on_now && !self.was_on;
        self.was_on = on_now;
        rising && on.is_some()
    }
}

/// What the checks look at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckInput<'a> {
    /// IMU health this tick.
    pub imu: Result<(), ImuProblem>,
    /// Attitude estimate valid (and finite).
    pub attitude_valid: bool,
    /// This tick's receiver frame, if valid.
    pub rc: Option<&'a RcInput>,
    /// The attitude estimate is within [`MAX_ARM_TILT_DEG`] of level ([`is_level`]).
    pub level: bool,
    /// A valid parameter set is in use (not the defaults after a bad store).
    pub params_valid: bool,
}

/// Whether roll `phi` and pitch `theta` \[rad\] put the body within
/// [`MAX_ARM_TILT_DEG`] of level: the tilt of body z from the vertical is
/// `acos(cos φ · cos θ)`.
pub fn is_level(phi: f32, theta: f32) -> bool {
    libm::cosf(phi) * libm::cosf(theta) >= COS_MAX_ARM_TILT
}

/// cos 25° (f32), the bound of [`is_level`], kept as a constant for the control tick.
const COS_MAX_ARM_TILT: f32 = 0.906_307_8;

/// The pre-arm checks; `arm_max` is the throttle threshold.
pub fn pre_arm(input: &CheckInput<'_>, arm_max: f32) -> Result<(), CheckFailure> {
    healthy(input)?;
    if !input.level {
        return Err(CheckFailure::NotLevel);
    }
    if !input.params_valid {
        return Err(CheckFailure::ParamsInvalid);
    }
    let rc = input.rc.ok_or(CheckFailure::ReceiverInvalid)?;
    // NaN counts as high.
    if rc.throttle.is_nan() || rc.throttle > arm_max {
        return Err(CheckFailure::ThrottleHigh);
    }
    if rc.test_switch {
        return Err(CheckFailure::TestSwitchOn);
    }
    Ok(())
}

/// The test-entry checks: `soft_start_done` whether the throttle has reached its stick,
/// `airborne` the airborne rule's verdict, `sequencer_idle` whether the sequencer is in
/// Idle, `selected` whether there is a test to fly (the selector's entry, or the single
/// test without a selector).
pub fn test_entry(
    input: &CheckInput<'_>,
    soft_start_done: bool,
    airborne: bool,
    sequencer_idle: bool,
    selected: bool,
) -> Result<(), CheckFailure> {
    healthy(input)?;
    if input.rc.is_none() {
        return Err(CheckFailure::ReceiverInvalid);
    }
    if !soft_start_done {
        return Err(CheckFailure::SoftStartRunning);
    }
    if !airborne {
        return Err(CheckFailure::NotAirborne);
    }
    if !sequencer_idle {
        return Err(CheckFailure::SequencerBusy);
    }
    if !selected {
        return Err(CheckFailure::NoTestSelected);
    }
    Ok(())
}

/// IMU and attitude checks shared by both.
fn healthy(input: &CheckInput<'_>) -> Result<(), CheckFailure> {
    input.imu.map_err(CheckFailure::Imu)?;
    if !input.attitude_valid {
        return Err(CheckFailure::AttitudeInvalid);
    }
    Ok(())
}
