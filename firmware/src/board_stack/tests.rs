//! The stack on the emulated IMU and an SBUS byte stream: boot and calibration, arming
//! through the receiver, the estimate under rotor vibration, IMU faults, receiver loss,
//! and arbitrary receiver bytes.

use embedded_hal_mock::eh1::delay::NoopDelay;
use proptest::prelude::*;
use sweephold_protocol::{Controls, Decoder, Frame};

use super::*;
use crate::app::{CheckFailure, ImuProblem, Mode, Refusal};
use crate::imu::emulator::{Fault, Icm42688Emulator, Imperfections};
use crate::imu::GRAVITY_M_S2;
use crate::receiver::{ModeSwitch, RcInput};

const DEG: f32 = core::f32::consts::PI / 180.0;

/// The stack on an emulated chip, a 1 kHz IMU clock, a 200 Hz control tick and a
/// transmitter sending a frame every 7 ms.
struct Bench {
    stack: BoardStack<Icm42688Emulator, NoopDelay>,
    now_us: u32,
    next_frame_us: u32,
    /// What the transmitter sends; `None`: nothing (link lost).
    transmitter: Option<RcInput>,
    bytes: Vec<u8>,
    telemetry: Vec<u8>,
    ticks: u32,
    last: Option<TickOutput>,
}

fn pilot(arm: bool, throttle: f32) -> RcInput {
    RcInput {
        sticks: Controls::default(),
        throttle,
        arm,
        test_switch: false,
        mode: ModeSwitch::Middle,
        selector: None,
    }
}

impl Bench {
    fn new(imperfections: Imperfections) -> Bench {
        let emulator = Icm42688Emulator::new(imperfections);
        let mut stack = BoardStack::new(
            emulator,
            NoopDelay,
            StackConfig::trex700l(sweephold_protocol::Axis::Lat),
        )
        .expect("config");
        stack.boot().expect("boot");
        Bench {
            stack,
            now_us: 0,
            next_frame_us: 0,
            transmitter: Some(pilot(false, 0.0)),
            bytes: Vec::new(),
            telemetry: Vec::new(),
            ticks: 0,
            last: None,
        }
    }

    fn emulator(&mut self) -> &mut Icm42688Emulator {
        self.stack.imu_spi_mut()
    }

    /// One millisecond: one IMU sample, a frame when due, a control tick every 5 ms.
    fn step_ms(&mut self) {
        self.emulator().advance_ns(1_000_000);
        self.now_us += 1000;
        self.stack.imu_sample(self.now_us);
        if self.now_us >= self.next_frame_us {
            self.next_frame_us += 7000;
            if let Some(input) = self.transmitter {
                let frame = ChannelMap::flybarless_default().encode(&input);
                self.bytes.extend_from_slice(&frame.encode());
            }
        }
        if self.now_us.is_multiple_of(5000) {
            let bytes = std::mem::take(&mut self.bytes);
            let out = self
                .stack
                .control_tick(self.now_us, &bytes, &mut self.telemetry);
            assert!(out.command.to_array().iter().all(|c| c.is_finite()));
            self.ticks += 1;
            self.last = Some(out);
        }
    }

    fn run_ms(&mut self, ms: u32) -> TickOutput {
        for _ in 0..ms {
            self.step_ms();
        }
        self.last.expect("a tick ran")
    }

    /// Boot still and level, arm, spool up to 0.8: Pilot mode, soft start done.
    fn armed(imperfections: Imperfections) -> Bench {
        let mut bench = Bench::new(imperfections);
        bench.run_ms(1500);
        assert!(matches!(bench.stack.boot_state(), BootState::Running(_)));
        bench.transmitter = Some(pilot(true, 0.0));
        assert_eq!(bench.run_ms(100).mode, Mode::Pilot);
        bench.transmitter = Some(pilot(true, 0.8));
        let out = bench.run_ms(4500);
        assert_eq!(out.mode, Mode::Pilot);
        assert!((out.throttle - 0.8).abs() < 1e-3, "{}", out.throttle);
        bench
    }
}

#[test]
fn boots_calibrates_the_gyro_bias_and_arms_through_the_receiver() {
    let mut bench = Bench::new(Imperfections::BENCH);
    let out = bench.run_ms(500);
    assert_eq!(bench.stack.boot_state(), BootState::Calibrating);
    assert_eq!(out.mode, Mode::Disarmed);
    bench.run_ms(700);
    let BootState::Running(bias) = bench.stack.boot_state() else {
        panic!("not calibrated: {:?}", bench.stack.boot_state());
    };
    // The emulator's bias (0.3, −0.2, 0.1) °/s, to within the mean of 1000 noisy samples.
    for (found, truth) in bias
        .gyro_rad_s
        .iter()
        .zip([0.3 * DEG, -0.2 * DEG, 0.1 * DEG])
    {
        assert!((found - truth).abs() < 1e-4, "{found} vs {truth}");
    }
    // Level at rest: estimate level, rates zero, specific force −g.
    let values = bench.stack.imu_values();
    for a in &values.attitude[..2] {
        assert!(a.abs() < 0.05 * DEG, "{a}");
    }
    for w in values.rates {
        assert!(w.abs() < 0.2 * DEG, "{w}");
    }
    assert!((values.specific_force[2] + GRAVITY_M_S2).abs() < 0.05);

    bench.transmitter = Some(pilot(true, 0.0));
    let out = bench.run_ms(100);
    assert_eq!(out.mode, Mode::Pilot);
    bench.transmitter = Some(pilot(true, 0.8));
    let out = bench.run_ms(2000);
    assert!(out.throttle > 0.3 && out.throttle < 0.5, "{}", out.throttle);
    let out = bench.run_ms(2500);
    assert!((out.throttle - 0.8).abs() < 1e-3);
    assert_eq!(out.esc_us, 1800);

    // One Sample per control tick, every frame intact.
    let mut decoder = Decoder::default();
    let frames: Vec<Frame> = decoder
        .feed(&bench.telemetry)
        .collect::<Result<_, _>>()
        .expect("intact telemetry");
    let samples = frames
        .iter()
        .filter(|f| matches!(f, Frame::Sample(_)))
        .count();
    assert_eq!(samples as u32, bench.ticks);
}

#[test]
fn a_reconfiguration_applies_on_the_ground_only() {
    let mut bench = Bench::new(Imperfections::BENCH);
    bench.run_ms(1500);
    assert!(matches!(bench.stack.boot_state(), BootState::Running(_)));
    bench.stack.set_params_valid(false);
    // Other gains, same mounting: applied, calibration kept, the parameter flag too.
    let mut config = *bench.stack.config();
    config.app.flight.gains.lat.kp *= 2.0;
    bench.stack.reconfigure(config).expect("disarmed");
    assert_eq!(*bench.stack.config(), config);
    assert_eq!(
        bench.stack.app().config().flight.gains.lat.kp,
        config.app.flight.gains.lat.kp
    );
    assert!(matches!(bench.stack.boot_state(), BootState::Running(_)));
    assert!(!bench.stack.app().params_valid());
    bench.stack.set_params_valid(true);
    // A refused configuration changes nothing.
    let mut bad = config;
    bad.channel_map.arm.channel = bad.channel_map.lateral.channel;
    assert!(bench.stack.reconfigure(bad).is_err());
    assert_eq!(*bench.stack.config(), config);
    // Armed: refused.
    bench.transmitter = Some(pilot(false, 0.0));
    bench.run_ms(100);
    bench.transmitter = Some(pilot(true, 0.0));
    assert_eq!(bench.run_ms(100).mode, Mode::Pilot);
    let mut armed = config;
    armed.app.flight.gains.lat.kp *= 2.0;
    assert!(matches!(
        bench.stack.reconfigure(armed),
        Err(StackError::Armed)
    ));
    assert_eq!(*bench.stack.config(), config);
    // Disarmed again, another mounting: the gyro calibration starts over.
    bench.transmitter = Some(pilot(false, 0.0));
    assert_eq!(bench.run_ms(100).mode, Mode::Disarmed);
    let mut mounted = config;
    mounted.orientation = crate::imu::ImuRotation::Yaw90.orientation();
    bench.stack.reconfigure(mounted).expect("disarmed");
    assert_eq!(bench.stack.boot_state(), BootState::Calibrating);
}

#[test]
fn arming_is_refused_while_the_gyro_calibrates() {
    let mut bench = Bench::new(Imperfections::BENCH);
    bench.run_ms(200);
    bench.transmitter = Some(pilot(true, 0.0));
    let mut refused = None;
    for _ in 0..20 {
        bench.step_ms();
        refused = refused.or(bench.last.and_then(|out| out.refused));
    }
    assert_eq!(
        refused,
        Some(Refusal::Arm(CheckFailure::Imu(ImuProblem::Calibrating)))
    );
    // Calibrated later, the switch already on does not arm.
    assert_eq!(bench.run_ms(1500).mode, Mode::Disarmed);
}

#[test]
fn a_board_moved_during_calibration_restarts_the_window() {
    let mut bench = Bench::new(Imperfections::BENCH);
    bench.run_ms(500);
    bench
        .emulator()
        .set_truth([0.0, 0.3, 0.0], [0.0, 0.0, -GRAVITY_M_S2]);
    bench.run_ms(20);
    bench
        .emulator()
        .set_truth([0.0; 3], [0.0, 0.0, -GRAVITY_M_S2]);
    bench.run_ms(900);
    assert_eq!(bench.stack.boot_state(), BootState::Calibrating);
    bench.run_ms(200);
    assert!(matches!(bench.stack.boot_state(), BootState::Running(_)));
}

#[test]
fn the_estimate_follows_a_roll_through_rotor_vibration() {
    let mut bench = Bench::armed(Imperfections::BENCH);
    bench
        .emulator()
        .set_imperfections(Imperfections::TREX700L_ROTOR_RUNNING);
    bench.run_ms(500);
    // Roll right at 0.5 rad/s for 200 ms: φ = 0.1 rad; the specific force turns with it.
    let mut phi = 0.0f32;
    for _ in 0..200 {
        phi += 0.5e-3;
        let g = GRAVITY_M_S2;
        bench
            .emulator()
            .set_truth([0.5, 0.0, 0.0], [0.0, -g * phi.sin(), -g * phi.cos()]);
        bench.step_ms();
    }
    let g = GRAVITY_M_S2;
    bench
        .emulator()
        .set_truth([0.0; 3], [0.0, -g * phi.sin(), -g * phi.cos()]);
    bench.run_ms(100);
    let mut largest_rate = 0.0f32;
    for _ in 0..1000 {
        bench.step_ms();
        if bench.stack.samples().is_multiple_of(5) {
            largest_rate = bench
                .stack
                .imu_values()
                .rates
                .iter()
                .fold(largest_rate, |m, w| m.max(w.abs()));
        }
    }
    let values = bench.stack.imu_values();
    assert!(
        (values.attitude[0] - 0.1).abs() < 0.3 * DEG,
        "phi {} deg",
        values.attitude[0] / DEG
    );
    assert!(values.attitude[1].abs() < 0.3 * DEG);
    // The rotor lines (0.02 rad/s at 35 Hz, 0.03 rad/s at 157.5 Hz) are notched out.
    assert!(largest_rate < 0.3 * DEG, "{} deg/s", largest_rate / DEG);
}

#[test]
fn a_stuck_imu_is_an_imu_failsafe_within_25_ms() {
    let mut bench = Bench::armed(Imperfections::BENCH);
    bench
        .emulator()
        .set_imperfections(Imperfections::TREX700L_ROTOR_RUNNING);
    bench.run_ms(100);
    bench.emulator().set_fault(Fault::Stuck);
    let mut elapsed = 0;
    while bench.last.map(|out| out.mode) != Some(Mode::ImuFailsafe) {
        bench.step_ms();
        elapsed += 1;
        assert!(elapsed <= 25, "still {:?}", bench.last.map(|o| o.mode));
    }
    assert_eq!(bench.stack.imu_fault(), Some(ImuFault::Stuck));
    // Latched: healing the chip does not bring the loops back before a new boot.
    bench.emulator().set_fault(Fault::None);
    assert_eq!(bench.run_ms(1000).mode, Mode::ImuFailsafe);
}

#[test]
fn saturated_and_missing_imus_are_faults() {
    for (fault, expected) in [
        (Fault::Saturate, ImuFault::Saturated),
        (Fault::Missing, ImuFault::Missing),
        (Fault::BusError, ImuFault::Missing),
    ] {
        let mut bench = Bench::armed(Imperfections::BENCH);
        bench.emulator().set_fault(fault);
        assert_eq!(bench.run_ms(20).mode, Mode::ImuFailsafe, "{fault:?}");
        assert_eq!(bench.stack.imu_fault(), Some(expected));
    }
}

#[test]
fn a_chip_missing_at_boot_blocks_arming() {
    let mut emulator = Icm42688Emulator::new(Imperfections::BENCH);
    emulator.set_fault(Fault::Missing);
    let mut stack = BoardStack::new(
        emulator,
        NoopDelay,
        StackConfig::trex700l(sweephold_protocol::Axis::Lat),
    )
    .expect("config");
    assert_eq!(stack.boot(), Err(ImuError::WrongId(0)));
    assert_eq!(
        stack.boot_state(),
        BootState::InitFailed(ImuError::WrongId(0))
    );
    assert_eq!(stack.imu_sample(1000), ImuStep::NotPolled);
    let map = ChannelMap::flybarless_default();
    let mut telemetry = Vec::new();
    let mut refused = None;
    for (tick, arm) in [(1u32, false), (2, false), (3, true)] {
        let bytes = map.encode(&pilot(arm, 0.0)).encode();
        let out = stack.control_tick(tick * 5000, &bytes, &mut telemetry);
        assert_eq!(out.mode, Mode::Disarmed);
        refused = refused.or(out.refused);
    }
    assert_eq!(
        refused,
        Some(Refusal::Arm(CheckFailure::Imu(ImuProblem::Fault(
            ImuFaultKind::Missing
        ))))
    );
    // The chip answers again: a new boot calibrates.
    stack.imu_spi_mut().set_fault(Fault::None);
    assert_eq!(stack.boot(), Ok(()));
    assert_eq!(stack.boot_state(), BootState::Calibrating);
}

#[test]
fn receiver_silence_is_a_loss_after_the_link_timeout() {
    let mut bench = Bench::armed(Imperfections::BENCH);
    bench.run_ms(3);
    bench.transmitter = None;
    let mut elapsed = 0;
    while bench.last.map(|out| out.mode) != Some(Mode::RcFailsafe) {
        bench.step_ms();
        elapsed += 1;
        assert!(elapsed <= 100 + 7 + 5, "still {:?}", bench.last);
    }
    assert!(elapsed >= 100 - 7, "lost after {elapsed} ms");
    // Frames again: regained after 0.2 s of valid frames.
    bench.transmitter = Some(pilot(true, 0.8));
    assert_eq!(bench.run_ms(150).mode, Mode::RcFailsafe);
    assert_eq!(bench.run_ms(150).mode, Mode::Pilot);
}

#[test]
fn the_failsafe_flag_is_a_loss_at_once() {
    let mut bench = Bench::armed(Imperfections::BENCH);
    let mut frame = ChannelMap::flybarless_default().encode(&pilot(true, 0.8));
    frame.failsafe = true;
    bench.transmitter = None;
    bench.run_ms(3);
    let mut telemetry = Vec::new();
    bench.now_us += 1000;
    let out = bench
        .stack
        .control_tick(bench.now_us, &frame.encode(), &mut telemetry);
    assert_eq!(out.mode, Mode::RcFailsafe);
}

#[test]
fn configurations_for_another_imu_rate_are_refused() {
    let mut config = StackConfig::trex700l(sweephold_protocol::Axis::Lat);
    config.estimator.sample_rate_hz = 500.0;
    let refused = BoardStack::new(Icm42688Emulator::default(), NoopDelay, config);
    assert!(matches!(refused, Err(StackError::RateMismatch)));
    let mut config = StackConfig::bo105(sweephold_protocol::Axis::Lon);
    config.channel_map.test.channel = 1;
    let refused = BoardStack::new(Icm42688Emulator::default(), NoopDelay, config);
    assert!(matches!(
        refused,
        Err(StackError::ChannelMap(ChannelMapError::DuplicateChannel))
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Whatever bytes arrive on the receiver line and whenever the ticks come, the stack
    /// answers with finite commands within the servo and ESC limits.
    #[test]
    fn arbitrary_receiver_bytes_and_tick_times_never_upset_the_stack(
        chunks in proptest::collection::vec(
            (proptest::collection::vec(any::<u8>(), 0..60), 0u32..20_000),
            1..80,
        ),
    ) {
        let mut bench = Bench::armed(Imperfections::BENCH);
        let mut telemetry = Vec::new();
        for (bytes, gap_us) in chunks {
            for _ in 0..gap_us / 1000 {
                bench.emulator().advance_ns(1_000_000);
                bench.now_us = bench.now_us.wrapping_add(1000);
                bench.stack.imu_sample(bench.now_us);
            }
            bench.now_us = bench.now_us.wrapping_add(gap_us % 1000);
            let out = bench.stack.control_tick(bench.now_us, &bytes, &mut telemetry);
            for c in out.command.to_array() {
                prop_assert!(c.is_finite() && c.abs() <= 1.0);
            }
            prop_assert!((1000..=2000).contains(&out.esc_us));
            prop_assert!(out.servo_us.iter().all(|&us| (800..=2200).contains(&us)));
        }
    }
}
