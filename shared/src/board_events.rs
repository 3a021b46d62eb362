//! What the board application reports beyond the test sequencer (protocol 1.4): its
//! flight mode, the IMU's health, refused arm and test requests, and host frames it
//! ignored. Each travels in an [`Event`](crate::Event) variant appended in 1.4:
//! [`ModeChange`](crate::Event::ModeChange), [`ImuHealthChange`](crate::Event::ImuHealthChange),
//! [`Refused`](crate::Event::Refused) and [`HostLinkIgnored`](crate::Event::HostLinkIgnored).
//!
//! A flight controller standing on the ground with no IMU streams, from its first
//! tick, an `ImuHealthChange { health: Missing }`; a pilot flipping the arm switch then
//! gets a `Refused { request: Arm, check: Imu(Missing) }`, one per flip.

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

/// The board application's flight mode.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FlightMode {
    /// Throttle cut, servos safe; the only mode in which a host link is obeyed.
    Disarmed,
    /// Armed, stabilised pilot mode (rate loops, heading-hold tail).
    Pilot,
    /// Armed, the sequencer flies a test on the bare airframe.
    Test,
    /// Armed, receiver lost: stabilised about the trim, collective and throttle held.
    RcFailsafe,
    /// Armed, IMU unusable: trim plus reduced direct pilot inputs, no loops.
    ImuFailsafe,
}

impl FlightMode {
    /// Short snake_case name used in reports and logs.
    pub const fn name(self) -> &'static str {
        match self {
            FlightMode::Disarmed => "disarmed",
            FlightMode::Pilot => "pilot",
            FlightMode::Test => "test",
            FlightMode::RcFailsafe => "rc_failsafe",
            FlightMode::ImuFailsafe => "imu_failsafe",
        }
    }
}

/// The IMU's health as the board application judges it each tick.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ImuHealth {
    /// Calibrated, fresh, finite samples.
    Ok,
    /// The boot gyro calibration is running (the aircraft must stand still).
    Calibrating,
    /// The IMU does not answer (not detected, or a bus error).
    Missing,
    /// The IMU answers with samples that do not change.
    Stuck,
    /// A gyro or accelerometer axis is at the end of its range.
    Saturated,
    /// The IMU has not finished its start-up, or its calibration found no still window.
    NotReady,
    /// A rate or specific-force value was NaN or infinite.
    NotFinite,
    /// No fresh sample for more than the stale limit.
    Stale,
}

impl ImuHealth {
    /// Short snake_case name used in reports and logs.
    pub const fn name(self) -> &'static str {
        match self {
            ImuHealth::Ok => "ok",
            ImuHealth::Calibrating => "calibrating",
            ImuHealth::Missing => "missing",
            ImuHealth::Stuck => "stuck",
            ImuHealth::Saturated => "saturated",
            ImuHealth::NotReady => "not_ready",
            ImuHealth::NotFinite => "not_finite",
            ImuHealth::Stale => "stale",
        }
    }
}

/// A pilot request the board application can refuse.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// The arm switch went on.
    Arm,
    /// The test switch went on.
    Test,
}

impl Request {
    /// Short snake_case name used in reports and logs.
    pub const fn name(self) -> &'static str {
        match self {
            Request::Arm => "arm",
            Request::Test => "test",
        }
    }
}

/// The check that refused a [`Request`] (the first that failed, in the board
/// application's order).
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RefusedCheck {
    /// The IMU is not healthy, and how.
    Imu(ImuHealth),
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
    /// The sequencer is not idle.
    SequencerBusy,
    /// The parameter store held no valid set: the defaults are in use until a set is
    /// saved. Since 1.5.
    ParamsInvalid,
    /// The board stands more than 25° from level (or the IMU mounting is wrong).
    /// Since 1.5.
    NotLevel,
    /// The aircraft is not airborne by the board application's rule (a test request on
    /// the ground). Since 1.6.
    NotAirborne,
    /// The test selector points at an empty entry of the test list. Since 1.7.
    NoTestSelected,
}

impl RefusedCheck {
    /// Short snake_case name used in reports and logs (the IMU's health is named
    /// separately).
    pub const fn name(self) -> &'static str {
        match self {
            RefusedCheck::Imu(_) => "imu",
            RefusedCheck::AttitudeInvalid => "attitude_invalid",
            RefusedCheck::ReceiverInvalid => "receiver_invalid",
            RefusedCheck::ThrottleHigh => "throttle_high",
            RefusedCheck::TestSwitchOn => "test_switch_on",
            RefusedCheck::SoftStartRunning => "soft_start_running",
            RefusedCheck::SequencerBusy => "sequencer_busy",
            RefusedCheck::ParamsInvalid => "params_invalid",
            RefusedCheck::NotLevel => "not_level",
            RefusedCheck::NotAirborne => "not_airborne",
            RefusedCheck::NoTestSelected => "no_test_selected",
        }
    }
}

/// Which host frame the board ignored.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HostFrame {
    /// A [`SensorIn`](crate::SensorIn): hardware in the loop.
    SensorIn,
    /// A [`LinkConfig`](crate::LinkConfig): a run-time configuration.
    Configure,
}

impl HostFrame {
    /// Short snake_case name used in reports and logs.
    pub const fn name(self) -> &'static str {
        match self {
            HostFrame::SensorIn => "sensor_in",
            HostFrame::Configure => "configure",
        }
    }
}
