//! The board application's plain input types.
//!
//! The board's drivers (IMU, attitude estimator, receiver) fill a [`TickInput`] once per
//! control tick; [`BoardApp::tick`](super::BoardApp::tick) answers with a
//! [`TickOutput`](super::TickOutput) ([`super::outputs`]). Nothing here knows a driver:
//! the types carry what the flight logic needs, in SI units (rad, rad/s, m/s²) and stick
//! fractions.
//!
//! Stick conventions are the command's ([`Controls`](sweephold_protocol::Controls)):
//! each stick in [−1, 1], a positive stick asks for a positive moment (lat → roll right,
//! lon → pitch nose up, ped → yaw nose right), collective up is positive. The receiver driver maps the transmitter's
//! channels (and their reversals) onto this.

/// Why the IMU driver says its data cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ImuFaultKind {
    /// The IMU does not answer (bus error, not detected).
    Missing,
    /// The IMU answers with samples that do not change (a hung sensor).
    Stuck,
    /// A gyro or accelerometer axis is at the end of its range: the rates are wrong.
    Saturated,
    /// The IMU has not finished its start-up (configuration, self-test).
    NotReady,
}

/// The IMU driver's verdict on this tick's sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ImuStatus {
    /// Bias-corrected rates and specific force are valid.
    Ok,
    /// The gyro bias is being measured (vehicle must be still); the rates are not yet
    /// bias-corrected. Blocks arming; in flight it counts as a fault.
    Calibrating,
    /// The sample is not usable.
    Fault(ImuFaultKind),
}

/// One tick's IMU sample and attitude estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImuInput {
    /// The driver's status.
    pub status: ImuStatus,
    /// The IMU produced a new sample since the last tick. A tick without one reuses the
    /// values below; more than `SafetyLimits::stale_limit_ticks` such ticks in a row
    /// count as a fault.
    pub fresh: bool,
    /// Bias-corrected body roll rate p [rad/s].
    pub p: f32,
    /// Bias-corrected body pitch rate q [rad/s].
    pub q: f32,
    /// Bias-corrected body yaw rate r [rad/s].
    pub r: f32,
    /// Specific force along body x [m/s²].
    pub ax: f32,
    /// Specific force along body y [m/s²].
    pub ay: f32,
    /// Specific force along body z [m/s²] (≈ −g at rest).
    pub az: f32,
    /// Roll attitude φ \[rad\].
    pub phi: f32,
    /// Pitch attitude θ \[rad\].
    pub theta: f32,
    /// Heading ψ \[rad\].
    pub psi: f32,
    /// The estimator's φ, θ, ψ are valid (converged, not diverged).
    pub attitude_valid: bool,
}

impl ImuInput {
    /// A healthy, fresh sample of a vehicle at rest, level, heading north.
    pub const AT_REST: ImuInput = ImuInput {
        status: ImuStatus::Ok,
        fresh: true,
        p: 0.0,
        q: 0.0,
        r: 0.0,
        ax: 0.0,
        ay: 0.0,
        az: -9.81,
        phi: 0.0,
        theta: 0.0,
        psi: 0.0,
        attitude_valid: true,
    };
}

/// The pilot's inputs and the mode switch are the receiver's own types: the channel map
/// produces them, the application reads them (what each mode-switch position selects is
/// [`PilotModeGains::switch_modes`](super::pilot_mode::PilotModeGains::switch_modes)).
pub use crate::receiver::{ModeSwitch, RcInput};

/// The receiver's state this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Receiver {
    /// No valid frame: the receiver reports signal loss (its failsafe flag or a frame
    /// timeout in the driver).
    Lost,
    /// A frame. A frame with a non-finite channel counts as lost.
    Valid(RcInput),
}

/// Everything one tick reads.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TickInput {
    /// IMU sample and attitude estimate.
    pub imu: ImuInput,
    /// Receiver state.
    pub rc: Receiver,
}
