//! The loop test (`InputKind::LoopSweep`): the pilot-mode loops stay closed through the
//! whole test and the sweep is added to the primary loop's output; the safety checks,
//! the pilot override and the bumpless hand-back work as in every test; non-finite
//! loop commands cannot reach the servos.

use super::*;
use crate::app::test_list::TestList;
use crate::controller::FlightController;
use sweephold_protocol::{InputKind, ProtocolVersion, Sample};

/// The tests' short TREX 700L record as a loop test on `axis`.
fn loop_config(axis: Axis) -> AppConfig {
    let mut config = test_config();
    config.flight.test.primary = axis;
    config.flight.test.input = InputKind::LoopSweep;
    config
}

/// The Sample of the last tick.
fn last_sample(rig: &Rig) -> Sample {
    match rig.tick_frames.last() {
        Some(Frame::Sample(sample)) => *sample,
        _ => panic!("no Sample"),
    }
}

/// Through the whole loop test the command is, on every axis, exactly what the
/// pilot-mode loops fly without a test (a twin application that never engages one,
/// given the same inputs), plus the sweep on the primary axis only, which is non-zero
/// during the excitation; the sum moves by at most the preset's command slew limit (the
/// TREX 700L's pedal) from the command of the tick before.
#[test]
fn the_sweep_is_added_to_the_closed_loops_command_on_its_axis_only() {
    for axis in [Axis::Lat, Axis::Lon, Axis::Ped] {
        let config = loop_config(axis);
        let mut test = Rig::armed(config);
        let mut twin = Rig::armed(config);
        moving(&mut test);
        moving(&mut twin);
        test.start_test();
        twin.ticks(2);
        let mut excited = 0;
        let mut largest_sweep = 0.0f32;
        let steps = config.flight.slew.steps(config.flight.dt_s());
        let mut previous = test.outputs.last().unwrap().command.to_array();
        for n in 0..4000 {
            // Motion that changes, so the loops' outputs do.
            let wobble = 0.1 * libm::sinf(n as f32 * 0.05);
            for rig in [&mut test, &mut twin] {
                rig.imu.p = 0.2 + wobble;
                rig.imu.q = -0.15 - wobble;
                rig.imu.r = 0.1 + 0.5 * wobble;
            }
            let out = test.tick();
            let reference = twin.tick();
            assert_eq!(reference.mode, Mode::Pilot);
            let sample = last_sample(&test);
            if out.phase == Phase::Done {
                break;
            }
            assert_eq!(out.mode, Mode::Test, "{axis:?} tick {n}");
            assert_eq!(out.abort, None);
            let sweep = sample.sweep.to_array();
            for k in 0..4 {
                let sum = reference.command.to_array()[k] + sweep[k];
                let expected = crate::slew::limit(previous[k], sum, steps[k]);
                assert!(
                    (out.command.to_array()[k] - expected).abs() < 1e-6,
                    "{axis:?} tick {n} axis {k}: {:?} vs loops {:?} + sweep {:?}",
                    out.command,
                    reference.command,
                    sample.sweep
                );
                if k != axis.index() {
                    assert_eq!(sweep[k], 0.0);
                }
            }
            previous = out.command.to_array();
            assert_eq!(sample.noise, Controls::default(), "no off-axis noise");
            assert_eq!(sample.hold, [HoldState::Released; 3], "no attitude hold");
            if is_excitation(out.phase) {
                excited += 1;
                largest_sweep = largest_sweep.max(sweep[axis.index()].abs());
                assert!(out.stick_mode.is_some(), "the loops fly the excitation");
            }
        }
        assert!(excited > 2000, "{axis:?}: {excited} excitation ticks");
        assert!(largest_sweep > 0.005, "{axis:?}: sweep {largest_sweep}");
        assert_eq!(test.app.flight_controller().phase(), Phase::Done);
        let headers: Vec<Header> = test
            .frames
            .iter()
            .filter_map(|f| match f {
                Frame::Header(h) => Some(*h),
                _ => None,
            })
            .collect();
        assert_eq!(headers.len(), 1);
        assert_eq!(headers[0].test.input, InputKind::LoopSweep);
        assert_eq!(headers[0].protocol, ProtocolVersion { major: 1, minor: 9 });
        // Back in the pilot mode after Done, bumplessly.
        let end = *test.outputs.last().unwrap();
        let first = test.tick();
        assert_eq!(first.mode, Mode::Pilot);
        assert_close(first.command, end.command, 1e-5);
    }
}

/// Rig in the Sweep phase of a loop test on lat.
fn in_loop_sweep() -> Rig {
    let mut rig = Rig::armed(loop_config(Axis::Lat));
    moving(&mut rig);
    rig.start_test();
    rig.run_until_phase(Phase::Sweep);
    rig.ticks(200);
    assert_eq!(rig.app.flight_controller().phase(), Phase::Sweep);
    rig
}

/// The pilot moving a stick aborts as an override even though the command moves with
/// the loops: the override check sees the pilot's hands.
#[test]
fn a_pilot_stick_displacement_aborts_a_loop_test_as_an_override() {
    let mut rig = in_loop_sweep();
    rig.rc.sticks.lon += 0.05;
    assert_eq!(rig.tick().abort, None);
    rig.rc.sticks.lon += 0.1;
    let out = rig.tick();
    assert_eq!(out.abort, Some(AbortReason::PilotOverride));
    let first = rig.tick();
    assert_eq!(first.mode, Mode::Pilot);
    assert_close(first.command, out.command, 1e-5);
}

/// The sequencer's limits and the application's failsafes end a loop test as any
/// other; its command that tick carries no sweep.
#[test]
fn limits_and_failsafes_abort_a_loop_test() {
    type Fault = fn(&mut Rig);
    let faults: [(AbortReason, Fault); 5] = [
        (AbortReason::AttitudeLimit, |rig| rig.imu.phi = 30.0 * DEG),
        (AbortReason::RateLimit, |rig| rig.imu.p = 4.0),
        (AbortReason::SwitchReleased, |rig| {
            rig.rc.test_switch = false
        }),
        (AbortReason::RcLost, |rig| rig.lost = true),
        (AbortReason::SensorNotFinite, |rig| rig.imu.q = f32::NAN),
    ];
    for (reason, fault) in faults {
        let mut rig = in_loop_sweep();
        fault(&mut rig);
        let out = rig.tick();
        assert!(out.abort.is_some(), "{reason:?}");
        if reason != AbortReason::SensorNotFinite {
            assert_eq!(out.abort, Some(reason));
        }
        assert_eq!(last_sample(&rig).sweep, Controls::default(), "{reason:?}");
        assert!(out.command.to_array().iter().all(|c| c.is_finite()));
        let next = rig.tick();
        assert_ne!(next.mode, Mode::Test, "{reason:?}");
    }
}

/// A non-finite loop command never reaches the servos: each non-finite value flies as
/// the pilot's stick, and the command stays finite and in [−1, 1].
#[test]
fn a_non_finite_loop_command_is_replaced_by_the_pilots_stick() {
    let mut config = loop_config(Axis::Lat).flight;
    config.trim_capture_s = 0.05;
    let mut fc = FlightController::new(config).unwrap();
    let mut sink = Vec::new();
    let mut input = SensorIn::default();
    input.meas.az = -9.81;
    input.pilot.sticks = Controls::from_array([0.1, -0.2, 0.05, 0.3]);
    for n in 0..2000u32 {
        input.seq = n;
        input.pilot.test_switch = n > 2;
        let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.2][(n % 4) as usize];
        fc.set_loop_command(Controls::from_array([bad, 0.4, bad, -bad]));
        let out = fc.step(&input, &mut sink);
        for (k, value) in out.command.to_array().into_iter().enumerate() {
            assert!(value.is_finite() && value.abs() <= 1.0, "tick {n} axis {k}");
        }
        if n > 50 && bad.is_nan() {
            assert_eq!(out.command.lon, 0.4, "tick {n}");
        }
    }
    assert_eq!(fc.phase(), Phase::Sweep);
}

/// The loop command is the step's only: a step without one flies the pilot's sticks.
#[test]
fn a_loop_command_is_used_by_one_step_only() {
    let mut config = loop_config(Axis::Lat).flight;
    config.trim_capture_s = 0.05;
    let mut fc = FlightController::new(config).unwrap();
    let mut input = SensorIn::default();
    input.meas.az = -9.81;
    input.pilot.sticks = Controls::from_array([0.1, -0.2, 0.05, 0.3]);
    fc.set_loop_command(Controls::from_array([0.5; 4]));
    assert_eq!(fc.step(&input, &mut Vec::new()).command.lon, 0.5);
    assert_eq!(fc.step(&input, &mut Vec::new()).command.lon, -0.2);
}

/// The collective has no loop: a loop test on it is refused; the loop-test list is valid
/// on both presets and its entries are the three loops.
#[test]
fn loop_tests_exist_for_the_three_loops_only() {
    let config = loop_config(Axis::Col);
    assert_eq!(
        config.flight.validate(),
        Err(crate::ConfigError::LoopOnCollective)
    );
    for vehicle in [VehicleId::Trex700l, VehicleId::Bo105] {
        let list = TestList::loop_tests(vehicle);
        let base = AppConfig::preset(vehicle, Axis::Lat);
        assert_eq!(list.validate(&base.flight), Ok(()));
        let axes: Vec<_> = (1..=list.slices)
            .map(|k| list.get(k).unwrap().axis)
            .collect();
        assert_eq!(axes, [Some(Axis::Lat), Some(Axis::Lon), Some(Axis::Ped)]);
        assert!((1..=3).all(|k| list.get(k).unwrap().input == InputKind::LoopSweep));
    }
}
