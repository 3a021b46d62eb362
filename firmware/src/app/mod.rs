//! The board application: the flight-mode logic that makes the test sequencer
//! ([`FlightController`]) a flight controller a pilot can fly.
//!
//! [`BoardApp::tick`] runs once per control tick on plain inputs ([`TickInput`]: the
//! IMU sample, attitude estimate and receiver frame) and returns a [`TickOutput`]: the
//! mode, the command, the four servo pulses through the CCPM mixer, the ESC pulse,
//! whether the host link may be obeyed, and an abort reason or a refused request.
//!
//! * [`modes`]: the modes (Disarmed, Pilot, Test, RcFailsafe, ImuFailsafe) and the
//!   transition rule;
//! * [`pilot_mode`]: the stabilised pilot mode's rate loops and heading hold;
//! * [`arming`]: pre-arm and test-entry checks, switch edges;
//! * [`airborne`]: the airborne and landed rule (no test on the ground, a landing
//!   aborts);
//! * [`test_list`]: the tests a flight can fly, chosen by the selector channel;
//! * [`failsafe`]: receiver and IMU monitors and the failsafe policies;
//! * [`cues`]: the status LED's pattern per phase, for the pilot;
//! * [`throttle`]: the ESC channel and its soft start;
//! * [`inputs`]: the input types;
//! * [`outputs`]: the output type.
//!
//! # The sequencer inside the application
//!
//! The sequencer is stepped every tick, in every mode, so that its telemetry (one
//! Sample per tick, Events, the Header at a test start) is continuous. Its `pilot`
//! input is the command the bare airframe gets when no test flies it; outside a test
//! the sequencer passes that through (Idle), so every Sample's `command` is the command
//! the board sent:
//!
//! * outside a test: the mode's own command (safe servos, pilot-mode loops, failsafe);
//! * in a test, before the excitation (Idle → Armed → TrimCapture): the pilot-mode
//!   loops' command. The pilot keeps flying the stabilised mode while the trim is
//!   captured, and the captured trim is the command that holds the aircraft there;
//! * during the excitation (FadeIn, Sweep, FadeOut): the captured trim plus the pilot's
//!   stick displacement from the sticks' mean during the capture. The sequencer ignores
//!   it but for its pilot-override check, which therefore aborts when the pilot moves a
//!   stick more than the override threshold. The loops are off: the sweep is flown on
//!   the bare airframe under the sequencer's conditional attitude hold.
//!
//! The measurements it gets are the IMU's rates, attitude and specific force, with
//! u = v = w = 0 (no air data on the board) and `seq` counting fresh IMU samples, so its
//! stale check works. The test switch it sees is the pilot's, in Test mode only.
//!
//! When the sequencer ends the test itself (Done, or an abort by one of its checks,
//! including the pilot releasing the test switch), the command of that tick is the
//! sequencer's (its pass-through: trim plus stick displacement, the excitation and the
//! hold removed at once) and the tick reports [`Mode::Test`]. From the next tick the
//! pilot-mode loops fly again, preloaded so that their first command equals that one.
//! When the application ends it (receiver lost, IMU fault or invalid attitude, arm
//! switch off) it calls [`FlightController::abort`] with its reason and the failsafe,
//! pilot-mode or disarmed command applies in the same tick, taken over bumplessly where
//! loops run.
//!
//! Every tick runs in bounded time, allocates nothing and cannot panic; non-finite
//! inputs become faults or invalid frames, never non-finite outputs.

pub mod airborne;
pub mod arming;
mod config;
pub mod cues;
pub mod failsafe;
pub mod inputs;
mod mode_command;
pub mod modes;
pub mod outputs;
pub mod pilot_mode;
pub mod reporting;
pub mod test_list;
pub mod throttle;

#[cfg(test)]
mod tests;

use sweephold_protocol::{
    Axis, Controls, Header, MeasurementFilter, Measurements, Phase, PilotInput, ProtocolVersion,
    SensorIn, TestSelection, VehicleId,
};

use crate::attitude_hold::clamp_finite;
use crate::config::{Config, ConfigError};
use crate::controller::FlightController;
use crate::mixer::{mix, PulseInverse};
use crate::sink::FrameSink;
use crate::trim::Trim;

use airborne::{AirborneDetector, AirborneInput, AirborneSettings};
use arming::{CheckInput, SwitchEdge};
use cues::{Cue, CueState, CueTracker};
use failsafe::{FailsafeSettings, ImuMonitor, ImuView, RcLossHold, RcMonitor};
use pilot_mode::{AxisDemand, Demand, LoopFactors, LoopSensors, PilotLoops, PilotModeGains};
use reporting::{BoardTap, Reporter};
use test_list::{engagement_seed, TestList, TestListError};
use throttle::{Throttle, ThrottleSettings};

pub use arming::{CheckFailure, Refusal};
pub use config::{AppConfig, AppConfigError};
pub use failsafe::ImuProblem;
pub use inputs::{ImuFaultKind, ImuInput, ImuStatus, ModeSwitch, RcInput, Receiver, TickInput};
pub use modes::Mode;
pub use outputs::TickOutput;
pub use pilot_mode::StickMode;

/// The command while disarmed ("servos safe"): cyclic centred, collective at mid
/// travel, tail centred, i.e. every servo at its centre pulse through the mixer. The
/// rotor is unpowered, the swash is at its mechanical reference, and it is the output
/// the board puts out before the first tick and after a fault.
pub const SAFE_COMMAND: Controls = Controls {
    lat: 0.0,
    lon: 0.0,
    ped: 0.0,
    col: 0.0,
};

/// Running mean of the pilot's raw sticks during a trim capture.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct StickMean {
    sum: [f32; 4],
    count: u32,
}

impl StickMean {
    fn add(&mut self, sticks: &Controls) {
        for (sum, value) in self.sum.iter_mut().zip(sticks.to_array()) {
            *sum += value;
        }
        self.count = self.count.saturating_add(1);
    }

    fn mean(&self) -> Option<[f32; 4]> {
        let n = self.count as f32;
        (self.count > 0).then(|| self.sum.map(|sum| sum / n))
    }
}

/// The board application. See the [module documentation](self).
#[derive(Clone, Debug)]
pub struct BoardApp {
    config: AppConfig,
    fc: FlightController,
    factors: LoopFactors,
    dt_s: f32,
    stale_limit_ticks: u32,
    regain_ticks: u32,
    recover_ticks: u32,
    /// `airborne.time_s` in ticks.
    airborne_ticks: u32,
    /// Largest throttle rise per tick (the soft start).
    throttle_rise: f32,
    mode: Mode,
    loops: PilotLoops,
    throttle: Throttle,
    imu: ImuMonitor,
    rc: RcMonitor,
    arm_switch: SwitchEdge,
    test_switch: SwitchEdge,
    /// The airborne and landed rule's counts.
    airborne: AirborneDetector,
    /// The command applied last tick.
    last_command: Controls,
    /// The loops take over from `last_command` on their next step.
    preload: bool,
    /// The trim the sequencer captured in this armed period.
    trim: Option<Trim>,
    /// What the receiver failsafe holds, from a loss until the signal is regained.
    loss: Option<RcLossHold>,
    /// The pilot's raw sticks during the running test's trim capture.
    stick_reference: StickMean,
    /// Trim sticks (lat, lon, ped) of the IMU failsafe.
    imu_trim: [f32; 3],
    /// What the board events last reported.
    reporter: Reporter,
    /// A valid parameter set is in use ([`BoardApp::set_params_valid`]).
    params_valid: bool,
    /// The filter the IMU measurements go through before the tick reads them, announced
    /// after each Header ([`BoardApp::set_measurement_filter`]).
    measurement_filter: Option<MeasurementFilter>,
    /// Tests engaged since power-up (the Header's engagement number).
    engagements: u16,
    /// The mixer turned around: the command each tick's pulses express, which its Sample
    /// logs.
    pulse_inverse: PulseInverse,
    /// The pilot cue shown and since when.
    cues: CueTracker,
    /// The pilot-mode loops' own command of the last tick of a loop test (the applied
    /// one holds the sweep too); `None` outside one.
    loop_output: Option<Controls>,
}

/// Ticks in `seconds` at `dt_s`, at least one.
fn ticks_in(seconds: f32, dt_s: f32) -> u32 {
    // Validated settings: finite, ≥ 0, at most hours; `as` saturates anyway.
    (libm::roundf(seconds / dt_s) as u32).max(1)
}

/// Phases in which the sequencer flies the excitation (its command, loops off).
fn is_excitation(phase: Phase) -> bool {
    matches!(phase, Phase::FadeIn | Phase::Sweep | Phase::FadeOut)
}

/// Phases in which a test is running.
fn is_running(phase: Phase) -> bool {
    matches!(phase, Phase::Armed | Phase::TrimCapture) || is_excitation(phase)
}

impl BoardApp {
    /// Validate `config` and build the application: Disarmed, throttle cut, sequencer
    /// Idle at tick 0.
    pub fn new(config: AppConfig) -> Result<BoardApp, AppConfigError> {
        config.validate()?;
        let fc = FlightController::new(config.flight).map_err(AppConfigError::Flight)?;
        let dt_s = config.flight.dt_s();
        Ok(BoardApp {
            factors: LoopFactors::new(&config.pilot, dt_s),
            dt_s,
            stale_limit_ticks: u32::from(config.flight.safety.stale_limit_ticks),
            regain_ticks: ticks_in(config.failsafe.rc_regain_s, dt_s),
            recover_ticks: ticks_in(config.failsafe.imu_recover_s, dt_s),
            airborne_ticks: ticks_in(config.airborne.time_s, dt_s),
            throttle_rise: dt_s / config.throttle.soft_start_s,
            mode: Mode::Disarmed,
            loops: PilotLoops::default(),
            throttle: Throttle::default(),
            imu: ImuMonitor::default(),
            rc: RcMonitor::default(),
            arm_switch: SwitchEdge::default(),
            test_switch: SwitchEdge::default(),
            airborne: AirborneDetector::default(),
            last_command: SAFE_COMMAND,
            preload: false,
            trim: None,
            loss: None,
            stick_reference: StickMean::default(),
            imu_trim: [0.0; 3],
            reporter: Reporter::default(),
            params_valid: true,
            measurement_filter: None,
            engagements: 0,
            pulse_inverse: PulseInverse::new(&config.flight.mixer),
            cues: CueTracker::default(),
            loop_output: None,
            fc,
            config,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &AppConfig {
        &self.config
    }

    /// The current mode (the one the next tick starts from).
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The sequencer (phase, trim, tick, header).
    pub fn flight_controller(&self) -> &FlightController {
        &self.fc
    }

    /// The Header of the configured test as the board application announces it (the
    /// sequencer's, at the board application's protocol version).
    pub fn header(&self) -> Header {
        let mut header = self.fc.header();
        header.protocol = header.protocol.max(ProtocolVersion::BOARD_APPLICATION);
        header
    }

    /// Whether the host link (hardware in the loop) may be obeyed: only while
    /// disarmed, never a takeover in flight.
    pub fn host_link_allowed(&self) -> bool {
        self.mode == Mode::Disarmed
    }

    /// The filter the measurements in [`TickInput`] went through (the board stack's IMU
    /// filter bank), announced in a [`Frame::MeasurementFilter`](sweephold_protocol::Frame::MeasurementFilter)
    /// after each Header so that the host can take it out of the responses. `None` (an
    /// application fed measurements nothing filtered): no such frame.
    pub fn set_measurement_filter(&mut self, filter: Option<MeasurementFilter>) {
        self.measurement_filter = filter;
    }

    /// Whether a valid parameter set is in use: false (the parameter store held no valid
    /// set, the defaults fly; [`crate::params::link::ParamLink::params_valid`]) refuses
    /// every arm request with [`CheckFailure::ParamsInvalid`] until a valid set is saved
    /// and this is set again. True from [`BoardApp::new`] (an application built without
    /// a store).
    pub fn set_params_valid(&mut self, valid: bool) {
        self.params_valid = valid;
    }

    /// Whether the pre-arm check counts the parameter set as valid.
    pub fn params_valid(&self) -> bool {
        self.params_valid
    }

    /// The command applied by the last tick.
    pub fn last_command(&self) -> Controls {
        self.last_command
    }

    /// The throttle output of the last tick, in [0, 1].
    pub fn throttle(&self) -> f32 {
        self.throttle.output()
    }

    /// The pilot-mode loops' state.
    pub fn pilot_loops(&self) -> &PilotLoops {
        &self.loops
    }

    /// The pilot cue of the last tick.
    pub fn cue(&self) -> Cue {
        self.cues.cue()
    }

    /// Whether the status LED is lit after the last tick: [`Cue::lit`] of the cue, from
    /// the tick it began.
    pub fn status_led(&self) -> bool {
        self.cues
            .lit(self.fc.tick().wrapping_sub(1), self.config.flight.rate_hz)
    }

    /// Run one tick: monitors, mode transition, the mode's command, the sequencer's step
    /// (telemetry into `sink`), throttle and mixer. Bounded time, no allocation, no
    /// panic for any input.
    pub fn tick<S: FrameSink>(&mut self, input: &TickInput, sink: &mut S) -> TickOutput {
        let mut sink = BoardTap {
            inner: sink,
            reason: None,
            measurement_filter: None,
            outputs: None,
        };
        // The tick this step's Sample and Events carry.
        let tick = self.fc.tick();
        let imu = self
            .imu
            .observe(&input.imu, self.stale_limit_ticks, self.recover_ticks);
        let rc = self.rc.observe(&input.rc);
        let arm_rising = self.arm_switch.update(rc.map(|frame| frame.arm));
        let test_rising = self.test_switch.update(rc.map(|frame| frame.test_switch));
        self.track_loss(rc.is_some());

        let checks = CheckInput {
            imu: imu.health,
            attitude_valid: imu.attitude.is_some(),
            rc: rc.as_ref(),
            level: imu
                .attitude
                .is_some_and(|[phi, theta, _]| arming::is_level(phi, theta)),
            params_valid: self.params_valid,
        };
        let soft_start_done = rc.is_some_and(|frame| self.throttle.settled(frame.throttle));
        let selection = self.selection(rc.as_ref());
        // The throttle output of the last tick: this tick's follows the transition.
        let air = self.airborne.observe(
            &self.config.airborne,
            &AirborneInput {
                collective: rc.map(|frame| frame.sticks.col),
                spooled: self.throttle.output() >= self.config.throttle.spooled_min,
                soft_start_done,
            },
            self.airborne_ticks,
        );
        let failsafe = &self.config.failsafe;
        let conditions = modes::Conditions {
            rc_valid: rc.is_some(),
            rc_regained: rc.is_some() && self.loss.is_none(),
            rc_loss_expired: self
                .loss
                .is_some_and(|hold| hold.expired(failsafe, self.dt_s)),
            arm_on: rc.is_some_and(|frame| frame.arm),
            arm_rising,
            test_rising,
            imu_healthy: imu.health.is_ok(),
            imu_recovered: imu.recovered,
            attitude_valid: imu.attitude.is_some(),
            landed: air.landed,
            pre_arm: arming::pre_arm(&checks, self.config.throttle.arm_max),
            test_ready: arming::test_entry(
                &checks,
                soft_start_done,
                air.airborne,
                self.fc.phase() == Phase::Idle,
                selection.is_some(),
            ),
        };
        let transition = modes::next(self.mode, &conditions);
        let engaging = transition.to == Mode::Test && self.mode != Mode::Test;
        self.enter(transition.to);
        if let Some(entry) = selection.filter(|_| engaging) {
            self.engage(entry);
        }
        if let Some(reason) = transition.abort {
            self.fc.abort(reason, &mut sink);
        }

        let throttle = self.update_throttle(rc.as_ref());
        let integrate = throttle >= self.config.throttle.spooled_min;
        let (command, stick_mode, test_switch) = self.mode_command(rc.as_ref(), &imu, integrate);

        let sensor = SensorIn {
            seq: self.imu.seq(),
            meas: Measurements {
                p: input.imu.p,
                q: input.imu.q,
                r: input.imu.r,
                phi: input.imu.phi,
                theta: input.imu.theta,
                psi: input.imu.psi,
                u: 0.0,
                v: 0.0,
                w: 0.0,
                ax: input.imu.ax,
                ay: input.imu.ay,
                az: input.imu.az,
            },
            pilot: PilotInput {
                sticks: command,
                test_switch,
            },
        };
        self.reporter.report(
            tick,
            reporting::imu_health(imu.health),
            transition.refused,
            self.mode,
            sink.inner,
        );
        // Only the sequencer's step sends Headers.
        sink.measurement_filter = self.measurement_filter.as_ref();
        sink.outputs = Some((&self.config.flight.mixer, &self.pulse_inverse));
        let out = self.fc.step(&sensor, &mut sink);
        let reported_mode = self.mode;
        let command = if self.mode == Mode::Test {
            let phase = self.fc.phase();
            if is_excitation(phase) {
                self.trim = Some(self.fc.trim());
            }
            if !is_running(phase) {
                // The sequencer ended the test: the loops take over from its command.
                self.mode = Mode::Pilot;
                self.preload = true;
            }
            out.command
        } else {
            command
        };

        self.last_command = command;
        let phase = self.fc.phase();
        let ended = if sink.reason.is_some() || transition.refused.is_some() {
            Some(Cue::Aborted)
        } else if reported_mode == Mode::Test && phase == Phase::Done {
            Some(Cue::Done)
        } else {
            None
        };
        self.cues.update(
            tick,
            self.config.flight.rate_hz,
            ended,
            CueState {
                mode: reported_mode,
                phase,
                hold: self.fc.hold_states(),
                params_valid: self.params_valid,
                ending: None,
            },
        );
        TickOutput {
            mode: reported_mode,
            stick_mode,
            phase: self.fc.phase(),
            command,
            servo_us: mix(&self.config.flight.mixer, &command),
            throttle,
            esc_us: self.config.throttle.pulse_us(throttle),
            host_link_allowed: self.host_link_allowed(),
            abort: sink.reason,
            refused: transition.refused,
        }
    }

    /// The test the selector chooses in this tick's frame: its entry of the test list
    /// (1 … 12) if not empty, entry 0 (the single configured test) without a selector
    /// channel; `None` without a valid frame or on an empty entry.
    fn selection(&self, rc: Option<&RcInput>) -> Option<u8> {
        let tests = &self.config.tests;
        match rc?.selector {
            None => Some(0),
            Some(position) => tests
                .entry_at(position)
                .filter(|entry| tests.get(*entry).is_some()),
        }
    }

    /// A test engages on `entry`: the sequencer flies that entry's test (the single
    /// configured one for entry 0) and its Header names the entry and the engagement.
    /// Read once, here: a selector moved during the test changes nothing.
    fn engage(&mut self, entry: u8) {
        self.engagements = self.engagements.saturating_add(1);
        let base = &self.config.flight.test;
        let mut test = self
            .config
            .tests
            .get(entry)
            .map_or(*base, |chosen| chosen.apply(base));
        test.seed = engagement_seed(base.seed, self.engagements);
        let selection = TestSelection {
            entry,
            engagement: self.engagements,
        };
        // Every entry was validated with the configuration (`AppConfig::validate`) and the
        // sequencer is idle (a test-entry check), so this is never refused.
        let _ = self.fc.set_test(test, Some(selection));
    }

    /// Start, count and end the receiver-loss hold (armed only).
    fn track_loss(&mut self, rc_valid: bool) {
        if !self.mode.is_armed() {
            self.loss = None;
            return;
        }
        match &mut self.loss {
            Some(hold) => hold.ticks = hold.ticks.saturating_add(1),
            None if !rc_valid => {
                self.loss = Some(RcLossHold {
                    collective: self.last_command.col,
                    throttle: self.throttle.output(),
                    ticks: 0,
                });
            }
            None => {}
        }
        if rc_valid && self.rc.valid_ticks() >= self.regain_ticks {
            self.loss = None;
        }
    }

    /// The effects of entering mode `to` (nothing if it is the current one).
    fn enter(&mut self, to: Mode) {
        let from = self.mode;
        if to == from {
            return;
        }
        match to {
            Mode::Disarmed => {
                self.throttle.cut();
                self.airborne.reset();
                self.loops.reset();
                self.trim = None;
                self.loss = None;
                self.preload = false;
            }
            Mode::Pilot | Mode::RcFailsafe => {
                if from == Mode::Disarmed {
                    self.throttle.cut();
                    self.loops.reset();
                }
                self.preload = true;
            }
            Mode::ImuFailsafe => {
                self.imu_trim = if from == Mode::Test && is_excitation(self.fc.phase()) {
                    let [lat, lon, ped, _] = self.fc.trim().sticks;
                    [lat, lon, ped]
                } else {
                    self.loops.steady()
                };
            }
            Mode::Test => self.stick_reference = StickMean::default(),
        }
        self.mode = to;
    }

    /// This tick's throttle output.
    fn update_throttle(&mut self, rc: Option<&RcInput>) -> f32 {
        if self.mode == Mode::Disarmed {
            self.throttle.cut();
            return 0.0;
        }
        match (self.loss, rc) {
            (Some(hold), _) => self.throttle.hold(hold.throttle),
            (None, Some(frame)) => self.throttle.follow(frame.throttle, self.throttle_rise),
            (None, None) => self.throttle.output(),
        }
    }

    /// The collective while the receiver is lost or not yet regained, else `None`.
    fn held_collective(&self) -> Option<f32> {
        self.loss
            .map(|hold| hold.collective(&self.config.failsafe, self.dt_s))
    }
}
