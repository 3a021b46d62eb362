//! The flight controller: test sequencer, conditional attitude hold, excitation, safety
//! and telemetry, advanced one fixed-rate tick at a time by [`FlightController::step`].
//!
//! # Sequencer
//!
//! ```text
//! Idle ──switch off→on──▶ Armed ──next tick──▶ TrimCapture ──trim_capture_s──▶ FadeIn
//!   ▲                                                                        │
//!   │ switch off                                       Sweep ◀───────────────┘
//!   │                                                    │
//! Done / Aborted ◀── excitation over (Done) ── FadeOut ◀─┘      any check fails → Aborted
//! ```
//!
//! * Arming needs a rising edge of the test switch. At boot the switch counts as off, so
//!   a switch already on at the first tick arms; after Done or Aborted the switch must go
//!   off (→ Idle) and on again.
//! * The Header frame goes out on the Armed → TrimCapture tick, just before that
//!   PhaseChange: the test starts there, and a test aborted in its Armed tick has none.
//! * The `phase` of a Sample is the phase after the tick's transitions, i.e. the one whose
//!   logic produced the command. Phases of zero length (no fade) are skipped.
//! * Armed, TrimCapture and the excitation phases are guarded by the safety checks; in
//!   Idle, Armed, TrimCapture, Done and Aborted the outputs are pilot pass-through.
//! * The excitation phases FadeIn / Sweep / FadeOut follow the excitation's segments (see
//!   [`SweepSignal`](crate::sweep::SweepSignal) and
//!   [`PulseSignal`](crate::pulse::PulseSignal)); every command there is
//!   `trim + perturbation`, clamped to [−1, 1] and, with a slew limit configured
//!   ([`Config::slew`]), moved from the tick before's command by at most its axis' step.
//!   With a hold slew limit ([`Config::hold_slew`]) the hold's share of the perturbation
//!   (what is left after the sweep and the noise) is first moved from its own value of
//!   the tick before by at most its axis' step; the sweep and the noise are added as
//!   they are.
//!   The perturbation's sweep (or pulse) and noise are the test's, times the vehicle's
//!   per-axis [`ExcitationScale`](crate::excitation_scale::ExcitationScale).
//!
//! # Sample fields
//!
//! `sweep_omega` is the instantaneous frequency dθ/dt of the sweep signal: ω(t) in the
//! Sweep phase, ω_min in FadeIn (the fade and the ω_min hold run at ω_min) and ω_max in
//! FadeOut; 0 in every other phase and for pulse inputs. `sweep` and `noise` are the
//! parts actually applied (0 on an axis whose hold is Engaged or Frozen in conditional
//! attitude hold), so `command − trim − sweep − noise` is the hold controller's share
//! (and, with a slew limit, what the limit held back).
//! `pilot` and `meas` are the raw inputs of the tick (a NaN that caused an abort is
//! logged as such).
//!
//! # Pilot override during trim capture
//!
//! During TrimCapture the sticks are compared with the running average of the capture so
//! far (from its second tick on): a pilot who moves more than the override threshold
//! while the trim is being taken aborts the test instead of corrupting the trim.
//!
//! # Frames per tick
//!
//! In order: the Header (test start only), Events as they happen, then exactly one Sample
//! — in every phase, so a missing tick shows up as a gap in `Sample::tick`.

use sweephold_protocol::{
    AbortReason, ActuatorOut, Axis, Controls, Event, ExcitationMode, FirmwareVersion, Frame,
    Header, HoldState, InputKind, Measurements, Phase, ProtocolVersion, Sample, SensorIn,
    TestConfig, TestSelection,
};

use crate::amplitude::{AmplitudeShaper, AxisEnvelope};
use crate::attitude_hold::{AttitudeController, AxisGains};
use crate::config::{CollectiveSource, Config, ConfigError, HoldReference};
use crate::excitation::{Excitation, ExcitationSample, ExcitationTicker};
use crate::hold::{next_hold_state, HoldThresholds};
use crate::mixer::mix;
use crate::noise::OffAxisNoise;
use crate::safety::{self, SafetyInput, StaleTracker};
use crate::sink::FrameSink;
use crate::slew;
use crate::trim::{Trim, TrimAccumulator};

/// What the flight controller commands in one tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output {
    /// Commands, fractions of full stick travel, each in [−1, 1] and finite.
    pub command: Controls,
    /// Servo pulse widths \[µs\]: swash servos 1 (front), 2 (right-rear), 3 (left-rear),
    /// tail.
    pub servo_us: [u16; 4],
}

impl Output {
    /// The in-the-loop answer to the [`SensorIn`] with sequence number `seq`, produced at
    /// `tick` (the value of [`FlightController::tick`] before the `step`).
    pub const fn actuator_out(&self, tick: u32, seq: u32) -> ActuatorOut {
        ActuatorOut {
            tick,
            seq,
            command: self.command,
            servo_us: self.servo_us,
        }
    }
}

/// This crate's version, as recorded in the Header.
pub const FIRMWARE_VERSION: FirmwareVersion = FirmwareVersion {
    major: parse_version_part(env!("CARGO_PKG_VERSION_MAJOR")),
    minor: parse_version_part(env!("CARGO_PKG_VERSION_MINOR")),
    patch: parse_version_part(env!("CARGO_PKG_VERSION_PATCH")),
};

/// Decimal digits to u8 at compile time (saturating; non-digits ignored).
const fn parse_version_part(text: &str) -> u8 {
    let mut rest = text.as_bytes();
    let mut value: u8 = 0;
    while let [digit, tail @ ..] = rest {
        if digit.is_ascii_digit() {
            value = value.saturating_mul(10).saturating_add(*digit - b'0');
        }
        rest = tail;
    }
    value
}

/// The held axes, in the order of `Sample::hold`.
const HELD_AXES: [Axis; 3] = [Axis::Lat, Axis::Lon, Axis::Ped];

/// Hold state and controller of one held axis.
#[derive(Clone, Copy, Debug, PartialEq)]
struct HeldAxis {
    state: HoldState,
    controller: AttitudeController,
    /// The perturbation (command − trim) actually applied last tick: the bumpless
    /// starting point of an engagement and the value a Frozen axis keeps.
    last_perturbation: f32,
    /// What is left of the controller's output after a release, fading with τ_r.
    release_carry: f32,
    /// The hold's share of the command applied last tick (the hold slew limit's starting
    /// point; only kept with a limit configured).
    last_hold: f32,
}

impl HeldAxis {
    const RELEASED: HeldAxis = HeldAxis {
        state: HoldState::Released,
        controller: AttitudeController::ZERO,
        last_perturbation: 0.0,
        release_carry: 0.0,
        last_hold: 0.0,
    };
}

/// Per-tick factors of one held axis, fixed by the configuration (computed once: the
/// exponentials are too slow for every tick).
#[derive(Clone, Copy, Debug, PartialEq)]
struct AxisDecay {
    /// e^{−dt/τ_r} of the release fade ([`fade_factor`]).
    release: f32,
    /// e^{−dt/τ_b} of the bumpless-transfer term.
    transfer: f32,
}

impl AxisDecay {
    fn new(gains: &AxisGains, dt_s: f32) -> Self {
        AxisDecay {
            release: fade_factor(gains.release_time_s, dt_s),
            transfer: AttitudeController::transfer_decay(gains, dt_s),
        }
    }
}

/// Everything one held axis needs from this tick's measurements.
#[derive(Clone, Copy, Debug)]
struct AxisInput {
    axis: Axis,
    gains: AxisGains,
    decay: AxisDecay,
    /// The angle the hold thresholds apply to \[rad\] (see [`HoldReference`]).
    hold_angle: f32,
    /// Attitude deviation from trim, the controller's error \[rad\].
    deviation: f32,
    /// Matching body rate [rad/s].
    rate: f32,
    /// Filtered noise sample for this axis.
    noise: f32,
}

/// The parts of one tick's command, for the Sample.
#[derive(Clone, Copy, Debug, PartialEq)]
struct TickParts {
    command: [f32; 4],
    sweep: [f32; 4],
    noise: [f32; 4],
    sweep_omega: f32,
}

impl TickParts {
    fn pass_through(pilot: [f32; 4]) -> Self {
        TickParts {
            command: pilot.map(clamp_unit),
            sweep: [0.0; 4],
            noise: [0.0; 4],
            sweep_omega: 0.0,
        }
    }
}

/// The flight controller. See the [module documentation](self) for the sequencer.
#[derive(Clone, Debug)]
pub struct FlightController {
    config: Config,
    header: Header,
    /// The excitation at this loop's ticks (no `f64` on the tick path).
    excitation: ExcitationTicker,
    /// The adaptive amplitude of an [`InputKind::AdaptiveSweep`] (`None`: fixed).
    shaper: Option<AmplitudeShaper>,
    /// The noise generator as configured; copied at each test start so that every test
    /// with the same seed gets the same noise.
    noise_at_start: OffAxisNoise,
    noise: OffAxisNoise,
    thresholds: HoldThresholds,
    dt_s: f32,
    /// Per-tick decay factors of lat, lon, ped.
    decays: [AxisDecay; 3],
    /// Largest command step per tick of lat, lon, ped, col (infinite: no slew limit).
    slew_steps: [f32; 4],
    /// Largest step per tick of the holds' share of lat, lon, ped (infinite: no limit).
    hold_slew_steps: [f32; 3],
    /// The commands of the tick before (the slew limit's starting point).
    last_command: [f32; 4],
    trim_capture_ticks: u32,
    phase: Phase,
    tick: u32,
    /// Ticks since the excitation started (time base of the sweep: t = n / rate).
    excitation_tick: u32,
    trim_accumulator: TrimAccumulator,
    trim: Trim,
    stale: StaleTracker,
    axes: [HeldAxis; 3],
    switch_was_on: bool,
    /// Last finite stick values, for pass-through of a non-finite stick.
    last_finite_pilot: [f32; 4],
    /// This tick's pilot-mode loop command in a loop test (see
    /// [`FlightController::set_loop_command`]); taken by the tick's step.
    loop_command: Option<[f32; 4]>,
}

impl FlightController {
    /// Validate `config` and build a controller in Idle at tick 0.
    pub fn new(config: Config) -> Result<FlightController, ConfigError> {
        let warnings = config.validate()?;
        let mut config = config;
        config.test.warnings = warnings;
        if warnings != 0 {
            warn!("test configuration warnings: {=u8:#x}", warnings);
        }
        let dt_s = config.dt_s();
        let noise = OffAxisNoise::new(
            config.test.seed,
            config.test.noise_rms,
            config.test.noise_cutoff_rad_s,
            dt_s,
        );
        let rate = f32::from(config.rate_hz);
        // Validation bounds trim_capture_s·rate to [1, 10 000].
        let trim_capture_ticks = libm::roundf(config.trim_capture_s * rate).max(1.0) as u32;
        Ok(FlightController {
            header: Header {
                protocol: ProtocolVersion::for_test(&config.test),
                firmware: FIRMWARE_VERSION,
                vehicle: config.vehicle,
                rate_hz: config.rate_hz,
                test: config.test,
                selection: None,
            },
            excitation: Excitation::from_test(&config.test).ticker(config.rate_hz),
            shaper: (config.test.input == InputKind::AdaptiveSweep).then(|| {
                AmplitudeShaper::new(
                    config.adaptive,
                    config.test.sweep.amplitude * config.excitation_scale.of(config.test.primary),
                    config.test.hold_release_rad,
                    config.safety.rate_limit_rad_s,
                )
            }),
            noise_at_start: noise.clone(),
            noise,
            thresholds: config.hold_thresholds(),
            dt_s,
            decays: [
                AxisDecay::new(&config.gains.lat, dt_s),
                AxisDecay::new(&config.gains.lon, dt_s),
                AxisDecay::new(&config.gains.ped, dt_s),
            ],
            slew_steps: config.slew.steps(dt_s),
            hold_slew_steps: config.hold_slew.steps(dt_s),
            last_command: [0.0; 4],
            trim_capture_ticks,
            phase: Phase::Idle,
            tick: 0,
            excitation_tick: 0,
            trim_accumulator: TrimAccumulator::default(),
            trim: Trim::default(),
            stale: StaleTracker::default(),
            axes: [HeldAxis::RELEASED; 3],
            switch_was_on: false,
            last_finite_pilot: [0.0; 4],
            loop_command: None,
            config,
        })
    }

    /// The Header sent at test start (vehicle, rate, test, warnings).
    pub fn header(&self) -> Header {
        self.header
    }

    /// Fly `test` from the next test on, announced with `selection` in its Header (the
    /// board application's test list). Only in Idle: in another phase nothing changes
    /// and it returns `Ok(false)`. The test is validated with the rest of the
    /// configuration as [`FlightController::new`] does; a refused one changes nothing.
    /// The sequencer's running state (tick, staleness, switch, last commands, trim)
    /// carries over.
    pub fn set_test(
        &mut self,
        test: TestConfig,
        selection: Option<TestSelection>,
    ) -> Result<bool, ConfigError> {
        if self.phase != Phase::Idle {
            return Ok(false);
        }
        let mut next = FlightController::new(Config {
            test,
            ..self.config
        })?;
        next.header.selection = selection;
        next.tick = self.tick;
        next.stale = self.stale;
        next.switch_was_on = self.switch_was_on;
        next.last_finite_pilot = self.last_finite_pilot;
        next.last_command = self.last_command;
        next.trim = self.trim;
        *self = next;
        Ok(true)
    }

    /// The current sequencer phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Number of ticks stepped so far (the tick number the next `step` will carry).
    pub fn tick(&self) -> u32 {
        self.tick
    }

    /// The validated configuration (with `test.warnings` filled in).
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The trim of the current or last test (zero before the first capture).
    pub fn trim(&self) -> Trim {
        self.trim
    }

    /// Hold states of lat, lon and ped.
    pub fn hold_states(&self) -> [HoldState; 3] {
        self.axes.map(|axis| axis.state)
    }

    /// Run one tick: sequencer, safety, excitation and hold, telemetry into `sink`.
    /// Bounded time, no allocation, no panic for any input.
    pub fn step(&mut self, input: &SensorIn, sink: &mut impl FrameSink) -> Output {
        let tick = self.tick;
        let unchanged_seq_ticks = self.stale.observe(input.seq);
        let pilot = self.sanitize_pilot(&input.pilot.sticks);
        let pilot = self.loop_or_pilot(pilot);
        let switch_on = input.pilot.test_switch;
        let switch_rising = switch_on && !self.switch_was_on;
        self.switch_was_on = switch_on;
        let phase_at_start = self.phase;

        match self.phase {
            Phase::Idle if switch_rising => self.set_phase(Phase::Armed, tick, sink),
            Phase::Done | Phase::Aborted if !switch_on => self.set_phase(Phase::Idle, tick, sink),
            _ => {}
        }

        if is_guarded(self.phase) {
            let mut stick_reference = match self.phase {
                Phase::TrimCapture => self.trim_accumulator.mean_sticks(),
                Phase::FadeIn | Phase::Sweep | Phase::FadeOut => Some(self.trim.sticks),
                _ => None,
            };
            if self.config.collective == CollectiveSource::Pilot {
                // The collective is the pilot's to move: compared with itself, it never
                // overrides (a non-finite stick is still a sensor fault).
                if let Some([_, _, _, col]) = stick_reference.as_mut() {
                    *col = input.pilot.sticks.col;
                }
            }
            let verdict = safety::check(
                &self.config.safety,
                &SafetyInput {
                    sensor: input,
                    unchanged_seq_ticks,
                    stick_reference,
                },
            );
            if let Some(reason) = verdict {
                self.abort_at(reason, tick, sink);
            }
        }

        // Armed lasts exactly one tick: the test starts on the next one.
        if self.phase == Phase::Armed && phase_at_start == Phase::Armed {
            emit(sink, &Frame::Header(self.header));
            self.trim_accumulator = TrimAccumulator::default();
            self.set_phase(Phase::TrimCapture, tick, sink);
        }

        let excite = match self.phase {
            Phase::TrimCapture => {
                self.trim_accumulator.add(&input.pilot.sticks, &input.meas);
                if self.trim_accumulator.count() >= self.trim_capture_ticks {
                    self.start_excitation(tick, sink);
                    true
                } else {
                    false
                }
            }
            Phase::FadeIn | Phase::Sweep | Phase::FadeOut => true,
            _ => false,
        };
        let parts = if excite {
            self.excite(&input.meas, pilot, tick, sink)
        } else {
            TickParts::pass_through(pilot)
        };

        self.last_command = parts.command;
        let command = Controls::from_array(parts.command);
        let sample = Sample {
            tick,
            phase: self.phase,
            primary: self.config.test.primary,
            sweep_omega: parts.sweep_omega,
            hold: self.hold_states(),
            command: sink.logged_command(&command),
            sweep: Controls::from_array(parts.sweep),
            noise: Controls::from_array(parts.noise),
            pilot: input.pilot.sticks,
            meas: input.meas,
        };
        emit(sink, &Frame::Sample(sample));
        self.tick = tick.wrapping_add(1);
        Output {
            command,
            servo_us: mix(&self.config.mixer, &command),
        }
    }

    /// Sticks with each non-finite value replaced by the last finite one.
    fn sanitize_pilot(&mut self, sticks: &Controls) -> [f32; 4] {
        for (kept, value) in self.last_finite_pilot.iter_mut().zip(sticks.to_array()) {
            if value.is_finite() {
                *kept = value;
            }
        }
        self.last_finite_pilot
    }

    fn set_phase(&mut self, to: Phase, tick: u32, sink: &mut impl FrameSink) {
        if self.phase != to {
            let from = self.phase;
            info!("tick {=u32}: phase {} -> {}", tick, from, to);
            emit(sink, &Frame::Event(Event::PhaseChange { tick, from, to }));
            self.phase = to;
        }
    }

    /// End a running test from outside the sequencer (the board application's receiver,
    /// IMU and disarm failsafes): in a guarded phase (Armed, TrimCapture, FadeIn, Sweep,
    /// FadeOut) emit the Abort Event with `reason`, release every held axis and go to
    /// Aborted, exactly as the sequencer's own checks do; the Events carry the tick the
    /// next [`step`](Self::step) will carry. Returns whether a test was ended; in Idle,
    /// Done and Aborted nothing happens. Like every abort, the switch must then go off
    /// (→ Idle) before the next test.
    pub fn abort(&mut self, reason: AbortReason, sink: &mut impl FrameSink) -> bool {
        if !is_guarded(self.phase) {
            return false;
        }
        self.abort_at(reason, self.tick, sink);
        true
    }

    fn abort_at(&mut self, reason: AbortReason, tick: u32, sink: &mut impl FrameSink) {
        warn!("tick {=u32}: abort: {}", tick, reason);
        emit(sink, &Frame::Event(Event::Abort { tick, reason }));
        self.release_all(tick, sink);
        self.set_phase(Phase::Aborted, tick, sink);
    }

    /// Release every held axis (end of the excitation or abort).
    fn release_all(&mut self, tick: u32, sink: &mut impl FrameSink) {
        for (held, axis) in self.axes.iter_mut().zip(HELD_AXES) {
            if held.state != HoldState::Released {
                emit(sink, &Frame::Event(Event::HoldReleased { tick, axis }));
            }
            *held = HeldAxis::RELEASED;
        }
    }

    /// Trim capture complete: fix the trim and reset the excitation's state.
    fn start_excitation(&mut self, tick: u32, sink: &mut impl FrameSink) {
        self.trim = self.trim_accumulator.trim();
        let trim = self.trim;
        info!("tick {=u32}: trim captured", tick);
        emit(
            sink,
            &Frame::Event(Event::TrimCaptured {
                tick,
                sticks: Controls::from_array(trim.sticks),
                phi: trim.phi,
                theta: trim.theta,
                psi: trim.psi,
            }),
        );
        self.excitation_tick = 0;
        if let Some(shaper) = &mut self.shaper {
            shaper.reset();
        }
        self.noise = self.noise_at_start.clone();
        self.axes = [HeldAxis::RELEASED; 3];
    }
}

/// exp(−dt/τ): the per-tick factor of a first-order fade with time constant τ (0: gone
/// at once). micromath's exp is plenty for a fade.
fn fade_factor(tau_s: f32, dt_s: f32) -> f32 {
    if tau_s > 0.0 {
        micromath::F32Ext::exp(-dt_s / tau_s)
    } else {
        0.0
    }
}

/// Phases the safety checks guard.
fn is_guarded(phase: Phase) -> bool {
    matches!(
        phase,
        Phase::Armed | Phase::TrimCapture | Phase::FadeIn | Phase::Sweep | Phase::FadeOut
    )
}

/// Encode `frame` and hand it to `sink`. Encoding cannot fail for the protocol's types
/// with a `MAX_FRAME_LEN` buffer; if it ever did, the frame is dropped (and shows up as
/// a gap) rather than stopping the control loop.
fn emit(sink: &mut impl FrameSink, frame: &Frame) {
    if sink.send_frame(frame).is_err() {
        error!("telemetry frame encoding failed");
    }
}

/// `value` clamped to [−1, 1]; NaN maps to 0.
fn clamp_unit(value: f32) -> f32 {
    crate::attitude_hold::clamp_finite(value, 1.0)
}

/// Angle wrapped to [−π, π]; non-finite maps to 0.
///
/// x − 2π·round(x/2π) lies in [−π, π] in exact arithmetic; the final clamp keeps it
/// there after rounding, even for huge |x| where the subtraction loses every digit.
pub fn wrap_pi(angle: f32) -> f32 {
    use core::f32::consts::{PI, TAU};
    if !angle.is_finite() {
        return 0.0;
    }
    (angle - TAU * libm::roundf(angle / TAU)).clamp(-PI, PI)
}

mod excitation;

#[cfg(test)]
#[path = "controller_tests.rs"]
mod tests;
