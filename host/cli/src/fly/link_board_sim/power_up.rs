//! Powering the emulated board up and bringing it into the hover, and the pause
//! between two tests of one power-up (see the [link's documentation](super)).

use rotorsim::Sim;
use sweephold_firmware::app::{AppConfig, Mode};
use sweephold_firmware::board_stack::{BoardStack, BootState, StackConfig};
use sweephold_firmware::filters::FilterBankConfig;
use sweephold_firmware::imu::emulator::{Icm42688Emulator, Imperfections};
use sweephold_firmware::imu::GRAVITY_M_S2;
use sweephold_firmware::receiver::{ChannelMap, ChannelSource, ModeSwitch, RcInput};
use sweephold_firmware::Config;
use sweephold_protocol::Controls;

use super::board::{Board, NoDelay};
use super::settings::{
    BoardSetup, BoardSimSettings, BETWEEN_TESTS_S, CALIBRATION_WAIT_S, GIMBAL_HOVER_S,
    HOVER_THROTTLE, LIFT_OFF_S,
};
use crate::fly::board_test_list::{self, SELECTOR_CHANNEL};
use crate::fly::imu_fault::ImuFaultPlan;
use crate::fly::servo_plant::{self, FrameHold, ServoGeometry};

/// Boot, arm and hover the board for a record flown with `config` (see the module
/// documentation).
pub(super) fn power_up(
    settings: &BoardSimSettings,
    config: &Config,
    logged: bool,
) -> anyhow::Result<Board> {
    let rate = u32::from(config.rate_hz);
    if rate == 0 || 1000 % rate != 0 {
        anyhow::bail!("--fc board-sim needs a rate that divides the IMU's 1000 Hz, not {rate} Hz");
    }
    let (mut stack_config, [swash_hz, tail_hz]) = match &settings.setup {
        BoardSetup::FromAircraft => {
            let preset = AppConfig::preset(config.vehicle, config.test.primary);
            let mut flight = *config;
            flight.mixer = servo_plant::board_mixer(&settings.swash);
            let app = AppConfig { flight, ..preset };
            let mut stack = StackConfig::with_app(app);
            if let Some([head, tail]) = settings.rotor_rpm {
                stack.filters = FilterBankConfig::helicopter(
                    stack.filters.sample_rate_hz,
                    head / 60.0,
                    tail / 60.0,
                );
            }
            (stack, servo_plant::board_frame_rates(&settings.swash))
        }
        BoardSetup::Stored(params) => (
            board_test_list::stored_with_record(params, config)?,
            [params.swash_frame_hz, params.tail_frame_hz],
        ),
    };
    // The record's test from the list, chosen by the selector: the board's single
    // test is then the preset's (the stored one's with a stored set).
    let own_test = match &settings.setup {
        BoardSetup::FromAircraft => {
            AppConfig::preset(config.vehicle, config.test.primary)
                .flight
                .test
        }
        BoardSetup::Stored(params) => params.stack.app.flight.test,
    };
    let record_test = stack_config.app.flight.test;
    let single = board_test_list::single_test(&own_test, &record_test);
    let mut listed = stack_config;
    listed.app.tests = settings.test_list;
    listed.app.flight.test = single;
    listed.channel_map.selector = ChannelSource::normal(SELECTOR_CHANNEL);
    let mut selector = None;
    stack_config.channel_map.selector = ChannelSource::normal(0);
    if let Some((_, position)) =
        board_test_list::selection(&listed.app.tests, &single, &record_test)
    {
        if listed.channel_map.validate().is_ok() && listed.app.validate().is_ok() {
            stack_config = listed;
            selector = Some(position);
        }
    }
    let mut map = ChannelMap::flybarless_default();
    map.selector = stack_config.channel_map.selector;
    let app = stack_config.app;
    let seed = devices_seed(config.test.seed);
    let rotor_lines = settings
        .rotor_rpm
        .map_or(Imperfections::TREX700L_ROTOR_RUNNING, |[head, tail]| {
            Imperfections::rotor_running(head / 60.0, tail / 60.0)
        });
    let (rotor_stopped, rotor_running) = if settings.vibration {
        (
            Imperfections {
                seed,
                ..Imperfections::BENCH
            },
            Imperfections {
                seed,
                ..rotor_lines
            },
        )
    } else {
        let quiet = Imperfections {
            gyro_noise_rad_s: Imperfections::BENCH.gyro_noise_rad_s,
            accel_noise_m_s2: Imperfections::BENCH.accel_noise_m_s2,
            seed,
            ..Imperfections::IDEAL
        };
        (quiet, quiet)
    };
    let mut emulator = Icm42688Emulator::new(rotor_stopped);
    if let Some(ImuFaultPlan { kind, at_s: None }) = settings.imu_fault {
        emulator.set_fault(kind.fault());
    }
    let mut stack = BoardStack::new(emulator, NoDelay, stack_config)
        .map_err(|e| anyhow::anyhow!("the board refuses its configuration: {e}"))?;
    if let Err(error) = stack.boot() {
        anyhow::bail!("the board's IMU did not start ({error:?}): the board cannot arm");
    }
    let max_angle = app.pilot.max_angle_rad;
    let trim = &settings.trim;
    let mut board = Board {
        stack,
        now_us: 0,
        next_frame_us: 0,
        wire: Vec::with_capacity(64),
        samples_per_tick: 1000 / rate,
        dt: 1.0 / f64::from(rate),
        record_ticks: 0,
        last: None,
        level_neutral: [
            (trim.phi / f64::from(max_angle)) as f32,
            (trim.theta / f64::from(max_angle)) as f32,
        ],
        trim_sticks: trim.controls.map(|c| c as f32),
        transmitting: true,
        elapsed_us: 0,
        servos: FrameHold::new(swash_hz, tail_hz, [0; 4]),
        geometry: ServoGeometry::new(&settings.swash),
        flown: [0.0; 4],
        truth: None,
        map,
        selector,
        log: logged.then(Vec::new),
        single_test: app.flight.test,
        powered_for: *config,
    };
    let ticks_in = |seconds: f64| (seconds * f64::from(rate)).ceil() as u64;
    let col = board.trim_sticks[3];
    let ground = |arm: bool, throttle: f32| RcInput {
        sticks: Controls {
            lat: 0.0,
            lon: 0.0,
            ped: 0.0,
            col,
        },
        throttle,
        arm,
        test_switch: false,
        mode: ModeSwitch::Middle,
        selector: None,
    };

    // 1. Ground, rotor stopped: calibration.
    let mut waited = 0;
    while !matches!(board.stack.boot_state(), BootState::Running(_)) {
        if waited > ticks_in(CALIBRATION_WAIT_S) {
            anyhow::bail!(
                "the board's gyro calibration did not finish ({:?})",
                board.stack.boot_state()
            );
        }
        board.unrecorded_tick(&ground(false, 0.0));
        waited += 1;
    }
    for _ in 0..ticks_in(0.2) {
        board.unrecorded_tick(&ground(false, 0.0));
    }

    // 2. Rotor running: arm, soft start.
    board.emulator().set_imperfections(rotor_running);
    let mut refused = None;
    for _ in 0..ticks_in(0.1) {
        let out = board.unrecorded_tick(&ground(true, 0.0));
        refused = refused.or(out.refused);
    }
    if board.stack.app().mode() != Mode::Pilot {
        anyhow::bail!(
            "the board refused to arm ({})",
            refused.map_or_else(|| "no reason given".to_string(), |r| format!("{r:?}"))
        );
    }
    let spool_s = f64::from(HOVER_THROTTLE * app.throttle.soft_start_s) + 0.2;
    for _ in 0..ticks_in(spool_s) {
        board.unrecorded_tick(&ground(true, HOVER_THROTTLE));
    }

    // 3. Lift-off: the IMU turns from level to the trim attitude.
    let lift_ticks = ticks_in(LIFT_OFF_S);
    let g = f64::from(GRAVITY_M_S2);
    for k in 1..=lift_ticks {
        let s = k as f64 / lift_ticks as f64;
        let shape = 0.5 * (1.0 - (std::f64::consts::PI * s).cos());
        let rate_shape = 0.5 * std::f64::consts::PI * (std::f64::consts::PI * s).sin() / LIFT_OFF_S;
        let (phi, theta) = (trim.phi * shape, trim.theta * shape);
        let (phi_dot, theta_dot) = (trim.phi * rate_shape, trim.theta * rate_shape);
        let rates = [phi_dot, theta_dot * phi.cos(), -theta_dot * phi.sin()];
        let force = [
            g * theta.sin(),
            -g * phi.sin() * theta.cos(),
            -g * phi.cos() * theta.cos(),
        ];
        board.set_truth(rates.map(|v| v as f32), force.map(|v| v as f32));
        let mut rc = board.transmitter(&Controls::from_array(board.trim_sticks), false);
        rc.sticks.lat = (phi / f64::from(max_angle)) as f32;
        rc.sticks.lon = (theta / f64::from(max_angle)) as f32;
        board.unrecorded_tick(&rc);
    }

    // 4. Hover on the gimbal: a copy of the aircraft, translation held.
    hover_on_gimbal(&mut board, settings, GIMBAL_HOVER_S, seed ^ 0x6_1AB1);
    let mode = board.stack.app().mode();
    if mode != Mode::Pilot {
        anyhow::bail!(
            "the board left the pilot mode before the record ({})",
            mode.name()
        );
    }
    Ok(board)
}

/// Hover `seconds` on the gimbal with the test switch off: a copy of the aircraft,
/// started at the trim with the simulator seed `sim_seed`, whose translation is held
/// (velocity and position reset every tick) while it rotates freely under the board.
fn hover_on_gimbal(board: &mut Board, settings: &BoardSimSettings, seconds: f64, sim_seed: u64) {
    let trim = &settings.trim;
    let mut options = settings.sim_options;
    options.seed = sim_seed;
    options.gust_level = 0.0;
    options.dropout_probability = 0.0;
    options.spike_probability = 0.0;
    let mut sim = Sim::at_trim(settings.heli.clone(), trim, options);
    let held = trim.state;
    let mut reading = sim.step(board.dt, trim.controls);
    let rc = board.transmitter(&Controls::from_array(board.trim_sticks), false);
    let ticks = (seconds / board.dt).ceil() as u64;
    for _ in 0..ticks {
        board.set_truth(
            [reading.p, reading.q, reading.r].map(|v| v as f32),
            [reading.ax, reading.ay, reading.az].map(|v| v as f32),
        );
        board.unrecorded_tick(&rc);
        reading = sim.step(board.dt, board.flown);
        let mut state = sim.state();
        for i in [
            rotorsim::model::U,
            rotorsim::model::V,
            rotorsim::model::W,
            rotorsim::model::NORTH,
            rotorsim::model::EAST,
            rotorsim::model::DOWN,
        ] {
            state.0[i] = held.0[i];
        }
        sim.set_state(state);
    }
}

/// The pause between two tests of one power-up, before the record flown with `config`:
/// the pilot releases the test switch, turns the selector to the record's entry and
/// brings the aircraft back into a steady hover ([`BETWEEN_TESTS_S`] on the gimbal).
/// Refused when the record's settings are not the flight's: only the test list's entries
/// differ between the tests of a power-up.
pub(super) fn next_test(
    board: &mut Board,
    settings: &BoardSimSettings,
    config: &Config,
    engagement: u64,
) -> anyhow::Result<()> {
    let record = config.test;
    let single = board.single_test;
    // The record's test with the flight's per-test fields: what the board would fly as
    // its single test if this record had powered it up.
    let shared = board_test_list::single_test(&single, &record);
    let same_flight = Config {
        test: sweephold_protocol::TestConfig {
            seed: single.seed,
            warnings: 0,
            ..shared
        },
        ..*config
    } == Config {
        test: sweephold_protocol::TestConfig {
            warnings: 0,
            ..single
        },
        ..board.powered_for
    };
    if !same_flight {
        anyhow::bail!(
            "this record's settings are not those of the flight the board was powered up \
             for: one power-up flies only the entries of its test list"
        );
    }
    let flown = sweephold_protocol::TestConfig {
        seed: single.seed,
        ..record
    };
    let (_, position) = board_test_list::selection(&settings.test_list, &single, &flown)
        .ok_or_else(|| anyhow::anyhow!("{NOT_IN_THE_LIST}"))?;
    board.selector = Some(position);
    board.record_ticks = 0;
    let seed = devices_seed(single.seed);
    hover_on_gimbal(
        board,
        settings,
        BETWEEN_TESTS_S,
        seed ^ 0x6_1AB1 ^ engagement << 40,
    );
    let mode = board.stack.app().mode();
    if mode != Mode::Pilot {
        anyhow::bail!(
            "the board left the pilot mode between two tests ({})",
            mode.name()
        );
    }
    Ok(())
}

/// Why a record cannot be flown on one power-up: its test is no entry of the list.
pub(super) const NOT_IN_THE_LIST: &str =
    "this record's test is not an entry of the board's test list: one power-up flies only the \
     list's tests";

/// The seed of the emulated devices (the IMU's imperfections, the gimbal hover's
/// simulator) of a board whose flight's noise seed is `test_seed`.
pub(super) fn devices_seed(test_seed: u32) -> u64 {
    0xB0A2_D51A_u64 ^ u64::from(test_seed).rotate_left(23)
}
