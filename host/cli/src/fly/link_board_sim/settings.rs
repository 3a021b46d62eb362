//! What the board-sim link is set up with: the aircraft, the board's setup, records per
//! power-up, and the timing of the emulated devices and of the simulated pilot.

use std::path::PathBuf;

use rotorsim::{Helicopter, SimOptions, Trim};
use sweephold_firmware::app::test_list::TestList;

use crate::fly::imu_fault::ImuFaultPlan;

/// The transmitter's frame period \[µs\] (SBUS high-speed mode).
pub const FRAME_PERIOD_US: u32 = 7_000;
/// Time one 25-byte frame takes on the wire \[µs\] (12 bits of 10 µs per byte).
pub(super) const FRAME_WIRE_US: u32 = 3_000;
/// The throttle the pilot flies with: the governor's set point.
pub const HOVER_THROTTLE: f32 = 0.8;
/// IMU sample period \[µs\].
pub(super) const IMU_PERIOD_US: u32 = 1_000;
/// The lift-off turn from level to the trim attitude \[s\].
pub(super) const LIFT_OFF_S: f64 = 2.0;
/// The hover on the gimbal before the record \[s\].
pub(super) const GIMBAL_HOVER_S: f64 = 10.0;
/// The steady hover between two tests of one power-up \[s\]: the test switch off, the
/// selector turned, the aircraft brought back to the hover. As long as the hover before the
/// first test: with 5 s the Bo-105's board-sim campaign matched its hover modes on 5 of 9
/// seeds and one 9-DOF fit went degenerate, with 10 s on 8 of 10, as with a power-up per
/// record (docs/decisions/2026-11-27-one-power-up-flight.md).
pub const BETWEEN_TESTS_S: f64 = 10.0;
/// Longest wait for the calibration \[s\] (its own timeout is 10 s).
pub(super) const CALIBRATION_WAIT_S: f64 = 11.0;

/// How many records one power-up of the board flies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PowerUp {
    /// Every record on a board powered up for it (its settings the record's).
    #[default]
    PerRecord,
    /// One power-up flies the records one after the other, each test chosen from the
    /// list by the selector, until one leaves the board out of the pilot mode (the next
    /// record then powers it up again); each power-up's log is one file.
    Once,
}

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
    /// follow them ([`crate::fly::servo_plant::board_rotor_rpm`]): the emulated IMU's rotor
    /// lines, and the notches of a board set up from the file. `None` (a full-size
    /// rotor): the board preset's 2100 rpm lines and notches.
    pub rotor_rpm: Option<[f32; 2]>,
    /// The test list the board is set up with (`FromAircraft`): the aircraft's campaign.
    pub test_list: TestList,
    /// How the board is set up.
    pub setup: BoardSetup,
    /// Records per power-up.
    pub power_up: PowerUp,
    /// The folder each power-up's log is written into (`power-up-N.bin`), with
    /// [`PowerUp::Once`].
    pub log_folder: Option<PathBuf>,
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
