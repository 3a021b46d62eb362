//! `--fc board-sim`: the board application flown on the host against emulated devices.
//!
//! The firmware's [`BoardStack`](sweephold_firmware::board_stack::BoardStack) — the code the board's runner calls: IMU driver,
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
//! record's mode, noise seed and the other shared settings are the board's, set by the
//! record that powers the board up: every record, or with `--power-up once` the first of
//! the flight). A record outside the list (another band, length or input) is the
//! board's single test, selector off, as before the list. With `--fc board-sim:FLASH`
//! it boots the set saved in FLASH ([`BoardSetup::Stored`]) and only the record's test
//! (axis, input, mode, seed, band, length, amplitude), the test list (the same as above:
//! the aircraft's campaign at the flight's record length), the selector channel and the
//! rate are the campaign's; its own single test is the stored one's.
//!
//! # One power-up, many tests (`--power-up once`)
//!
//! A real flight flies the whole campaign on one power-up: the pilot turns the selector
//! to the next entry between two tests. With [`PowerUp::Once`] the link keeps its board
//! from record to record: the first record powers it up (its settings, the flight's: mode,
//! noise seed, fades, hold), and before each later one the pilot releases the test switch,
//! turns the selector to the record's entry and hovers [`BETWEEN_TESTS_S`] on the gimbal
//! (the aircraft brought back into a steady hover) before the record's simulator starts
//! at the trim. The board's estimator, loops, engagement count and log carry on; each test
//! gets its own noise seed from the engagement number (the firmware's test list). A record
//! whose settings are not the flight's, or whose test is no entry of the list, is refused.
//! A record that leaves the board outside the pilot mode (a failsafe) ends the power-up:
//! the next record powers the board up again. The board's log, every frame from power-on
//! (the ticks before and between the records included), is written as `power-up-N.bin`
//! into the `log` folder of the output folder ([`LOG_FOLDER`], [`power_up_log_name`]): a
//! folder of its own, so that the output folder's dumps and the log never stand for the
//! same tests twice where a folder stands for the dumps in it (`identify DIR`). Each
//! record's dump is the log's stretch of its test.
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

mod board;
mod power_up;
mod settings;
mod steady;

use std::path::Path;

use sweephold_firmware::app::Mode;
use sweephold_firmware::Config;
use sweephold_protocol::{ActuatorOut, SensorIn};

pub use super::imu_fault::{ImuFaultKind, ImuFaultPlan, ImuFaultPlanError};
use super::link::FlightControllerLink;
use crate::output::write_atomic;
use anyhow::Context;
use board::Board;
pub use settings::{
    BoardSetup, BoardSimSettings, PowerUp, BETWEEN_TESTS_S, FRAME_PERIOD_US, HOVER_THROTTLE,
};
pub use steady::{
    fly_steady_flights, SteadyCondition, SteadyFlights, GNSS_RATE_HZ, GNSS_VELOCITY_NOISE_M_S,
    HOLD_S, SETTLE_S,
};

/// The board application on emulated devices. See the [module documentation](self).
pub struct BoardSimLink {
    settings: BoardSimSettings,
    board: Option<Board>,
    /// Power-ups so far (the number of the current one's log).
    power_ups: u32,
    /// Records flown on the current power-up.
    records_on_power_up: u64,
}

/// The folder of the power-up logs inside `fly`'s output folder.
pub const LOG_FOLDER: &str = "log";

/// The file name of the `n`-th power-up's log.
pub fn power_up_log_name(n: u32) -> String {
    format!("power-up-{n}.bin")
}

impl BoardSimLink {
    /// A link with no record started yet.
    pub fn new(settings: BoardSimSettings) -> Self {
        BoardSimLink {
            settings,
            board: None,
            power_ups: 0,
            records_on_power_up: 0,
        }
    }

    /// Write the current power-up's log, if the board keeps one, into the log folder.
    fn write_log(&self) -> anyhow::Result<()> {
        let (Some(board), Some(folder)) = (&self.board, &self.settings.log_folder) else {
            return Ok(());
        };
        match &board.log {
            Some(log) => write_log(folder, self.power_ups, log),
            None => Ok(()),
        }
    }
}

/// Write power-up `n`'s log into `folder` (made if missing).
fn write_log(folder: &Path, n: u32, log: &[u8]) -> anyhow::Result<()> {
    std::fs::create_dir_all(folder)
        .with_context(|| format!("cannot create {}", folder.display()))?;
    write_atomic(&folder.join(power_up_log_name(n)), log)
}

impl FlightControllerLink for BoardSimLink {
    fn describe(&self) -> String {
        "board-sim".to_string()
    }

    fn begin_record(&mut self, config: &Config) -> anyhow::Result<()> {
        let settings = &self.settings;
        let once = settings.power_up == PowerUp::Once;
        if once {
            // The next test of the same power-up while the board still flies the pilot
            // mode; otherwise (first record, or the last one left the board in a
            // failsafe) the board is powered up again.
            let flying = self
                .board
                .as_ref()
                .is_some_and(|board| board.stack.app().mode() == Mode::Pilot);
            if flying {
                if let Some(board) = self.board.as_mut() {
                    self.records_on_power_up += 1;
                    return power_up::next_test(board, settings, config, self.records_on_power_up);
                }
            }
            self.write_log()?;
        }
        self.board = None;
        let board = power_up::power_up(settings, config, once)?;
        if once && board.selector.is_none() {
            anyhow::bail!("{}", power_up::NOT_IN_THE_LIST);
        }
        self.board = Some(board);
        self.power_ups += 1;
        self.records_on_power_up = 0;
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
        let start = telemetry.len();
        let out = board.tick(&rc, telemetry);
        if let Some(log) = board.log.as_mut() {
            log.extend_from_slice(&telemetry[start..]);
        }
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

    fn end_flight(&mut self) -> anyhow::Result<()> {
        self.write_log()
    }
}
