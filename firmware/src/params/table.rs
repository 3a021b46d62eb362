//! The parameter definitions: name, unit, range, kind, one line of meaning. The order is
//! the order of the stored record and of a list over the link; a parameter is only ever
//! appended (a change of order or meaning bumps [`TABLE_VERSION`]).

/// What values a parameter takes besides its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    /// Any finite value in the range.
    Real,
    /// A whole number in the range.
    Integer,
    /// One of these values (each within the range).
    OneOf(&'static [f32]),
}

/// One parameter's definition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamDef {
    /// Its name, at most [`MAX_NAME_LEN`] characters, upper case.
    pub name: &'static str,
    /// Its unit ("" for a number without one).
    pub unit: &'static str,
    /// Smallest accepted value.
    pub min: f32,
    /// Largest accepted value.
    pub max: f32,
    /// Real, integer or one of a list.
    pub kind: ParamKind,
    /// What it sets (empty in the flight-controller image: the `doc_text` macro).
    pub doc: &'static str,
}

/// Longest parameter name (ArduPilot's limit, which Rotorflight's names also keep).
pub const MAX_NAME_LEN: usize = 16;

/// The version of the table's layout, stored with every record: a record of another
/// version is not loaded (its values could mean other things). Version 2 appended
/// `FRAME`, version 3 the excitation scales, slew limits and the holds' reference,
/// integrator limits, time constants and directions, version 4 the test's collective
/// source and the airborne rule, version 5 the test list (`TEST_SEL_CH`, `TEST_SEL_N`,
/// `TEST1_*` … `TEST12_*`), version 6 the holds' slew limits (`HSLEW_*`): a record of
/// an older version holds no base preset or none of those and boots the defaults.
/// Version 7 appended the pilot mode's rate-loop gains and outer-loop gains (`PM_*`).
pub const TABLE_VERSION: u16 = 7;

/// Swash type codes: H1, 120°, 135°, 140°.
const SWASH_TYPES: &[f32] = &[0.0, 120.0, 135.0, 140.0];
/// Base presets, by [`frame_vehicle`] code: TREX 700L, Bo-105.
const FRAMES: &[f32] = &[0.0, 1.0];
/// Servo direction: normal or reversed.
const DIRECTIONS: &[f32] = &[-1.0, 1.0];
/// ArduPilot's numbers of the 24 axis-aligned rotations and the two aliases.
const ROTATIONS: &[f32] = &[
    0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0, 22.0, 24.0, 25.0, 26.0, 27.0,
    28.0, 29.0, 30.0, 31.0, 32.0, 33.0, 34.0, 35.0, 36.0, 37.0,
];
/// Pulse widths a servo or receiver setting may take \[µs\]: 760 µs-centre tail servos
/// included.
const PULSE_MIN: f32 = 500.0;
const PULSE_MAX: f32 = 2500.0;
/// Largest pilot-mode rate-loop Kp \[stick per rad/s\]: full stick at 1 rad/s of rate
/// error is already several times the presets' (0.024–0.8) and `tune`'s designs; above
/// it the loop's crossover lies beyond every servo's and the 200 Hz tick's reach.
const PM_KP_MAX: f32 = 2.0;
/// Largest pilot-mode rate-loop Ki \[stick per rad\]: ten times the presets' (0.3–0.6).
const PM_KI_MAX: f32 = 10.0;
/// Pilot-mode outer-loop gains (K_lvl, K_ψ) \[1/s\]: at least 0.1 /s (a Level stick or
/// heading hold that returns slower than in 10 s holds nothing), at most 20 /s, the
/// rate loops' highest crossover `tune` designs for (an outer loop sits below its inner).
const PM_OUTER_MIN: f32 = 0.1;
const PM_OUTER_MAX: f32 = 20.0;

/// A parameter's doc line: the text on the host; empty in the flight-controller image
/// (`target_os = "none"`), which never shows it and would spend about 9 KiB of its
/// flash budget on the lines. The host reads the same table, so `sweephold fc` and the
/// README check keep the text.
#[cfg(not(target_os = "none"))]
macro_rules! doc_text {
    ($doc:literal) => {
        $doc
    };
}

/// See the host variant.
#[cfg(target_os = "none")]
macro_rules! doc_text {
    ($doc:literal) => {
        ""
    };
}

macro_rules! params {
    ($( $id:ident = $name:literal, $unit:literal, $min:expr, $max:expr, $kind:expr, $doc:literal; )*) => {
        /// Every parameter, in table order.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[allow(non_camel_case_types)]
        #[repr(u8)]
        pub enum ParamId {
            $( #[doc = $doc] $id, )*
        }

        /// Number of parameters.
        pub const COUNT: usize = [$( stringify!($id) ),*].len();

        /// The definitions, in table order.
        pub const DEFS: [ParamDef; COUNT] = [
            $( ParamDef { name: $name, unit: $unit, min: $min, max: $max, kind: $kind, doc: doc_text!($doc) }, )*
        ];

        impl ParamId {
            /// Every parameter, in table order.
            pub const ALL: [ParamId; COUNT] = [$( ParamId::$id ),*];
        }
    };
}

use sweephold_protocol::VehicleId;
use ParamKind::{Integer, OneOf, Real};

params! {
    SwashType = "SWASH_TYPE", "", 0.0, 140.0, OneOf(SWASH_TYPES), "Swash type: 0 H1 (mechanical), 120, 135 or 140 (CCPM plate angle).";
    SwashPhase = "SWASH_PHASE", "deg", -180.0, 180.0, Real, "Phase angle subtracted from every servo azimuth (clockwise positive).";
    SwashLead = "SWASH_LEAD", "", 1.0, 3.0, Integer, "Swash output on the fore-aft axis (front); the others follow clockwise.";
    Servo1Dir = "SERVO1_DIR", "", -1.0, 1.0, OneOf(DIRECTIONS), "Swash output 1 direction: 1 normal, -1 reversed.";
    Servo1Mid = "SERVO1_MID", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 1 pulse at zero height (centre).";
    Servo1Min = "SERVO1_MIN", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 1 lowest pulse.";
    Servo1Max = "SERVO1_MAX", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 1 highest pulse.";
    Servo1Throw = "SERVO1_THROW", "us", 0.0, 1000.0, Real, "Swash output 1 pulse per unit height.";
    Servo2Dir = "SERVO2_DIR", "", -1.0, 1.0, OneOf(DIRECTIONS), "Swash output 2 direction: 1 normal, -1 reversed.";
    Servo2Mid = "SERVO2_MID", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 2 pulse at zero height (centre).";
    Servo2Min = "SERVO2_MIN", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 2 lowest pulse.";
    Servo2Max = "SERVO2_MAX", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 2 highest pulse.";
    Servo2Throw = "SERVO2_THROW", "us", 0.0, 1000.0, Real, "Swash output 2 pulse per unit height.";
    Servo3Dir = "SERVO3_DIR", "", -1.0, 1.0, OneOf(DIRECTIONS), "Swash output 3 direction: 1 normal, -1 reversed.";
    Servo3Mid = "SERVO3_MID", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 3 pulse at zero height (centre).";
    Servo3Min = "SERVO3_MIN", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 3 lowest pulse.";
    Servo3Max = "SERVO3_MAX", "us", PULSE_MIN, PULSE_MAX, Integer, "Swash output 3 highest pulse.";
    Servo3Throw = "SERVO3_THROW", "us", 0.0, 1000.0, Real, "Swash output 3 pulse per unit height.";
    TailDir = "TAIL_DIR", "", -1.0, 1.0, OneOf(DIRECTIONS), "Tail servo direction: 1 normal, -1 reversed.";
    TailMid = "TAIL_MID", "us", PULSE_MIN, PULSE_MAX, Integer, "Tail servo centre pulse (760 for narrow-band servos).";
    TailMin = "TAIL_MIN", "us", PULSE_MIN, PULSE_MAX, Integer, "Tail servo lowest pulse.";
    TailMax = "TAIL_MAX", "us", PULSE_MIN, PULSE_MAX, Integer, "Tail servo highest pulse.";
    TailThrow = "TAIL_THROW", "us", 0.0, 1000.0, Real, "Tail servo pulse per unit pedal height.";
    ServoRate = "SERVO_RATE", "Hz", 50.0, 333.0, Integer, "Swash servo frame rate (read by the board's output timers).";
    TailRate = "TAIL_RATE", "Hz", 50.0, 333.0, Integer, "Tail servo frame rate (read by the board's output timers).";
    CollMin = "COLL_MIN", "", -1.0, 1.0, Real, "Swash height at full negative collective command.";
    CollMax = "COLL_MAX", "", -1.0, 1.0, Real, "Swash height at full positive collective command.";
    CycScale = "CYC_SCALE", "", 0.0, 1.0, Real, "Swash height per unit cyclic command.";
    PedScale = "PED_SCALE", "", 0.0, 1.0, Real, "Tail height per unit pedal command.";
    CycRing = "CYC_RING", "", 0.1, 1.5, Real, "Cyclic ring: longest (lat, lon) command vector; 1.5 never limits.";
    RcLat = "RC_LAT", "", 1.0, 16.0, Integer, "Receiver channel of the lateral cyclic (aileron).";
    RcLon = "RC_LON", "", 1.0, 16.0, Integer, "Receiver channel of the longitudinal cyclic (elevator).";
    RcThr = "RC_THR", "", 1.0, 16.0, Integer, "Receiver channel of the throttle.";
    RcPed = "RC_PED", "", 1.0, 16.0, Integer, "Receiver channel of the pedal (rudder).";
    RcArm = "RC_ARM", "", 1.0, 16.0, Integer, "Receiver channel of the arm switch.";
    RcCol = "RC_COL", "", 1.0, 16.0, Integer, "Receiver channel of the collective.";
    RcTest = "RC_TEST", "", 1.0, 16.0, Integer, "Receiver channel of the test switch.";
    RcMode = "RC_MODE", "", 1.0, 16.0, Integer, "Receiver channel of the mode switch.";
    RcRev = "RC_REV", "", 0.0, 255.0, Integer, "Reversed functions, bit i of lat, lon, thr, ped, arm, col, test, mode.";
    RcMin = "RC_MIN", "", 0.0, 2047.0, Integer, "Raw SBUS value at full negative travel.";
    RcMid = "RC_MID", "", 0.0, 2047.0, Integer, "Raw SBUS value at centre.";
    RcMax = "RC_MAX", "", 0.0, 2047.0, Integer, "Raw SBUS value at full positive travel.";
    RcTimeout = "RC_TIMEOUT", "ms", 20.0, 1000.0, Integer, "Receiver link lost after this long without an intact frame.";
    ImuRot = "IMU_ROT", "", 0.0, 37.0, OneOf(ROTATIONS), "The board's mounting in the aircraft, ArduPilot's ROTATION_* number (axis-aligned only).";
    HeadRpm = "HEAD_RPM", "rpm", 600.0, 4000.0, Real, "Main rotor speed: places the 1/rev and 2/rev notches.";
    TailRpm = "TAIL_RPM", "rpm", 1200.0, 20000.0, Real, "Tail rotor speed: places the tail notch.";
    HoldLatP = "HOLD_LAT_P", "1/rad", 0.0, 20.0, Real, "Attitude hold, roll: stick per rad of attitude error.";
    HoldLatI = "HOLD_LAT_I", "1/rad/s", 0.0, 20.0, Real, "Attitude hold, roll: stick per rad·s of integrated error.";
    HoldLatD = "HOLD_LAT_D", "s/rad", 0.0, 5.0, Real, "Attitude hold, roll: stick per rad/s of roll rate.";
    HoldLatLim = "HOLD_LAT_LIM", "", 0.01, 1.0, Real, "Attitude hold, roll: output limit, fraction of stick.";
    HoldLonP = "HOLD_LON_P", "1/rad", 0.0, 20.0, Real, "Attitude hold, pitch: stick per rad of attitude error.";
    HoldLonI = "HOLD_LON_I", "1/rad/s", 0.0, 20.0, Real, "Attitude hold, pitch: stick per rad·s of integrated error.";
    HoldLonD = "HOLD_LON_D", "s/rad", 0.0, 5.0, Real, "Attitude hold, pitch: stick per rad/s of pitch rate.";
    HoldLonLim = "HOLD_LON_LIM", "", 0.01, 1.0, Real, "Attitude hold, pitch: output limit, fraction of stick.";
    HoldPedP = "HOLD_PED_P", "1/rad", 0.0, 20.0, Real, "Heading hold: stick per rad of heading error.";
    HoldPedI = "HOLD_PED_I", "1/rad/s", 0.0, 20.0, Real, "Heading hold: stick per rad·s of integrated error.";
    HoldPedD = "HOLD_PED_D", "s/rad", 0.0, 5.0, Real, "Heading hold: stick per rad/s of yaw rate.";
    HoldPedLim = "HOLD_PED_LIM", "", 0.01, 1.0, Real, "Heading hold: output limit, fraction of stick.";
    HoldEngage = "HOLD_ENGAGE", "deg", 0.5, 90.0, Real, "Conditional hold engages beyond this attitude error.";
    HoldRelease = "HOLD_RELEASE", "deg", 0.5, 90.0, Real, "Conditional hold releases within this attitude error.";
    AbortAtt = "ABORT_ATT", "deg", 1.0, 90.0, Real, "Test abort: roll or pitch beyond this.";
    AbortRateRoll = "ABORT_RATE_R", "deg/s", 1.0, 1000.0, Real, "Test abort: roll rate beyond this.";
    AbortRatePitch = "ABORT_RATE_P", "deg/s", 1.0, 1000.0, Real, "Test abort: pitch rate beyond this.";
    AbortRateYaw = "ABORT_RATE_Y", "deg/s", 1.0, 1000.0, Real, "Test abort: yaw rate beyond this.";
    AbortStick = "ABORT_STICK", "", 0.01, 1.0, Real, "Test abort: pilot stick moved this far from its trim.";
    TestAxis = "TEST_AXIS", "", 0.0, 3.0, Integer, "Axis under test: 0 lat, 1 lon, 2 ped, 3 col.";
    TestInput = "TEST_INPUT", "", 0.0, 4.0, Integer, "Input: 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    TestMode = "TEST_MODE", "", 0.0, 2.0, Integer, "Mode: 0 conditional attitude hold, 1 standard, 2 off-axis noise.";
    SweepRecord = "SWP_TREC", "s", 1.0, 3600.0, Real, "Sweep record length.";
    SweepAmp = "SWP_AMP", "", 0.001, 0.5, Real, "Sweep amplitude, fraction of stick travel.";
    SweepOmegaMin = "SWP_WMIN", "rad/s", 0.01, 100.0, Real, "Sweep start frequency.";
    SweepOmegaMax = "SWP_WMAX", "rad/s", 0.01, 400.0, Real, "Sweep end frequency.";
    SweepFade = "SWP_FADE", "s", 0.0, 60.0, Real, "Raised-cosine fade-in and fade-out length.";
    SweepHold = "SWP_HOLD", "", 0.0, 255.0, Integer, "Cycles at the start frequency before the sweep.";
    PulseAmp = "PULSE_AMP", "", 0.001, 0.5, Real, "Doublet / 3-2-1-1 amplitude, fraction of stick travel.";
    PulseWidth = "PULSE_WIDTH", "s", 0.01, 60.0, Real, "Doublet / 3-2-1-1 unit pulse width.";
    NoiseRms = "NOISE_RMS", "", 0.0, 0.5, Real, "Off-axis noise RMS, fraction of stick travel.";
    NoiseCutoff = "NOISE_CUTOFF", "rad/s", 0.01, 3200.0, Real, "Off-axis noise low-pass cut-off.";
    TestSeed = "TEST_SEED", "", 0.0, 16_777_215.0, Integer, "Noise seed (up to 2^24 - 1, exact in the f32 value).";
    TestFreeze = "TEST_FREEZE", "", 0.0, 1.0, Integer, "1: freeze the excitation while the hold is engaged in band.";
    Frame = "FRAME", "", 0.0, 1.0, OneOf(FRAMES), "Base preset for everything the table does not hold: 0 TREX 700L, 1 Bo-105 (simulator).";
    ExcScaleLat = "EXC_SCALE_LAT", "", 0.001, 1.0, Real, "Excitation scale of lat: fraction of the test's amplitude and noise.";
    ExcScaleLon = "EXC_SCALE_LON", "", 0.001, 1.0, Real, "Excitation scale of lon: fraction of the test's amplitude and noise.";
    ExcScalePed = "EXC_SCALE_PED", "", 0.001, 1.0, Real, "Excitation scale of ped: fraction of the test's amplitude and noise.";
    ExcScaleCol = "EXC_SCALE_COL", "", 0.001, 1.0, Real, "Excitation scale of col: fraction of the test's amplitude and noise.";
    SlewLat = "SLEW_LAT", "1/s", 0.0, 1000.0, Real, "Excitation phases' lat command slew limit (stick per s); 0: none.";
    SlewLon = "SLEW_LON", "1/s", 0.0, 1000.0, Real, "Excitation phases' lon command slew limit (stick per s); 0: none.";
    SlewPed = "SLEW_PED", "1/s", 0.0, 1000.0, Real, "Excitation phases' ped command slew limit (stick per s); 0: none.";
    SlewCol = "SLEW_COL", "1/s", 0.0, 1000.0, Real, "Excitation phases' col command slew limit (stick per s); 0: none.";
    HoldRef = "HOLD_REF", "", 0.0, 1.0, Integer, "Hold thresholds on roll and pitch from: 0 level, 1 the captured trim.";
    HoldLatIlim = "HOLD_LAT_ILIM", "", 0.0, 1.0, Real, "Attitude hold, roll: integrator limit, fraction of stick.";
    HoldLatBump = "HOLD_LAT_TBUMP", "s", 0.0, 10.0, Real, "Attitude hold, roll: bumpless hand-over time constant.";
    HoldLatFade = "HOLD_LAT_TFADE", "s", 0.0, 10.0, Real, "Attitude hold, roll: output fade time constant after a release.";
    HoldLatRev = "HOLD_LAT_REV", "", 0.0, 1.0, Integer, "Attitude hold, roll: 1 if a positive command gives a negative moment.";
    HoldLonIlim = "HOLD_LON_ILIM", "", 0.0, 1.0, Real, "Attitude hold, pitch: integrator limit, fraction of stick.";
    HoldLonBump = "HOLD_LON_TBUMP", "s", 0.0, 10.0, Real, "Attitude hold, pitch: bumpless hand-over time constant.";
    HoldLonFade = "HOLD_LON_TFADE", "s", 0.0, 10.0, Real, "Attitude hold, pitch: output fade time constant after a release.";
    HoldLonRev = "HOLD_LON_REV", "", 0.0, 1.0, Integer, "Attitude hold, pitch: 1 if a positive command gives a negative moment.";
    HoldPedIlim = "HOLD_PED_ILIM", "", 0.0, 1.0, Real, "Heading hold: integrator limit, fraction of stick.";
    HoldPedBump = "HOLD_PED_TBUMP", "s", 0.0, 10.0, Real, "Heading hold: bumpless hand-over time constant.";
    HoldPedFade = "HOLD_PED_TFADE", "s", 0.0, 10.0, Real, "Heading hold: output fade time constant after a release.";
    HoldPedRev = "HOLD_PED_REV", "", 0.0, 1.0, Integer, "Heading hold: 1 if a positive command gives a negative moment.";
    TestColSrc = "TEST_COL_SRC", "", 0.0, 1.0, Integer, "Collective during a test: 0 the captured trim, 1 the pilot's stick (plus the sweep on col tests).";
    AirColMin = "AIR_COL_MIN", "", -1.0, 1.0, Real, "Airborne: collective stick at or above this for AIR_TIME; landed: below it for AIR_TIME.";
    AirTime = "AIR_TIME", "s", 0.0, 10.0, Real, "Time the collective must stay above (airborne) or below (landed) AIR_COL_MIN.";
    TestSelCh = "TEST_SEL_CH", "", 0.0, 16.0, Integer, "Receiver channel of the test selector (knob or switch) choosing a TESTn entry; 0: none, the test switch flies the TEST_* test.";
    TestSelN = "TEST_SEL_N", "", 1.0, 12.0, Integer, "Equal slices of the selector channel's travel, selecting entries 1 to TEST_SEL_N (3 for a 3-position switch).";
    Test1Axis = "TEST1_AXIS", "", 0.0, 4.0, Integer, "Test list entry 1: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test1Input = "TEST1_INPUT", "", 0.0, 4.0, Integer, "Test list entry 1: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test1Wmin = "TEST1_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 1: sweep start frequency.";
    Test1Wmax = "TEST1_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 1: sweep end frequency.";
    Test1Width = "TEST1_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 1: doublet / 3-2-1-1 unit pulse width.";
    Test1Trec = "TEST1_TREC", "s", 0.0, 3600.0, Real, "Test list entry 1: record length; 0: empty entry.";
    Test1Amp = "TEST1_AMP", "", 0.001, 0.5, Real, "Test list entry 1: sweep or pulse amplitude, fraction of stick travel.";
    Test2Axis = "TEST2_AXIS", "", 0.0, 4.0, Integer, "Test list entry 2: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test2Input = "TEST2_INPUT", "", 0.0, 4.0, Integer, "Test list entry 2: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test2Wmin = "TEST2_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 2: sweep start frequency.";
    Test2Wmax = "TEST2_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 2: sweep end frequency.";
    Test2Width = "TEST2_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 2: doublet / 3-2-1-1 unit pulse width.";
    Test2Trec = "TEST2_TREC", "s", 0.0, 3600.0, Real, "Test list entry 2: record length; 0: empty entry.";
    Test2Amp = "TEST2_AMP", "", 0.001, 0.5, Real, "Test list entry 2: sweep or pulse amplitude, fraction of stick travel.";
    Test3Axis = "TEST3_AXIS", "", 0.0, 4.0, Integer, "Test list entry 3: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test3Input = "TEST3_INPUT", "", 0.0, 4.0, Integer, "Test list entry 3: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test3Wmin = "TEST3_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 3: sweep start frequency.";
    Test3Wmax = "TEST3_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 3: sweep end frequency.";
    Test3Width = "TEST3_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 3: doublet / 3-2-1-1 unit pulse width.";
    Test3Trec = "TEST3_TREC", "s", 0.0, 3600.0, Real, "Test list entry 3: record length; 0: empty entry.";
    Test3Amp = "TEST3_AMP", "", 0.001, 0.5, Real, "Test list entry 3: sweep or pulse amplitude, fraction of stick travel.";
    Test4Axis = "TEST4_AXIS", "", 0.0, 4.0, Integer, "Test list entry 4: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test4Input = "TEST4_INPUT", "", 0.0, 4.0, Integer, "Test list entry 4: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test4Wmin = "TEST4_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 4: sweep start frequency.";
    Test4Wmax = "TEST4_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 4: sweep end frequency.";
    Test4Width = "TEST4_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 4: doublet / 3-2-1-1 unit pulse width.";
    Test4Trec = "TEST4_TREC", "s", 0.0, 3600.0, Real, "Test list entry 4: record length; 0: empty entry.";
    Test4Amp = "TEST4_AMP", "", 0.001, 0.5, Real, "Test list entry 4: sweep or pulse amplitude, fraction of stick travel.";
    Test5Axis = "TEST5_AXIS", "", 0.0, 4.0, Integer, "Test list entry 5: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test5Input = "TEST5_INPUT", "", 0.0, 4.0, Integer, "Test list entry 5: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test5Wmin = "TEST5_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 5: sweep start frequency.";
    Test5Wmax = "TEST5_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 5: sweep end frequency.";
    Test5Width = "TEST5_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 5: doublet / 3-2-1-1 unit pulse width.";
    Test5Trec = "TEST5_TREC", "s", 0.0, 3600.0, Real, "Test list entry 5: record length; 0: empty entry.";
    Test5Amp = "TEST5_AMP", "", 0.001, 0.5, Real, "Test list entry 5: sweep or pulse amplitude, fraction of stick travel.";
    Test6Axis = "TEST6_AXIS", "", 0.0, 4.0, Integer, "Test list entry 6: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test6Input = "TEST6_INPUT", "", 0.0, 4.0, Integer, "Test list entry 6: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test6Wmin = "TEST6_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 6: sweep start frequency.";
    Test6Wmax = "TEST6_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 6: sweep end frequency.";
    Test6Width = "TEST6_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 6: doublet / 3-2-1-1 unit pulse width.";
    Test6Trec = "TEST6_TREC", "s", 0.0, 3600.0, Real, "Test list entry 6: record length; 0: empty entry.";
    Test6Amp = "TEST6_AMP", "", 0.001, 0.5, Real, "Test list entry 6: sweep or pulse amplitude, fraction of stick travel.";
    Test7Axis = "TEST7_AXIS", "", 0.0, 4.0, Integer, "Test list entry 7: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test7Input = "TEST7_INPUT", "", 0.0, 4.0, Integer, "Test list entry 7: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test7Wmin = "TEST7_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 7: sweep start frequency.";
    Test7Wmax = "TEST7_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 7: sweep end frequency.";
    Test7Width = "TEST7_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 7: doublet / 3-2-1-1 unit pulse width.";
    Test7Trec = "TEST7_TREC", "s", 0.0, 3600.0, Real, "Test list entry 7: record length; 0: empty entry.";
    Test7Amp = "TEST7_AMP", "", 0.001, 0.5, Real, "Test list entry 7: sweep or pulse amplitude, fraction of stick travel.";
    Test8Axis = "TEST8_AXIS", "", 0.0, 4.0, Integer, "Test list entry 8: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test8Input = "TEST8_INPUT", "", 0.0, 4.0, Integer, "Test list entry 8: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test8Wmin = "TEST8_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 8: sweep start frequency.";
    Test8Wmax = "TEST8_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 8: sweep end frequency.";
    Test8Width = "TEST8_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 8: doublet / 3-2-1-1 unit pulse width.";
    Test8Trec = "TEST8_TREC", "s", 0.0, 3600.0, Real, "Test list entry 8: record length; 0: empty entry.";
    Test8Amp = "TEST8_AMP", "", 0.001, 0.5, Real, "Test list entry 8: sweep or pulse amplitude, fraction of stick travel.";
    Test9Axis = "TEST9_AXIS", "", 0.0, 4.0, Integer, "Test list entry 9: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test9Input = "TEST9_INPUT", "", 0.0, 4.0, Integer, "Test list entry 9: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test9Wmin = "TEST9_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 9: sweep start frequency.";
    Test9Wmax = "TEST9_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 9: sweep end frequency.";
    Test9Width = "TEST9_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 9: doublet / 3-2-1-1 unit pulse width.";
    Test9Trec = "TEST9_TREC", "s", 0.0, 3600.0, Real, "Test list entry 9: record length; 0: empty entry.";
    Test9Amp = "TEST9_AMP", "", 0.001, 0.5, Real, "Test list entry 9: sweep or pulse amplitude, fraction of stick travel.";
    Test10Axis = "TEST10_AXIS", "", 0.0, 4.0, Integer, "Test list entry 10: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test10Input = "TEST10_INPUT", "", 0.0, 4.0, Integer, "Test list entry 10: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test10Wmin = "TEST10_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 10: sweep start frequency.";
    Test10Wmax = "TEST10_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 10: sweep end frequency.";
    Test10Width = "TEST10_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 10: doublet / 3-2-1-1 unit pulse width.";
    Test10Trec = "TEST10_TREC", "s", 0.0, 3600.0, Real, "Test list entry 10: record length; 0: empty entry.";
    Test10Amp = "TEST10_AMP", "", 0.001, 0.5, Real, "Test list entry 10: sweep or pulse amplitude, fraction of stick travel.";
    Test11Axis = "TEST11_AXIS", "", 0.0, 4.0, Integer, "Test list entry 11: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test11Input = "TEST11_INPUT", "", 0.0, 4.0, Integer, "Test list entry 11: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test11Wmin = "TEST11_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 11: sweep start frequency.";
    Test11Wmax = "TEST11_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 11: sweep end frequency.";
    Test11Width = "TEST11_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 11: doublet / 3-2-1-1 unit pulse width.";
    Test11Trec = "TEST11_TREC", "s", 0.0, 3600.0, Real, "Test list entry 11: record length; 0: empty entry.";
    Test11Amp = "TEST11_AMP", "", 0.001, 0.5, Real, "Test list entry 11: sweep or pulse amplitude, fraction of stick travel.";
    Test12Axis = "TEST12_AXIS", "", 0.0, 4.0, Integer, "Test list entry 12: axis, 0 none (empty entry), 1 lat, 2 lon, 3 ped, 4 col.";
    Test12Input = "TEST12_INPUT", "", 0.0, 4.0, Integer, "Test list entry 12: input, 0 sweep, 1 doublet, 2 3-2-1-1, 3 adaptive sweep, 4 loop sweep.";
    Test12Wmin = "TEST12_WMIN", "rad/s", 0.01, 100.0, Real, "Test list entry 12: sweep start frequency.";
    Test12Wmax = "TEST12_WMAX", "rad/s", 0.01, 400.0, Real, "Test list entry 12: sweep end frequency.";
    Test12Width = "TEST12_WIDTH", "s", 0.01, 60.0, Real, "Test list entry 12: doublet / 3-2-1-1 unit pulse width.";
    Test12Trec = "TEST12_TREC", "s", 0.0, 3600.0, Real, "Test list entry 12: record length; 0: empty entry.";
    Test12Amp = "TEST12_AMP", "", 0.001, 0.5, Real, "Test list entry 12: sweep or pulse amplitude, fraction of stick travel.";
    HoldSlewLat = "HSLEW_LAT", "1/s", 0.0, 1000.0, Real, "Excitation phases: slew limit of the roll hold's share of lat (stick per s); 0: none.";
    HoldSlewLon = "HSLEW_LON", "1/s", 0.0, 1000.0, Real, "Excitation phases: slew limit of the pitch hold's share of lon (stick per s); 0: none.";
    HoldSlewPed = "HSLEW_PED", "1/s", 0.0, 1000.0, Real, "Excitation phases: slew limit of the heading hold's share of ped (stick per s); 0: none.";
    PilotRollKp = "PM_ROLL_KP", "s/rad", 0.0, PM_KP_MAX, Real, "Pilot mode, roll-rate loop: stick per rad/s of rate error (Kp).";
    PilotRollKi = "PM_ROLL_KI", "1/rad", 0.0, PM_KI_MAX, Real, "Pilot mode, roll-rate loop: stick per rad of integrated rate error (Ki).";
    PilotPitchKp = "PM_PITCH_KP", "s/rad", 0.0, PM_KP_MAX, Real, "Pilot mode, pitch-rate loop: stick per rad/s of rate error (Kp).";
    PilotPitchKi = "PM_PITCH_KI", "1/rad", 0.0, PM_KI_MAX, Real, "Pilot mode, pitch-rate loop: stick per rad of integrated rate error (Ki).";
    PilotYawKp = "PM_YAW_KP", "s/rad", 0.0, PM_KP_MAX, Real, "Pilot mode, yaw-rate loop: pedal per rad/s of rate error (Kp).";
    PilotYawKi = "PM_YAW_KI", "1/rad", 0.0, PM_KI_MAX, Real, "Pilot mode, yaw-rate loop: pedal per rad of integrated rate error (Ki).";
    PilotLevelGain = "PM_LEVEL_K", "1/s", PM_OUTER_MIN, PM_OUTER_MAX, Real, "Pilot mode, Level stick: desired rate per rad of attitude error (K_lvl).";
    PilotHeadingGain = "PM_HEADING_K", "1/s", PM_OUTER_MIN, PM_OUTER_MAX, Real, "Pilot mode, heading hold: desired yaw rate per rad of heading error (K_ψ).";
}

/// The vehicle whose preset a `FRAME` value names (ArduPilot's `FRAME_CLASS` idea: one
/// image, the airframe chosen by a parameter).
pub const fn frame_vehicle(code: f32) -> Option<VehicleId> {
    if code == 0.0 {
        Some(VehicleId::Trex700l)
    } else if code == 1.0 {
        Some(VehicleId::Bo105)
    } else {
        None
    }
}

/// The `FRAME` value of `vehicle`.
pub const fn frame_code(vehicle: VehicleId) -> f32 {
    match vehicle {
        VehicleId::Trex700l => 0.0,
        VehicleId::Bo105 => 1.0,
    }
}
