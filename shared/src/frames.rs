//! The frame types that cross the wire.
//!
//! Every frame is one [`Frame`] value. The flight controller streams a [`Header`] when a
//! test starts, one [`Sample`] per tick, and an [`Event`] whenever something discrete
//! happens. When a flight controller runs in the loop with the host simulator, the host
//! sends a [`SensorIn`] each tick and the flight controller answers with an
//! [`ActuatorOut`].
//!
//! Units are SI throughout: rad, rad/s, m/s, m/s², s. Control commands are fractions of
//! full stick travel in [−1, 1].

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

pub use crate::board_events::{FlightMode, HostFrame, ImuHealth, RefusedCheck, Request};
pub use crate::param_frames::{
    ParamName, ParamOp, ParamRefusal, ParamReply, ParamRequest, ParamStoreStatus, PARAM_NAME_LEN,
};
pub use crate::servo_frames::{
    ServoTarget, ServoTest, ServoTestEnd, ServoTestRefusal, ServoTestReply, ServoTestStatus,
    MAX_SERVO_HOLD_MS,
};
pub use crate::vocabulary::{
    AbortReason, Axis, Controls, ExcitationMode, FirmwareVersion, HoldState, InputKind, Phase,
    VehicleId,
};

/// Version of the wire protocol. A host refuses a dump whose `major` differs from its
/// own; `minor` bumps only add frame variants at the end of [`Frame`] or enum variants at
/// the end of an enum, which an older host reports as corrupt frames and skips.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ProtocolVersion {
    /// Incompatible layout changes.
    pub major: u16,
    /// Compatible additions.
    pub minor: u16,
}

/// The protocol version this crate speaks.
/// 1.1 added [`Frame::Configure`] and [`Frame::ConfigureResult`]; 1.2 the board
/// application's abort reasons [`AbortReason::RcLost`], [`AbortReason::ImuFault`] and
/// [`AbortReason::Disarmed`]; 1.3 [`InputKind::AdaptiveSweep`]; 1.4 the board
/// application's events ([`Event::ModeChange`], [`Event::ImuHealthChange`],
/// [`Event::Refused`], [`Event::HostLinkIgnored`]); 1.5 the parameter frames
/// ([`Frame::ParamRequest`], [`Frame::ParamReply`]), [`Event::ParamStore`] and the
/// refusals [`RefusedCheck::ParamsInvalid`] and [`RefusedCheck::NotLevel`]; 1.6 the
/// abort reason [`AbortReason::Landed`] and the refusal [`RefusedCheck::NotAirborne`];
/// 1.7 the Header's [`Header::selection`] (the test list entry and the engagement count),
/// the refusal [`RefusedCheck::NoTestSelected`] and [`Frame::MeasurementFilter`]; 1.8 the
/// bench servo test ([`Frame::ServoTest`], [`Frame::ServoTestReply`]); 1.9 the loop test
/// [`InputKind::LoopSweep`].
pub const PROTOCOL_VERSION: ProtocolVersion = ProtocolVersion { major: 1, minor: 9 };

impl ProtocolVersion {
    /// The version a [`Header`] of `test` announces: the oldest one whose decoders read
    /// everything the test streams. A test that uses nothing added since 1.2 announces
    /// 1.2, so its dumps are byte for byte those of a 1.2 flight controller and every
    /// 1.2 host reads them whole; [`InputKind::AdaptiveSweep`] needs 1.3 and
    /// [`InputKind::LoopSweep`] 1.9. A board
    /// application's stream also carries the 1.4 events: it announces
    /// [`ProtocolVersion::BOARD_APPLICATION`] whatever its test.
    pub const fn for_test(test: &TestConfig) -> ProtocolVersion {
        match test.input {
            InputKind::AdaptiveSweep => ProtocolVersion { major: 1, minor: 3 },
            InputKind::LoopSweep => ProtocolVersion { major: 1, minor: 9 },
            InputKind::Sweep | InputKind::Doublet | InputKind::ThreeTwoOneOne => {
                ProtocolVersion { major: 1, minor: 2 }
            }
        }
    }
}

impl ProtocolVersion {
    /// The version the board application's Headers announce: its streams carry the
    /// events added in 1.4 and its Headers the [`Header::selection`] of 1.7 (and after
    /// each Header the 1.7 [`Frame::MeasurementFilter`]).
    pub const BOARD_APPLICATION: ProtocolVersion = ProtocolVersion { major: 1, minor: 7 };

    /// The later of `self` and `other`.
    pub const fn max(self, other: ProtocolVersion) -> ProtocolVersion {
        if other.major > self.major || (other.major == self.major && other.minor > self.minor) {
            other
        } else {
            self
        }
    }
}

impl core::fmt::Display for ProtocolVersion {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}.{}", self.major, self.minor)
    }
}

/// What the flight controller's sensors report each tick, in body axes.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measurements {
    /// Roll rate [rad/s].
    pub p: f32,
    /// Pitch rate [rad/s].
    pub q: f32,
    /// Yaw rate [rad/s].
    pub r: f32,
    /// Roll attitude φ \[rad\].
    pub phi: f32,
    /// Pitch attitude θ \[rad\].
    pub theta: f32,
    /// Heading ψ \[rad\], in (−π, π].
    pub psi: f32,
    /// Body-axis velocity u [m/s].
    pub u: f32,
    /// Body-axis velocity v [m/s].
    pub v: f32,
    /// Body-axis velocity w [m/s].
    pub w: f32,
    /// Specific force along x as an accelerometer at the CG reads it [m/s²].
    pub ax: f32,
    /// Specific force along y [m/s²].
    pub ay: f32,
    /// Specific force along z [m/s²] (≈ −g in hover).
    pub az: f32,
}

/// The pilot's inputs as the flight controller reads them from the receiver.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PilotInput {
    /// Stick positions, fractions of full travel.
    pub sticks: Controls,
    /// The test switch: `true` in the test position (arms the sequencer).
    pub test_switch: bool,
}

/// Sweep parameters of the active test (paper Eq. 19–23).
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SweepSettings {
    /// Record length T_rec \[s\] (fades and the ω_min hold come on top).
    pub t_rec_s: f32,
    /// Amplitude A, fraction of full stick travel.
    pub amplitude: f32,
    /// Start frequency ω_min [rad/s].
    pub omega_min: f32,
    /// End frequency ω_max [rad/s].
    pub omega_max: f32,
    /// Raised-cosine fade-in and fade-out length \[s\]; 0 disables.
    pub fade_s: f32,
    /// Cycles at ω_min before the sweep proper; 0 disables.
    pub start_hold_cycles: u8,
}

/// Pulse parameters of doublet and 3-2-1-1 inputs.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PulseSettings {
    /// Pulse amplitude, fraction of full stick travel.
    pub amplitude: f32,
    /// Base pulse width \[s\].
    pub width_s: f32,
}

/// Bit in [`TestConfig::warnings`]: T_rec is shorter than 4·T_max = 4·2π/ω_min.
pub const WARN_RECORD_SHORT: u8 = 1 << 0;

/// The test the flight controller is flying, as recorded in the [`Header`].
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TestConfig {
    /// How the off-axis inputs are treated.
    pub mode: ExcitationMode,
    /// The excited axis.
    pub primary: Axis,
    /// The excitation signal.
    pub input: InputKind,
    /// Sweep parameters (used when `input` is [`InputKind::Sweep`]).
    pub sweep: SweepSettings,
    /// Pulse parameters (used for doublet and 3-2-1-1).
    pub pulse: PulseSettings,
    /// RMS of the off-axis noise, fraction of full stick travel.
    pub noise_rms: f32,
    /// Low-pass cutoff of the off-axis noise [rad/s].
    pub noise_cutoff_rad_s: f32,
    /// Seed of the noise generator.
    pub seed: u32,
    /// Attitude above which the hold controller engages \[rad\] (paper: 6°).
    pub hold_engage_rad: f32,
    /// Attitude below which the hold controller releases \[rad\] (paper: 4°).
    pub hold_release_rad: f32,
    /// Freeze the last command inside the hysteresis band instead of keeping the prior form.
    pub freeze_in_band: bool,
    /// Bit set of `WARN_*` flags raised when the configuration was built.
    pub warnings: u8,
}

/// Sent once when a test starts: who is flying what.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    /// Wire protocol version; must stay the first field (decoders peek at it).
    pub protocol: ProtocolVersion,
    /// Firmware version.
    pub firmware: FirmwareVersion,
    /// Configured vehicle.
    pub vehicle: VehicleId,
    /// Fixed tick rate of the control loop \[Hz\].
    pub rate_hz: u16,
    /// The active test.
    pub test: TestConfig,
    /// Which test of the board's test list this is and how many tests the board engaged
    /// since power-up (board application, since 1.7). `None` in the Headers of a flight
    /// controller without a test list and of streams before 1.7: it then takes no bytes
    /// on the wire, so their Headers are byte for byte what they were and a 1.7 decoder
    /// reads the older ones whole.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "absent_at_end"
    )]
    pub selection: Option<TestSelection>,
}

/// The test list entry a Header's test came from and its engagement number (since 1.7).
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TestSelection {
    /// The entry of the test list, 1 … 12; 0: the single configured test (no selector
    /// channel).
    pub entry: u8,
    /// This test's number among the tests engaged since power-up, from 1.
    pub engagement: u16,
}

/// A trailing optional field: `None` where the frame ends before it (the layout before
/// the field existed), else the value postcard reads.
fn absent_at_end<'de, D, T>(deserializer: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    Ok(Option::<T>::deserialize(deserializer).unwrap_or(None))
}

/// One firmware tick: what was commanded, why, and what the sensors saw.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Tick counter since boot; consecutive Samples differ by one.
    pub tick: u32,
    /// Sequencer phase during this tick.
    pub phase: Phase,
    /// Excited axis.
    pub primary: Axis,
    /// Instantaneous sweep frequency dθ/dt [rad/s]; 0 outside a sweep.
    pub sweep_omega: f32,
    /// Hold state of the lateral, longitudinal and pedal axes.
    pub hold: [HoldState; 3],
    /// Applied commands (trim + perturbation, or pilot pass-through).
    pub command: Controls,
    /// Sweep (or pulse) component of the commands.
    pub sweep: Controls,
    /// Off-axis noise component of the commands.
    pub noise: Controls,
    /// Pilot stick positions.
    pub pilot: Controls,
    /// Sensor measurements used in this tick.
    pub meas: Measurements,
}

/// Something discrete that happened at a tick.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// The sequencer changed phase.
    PhaseChange {
        /// Tick of the change.
        tick: u32,
        /// Phase before.
        from: Phase,
        /// Phase after.
        to: Phase,
    },
    /// The attitude-hold controller engaged on an axis.
    HoldEngaged {
        /// Tick of the change.
        tick: u32,
        /// Axis (lat, lon or ped).
        axis: Axis,
    },
    /// The attitude-hold controller released an axis.
    HoldReleased {
        /// Tick of the change.
        tick: u32,
        /// Axis (lat, lon or ped).
        axis: Axis,
    },
    /// Trim capture finished: the trim every command is built on.
    TrimCaptured {
        /// Tick of the capture.
        tick: u32,
        /// Averaged pilot sticks.
        sticks: Controls,
        /// Averaged roll attitude \[rad\].
        phi: f32,
        /// Averaged pitch attitude \[rad\].
        theta: f32,
        /// Heading at capture \[rad\].
        psi: f32,
    },
    /// The test was aborted; outputs fell back to pilot pass-through in this tick.
    Abort {
        /// Tick of the abort.
        tick: u32,
        /// Why.
        reason: AbortReason,
    },
    /// The board application changed flight mode. Since 1.4.
    ModeChange {
        /// Tick of the change.
        tick: u32,
        /// Mode before.
        from: FlightMode,
        /// Mode after.
        to: FlightMode,
    },
    /// The IMU's health changed; also sent on the board application's first tick.
    /// Since 1.4.
    ImuHealthChange {
        /// Tick of the change.
        tick: u32,
        /// Health from this tick on.
        health: ImuHealth,
    },
    /// The board application refused an arm or test request. Since 1.4.
    Refused {
        /// Tick of the request.
        tick: u32,
        /// What was asked.
        request: Request,
        /// The first check that failed.
        check: RefusedCheck,
    },
    /// A host frame arrived while the board was armed and was ignored: hardware in the
    /// loop is entered on the ground only. Sent for the first such frame of each armed
    /// period. Since 1.4.
    HostLinkIgnored {
        /// Tick of the frame.
        tick: u32,
        /// Which frame.
        frame: HostFrame,
    },
    /// What the parameter store held at boot (defaults in use unless `Loaded`).
    /// Since 1.5.
    ParamStore {
        /// Tick of the report.
        tick: u32,
        /// What was found.
        status: ParamStoreStatus,
    },
}

/// Host → flight controller, each tick, when running in the loop: the simulated sensors
/// and pilot.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorIn {
    /// Sensor sample counter; a value that does not change marks a stale sample.
    pub seq: u32,
    /// The measurements.
    pub meas: Measurements,
    /// The pilot.
    pub pilot: PilotInput,
}

/// Flight controller → host, each tick, when running in the loop: the outputs.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ActuatorOut {
    /// Tick that produced these outputs.
    pub tick: u32,
    /// Seq of the [`SensorIn`] they answer.
    pub seq: u32,
    /// Commands, fractions of full stick travel.
    pub command: Controls,
    /// Servo pulse widths \[µs\]: swash servos 1–3, tail.
    pub servo_us: [u16; 4],
}

/// Host → flight controller (protocol 1.1): fly `test` on `vehicle` at `rate_hz`.
///
/// The flight controller builds its configuration from its own preset for `vehicle` and
/// `test.primary` (gains, mixer, safety limits, trim capture), replaces the preset's
/// rate and test with these, and restarts its flight logic on it (tick 0, sequencer
/// Idle). Everything else of the configuration stays the preset's, so a host that needs
/// other settings must rebuild the image. The answer is a [`ConfigureResult`]; when the
/// new configuration is accepted a [`Header`] describing it goes out before the answer.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkConfig {
    /// The vehicle whose preset the configuration starts from.
    pub vehicle: VehicleId,
    /// Tick rate of the flight logic \[Hz\] (the firmware accepts 50–1000).
    pub rate_hz: u16,
    /// The test to fly; its `warnings` are recomputed by the flight controller.
    pub test: TestConfig,
}

/// Flight controller → host (protocol 1.1): the answer to a [`LinkConfig`].
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigureResult {
    /// `true`: the new configuration is in force and the flight logic restarted on it.
    /// `false`: it was refused and the previous configuration stays in force.
    pub accepted: bool,
    /// Why it was refused: the position of the firmware's `ConfigError` variant in its
    /// declaration (0 when accepted). The host names it by validating the same
    /// configuration with the firmware library itself.
    pub refusal: u8,
}

/// Everything that crosses the wire. `Header` must stay variant 0: a decoder peeks at
/// the protocol version of a Header it cannot fully decode.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(clippy::large_enum_variant)]
pub enum Frame {
    /// Test start.
    Header(Header),
    /// One tick.
    Sample(Sample),
    /// A discrete event.
    Event(Event),
    /// In-the-loop sensors (host → flight controller).
    SensorIn(SensorIn),
    /// In-the-loop outputs (flight controller → host).
    ActuatorOut(ActuatorOut),
    /// Run-time configuration (host → flight controller). Since protocol 1.1.
    Configure(LinkConfig),
    /// The answer to a [`Frame::Configure`] (flight controller → host). Since 1.1.
    ConfigureResult(ConfigureResult),
    /// A parameter request (host → flight controller). Since 1.5.
    ParamRequest(ParamRequest),
    /// The answer to a [`Frame::ParamRequest`] (flight controller → host). Since 1.5.
    ParamReply(ParamReply),
    /// The digital filter the test's IMU measurements went through before the flight
    /// logic read them; sent by the board application right after each [`Header`].
    /// Since 1.7.
    MeasurementFilter(MeasurementFilter),
    /// Move one servo on the bench, disarmed (host → flight controller). Since 1.8.
    ServoTest(ServoTest),
    /// The answer to a [`Frame::ServoTest`], and the end of a servo test (flight
    /// controller → host). Since 1.8.
    ServoTestReply(ServoTestReply),
}

/// Biquad sections in series per [`MeasurementFilter`]: the board's low-pass and its
/// three rotor notches.
pub const MEASUREMENT_FILTER_SECTIONS: usize = 4;

/// A chain of biquad sections run at `sample_rate_hz` on every IMU channel (the body
/// rates and specific forces, and through them the attitude estimate) before the
/// control tick reads the newest output. Section `k` is
///
/// ```text
/// H_k(z) = (b₀ + b₁ z⁻¹ + b₂ z⁻²) / (1 + a₁ z⁻¹ + a₂ z⁻²),   sections[k] = [b₀, b₁, b₂, a₁, a₂]
/// ```
///
/// and the filter is their product, evaluated at z = e^{jω/sample_rate_hz}. An unused
/// section is the identity `[1, 0, 0, 0, 0]`. A frequency response identified from these
/// measurements holds this filter as well as the aircraft; the host divides it out.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MeasurementFilter {
    /// Rate the sections run at \[Hz\].
    pub sample_rate_hz: f32,
    /// The sections, in the order they run.
    pub sections: [[f32; 5]; MEASUREMENT_FILTER_SECTIONS],
}
