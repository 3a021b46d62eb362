//! proptest strategies for every wire type (shared by the test files of this crate).
#![allow(dead_code)]

use proptest::prelude::*;
use sweephold_protocol::*;

/// Any f32, NaN and infinities included.
pub fn real() -> impl Strategy<Value = f32> {
    proptest::num::f32::ANY
}

pub fn axis() -> impl Strategy<Value = Axis> {
    prop_oneof![
        Just(Axis::Lat),
        Just(Axis::Lon),
        Just(Axis::Ped),
        Just(Axis::Col)
    ]
}

pub fn phase() -> impl Strategy<Value = Phase> {
    prop_oneof![
        Just(Phase::Idle),
        Just(Phase::Armed),
        Just(Phase::TrimCapture),
        Just(Phase::FadeIn),
        Just(Phase::Sweep),
        Just(Phase::FadeOut),
        Just(Phase::Done),
        Just(Phase::Aborted),
    ]
}

pub fn hold() -> impl Strategy<Value = HoldState> {
    prop_oneof![
        Just(HoldState::Released),
        Just(HoldState::Engaged),
        Just(HoldState::Frozen)
    ]
}

pub fn reason() -> impl Strategy<Value = AbortReason> {
    prop_oneof![
        Just(AbortReason::AttitudeLimit),
        Just(AbortReason::RateLimit),
        Just(AbortReason::SensorNotFinite),
        Just(AbortReason::SensorStale),
        Just(AbortReason::PilotOverride),
        Just(AbortReason::SwitchReleased),
        Just(AbortReason::RcLost),
        Just(AbortReason::ImuFault),
        Just(AbortReason::Disarmed),
        Just(AbortReason::Landed),
    ]
}

pub fn controls() -> impl Strategy<Value = Controls> {
    (real(), real(), real(), real()).prop_map(|(lat, lon, ped, col)| Controls {
        lat,
        lon,
        ped,
        col,
    })
}

pub fn measurements() -> impl Strategy<Value = Measurements> {
    proptest::array::uniform12(real()).prop_map(|m| Measurements {
        p: m[0],
        q: m[1],
        r: m[2],
        phi: m[3],
        theta: m[4],
        psi: m[5],
        u: m[6],
        v: m[7],
        w: m[8],
        ax: m[9],
        ay: m[10],
        az: m[11],
    })
}

pub fn test_config() -> impl Strategy<Value = TestConfig> {
    let mode = prop_oneof![
        Just(ExcitationMode::ConditionalAttitudeHold),
        Just(ExcitationMode::Standard),
        Just(ExcitationMode::OffAxisNoise),
    ];
    let input = prop_oneof![
        Just(InputKind::Sweep),
        Just(InputKind::Doublet),
        Just(InputKind::ThreeTwoOneOne),
        Just(InputKind::AdaptiveSweep),
        Just(InputKind::LoopSweep)
    ];
    let sweep = (real(), real(), real(), real(), real(), any::<u8>()).prop_map(
        |(t_rec_s, amplitude, omega_min, omega_max, fade_s, start_hold_cycles)| SweepSettings {
            t_rec_s,
            amplitude,
            omega_min,
            omega_max,
            fade_s,
            start_hold_cycles,
        },
    );
    let pulse =
        (real(), real()).prop_map(|(amplitude, width_s)| PulseSettings { amplitude, width_s });
    (
        (mode, axis(), input, sweep, pulse),
        (
            real(),
            real(),
            any::<u32>(),
            real(),
            real(),
            any::<bool>(),
            any::<u8>(),
        ),
    )
        .prop_map(
            |(
                (mode, primary, input, sweep, pulse),
                (
                    noise_rms,
                    noise_cutoff_rad_s,
                    seed,
                    hold_engage_rad,
                    hold_release_rad,
                    freeze_in_band,
                    warnings,
                ),
            )| TestConfig {
                mode,
                primary,
                input,
                sweep,
                pulse,
                noise_rms,
                noise_cutoff_rad_s,
                seed,
                hold_engage_rad,
                hold_release_rad,
                freeze_in_band,
                warnings,
            },
        )
}

pub fn header() -> impl Strategy<Value = Header> {
    (
        any::<u16>(),
        any::<[u8; 3]>(),
        any::<bool>(),
        any::<u16>(),
        test_config(),
        proptest::option::of((any::<u8>(), any::<u16>())),
    )
        .prop_map(|(minor, fw, bo, rate_hz, test, selection)| Header {
            protocol: ProtocolVersion {
                major: PROTOCOL_VERSION.major,
                minor,
            },
            firmware: FirmwareVersion {
                major: fw[0],
                minor: fw[1],
                patch: fw[2],
            },
            vehicle: if bo {
                VehicleId::Bo105
            } else {
                VehicleId::Trex700l
            },
            rate_hz,
            test,
            selection: selection.map(|(entry, engagement)| TestSelection { entry, engagement }),
        })
}

pub fn sample() -> impl Strategy<Value = Sample> {
    (
        (
            any::<u32>(),
            phase(),
            axis(),
            real(),
            [hold(), hold(), hold()],
        ),
        (
            controls(),
            controls(),
            controls(),
            controls(),
            measurements(),
        ),
    )
        .prop_map(
            |((tick, phase, primary, sweep_omega, hold), (command, sweep, noise, pilot, meas))| {
                Sample {
                    tick,
                    phase,
                    primary,
                    sweep_omega,
                    hold,
                    command,
                    sweep,
                    noise,
                    pilot,
                    meas,
                }
            },
        )
}

pub fn event() -> impl Strategy<Value = Event> {
    prop_oneof![
        (any::<u32>(), phase(), phase()).prop_map(|(tick, from, to)| Event::PhaseChange {
            tick,
            from,
            to
        }),
        (any::<u32>(), axis()).prop_map(|(tick, axis)| Event::HoldEngaged { tick, axis }),
        (any::<u32>(), axis()).prop_map(|(tick, axis)| Event::HoldReleased { tick, axis }),
        (any::<u32>(), controls(), real(), real(), real()).prop_map(
            |(tick, sticks, phi, theta, psi)| Event::TrimCaptured {
                tick,
                sticks,
                phi,
                theta,
                psi
            }
        ),
        (any::<u32>(), reason()).prop_map(|(tick, reason)| Event::Abort { tick, reason }),
        (any::<u32>(), param_store_status())
            .prop_map(|(tick, status)| Event::ParamStore { tick, status }),
    ]
}

pub fn param_store_status() -> impl Strategy<Value = ParamStoreStatus> {
    prop_oneof![
        Just(ParamStoreStatus::Loaded),
        Just(ParamStoreStatus::Empty),
        Just(ParamStoreStatus::Corrupt),
        Just(ParamStoreStatus::OtherVersion),
        Just(ParamStoreStatus::Invalid),
        Just(ParamStoreStatus::FlashError),
    ]
}

/// Any 16 name bytes, valid names or not (a decoder must carry whatever arrives).
pub fn param_name() -> impl Strategy<Value = ParamName> {
    prop_oneof![
        "[A-Z0-9_]{1,16}".prop_map(|name| ParamName::new(&name).unwrap()),
        Just(ParamName::EMPTY),
    ]
}

pub fn param_op() -> impl Strategy<Value = ParamOp> {
    prop_oneof![
        Just(ParamOp::List),
        Just(ParamOp::Get),
        Just(ParamOp::Set),
        Just(ParamOp::Save),
        Just(ParamOp::Reset),
    ]
}

pub fn param_refusal() -> impl Strategy<Value = ParamRefusal> {
    prop_oneof![
        Just(ParamRefusal::Armed),
        Just(ParamRefusal::UnknownName),
        Just(ParamRefusal::NotFinite),
        Just(ParamRefusal::OutOfRange),
        Just(ParamRefusal::NotAnInteger),
        Just(ParamRefusal::NotAChoice),
        Just(ParamRefusal::Inconsistent),
        Just(ParamRefusal::StoreFailed),
        Just(ParamRefusal::NoStore),
    ]
}

pub fn param_request() -> impl Strategy<Value = ParamRequest> {
    prop_oneof![
        Just(ParamRequest::List),
        param_name().prop_map(|name| ParamRequest::Get { name }),
        (param_name(), real()).prop_map(|(name, value)| ParamRequest::Set { name, value }),
        Just(ParamRequest::Save),
        Just(ParamRequest::Reset),
    ]
}

pub fn param_reply() -> impl Strategy<Value = ParamReply> {
    prop_oneof![
        (any::<u16>(), any::<u16>(), param_name(), real()).prop_map(
            |(index, count, name, value)| ParamReply::Value {
                index,
                count,
                name,
                value
            }
        ),
        param_op().prop_map(|op| ParamReply::Done { op }),
        (param_op(), param_name(), param_refusal())
            .prop_map(|(op, name, reason)| ParamReply::Refused { op, name, reason }),
    ]
}

pub fn sensor_in() -> impl Strategy<Value = SensorIn> {
    (any::<u32>(), measurements(), controls(), any::<bool>()).prop_map(
        |(seq, meas, sticks, test_switch)| SensorIn {
            seq,
            meas,
            pilot: PilotInput {
                sticks,
                test_switch,
            },
        },
    )
}

pub fn actuator_out() -> impl Strategy<Value = ActuatorOut> {
    (any::<u32>(), any::<u32>(), controls(), any::<[u16; 4]>()).prop_map(
        |(tick, seq, command, servo_us)| ActuatorOut {
            tick,
            seq,
            command,
            servo_us,
        },
    )
}

pub fn frame() -> impl Strategy<Value = Frame> {
    prop_oneof![
        header().prop_map(Frame::Header),
        sample().prop_map(Frame::Sample),
        event().prop_map(Frame::Event),
        sensor_in().prop_map(Frame::SensorIn),
        actuator_out().prop_map(Frame::ActuatorOut),
        link_config().prop_map(Frame::Configure),
        configure_result().prop_map(Frame::ConfigureResult),
        param_request().prop_map(Frame::ParamRequest),
        param_reply().prop_map(Frame::ParamReply),
    ]
}

pub fn link_config() -> impl Strategy<Value = LinkConfig> {
    (any::<bool>(), any::<u16>(), test_config()).prop_map(|(bo, rate_hz, test)| LinkConfig {
        vehicle: if bo {
            VehicleId::Bo105
        } else {
            VehicleId::Trex700l
        },
        rate_hz,
        test,
    })
}

pub fn configure_result() -> impl Strategy<Value = ConfigureResult> {
    (any::<bool>(), any::<u8>())
        .prop_map(|(accepted, refusal)| ConfigureResult { accepted, refusal })
}
