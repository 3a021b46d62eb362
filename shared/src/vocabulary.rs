//! The words frames are made of: versions, the vehicle, axes, excitation modes and
//! inputs, the sequencer's phases, hold states, abort reasons and the four controls.
//! Re-exported by [`frames`](crate::frames); their order and variants are the wire's
//! (postcard encodes enum variants by index and struct fields in order).

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

/// Semantic version of the firmware that produced a dump.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FirmwareVersion {
    /// Major version.
    pub major: u8,
    /// Minor version.
    pub minor: u8,
    /// Patch version.
    pub patch: u8,
}

impl core::fmt::Display for FirmwareVersion {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}.{}.{}", self.major, self.minor, self.patch)
    }
}

/// Which aircraft the flight controller is configured for.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum VehicleId {
    /// MBB Bo-105 (full scale; flown in simulation).
    Bo105,
    /// TREX 700L-class flybarless model helicopter.
    Trex700l,
}

impl VehicleId {
    /// Lower-case name used on the command line and in file names.
    pub const fn name(self) -> &'static str {
        match self {
            VehicleId::Bo105 => "bo105",
            VehicleId::Trex700l => "trex700l",
        }
    }
}

/// A control axis. Order everywhere: lateral, longitudinal, pedal, collective.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Axis {
    /// Lateral cyclic (δ_lat), held on roll attitude φ.
    Lat,
    /// Longitudinal cyclic (δ_lon), held on pitch attitude θ.
    Lon,
    /// Pedal (δ_ped), held on heading error ψ − ψ_trim.
    Ped,
    /// Collective (δ_col); never held, never given off-axis noise.
    Col,
}

impl Axis {
    /// All four axes in wire order.
    pub const ALL: [Axis; 4] = [Axis::Lat, Axis::Lon, Axis::Ped, Axis::Col];

    /// Lower-case name used on the command line, in CSV columns and file names.
    pub const fn name(self) -> &'static str {
        match self {
            Axis::Lat => "lat",
            Axis::Lon => "lon",
            Axis::Ped => "ped",
            Axis::Col => "col",
        }
    }

    /// Position in [`Axis::ALL`] and in `[f32; 4]` control arrays.
    pub const fn index(self) -> usize {
        match self {
            Axis::Lat => 0,
            Axis::Lon => 1,
            Axis::Ped => 2,
            Axis::Col => 3,
        }
    }
}

/// How the non-primary axes are treated during an excitation (paper §IV.B).
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ExcitationMode {
    /// Conditional attitude hold plus off-axis noise: the paper's method.
    ConditionalAttitudeHold,
    /// Attitude-hold controller always on, sweep added on the primary axis (paper Fig. 3).
    Standard,
    /// Controller always on plus off-axis noise (Tischler's method).
    OffAxisNoise,
}

/// The excitation signal on the primary axis.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InputKind {
    /// Tischler's exponential computer-generated frequency sweep.
    Sweep,
    /// Doublet: +A for one pulse width, −A for one pulse width.
    Doublet,
    /// 3-2-1-1 multistep: +A 3w, −A 2w, +A 1w, −A 1w.
    ThreeTwoOneOne,
    /// The same exponential sweep with its amplitude adapted online from the attitude and
    /// rate envelope of its last cycle, around A (the firmware's `amplitude` module).
    /// Since protocol 1.3.
    AdaptiveSweep,
    /// A loop test: the same exponential sweep added to the board's pilot-mode loop of
    /// the primary axis at its output (the loop's actuator command), the pilot-mode
    /// loops closed on every axis; no off-axis noise, no attitude hold. `command` −
    /// `sweep` of each Sample is then the loops' own output, and the broken-loop
    /// response at the actuator is −(command − sweep)/command (docs/formats.md, "Loop
    /// tests"). Since protocol 1.9; flown by the board application only.
    LoopSweep,
}

impl InputKind {
    /// Whether the input is a frequency sweep (fixed or adaptive amplitude, or a loop test).
    pub const fn is_sweep(self) -> bool {
        matches!(
            self,
            InputKind::Sweep | InputKind::AdaptiveSweep | InputKind::LoopSweep
        )
    }

    /// Whether the input is a loop test ([`InputKind::LoopSweep`]).
    pub const fn is_loop(self) -> bool {
        matches!(self, InputKind::LoopSweep)
    }
}

/// Phase of the test sequencer.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// Pilot has full authority; waiting for the test switch.
    Idle,
    /// Test switch on; the sequencer starts trim capture on the next tick.
    Armed,
    /// Averaging pilot sticks and attitude to define the trim.
    TrimCapture,
    /// Raised-cosine fade-in of the excitation (and the ω_min hold, if configured).
    FadeIn,
    /// The excitation proper (sweep, doublet or 3-2-1-1).
    Sweep,
    /// Raised-cosine fade-out of the excitation.
    FadeOut,
    /// Test complete; pilot pass-through until the switch is released.
    Done,
    /// Test aborted; pilot pass-through until the switch is cycled.
    Aborted,
}

/// State of the conditional attitude hold on one axis.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HoldState {
    /// Controller released: the axis carries its excitation.
    Released,
    /// Controller engaged: the axis carries the attitude-hold command.
    Engaged,
    /// Inside the hysteresis band with the freeze option: last command held constant.
    Frozen,
}

/// Why a test was aborted.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AbortReason {
    /// |φ| or |θ| above the abort limit.
    AttitudeLimit,
    /// |p|, |q| or |r| above its limit.
    RateLimit,
    /// A sensor value was NaN or infinite.
    SensorNotFinite,
    /// The sensor sample did not change for more than the stale limit of ticks.
    SensorStale,
    /// A pilot stick moved more than the override threshold away from its trim.
    PilotOverride,
    /// The pilot's test switch left the test position.
    SwitchReleased,
    /// The receiver lost the pilot's signal (or delivered an invalid frame) during the
    /// test.
    RcLost,
    /// The IMU reported a fault, stopped delivering samples or delivered non-finite values,
    /// or the attitude estimate became invalid, during the test.
    ImuFault,
    /// The pilot disarmed (arm switch off: throttle cut) during the test.
    Disarmed,
    /// The board application's landed condition held during the test (collective stick
    /// low for a time, or the throttle below the rotor-under-power level). Since 1.6.
    Landed,
}

impl AbortReason {
    /// Short snake_case name used in reports and JSON.
    pub const fn name(self) -> &'static str {
        match self {
            AbortReason::AttitudeLimit => "attitude_limit",
            AbortReason::RateLimit => "rate_limit",
            AbortReason::SensorNotFinite => "sensor_not_finite",
            AbortReason::SensorStale => "sensor_stale",
            AbortReason::PilotOverride => "pilot_override",
            AbortReason::SwitchReleased => "switch_released",
            AbortReason::RcLost => "rc_lost",
            AbortReason::ImuFault => "imu_fault",
            AbortReason::Disarmed => "disarmed",
            AbortReason::Landed => "landed",
        }
    }
}

/// One value per control axis, in fractions of full stick travel ([−1, 1]).
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Controls {
    /// Lateral cyclic.
    pub lat: f32,
    /// Longitudinal cyclic.
    pub lon: f32,
    /// Pedal.
    pub ped: f32,
    /// Collective.
    pub col: f32,
}

impl Controls {
    /// The four values in axis order (lat, lon, ped, col).
    pub const fn to_array(self) -> [f32; 4] {
        [self.lat, self.lon, self.ped, self.col]
    }

    /// Build from an array in axis order (lat, lon, ped, col).
    pub const fn from_array(a: [f32; 4]) -> Self {
        Controls {
            lat: a[0],
            lon: a[1],
            ped: a[2],
            col: a[3],
        }
    }

    /// The value on one axis.
    pub const fn get(&self, axis: Axis) -> f32 {
        match axis {
            Axis::Lat => self.lat,
            Axis::Lon => self.lon,
            Axis::Ped => self.ped,
            Axis::Col => self.col,
        }
    }
}
