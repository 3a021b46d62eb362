//! The pilot mode's gains as parameters (`PM_*`, table version 7): a changed value
//! reaches the loops of the board application built from the table, a value outside its
//! range is refused, and the defaults are each preset's gains.

use sweephold_protocol::{Axis, VehicleId};

use super::*;
use crate::app::{BoardApp, ImuInput, ModeSwitch, RcInput, Receiver, TickInput};

/// The board application of `table`, armed with the mode switch at `switch`; with
/// `powered`, the throttle then raised to 0.8 and its soft start flown out (the
/// integrators run; without, they leak on the ground); then `ticks` control ticks with
/// `imu`. Returns the application.
fn flown(
    table: &ParamTable,
    switch: ModeSwitch,
    powered: bool,
    imu: ImuInput,
    ticks: usize,
) -> BoardApp {
    let params = table.params().expect("a consistent set");
    let mut app = BoardApp::new(params.stack.app).expect("a valid application");
    let mut rc = RcInput::NEUTRAL;
    rc.mode = switch;
    let tick = |app: &mut BoardApp, rc: RcInput, imu: ImuInput| {
        let mut bytes = Vec::new();
        let input = TickInput {
            imu,
            rc: Receiver::Valid(rc),
        };
        app.tick(&input, &mut bytes)
    };
    for _ in 0..10 {
        tick(&mut app, rc, ImuInput::AT_REST);
    }
    rc.arm = true;
    let armed = tick(&mut app, rc, ImuInput::AT_REST);
    assert_eq!(armed.mode, crate::app::Mode::Pilot, "{:?}", armed.refused);
    if powered {
        rc.throttle = 0.8;
        let soft_start = params.stack.app.throttle.soft_start_s;
        for _ in 0..(soft_start * 200.0) as usize + 2 {
            tick(&mut app, rc, ImuInput::AT_REST);
        }
        assert_eq!(app.throttle(), 0.8);
    }
    for _ in 0..ticks {
        tick(&mut app, rc, imu);
    }
    app
}

/// The TREX 700L defaults with `id` set to `value`.
fn with(id: ParamId, value: f32) -> ParamTable {
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    table.set(id, value).expect("in range");
    table
}

#[test]
fn the_defaults_are_each_presets_pilot_mode_gains() {
    for vehicle in [VehicleId::Trex700l, VehicleId::Bo105] {
        let table = ParamTable::defaults(vehicle);
        let pilot = crate::app::AppConfig::preset(vehicle, Axis::Lat).pilot;
        let expected = [
            (ParamId::PilotRollKp, pilot.roll.kp),
            (ParamId::PilotRollKi, pilot.roll.ki),
            (ParamId::PilotPitchKp, pilot.pitch.kp),
            (ParamId::PilotPitchKi, pilot.pitch.ki),
            (ParamId::PilotYawKp, pilot.yaw.kp),
            (ParamId::PilotYawKi, pilot.yaw.ki),
            (ParamId::PilotLevelGain, pilot.level_gain),
            (ParamId::PilotHeadingGain, pilot.heading_gain),
        ];
        for (id, value) in expected {
            assert_eq!(
                table.get(id).to_bits(),
                value.to_bits(),
                "{vehicle:?} {id:?}"
            );
        }
        assert_eq!(table.params().unwrap().stack.app.pilot, pilot);
    }
}

#[test]
fn a_changed_rate_gain_reaches_the_rate_loop_it_names() {
    // Rate stick centred, on the ground, the aircraft rolling and pitching at 0.5 rad/s
    // and yawing at 0.05 rad/s (the tail's command stays inside its servo's slew limit,
    // 0.02 per tick): one tick later each axis' command differs from the defaults' by
    // −ΔKp·rate on that axis alone (the integrators leak on the ground: the same on
    // both).
    let rates = ImuInput {
        p: 0.5,
        q: 0.5,
        r: 0.05,
        ..ImuInput::AT_REST
    };
    let base = flown(
        &ParamTable::defaults(VehicleId::Trex700l),
        ModeSwitch::Low,
        false,
        rates,
        1,
    )
    .last_command()
    .to_array();
    let defaults = ParamTable::defaults(VehicleId::Trex700l);
    for (axis, id) in [
        ParamId::PilotRollKp,
        ParamId::PilotPitchKp,
        ParamId::PilotYawKp,
    ]
    .into_iter()
    .enumerate()
    {
        let kp = defaults.get(id);
        let changed = flown(&with(id, 2.0 * kp), ModeSwitch::Low, false, rates, 1)
            .last_command()
            .to_array();
        for (k, (b, c)) in base.iter().zip(changed).take(3).enumerate() {
            if k == axis {
                let expected = -kp * [rates.p, rates.q, rates.r][k];
                assert!(
                    ((c - b) - expected).abs() < 0.02 * expected.abs(),
                    "{id:?}: {} against {expected}",
                    c - b
                );
            } else {
                assert_eq!(b.to_bits(), c.to_bits(), "{id:?} moved axis {k}");
            }
        }
    }
}

#[test]
fn a_changed_integral_gain_reaches_the_integrator() {
    // Under power (the integrators run), 20 ticks of a rate error: three times the Ki
    // gives three times the integral on its own axis and the same on the others.
    let rates = ImuInput {
        p: 0.5,
        q: 0.5,
        r: 0.05,
        ..ImuInput::AT_REST
    };
    let defaults = ParamTable::defaults(VehicleId::Trex700l);
    let base = flown(&defaults, ModeSwitch::Low, true, rates, 20)
        .pilot_loops()
        .loops();
    for (axis, id) in [
        ParamId::PilotRollKi,
        ParamId::PilotPitchKi,
        ParamId::PilotYawKi,
    ]
    .into_iter()
    .enumerate()
    {
        let changed = flown(
            &with(id, 3.0 * defaults.get(id)),
            ModeSwitch::Low,
            true,
            rates,
            20,
        )
        .pilot_loops()
        .loops();
        for (k, (b, c)) in base.iter().zip(changed).enumerate() {
            let (b, c) = (b.integral(), c.integral());
            if k == axis {
                assert!(b < 0.0, "{id:?}: {b}");
                assert!((c / b - 3.0).abs() < 0.05, "{id:?}: {c} against 3 × {b}");
            } else {
                assert_eq!(b.to_bits(), c.to_bits(), "{id:?} moved axis {k}");
            }
        }
    }
}

#[test]
fn a_changed_level_or_heading_gain_sets_the_outer_loops_target() {
    // Level stick centred at 0.1 rad of roll and pitch: rate targets −K_lvl·0.1 once the
    // shaping has caught up (1 s).
    let tilted = ImuInput {
        phi: 0.1,
        theta: 0.1,
        ..ImuInput::AT_REST
    };
    for k_lvl in [3.0f32, 6.5] {
        let table = with(ParamId::PilotLevelGain, k_lvl);
        let [roll, pitch, _] = flown(&table, ModeSwitch::High, false, tilted, 200)
            .pilot_loops()
            .loops();
        for target in [roll.target(), pitch.target()] {
            assert!(
                (target + k_lvl * 0.1).abs() < 1e-4,
                "K_lvl {k_lvl}: {target}"
            );
        }
    }
    // Heading held at 0 (pedal centred from arming on), blown 5° round: the yaw rate
    // target is −K_ψ·5°.
    let turned = ImuInput {
        psi: 5.0f32.to_radians(),
        ..ImuInput::AT_REST
    };
    for k_psi in [2.5f32, 5.0] {
        let table = with(ParamId::PilotHeadingGain, k_psi);
        let app = flown(&table, ModeSwitch::Low, false, turned, 100);
        assert_eq!(app.pilot_loops().held_heading(), Some(0.0));
        let [_, _, yaw] = app.pilot_loops().loops();
        let expected = -k_psi * 5.0f32.to_radians();
        assert!(
            (yaw.target() - expected).abs() < 1e-3,
            "K_ψ {k_psi}: {}",
            yaw.target()
        );
    }
}

#[test]
fn pilot_mode_gains_outside_their_ranges_are_refused() {
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    let before = table;
    for (name, value) in [
        ("PM_ROLL_KP", -0.01),
        ("PM_ROLL_KP", 2.5),
        ("PM_PITCH_KI", -0.1),
        ("PM_PITCH_KI", 11.0),
        ("PM_YAW_KP", f32::NAN),
        ("PM_YAW_KI", f32::INFINITY),
        ("PM_LEVEL_K", 0.0),
        ("PM_LEVEL_K", 25.0),
        ("PM_HEADING_K", 0.05),
        ("PM_HEADING_K", 21.0),
    ] {
        let refused = table.set_by_name(name, value);
        assert!(
            matches!(refused, Err(SetError::OutOfRange | SetError::NotFinite)),
            "{name} = {value}: {refused:?}"
        );
    }
    assert_eq!(table, before);
    // The ends of each range are taken.
    for (name, value) in [
        ("PM_ROLL_KP", 0.0),
        ("PM_ROLL_KP", 2.0),
        ("PM_YAW_KI", 10.0),
        ("PM_LEVEL_K", 0.1),
        ("PM_HEADING_K", 20.0),
    ] {
        assert_eq!(table.set_by_name(name, value), Ok(()), "{name} = {value}");
        assert!(table.params().is_ok(), "{name} = {value}");
    }
}
