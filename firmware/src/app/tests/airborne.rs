//! The airborne rule at test entry, the landed abort, and the collective source of a
//! test, through the whole application.

use super::*;
use crate::config::CollectiveSource;

/// The lowest collective of the tests' ground: well below the TREX preset's `col_min`.
const COLLECTIVE_DOWN: f32 = -0.6;

/// Ticks in the airborne time of `rig`'s configuration (200 Hz).
fn airborne_ticks(rig: &Rig) -> usize {
    (rig.app.config().airborne.time_s * 200.0) as usize
}

fn test_request(rig: &mut Rig) -> TickOutput {
    rig.rc.test_switch = false;
    rig.tick();
    rig.rc.test_switch = true;
    rig.tick()
}

fn with_collective(source: CollectiveSource) -> AppConfig {
    let mut config = test_config();
    config.flight.collective = source;
    config
}

fn in_sweep(config: AppConfig) -> Rig {
    let mut rig = Rig::armed(config);
    rig.start_test();
    rig.run_until_phase(Phase::Sweep);
    rig.ticks(200);
    rig
}

#[test]
fn a_test_on_the_ground_is_refused_not_airborne_and_nothing_is_excited() {
    let mut rig = Rig::armed(test_config());
    rig.rc.sticks.col = COLLECTIVE_DOWN;
    rig.ticks(airborne_ticks(&rig) + 10);
    let out = test_request(&mut rig);
    assert_eq!(
        out.refused,
        Some(Refusal::Test(CheckFailure::NotAirborne)),
        "collective down"
    );
    assert_eq!(out.mode, Mode::Pilot);
    assert_eq!(out.phase, Phase::Idle);
    assert!(
        rig.tick_events().iter().any(|e| matches!(
            e,
            Event::Refused {
                check: sweephold_protocol::RefusedCheck::NotAirborne,
                ..
            }
        )),
        "the refusal is reported"
    );
    // The switch stays on: no test starts when the collective comes up.
    rig.rc.sticks.col = STICKS[3];
    let out = rig.ticks(3 * airborne_ticks(&rig));
    assert_eq!((out.mode, out.phase), (Mode::Pilot, Phase::Idle));
    // Raised for less than the airborne time: still refused.
    rig.rc.sticks.col = COLLECTIVE_DOWN;
    rig.ticks(5);
    rig.rc.sticks.col = STICKS[3];
    rig.ticks(airborne_ticks(&rig) / 2);
    let out = test_request(&mut rig);
    assert_eq!(out.refused, Some(Refusal::Test(CheckFailure::NotAirborne)));
    // Raised for the airborne time: the test starts.
    rig.ticks(airborne_ticks(&rig));
    rig.start_test();
    // No Sample before the refusals ever carried an excitation.
    assert!(rig
        .outputs
        .iter()
        .all(|o| o.phase == Phase::Idle || o.mode == Mode::Test));
}

#[test]
fn a_test_during_the_soft_start_is_refused_before_the_airborne_rule() {
    let mut rig = Rig::new(test_config());
    rig.ticks(10);
    rig.arm();
    rig.rc.throttle = FLIGHT_THROTTLE;
    rig.ticks(300);
    let out = test_request(&mut rig);
    assert_eq!(
        out.refused,
        Some(Refusal::Test(CheckFailure::SoftStartRunning))
    );
}

#[test]
fn a_landing_during_a_sweep_aborts_with_landed() {
    let mut rig = in_sweep(with_collective(CollectiveSource::Pilot));
    rig.rc.sticks.col = COLLECTIVE_DOWN;
    // Below the threshold for less than the airborne time: the sweep goes on.
    for _ in 1..airborne_ticks(&rig) {
        let out = rig.tick();
        assert_eq!((out.mode, out.abort), (Mode::Test, None));
        assert_eq!(out.phase, Phase::Sweep);
    }
    let out = rig.tick();
    assert_eq!(out.abort, Some(AbortReason::Landed));
    assert_eq!(out.mode, Mode::Pilot);
    assert!(rig.tick_events().iter().any(|e| matches!(
        e,
        Event::Abort {
            reason: AbortReason::Landed,
            ..
        }
    )));
    // The pilot-mode collective is the stick's from then on.
    assert_eq!(rig.tick().command.col, COLLECTIVE_DOWN);
}

#[test]
fn a_throttle_cut_during_a_sweep_aborts_with_landed_at_once() {
    for source in [CollectiveSource::Trim, CollectiveSource::Pilot] {
        let mut rig = in_sweep(with_collective(source));
        rig.rc.throttle = 0.0;
        // The throttle output follows the stick down this tick; the rule reads it on the
        // next.
        assert_eq!(rig.tick().abort, None, "{source:?}");
        let out = rig.tick();
        assert_eq!(out.abort, Some(AbortReason::Landed), "{source:?}");
        assert_eq!(out.mode, Mode::Pilot);
    }
}

#[test]
fn with_the_trim_collective_a_lowered_stick_is_a_pilot_override() {
    let mut rig = in_sweep(with_collective(CollectiveSource::Trim));
    let trim_col = rig.app.flight_controller().trim().sticks[3];
    assert_eq!(rig.tick().command.col, trim_col);
    rig.rc.sticks.col += 0.05;
    assert_eq!(
        rig.tick().command.col,
        trim_col,
        "the stick does not reach it"
    );
    rig.rc.sticks.col = COLLECTIVE_DOWN;
    assert_eq!(rig.tick().abort, Some(AbortReason::PilotOverride));
}

#[test]
fn with_the_pilot_collective_the_stick_reaches_the_command_on_a_lateral_sweep() {
    let mut rig = in_sweep(with_collective(CollectiveSource::Pilot));
    let servos_before = rig.tick().servo_us;
    for step in [0.2, -0.3, 0.45] {
        rig.rc.sticks.col = STICKS[3] + step;
        let out = rig.tick();
        assert_eq!(out.abort, None, "the collective is not an override");
        assert_eq!(out.phase, Phase::Sweep);
        assert!(
            (out.command.col - (STICKS[3] + step)).abs() < 1e-5,
            "command col {} for stick {}",
            out.command.col,
            STICKS[3] + step
        );
    }
    // Every swash servo moved with the collective (common mode), the tail did not by it.
    rig.rc.sticks.col = STICKS[3] + 0.2;
    let raised = rig.tick().servo_us;
    let moved = |i: usize| i32::from(raised[i]) - i32::from(servos_before[i]);
    assert!(
        (0..3).all(|i| moved(i).abs() > 20),
        "{servos_before:?} → {raised:?}"
    );
    // The cyclic sticks are still overrides.
    rig.rc.sticks.lat += 0.2;
    assert_eq!(rig.tick().abort, Some(AbortReason::PilotOverride));
}

#[test]
fn with_the_pilot_collective_a_collective_sweep_adds_to_the_stick() {
    let mut config = with_collective(CollectiveSource::Pilot);
    config.flight.test.primary = Axis::Col;
    let mut rig = in_sweep(config);
    rig.rc.sticks.col = STICKS[3] + 0.1;
    for _ in 0..50 {
        let out = rig.tick();
        assert_eq!(out.abort, None);
        let Some(Frame::Sample(sample)) = rig.tick_frames.last() else {
            panic!("no sample");
        };
        assert!(
            (out.command.col - (STICKS[3] + 0.1 + sample.sweep.col)).abs() < 1e-5,
            "col {} = stick + sweep {}",
            out.command.col,
            sample.sweep.col
        );
    }
    assert!(rig
        .outputs
        .iter()
        .rev()
        .take(50)
        .any(|o| (o.command.col - (STICKS[3] + 0.1)).abs() > 1e-3));
}
