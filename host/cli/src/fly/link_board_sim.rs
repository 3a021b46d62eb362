//! `--fc board-sim`: the board application flown on the host against emulated devices.
//!
//! The firmware's [`BoardStack`] — the code the board's runner calls: IMU driver,
//! monitor, calibration, filter bank, estimator, SBUS decoder, link monitor, channel map
//! and the board application — runs in-process on a register-level ICM-42688-P emulator
//! and an SBUS byte stream. Per lockstep tick (one [`SensorIn`] at the record's rate):
//!
//! 1. the emulator is given the simulator's body rates and specific force (`input.meas`:
//!    p, q, r and a_x, a_y, a_z, specific force, ≈ (0, 0, −g) in hover) as its truth at
//!    the end of the tick;
//! 2. it advances 1 ms at a time, its truth on the line from the last tick's to this
//!    one's (a chip samples the motion between the simulator's steps; the newest sample
//!    is this tick's truth), and the stack polls it after each sample (`imu_sample`,
//!    1 kHz: 5 samples per tick at 200 Hz);
//! 3. the simulated transmitter sends an SBUS frame every 7 ms (high-speed mode); the
//!    frames complete by the tick go into the tick's byte stream;
//! 4. `control_tick` runs the application; its command and servo pulses are the reply,
//!    and the sequencer's telemetry goes into the dump as with the in-process link;
//! 5. the servo pulses reach the simulated rotor through the aircraft's servo geometry
//!    (its `[swash]` table), each servo taking a new pulse only when one of its frames
//!    starts ([`super::servo_plant`]): the simulator flies what the servos
//!    do, not the command.
//!
//! # The board's setup
//!
//! With `--fc board-sim` the board is set up from the aircraft file in memory: the
//! record's configuration (the preset with the file's `[flight_controller]` settings),
//! its mixer and servo frame rates those of the file's `[swash]` table and its vibration
//! notches at the file's rotor speeds, as `fc params push` would set them, and the file's campaign as its test list on a selector channel
//! ([`super::board_test_list`]). A record whose test is an entry of the list is chosen
//! in the air: the simulated transmitter's selector sits at that entry's slice when the
//! test switch engages, and the board's own single test stays the preset's (the
//! record's mode, noise seed and the other shared settings are the board's, one record
//! per power-up). A record outside the list (another band, length or input) is the
//! board's single test, selector off, as before the list. With `--fc board-sim:FLASH`
//! it boots the set saved in FLASH ([`BoardSetup::Stored`]) and only the record's test
//! (axis, input, mode, seed, band, length, amplitude), the test list (the same as above:
//! the aircraft's campaign at the flight's record length), the selector channel and the
//! rate are the campaign's; its own single test is the stored one's.
//!
//! # The simulated pilot and transmitter
//!
//! The fly loop's pilot holds the bare airframe's trim sticks (plus noise or an
//! override). On the transmitter the pilot flies the stabilised mode, mode switch in the
//! middle (Level), so the same hands become:
//!
//! ```text
//! lat = φ_trim/angle_max + (stick_lat − trim_lat)      Level: the trim attitude
//! lon = θ_trim/angle_max + (stick_lon − trim_lon)
//! ped = stick_ped − trim_ped                           centred: heading hold
//! col = stick_col                                      the collective passes straight
//! throttle 0.8 (the governor's set point), arm switch on, test switch the loop's
//! ```
//!
//! During a test's excitation the application feeds the sequencer the captured trim plus
//! the sticks' displacement from their mean during the capture, so the sweep flies as
//! with the other links and a stick moved off trim is still a pilot override.
//!
//! # Before the record (`begin_record`)
//!
//! The board is booted and the aircraft brought into the hover before the first
//! simulated tick, so every record starts in Pilot mode at the hover trim:
//!
//! 1. ground, rotor stopped, level and still: boot, gyro calibration (1 s), arm switch off,
//!    throttle 0; the emulator has its bench imperfections (bias, noise, scale errors),
//!    or with `--vibration none` its white noise alone: an ideal chip's output at rest
//!    is constant, which the IMU monitor rightly takes for a hung chip (stuck after
//!    20 identical reads), so the board would never arm;
//! 2. rotor running (the emulator's rotor vibration lines, at the aircraft's 1/rev,
//!    2/rev and tail rotor frequencies, from now on, unless `none`):
//!    arm switch on with the throttle low, then throttle 0.8: the soft start (4 s);
//! 3. lift-off: the IMU turns smoothly from level to the trim attitude in 2 s, the
//!    Level sticks with it;
//! 4. hover on a gimbal for 10 s: the stack flies a copy of the simulated aircraft,
//!    started at the trim, whose translation is held (velocity and position reset every
//!    tick) while it rotates freely. The rate loops' integrators take up the trim
//!    controls and the estimator settles; the record's own simulator then starts at the
//!    trim with the stack in that state.
//!
//! The telemetry of these ticks is not recorded. A boot that fails (no IMU) or an arming
//! the board refuses fails the record with the board's reason.
//!
//! # Faults
//!
//! `--rc-loss T`: no SBUS frame is sent from record time T on (the receiver's link
//! timeout, 100 ms, then declares the loss). `--imu-fault stuck@T|saturate@T|missing@T`:
//! the emulator's fault from record time T on; `missing` without a time: no chip from
//! power-on (the boot fails). Record time counts the record's ticks from its first.

use embedded_hal::delay::DelayNs;
use rotorsim::{Helicopter, Sim, SimOptions, Trim};
use sweephold_firmware::app::test_list::TestList;
use sweephold_firmware::app::{AppConfig, Mode, TickOutput};
use sweephold_firmware::board_stack::{BoardStack, BootState, StackConfig};
use sweephold_firmware::filters::FilterBankConfig;
use sweephold_firmware::imu::emulator::{Icm42688Emulator, Imperfections};
use sweephold_firmware::imu::GRAVITY_M_S2;
use sweephold_firmware::receiver::{ChannelMap, ChannelSource, ModeSwitch, RcInput};
use sweephold_firmware::{Config, FrameSink};
use sweephold_protocol::{ActuatorOut, Controls, SensorIn};

use super::board_test_list::{self, SELECTOR_CHANNEL};
pub use super::imu_fault::{ImuFaultKind, ImuFaultPlan, ImuFaultPlanError};
use super::link::FlightControllerLink;
use super::servo_plant::{self, FrameHold, ServoGeometry};

/// The transmitter's frame period \[µs\] (SBUS high-speed mode).
pub const FRAME_PERIOD_US: u32 = 7_000;
/// Time one 25-byte frame takes on the wire \[µs\] (12 bits of 10 µs per byte).
const FRAME_WIRE_US: u32 = 3_000;
/// The throttle the pilot flies with: the governor's set point.
pub const HOVER_THROTTLE: f32 = 0.8;
/// IMU sample period \[µs\].
const IMU_PERIOD_US: u32 = 1_000;
/// The lift-off turn from level to the trim attitude \[s\].
const LIFT_OFF_S: f64 = 2.0;
/// The hover on the gimbal before the record \[s\].
const GIMBAL_HOVER_S: f64 = 10.0;
/// Longest wait for the calibration \[s\] (its own timeout is 10 s).
const CALIBRATION_WAIT_S: f64 = 11.0;

/// What the board-sim link needs besides the record's configuration.
#[derive(Clone, Debug)]
pub struct BoardSimSettings {
    /// The simulated aircraft (the gimbal hover flies a copy).
    pub heli: Helicopter,
    /// Its hover trim.
    pub trim: Trim,
    /// The simulator's options for the gimbal hover (sensors, actuators, plant).
    pub sim_options: SimOptions,
    /// Rotor vibration and the chip's imperfections (`--vibration default`), or a chip
    /// with its white noise only (`none`).
    pub vibration: bool,
    /// Record time from which no SBUS frame is sent \[s\].
    pub rc_loss_at_s: Option<f64>,
    /// IMU fault to inject.
    pub imu_fault: Option<ImuFaultPlan>,
    /// The aircraft's servo geometry: the board's pulses reach the rotor through it.
    pub swash: aircraft::Swash,
    /// The aircraft's main and tail rotor speeds \[rpm\] when a board's notches can
    /// follow them ([`servo_plant::board_rotor_rpm`]): the emulated IMU's rotor
    /// lines, and the notches of a board set up from the file. `None` (a full-size
    /// rotor): the board preset's 2100 rpm lines and notches.
    pub rotor_rpm: Option<[f32; 2]>,
    /// The test list the board is set up with (`FromAircraft`): the aircraft's campaign.
    pub test_list: TestList,
    /// How the board is set up.
    pub setup: BoardSetup,
}

/// Where the board's configuration comes from.
#[derive(Clone, Debug)]
pub enum BoardSetup {
    /// The aircraft file in memory: the record's configuration, the mixer and frame
    /// rates of its `[swash]` table.
    FromAircraft,
    /// A parameter set saved on the board (`--fc board-sim:FLASH`).
    Stored(Box<sweephold_firmware::params::Params>),
}

/// A delay that returns at once: the emulator's time moves only with `advance`.
struct NoDelay;

impl DelayNs for NoDelay {
    fn delay_ns(&mut self, _ns: u32) {}
}

/// Drops every frame (the telemetry of the ticks before the record).
struct Discard;

impl FrameSink for Discard {
    fn write_frame(&mut self, _bytes: &[u8]) {}
}

type Stack = BoardStack<Icm42688Emulator, NoDelay>;

/// One record's board, emulator and transmitter.
struct Board {
    stack: Stack,
    /// The board's µs clock.
    now_us: u32,
    /// When the transmitter starts its next frame.
    next_frame_us: u32,
    /// Bytes on the wire not yet read by a control tick.
    wire: Vec<u8>,
    /// IMU samples per control tick.
    samples_per_tick: u32,
    /// Control tick period \[s\].
    dt: f64,
    /// Ticks of the record so far.
    record_ticks: u64,
    /// The output of the last tick.
    last: Option<TickOutput>,
    /// The pilot's Level sticks at the trim attitude (lat, lon).
    level_neutral: [f32; 2],
    /// The fly loop's trim sticks.
    trim_sticks: [f32; 4],
    /// The transmitter sends frames.
    transmitting: bool,
    /// Board time since power-on \[µs\] (not wrapping).
    elapsed_us: u64,
    /// The pulses the servos hold between their frames.
    servos: FrameHold,
    /// The aircraft's servo geometry.
    geometry: ServoGeometry,
    /// What the rotor gets over the current tick (lat, lon, ped, col).
    flown: [f64; 4],
    /// The IMU's truth (rates, specific force) at the end of the last tick and at the
    /// end of this one: the chip samples in between lie on the line joining them.
    truth: Option<[Truth; 2]>,
    /// The transmitter's channel map: the board's default one, with its selector channel.
    map: ChannelMap,
    /// The selector's position (the record's entry), if the board has a selector.
    selector: Option<f32>,
}

/// Body rates \[rad/s\] and specific force \[m/s²\] the emulated chip senses.
type Truth = ([f32; 3], [f32; 3]);

impl Board {
    fn emulator(&mut self) -> &mut Icm42688Emulator {
        self.stack.imu_spi_mut()
    }

    /// What the chip senses at the end of the next tick. The simulator gives the truth
    /// once per tick; a real chip samples the motion in between, so the samples of the
    /// tick are interpolated from the last tick's truth to this one (the newest sample,
    /// the one the tick reads, is this truth itself). Holding the truth for the whole
    /// tick instead would make the IMU filter bank's lag look half a tick shorter than on
    /// a board.
    fn set_truth(&mut self, rates: [f32; 3], force: [f32; 3]) {
        let previous = self.truth.map_or((rates, force), |[_, end]| end);
        self.truth = Some([previous, (rates, force)]);
    }

    /// One control tick with the transmitter sending `rc` (if transmitting): the
    /// samples and frames that fall due, then the stack's control tick.
    fn tick(&mut self, rc: &RcInput, sink: &mut impl FrameSink) -> TickOutput {
        let map = self.map;
        for sample in 1..=self.samples_per_tick {
            if let Some([(rates_0, force_0), (rates_1, force_1)]) = self.truth {
                let s = sample as f32 / self.samples_per_tick as f32;
                let lerp = |a: [f32; 3], b: [f32; 3]| [0, 1, 2].map(|i| a[i] + s * (b[i] - a[i]));
                self.emulator()
                    .set_truth(lerp(rates_0, rates_1), lerp(force_0, force_1));
            }
            self.emulator().advance_ns(u64::from(IMU_PERIOD_US) * 1000);
            self.now_us = self.now_us.wrapping_add(IMU_PERIOD_US);
            self.stack.imu_sample(self.now_us);
            // A frame is read once it is complete on the wire.
            while self.now_us.wrapping_sub(self.next_frame_us) as i32 >= FRAME_WIRE_US as i32 {
                if self.transmitting {
                    self.wire.extend_from_slice(&map.encode(rc).encode());
                }
                self.next_frame_us = self.next_frame_us.wrapping_add(FRAME_PERIOD_US);
            }
        }
        let out = self.stack.control_tick(self.now_us, &self.wire, sink);
        self.wire.clear();
        self.last = Some(out);
        self.elapsed_us += u64::from(self.samples_per_tick * IMU_PERIOD_US);
        let tick_us = u64::from(self.samples_per_tick * IMU_PERIOD_US);
        let held = self.servos.tick(self.elapsed_us, tick_us, out.servo_us);
        self.flown = self.geometry.controls(held);
        out
    }

    /// The pilot's transmitter for the fly loop's `sticks` and test switch.
    fn transmitter(&self, sticks: &Controls, test_switch: bool) -> RcInput {
        let [lat, lon, ped, col] = sticks.to_array();
        let [t_lat, t_lon, t_ped, _] = self.trim_sticks;
        let [n_lat, n_lon] = self.level_neutral;
        RcInput {
            sticks: Controls {
                lat: n_lat + (lat - t_lat),
                lon: n_lon + (lon - t_lon),
                ped: ped - t_ped,
                col,
            },
            throttle: HOVER_THROTTLE,
            arm: true,
            test_switch,
            mode: ModeSwitch::Middle,
            selector: self.selector,
        }
    }
}

/// The board application on emulated devices. See the [module documentation](self).
pub struct BoardSimLink {
    settings: BoardSimSettings,
    board: Option<Board>,
}

impl BoardSimLink {
    /// A link with no record started yet.
    pub fn new(settings: BoardSimSettings) -> Self {
        BoardSimLink {
            settings,
            board: None,
        }
    }

    /// Boot, arm and hover the board for a record flown with `config` (see the module
    /// documentation).
    fn prepare(&self, config: &Config) -> anyhow::Result<Board> {
        let settings = &self.settings;
        let rate = u32::from(config.rate_hz);
        if rate == 0 || 1000 % rate != 0 {
            anyhow::bail!(
                "--fc board-sim needs a rate that divides the IMU's 1000 Hz, not {rate} Hz"
            );
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
        let seed = 0xB0A2_D51A_u64 ^ u64::from(config.test.seed).rotate_left(23);
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
            board.tick(&ground(false, 0.0), &mut Discard);
            waited += 1;
        }
        for _ in 0..ticks_in(0.2) {
            board.tick(&ground(false, 0.0), &mut Discard);
        }

        // 2. Rotor running: arm, soft start.
        board.emulator().set_imperfections(rotor_running);
        let mut refused = None;
        for _ in 0..ticks_in(0.1) {
            let out = board.tick(&ground(true, 0.0), &mut Discard);
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
            board.tick(&ground(true, HOVER_THROTTLE), &mut Discard);
        }

        // 3. Lift-off: the IMU turns from level to the trim attitude.
        let lift_ticks = ticks_in(LIFT_OFF_S);
        let g = f64::from(GRAVITY_M_S2);
        for k in 1..=lift_ticks {
            let s = k as f64 / lift_ticks as f64;
            let shape = 0.5 * (1.0 - (std::f64::consts::PI * s).cos());
            let rate_shape =
                0.5 * std::f64::consts::PI * (std::f64::consts::PI * s).sin() / LIFT_OFF_S;
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
            board.tick(&rc, &mut Discard);
        }

        // 4. Hover on the gimbal: a copy of the aircraft, translation held.
        let mut options = settings.sim_options;
        options.seed = seed ^ 0x6_1AB1;
        options.gust_level = 0.0;
        options.dropout_probability = 0.0;
        options.spike_probability = 0.0;
        let mut sim = Sim::at_trim(settings.heli.clone(), trim, options);
        let held = trim.state;
        let mut reading = sim.step(board.dt, trim.controls);
        let rc = board.transmitter(&Controls::from_array(board.trim_sticks), false);
        for _ in 0..ticks_in(GIMBAL_HOVER_S) {
            board.set_truth(
                [reading.p, reading.q, reading.r].map(|v| v as f32),
                [reading.ax, reading.ay, reading.az].map(|v| v as f32),
            );
            board.tick(&rc, &mut Discard);
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
        let mode = board.stack.app().mode();
        if mode != Mode::Pilot {
            anyhow::bail!(
                "the board left the pilot mode before the record ({})",
                mode.name()
            );
        }
        Ok(board)
    }
}

impl FlightControllerLink for BoardSimLink {
    fn describe(&self) -> String {
        "board-sim".to_string()
    }

    fn begin_record(&mut self, config: &Config) -> anyhow::Result<()> {
        self.board = None;
        self.board = Some(self.prepare(config)?);
        Ok(())
    }

    fn exchange(
        &mut self,
        input: &SensorIn,
        telemetry: &mut Vec<u8>,
    ) -> anyhow::Result<ActuatorOut> {
        let settings = &self.settings;
        let board = self
            .board
            .as_mut()
            .ok_or_else(|| anyhow::anyhow!("no record started on the board-sim link"))?;
        let t = board.record_ticks as f64 * board.dt;
        if let Some(ImuFaultPlan {
            kind,
            at_s: Some(at),
        }) = settings.imu_fault
        {
            if t >= at {
                board.emulator().set_fault(kind.fault());
            }
        }
        if let Some(at) = settings.rc_loss_at_s {
            board.transmitting = t < at;
        }
        let m = &input.meas;
        board.set_truth([m.p, m.q, m.r], [m.ax, m.ay, m.az]);
        let rc = board.transmitter(&input.pilot.sticks, input.pilot.test_switch);
        let out = board.tick(&rc, telemetry);
        board.record_ticks += 1;
        let tick = board.stack.app().flight_controller().tick().wrapping_sub(1);
        Ok(ActuatorOut {
            tick,
            seq: input.seq,
            command: out.command,
            servo_us: out.servo_us,
        })
    }

    fn controls_flown(&self, out: &ActuatorOut) -> [f64; 4] {
        self.board
            .as_ref()
            .map_or(out.command.to_array().map(f64::from), |board| board.flown)
    }

    fn board_mode(&self) -> Option<&'static str> {
        self.board
            .as_ref()
            .and_then(|board| board.last)
            .map(|out| out.mode.name())
    }
}
