//! What the board application tells the host and the log besides the sequencer's
//! telemetry (protocol 1.4 events): its mode changes, the IMU's health when it changes
//! (and on the first tick, so a dump always says whether the IMU was there), and every
//! refused arm or test request with the check that refused it.
//!
//! The sequencer's Headers pass through [`BoardTap`], which raises their protocol
//! version to [`ProtocolVersion::BOARD_APPLICATION`] (a decoder that reads a board
//! application's stream must know these events) and follows each with the
//! [`Frame::MeasurementFilter`] the IMU measurements went through, when there is one.

use sweephold_protocol::codec::EncodeError;
use sweephold_protocol::{
    AbortReason, Controls, Event, FlightMode, Frame, ImuHealth, MeasurementFilter, ProtocolVersion,
    RefusedCheck, Request,
};

use super::arming::{CheckFailure, Refusal};
use super::failsafe::ImuProblem;
use super::inputs::ImuFaultKind;
use super::modes::Mode;
use crate::mixer::{mix, MixerConfig, PulseInverse};
use crate::sink::FrameSink;

/// The application's mode as it goes on the wire.
pub const fn flight_mode(mode: Mode) -> FlightMode {
    match mode {
        Mode::Disarmed => FlightMode::Disarmed,
        Mode::Pilot => FlightMode::Pilot,
        Mode::Test => FlightMode::Test,
        Mode::RcFailsafe => FlightMode::RcFailsafe,
        Mode::ImuFailsafe => FlightMode::ImuFailsafe,
    }
}

/// This tick's IMU health as it goes on the wire.
pub const fn imu_health(health: Result<(), ImuProblem>) -> ImuHealth {
    match health {
        Ok(()) => ImuHealth::Ok,
        Err(ImuProblem::Calibrating) => ImuHealth::Calibrating,
        Err(ImuProblem::NotFinite) => ImuHealth::NotFinite,
        Err(ImuProblem::Stale) => ImuHealth::Stale,
        Err(ImuProblem::Fault(ImuFaultKind::Missing)) => ImuHealth::Missing,
        Err(ImuProblem::Fault(ImuFaultKind::Stuck)) => ImuHealth::Stuck,
        Err(ImuProblem::Fault(ImuFaultKind::Saturated)) => ImuHealth::Saturated,
        Err(ImuProblem::Fault(ImuFaultKind::NotReady)) => ImuHealth::NotReady,
    }
}

/// A failed check as it goes on the wire.
pub const fn refused_check(check: CheckFailure) -> RefusedCheck {
    match check {
        CheckFailure::Imu(problem) => RefusedCheck::Imu(imu_health(Err(problem))),
        CheckFailure::AttitudeInvalid => RefusedCheck::AttitudeInvalid,
        CheckFailure::ReceiverInvalid => RefusedCheck::ReceiverInvalid,
        CheckFailure::ThrottleHigh => RefusedCheck::ThrottleHigh,
        CheckFailure::TestSwitchOn => RefusedCheck::TestSwitchOn,
        CheckFailure::SoftStartRunning => RefusedCheck::SoftStartRunning,
        CheckFailure::SequencerBusy => RefusedCheck::SequencerBusy,
        CheckFailure::ParamsInvalid => RefusedCheck::ParamsInvalid,
        CheckFailure::NotLevel => RefusedCheck::NotLevel,
        CheckFailure::NotAirborne => RefusedCheck::NotAirborne,
        CheckFailure::NoTestSelected => RefusedCheck::NoTestSelected,
    }
}

/// A refusal as its Event.
pub const fn refusal_event(tick: u32, refusal: Refusal) -> Event {
    let (request, check) = match refusal {
        Refusal::Arm(check) => (Request::Arm, check),
        Refusal::Test(check) => (Request::Test, check),
    };
    Event::Refused {
        tick,
        request,
        check: refused_check(check),
    }
}

/// Remembers what was last reported, so each change goes out once.
///
/// The events of a tick go out before its Sample, like the sequencer's own, so a
/// tick's last frame stays its Sample. The mode reported is the tick's
/// [`TickOutput::mode`](super::TickOutput::mode): on the tick the sequencer ends a test
/// that is still `Test`, and the change to the pilot mode is reported on the next tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reporter {
    /// The IMU health last reported; `None` before the first tick.
    imu: Option<ImuHealth>,
    /// The mode last reported (the application starts Disarmed).
    mode: Mode,
}

impl Default for Reporter {
    fn default() -> Self {
        Reporter {
            imu: None,
            mode: Mode::Disarmed,
        }
    }
}

impl Reporter {
    /// Report this tick's events: the IMU health if it changed (always on the first
    /// tick), a refusal, and the mode if it changed. A frame the sink cannot encode is
    /// dropped: telemetry never stops the tick.
    pub fn report<S: FrameSink>(
        &mut self,
        tick: u32,
        health: ImuHealth,
        refused: Option<Refusal>,
        mode: Mode,
        sink: &mut S,
    ) {
        if self.imu != Some(health) {
            self.imu = Some(health);
            let _ = sink.send_frame(&Frame::Event(Event::ImuHealthChange { tick, health }));
        }
        if let Some(refusal) = refused {
            let _ = sink.send_frame(&Frame::Event(refusal_event(tick, refusal)));
        }
        if mode != self.mode {
            let event = Event::ModeChange {
                tick,
                from: flight_mode(self.mode),
                to: flight_mode(mode),
            };
            self.mode = mode;
            let _ = sink.send_frame(&Frame::Event(event));
        }
    }
}

/// Passes the sequencer's frames on: notes the reason of an Abort Event among them,
/// raises each Header's protocol version to the board application's and follows it with
/// the measurement filter, and has the Samples log the command as the servo pulses
/// express it ([`FrameSink::logged_command`]; the rotor flies the pulses, not the
/// unrounded command).
pub struct BoardTap<'a, S: FrameSink> {
    /// Where the frames go.
    pub inner: &'a mut S,
    /// The reason of the Abort Event that passed, if one did.
    pub reason: Option<AbortReason>,
    /// Sent after each Header, when there is one.
    pub measurement_filter: Option<&'a MeasurementFilter>,
    /// The mixer and its inverse the logged commands go through, when there is one.
    pub outputs: Option<(&'a MixerConfig, &'a PulseInverse)>,
}

impl<S: FrameSink> FrameSink for BoardTap<'_, S> {
    fn write_frame(&mut self, bytes: &[u8]) {
        self.inner.write_frame(bytes);
    }

    fn logged_command(&self, command: &Controls) -> Controls {
        match self.outputs {
            Some((mixer, inverse)) => inverse.command(mix(mixer, command), command),
            None => *command,
        }
    }

    fn send_frame(&mut self, frame: &Frame) -> Result<(), EncodeError> {
        match frame {
            Frame::Event(Event::Abort { reason, .. }) => {
                self.reason = Some(*reason);
                self.inner.send_frame(frame)
            }
            Frame::Header(header) => {
                let mut header = *header;
                header.protocol = header.protocol.max(ProtocolVersion::BOARD_APPLICATION);
                self.inner.send_frame(&Frame::Header(header))?;
                match self.measurement_filter {
                    Some(filter) => self.inner.send_frame(&Frame::MeasurementFilter(*filter)),
                    None => Ok(()),
                }
            }
            _ => self.inner.send_frame(frame),
        }
    }
}
