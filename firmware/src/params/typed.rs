//! The typed view of the parameter table: the configuration structs the control code
//! reads, filled from the values, and the values read back from them (the defaults).
//!
//! Every parameter maps onto one field (or, for `COLL_MIN`/`COLL_MAX`, `HEAD_RPM` and
//! `TAIL_RPM`, a pair of fields); everything else keeps the preset's value. Angles are
//! in degrees on the table and radians in the structs, converted with the same
//! `π/180` the presets are written with, so the defaults give the preset bit for bit
//! (tested for both presets).

use sweephold_protocol::{Axis, ExcitationMode, InputKind, VehicleId};

use super::table::{frame_code, frame_vehicle, ParamId, COUNT};
use crate::app::test_list::{TestEntry, TEST_LIST_LEN};
use crate::app::{AppConfig, AppConfigError};
use crate::board_stack::StackConfig;
use crate::config::{CollectiveSource, ConfigError, HoldReference};
use crate::filters::{FilterBank, FilterBankConfig, FilterError};
use crate::imu::ImuRotation;
use crate::mixer::ServoConfig;
use crate::receiver::{ChannelMapError, ChannelSource};
use crate::swash::{SwashError, SwashGeometry, SwashType};

mod values;
pub use values::values_of;

/// Each swash output's parameters: direction, centre, limits, throw.
const SWASH_SERVO_IDS: [[ParamId; 5]; 3] = [
    [
        ParamId::Servo1Dir,
        ParamId::Servo1Mid,
        ParamId::Servo1Min,
        ParamId::Servo1Max,
        ParamId::Servo1Throw,
    ],
    [
        ParamId::Servo2Dir,
        ParamId::Servo2Mid,
        ParamId::Servo2Min,
        ParamId::Servo2Max,
        ParamId::Servo2Throw,
    ],
    [
        ParamId::Servo3Dir,
        ParamId::Servo3Mid,
        ParamId::Servo3Min,
        ParamId::Servo3Max,
        ParamId::Servo3Throw,
    ],
];

/// The tail servo's parameters, in the same order.
const TAIL_SERVO_IDS: [ParamId; 5] = [
    ParamId::TailDir,
    ParamId::TailMid,
    ParamId::TailMin,
    ParamId::TailMax,
    ParamId::TailThrow,
];

/// Each held axis' (lat, lon, ped) integrator limit, bumpless and fade time constants and
/// direction.
const HOLD_MORE_IDS: [[ParamId; 4]; 3] = [
    [
        ParamId::HoldLatIlim,
        ParamId::HoldLatBump,
        ParamId::HoldLatFade,
        ParamId::HoldLatRev,
    ],
    [
        ParamId::HoldLonIlim,
        ParamId::HoldLonBump,
        ParamId::HoldLonFade,
        ParamId::HoldLonRev,
    ],
    [
        ParamId::HoldPedIlim,
        ParamId::HoldPedBump,
        ParamId::HoldPedFade,
        ParamId::HoldPedRev,
    ],
];

/// The excitation scale of lat, lon, ped, col.
const EXC_SCALE_IDS: [ParamId; 4] = [
    ParamId::ExcScaleLat,
    ParamId::ExcScaleLon,
    ParamId::ExcScalePed,
    ParamId::ExcScaleCol,
];

/// The excitation phases' command slew limits of lat, lon, ped, col.
const SLEW_IDS: [ParamId; 4] = [
    ParamId::SlewLat,
    ParamId::SlewLon,
    ParamId::SlewPed,
    ParamId::SlewCol,
];

/// The excitation phases' slew limits of the holds' share of lat, lon, ped.
const HOLD_SLEW_IDS: [ParamId; 3] = [
    ParamId::HoldSlewLat,
    ParamId::HoldSlewLon,
    ParamId::HoldSlewPed,
];

/// The pilot mode's rate loops (roll, pitch, yaw): Kp, Ki.
const PILOT_RATE_IDS: [[ParamId; 2]; 3] = [
    [ParamId::PilotRollKp, ParamId::PilotRollKi],
    [ParamId::PilotPitchKp, ParamId::PilotPitchKi],
    [ParamId::PilotYawKp, ParamId::PilotYawKi],
];

const DEG: f32 = core::f32::consts::PI / 180.0;

/// Parameters per test list entry: `TESTn_AXIS`, `_INPUT`, `_WMIN`, `_WMAX`, `_WIDTH`,
/// `_TREC`, `_AMP`, in this order, entry after entry from `TEST1_AXIS` on.
const ENTRY_FIELDS: usize = 7;

/// The parameter of field `field` of test list entry `entry` (0-based both).
fn entry_param(entry: usize, field: usize) -> ParamId {
    ParamId::ALL
        .get(ParamId::Test1Axis.index() + entry * ENTRY_FIELDS + field)
        .copied()
        .unwrap_or(ParamId::Test1Axis)
}

/// The entry the seven values (in [`ENTRY_FIELDS`] order) describe; `None` for an
/// input number outside the table's.
fn entry_from(
    [axis, input, wmin, wmax, width, trec, amp]: [f32; ENTRY_FIELDS],
) -> Option<TestEntry> {
    Some(TestEntry {
        axis: match axis as usize {
            0 => None,
            n => Some(*Axis::ALL.get(n - 1)?),
        },
        input: *INPUTS.get(input as usize)?,
        omega_min: wmin,
        omega_max: wmax,
        pulse_width_s: width,
        t_rec_s: trec,
        amplitude: amp,
    })
}

/// The default swash servo frame rate \[Hz\]: 333, the fastest the table allows. A
/// flybarless head is flown with digital servos, which take 333 Hz frames; at the 50 Hz
/// of analog servos, three of every four 200 Hz control ticks' commands never reached a
/// servo and the hold it applied was not the logged one. An analog servo needs
/// `SERVO_RATE` 50 (it may overheat at 333).
pub const DEFAULT_FRAME_HZ: u16 = 333;

/// The default tail servo frame rate \[Hz\]: 333 too. The yaw loop is the fastest of
/// the helicopter and its servo the one a lost command costs most; flybarless tail
/// servos are digital (narrow-band 760 µs ones take 333 Hz and more, wide-band digital
/// ones 333 Hz). An analog tail servo needs `TAIL_RATE` 50.
pub const DEFAULT_TAIL_FRAME_HZ: u16 = 333;

/// Everything the parameters set, typed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// The sensor-to-servo stack's configuration (application, sequencer, mixer,
    /// receiver, filters; its `orientation` is `imu_rotation`'s).
    pub stack: StackConfig,
    /// The IMU mounting.
    pub imu_rotation: ImuRotation,
    /// Swash servo frame rate \[Hz\].
    pub swash_frame_hz: u16,
    /// Tail servo frame rate \[Hz\].
    pub tail_frame_hz: u16,
}

/// Why a set of values does not make a usable configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamsError {
    /// A value is refused by its own definition (a table built unchecked).
    Value(ParamId),
    /// Swash type, phase or lead servo invalid.
    Swash(SwashError),
    /// A servo's limits do not surround its centre, or the mixer's scales are invalid.
    Mixer,
    /// Receiver channels repeat or the raw range is not increasing.
    ChannelMap(ChannelMapError),
    /// The notch frequencies cannot be designed at the IMU rate.
    Filters(FilterError),
    /// The test, the hold or the abort limits are refused.
    Flight(ConfigError),
    /// The application's settings are refused.
    App(AppConfigError),
}

impl ParamsError {
    /// Human-readable explanation.
    pub const fn message(self) -> &'static str {
        match self {
            ParamsError::Value(_) => "a value is outside its parameter's range",
            ParamsError::Swash(SwashError::PhaseOutOfRange) => "swash phase outside ±180°",
            ParamsError::Swash(SwashError::LeadOutOfRange) => "swash lead servo not 1-3",
            ParamsError::Mixer => "servo limits must surround the centre (min < max)",
            ParamsError::ChannelMap(_) => "receiver channels must differ, min < mid < max",
            ParamsError::Filters(_) => "rotor speeds give notches the filters cannot place",
            ParamsError::Flight(error) => error.message(),
            ParamsError::App(error) => error.message(),
        }
    }
}

impl Params {
    /// The preset of `vehicle`: [`AppConfig::preset`] on the lateral axis in the board's
    /// standard stack with the collective the pilot's during a test
    /// ([`CollectiveSource::Pilot`]), no IMU rotation, 333 Hz servo frames ([`DEFAULT_FRAME_HZ`],
    /// [`DEFAULT_TAIL_FRAME_HZ`]).
    pub const fn preset(vehicle: VehicleId) -> Self {
        let mut app = AppConfig::preset(vehicle, Axis::Lat);
        // On the board the pilot keeps height with the collective during a test.
        app.flight.collective = CollectiveSource::Pilot;
        Params {
            stack: StackConfig::with_app(app),
            imu_rotation: ImuRotation::None,
            swash_frame_hz: DEFAULT_FRAME_HZ,
            tail_frame_hz: DEFAULT_TAIL_FRAME_HZ,
        }
    }

    /// The configuration `values` describe on top of the preset their `FRAME` names,
    /// checked as a whole.
    pub fn from_values(values: &[f32; COUNT]) -> Result<Self, ParamsError> {
        for (id, value) in ParamId::ALL.iter().zip(values) {
            id.def()
                .check(*value)
                .map_err(|_| ParamsError::Value(*id))?;
        }
        let v = |id: ParamId| values.get(id.index()).copied().unwrap_or(0.0);
        let vehicle = frame_vehicle(v(ParamId::Frame)).ok_or(ParamsError::Value(ParamId::Frame))?;
        let mut params = Params::preset(vehicle);
        let stack = &mut params.stack;

        let kind = SwashType::from_code(v(ParamId::SwashType) as u16)
            .ok_or(ParamsError::Value(ParamId::SwashType))?;
        let mixer = &mut stack.app.flight.mixer;
        mixer.geometry =
            SwashGeometry::new(kind, v(ParamId::SwashPhase), v(ParamId::SwashLead) as u8)
                .map_err(ParamsError::Swash)?;
        for (servo, ids) in mixer.swash.iter_mut().zip(SWASH_SERVO_IDS) {
            *servo = servo_from(ids.map(v));
        }
        mixer.tail = servo_from(TAIL_SERVO_IDS.map(v));
        let (coll_min, coll_max) = (v(ParamId::CollMin), v(ParamId::CollMax));
        mixer.collective_scale = 0.5 * (coll_max - coll_min);
        mixer.collective_offset = 0.5 * (coll_max + coll_min);
        mixer.cyclic_scale = v(ParamId::CycScale);
        mixer.pedal_scale = v(ParamId::PedScale);
        mixer.cyclic_ring = v(ParamId::CycRing);
        if !mixer.is_valid() {
            return Err(ParamsError::Mixer);
        }
        params.swash_frame_hz = v(ParamId::ServoRate) as u16;
        params.tail_frame_hz = v(ParamId::TailRate) as u16;

        let map = &mut stack.channel_map;
        let reversed = v(ParamId::RcRev) as u8;
        let channel_ids = [
            ParamId::RcLat,
            ParamId::RcLon,
            ParamId::RcThr,
            ParamId::RcPed,
            ParamId::RcArm,
            ParamId::RcCol,
            ParamId::RcTest,
            ParamId::RcMode,
        ];
        let sources = [
            &mut map.lateral,
            &mut map.longitudinal,
            &mut map.throttle,
            &mut map.pedal,
            &mut map.arm,
            &mut map.collective,
            &mut map.test,
            &mut map.mode,
        ];
        for (bit, (source, id)) in sources.into_iter().zip(channel_ids).enumerate() {
            *source = ChannelSource {
                channel: v(id) as u8,
                reversed: reversed & (1 << bit) != 0,
            };
        }
        map.range.min = v(ParamId::RcMin) as u16;
        map.range.centre = v(ParamId::RcMid) as u16;
        map.range.max = v(ParamId::RcMax) as u16;
        map.validate().map_err(ParamsError::ChannelMap)?;
        stack.rc_timeout_us = v(ParamId::RcTimeout) as u32 * 1000;

        params.imu_rotation = ImuRotation::from_code(v(ParamId::ImuRot) as u8)
            .ok_or(ParamsError::Value(ParamId::ImuRot))?;
        stack.orientation = params.imu_rotation.orientation();
        stack.filters = FilterBankConfig::helicopter(
            stack.filters.sample_rate_hz,
            v(ParamId::HeadRpm) / 60.0,
            v(ParamId::TailRpm) / 60.0,
        );
        FilterBank::new(stack.filters).map_err(ParamsError::Filters)?;

        let flight = &mut stack.app.flight;
        let gains = [
            (
                &mut flight.gains.lat,
                [
                    ParamId::HoldLatP,
                    ParamId::HoldLatI,
                    ParamId::HoldLatD,
                    ParamId::HoldLatLim,
                ],
            ),
            (
                &mut flight.gains.lon,
                [
                    ParamId::HoldLonP,
                    ParamId::HoldLonI,
                    ParamId::HoldLonD,
                    ParamId::HoldLonLim,
                ],
            ),
            (
                &mut flight.gains.ped,
                [
                    ParamId::HoldPedP,
                    ParamId::HoldPedI,
                    ParamId::HoldPedD,
                    ParamId::HoldPedLim,
                ],
            ),
        ];
        for ((axis, [p, i, d, limit]), [ilim, bump, fade, rev]) in
            gains.into_iter().zip(HOLD_MORE_IDS)
        {
            axis.kp = v(p);
            axis.ki = v(i);
            axis.kd = v(d);
            axis.output_limit = v(limit);
            // Not above the output limit: the flight configuration's check refuses that.
            axis.integrator_limit = v(ilim);
            axis.bumpless_time_s = v(bump);
            axis.release_time_s = v(fade);
            axis.reversed = v(rev) != 0.0;
        }
        flight.hold_reference = if v(ParamId::HoldRef) == 0.0 {
            HoldReference::Level
        } else {
            HoldReference::Trim
        };
        flight.excitation_scale.per_axis = EXC_SCALE_IDS.map(v);
        // 0 stands for no limit (an infinite value cannot be a parameter).
        flight.slew.per_s = SLEW_IDS.map(|id| match v(id) {
            0.0 => f32::INFINITY,
            rate => rate,
        });
        flight.hold_slew.per_s = HOLD_SLEW_IDS.map(|id| match v(id) {
            0.0 => f32::INFINITY,
            rate => rate,
        });
        let test = &mut flight.test;
        test.hold_engage_rad = v(ParamId::HoldEngage) * DEG;
        test.hold_release_rad = v(ParamId::HoldRelease) * DEG;
        let safety = &mut flight.safety;
        safety.attitude_limit_rad = v(ParamId::AbortAtt) * DEG;
        safety.rate_limit_rad_s = [
            v(ParamId::AbortRateRoll) * DEG,
            v(ParamId::AbortRatePitch) * DEG,
            v(ParamId::AbortRateYaw) * DEG,
        ];
        safety.pilot_override = v(ParamId::AbortStick);

        test.primary = *Axis::ALL
            .get(v(ParamId::TestAxis) as usize)
            .ok_or(ParamsError::Value(ParamId::TestAxis))?;
        test.input = *INPUTS
            .get(v(ParamId::TestInput) as usize)
            .ok_or(ParamsError::Value(ParamId::TestInput))?;
        test.mode = *MODES
            .get(v(ParamId::TestMode) as usize)
            .ok_or(ParamsError::Value(ParamId::TestMode))?;
        test.sweep.t_rec_s = v(ParamId::SweepRecord);
        test.sweep.amplitude = v(ParamId::SweepAmp);
        test.sweep.omega_min = v(ParamId::SweepOmegaMin);
        test.sweep.omega_max = v(ParamId::SweepOmegaMax);
        test.sweep.fade_s = v(ParamId::SweepFade);
        test.sweep.start_hold_cycles = v(ParamId::SweepHold) as u8;
        test.pulse.amplitude = v(ParamId::PulseAmp);
        test.pulse.width_s = v(ParamId::PulseWidth);
        test.noise_rms = v(ParamId::NoiseRms);
        test.noise_cutoff_rad_s = v(ParamId::NoiseCutoff);
        test.seed = v(ParamId::TestSeed) as u32;
        test.freeze_in_band = v(ParamId::TestFreeze) != 0.0;
        flight.collective = if v(ParamId::TestColSrc) == 0.0 {
            CollectiveSource::Trim
        } else {
            CollectiveSource::Pilot
        };
        stack.app.airborne.col_min = v(ParamId::AirColMin);
        stack.app.airborne.time_s = v(ParamId::AirTime);
        stack.channel_map.selector = ChannelSource {
            channel: v(ParamId::TestSelCh) as u8,
            reversed: false,
        };
        stack
            .channel_map
            .validate()
            .map_err(ParamsError::ChannelMap)?;
        let list = &mut stack.app.tests;
        list.slices = v(ParamId::TestSelN) as u8;
        for (k, entry) in list.entries.iter_mut().enumerate() {
            let values = core::array::from_fn(|f| v(entry_param(k, f)));
            *entry = entry_from(values).ok_or(ParamsError::Value(entry_param(k, 1)))?;
        }
        let pilot = &mut stack.app.pilot;
        for (axis, [kp, ki]) in [&mut pilot.roll, &mut pilot.pitch, &mut pilot.yaw]
            .into_iter()
            .zip(PILOT_RATE_IDS)
        {
            axis.kp = v(kp);
            axis.ki = v(ki);
        }
        pilot.level_gain = v(ParamId::PilotLevelGain);
        pilot.heading_gain = v(ParamId::PilotHeadingGain);
        let flight = &mut stack.app.flight;
        flight.test.warnings = flight.validate().map_err(ParamsError::Flight)?;
        stack.app.validate().map_err(ParamsError::App)?;
        Ok(params)
    }
}

/// [`InputKind`] by its `TEST_INPUT` number.
const INPUTS: [InputKind; 5] = [
    InputKind::Sweep,
    InputKind::Doublet,
    InputKind::ThreeTwoOneOne,
    InputKind::AdaptiveSweep,
    InputKind::LoopSweep,
];
/// [`ExcitationMode`] by its `TEST_MODE` number.
const MODES: [ExcitationMode; 3] = [
    ExcitationMode::ConditionalAttitudeHold,
    ExcitationMode::Standard,
    ExcitationMode::OffAxisNoise,
];

/// A servo from (direction, centre, min, max, throw).
fn servo_from([direction, centre, min, max, throw]: [f32; 5]) -> ServoConfig {
    ServoConfig {
        centre_us: centre as u16,
        throw_us: throw,
        min_us: min as u16,
        max_us: max as u16,
        reversed: direction < 0.0,
    }
}
