//! The emulated board of `--fc board-sim`: the firmware's stack on an ICM-42688-P
//! emulator, the transmitter's SBUS stream and the servos' frames, one control tick at a
//! time.

use embedded_hal::delay::DelayNs;
use sweephold_firmware::app::TickOutput;
use sweephold_firmware::board_stack::BoardStack;
use sweephold_firmware::imu::emulator::Icm42688Emulator;
use sweephold_firmware::receiver::{ChannelMap, ModeSwitch, RcInput};
use sweephold_firmware::FrameSink;
use sweephold_protocol::Controls;

use super::settings::{FRAME_PERIOD_US, FRAME_WIRE_US, HOVER_THROTTLE, IMU_PERIOD_US};
use crate::fly::servo_plant::{FrameHold, ServoGeometry};

/// A delay that returns at once: the emulator's time moves only with `advance`.
pub(super) struct NoDelay;

impl DelayNs for NoDelay {
    fn delay_ns(&mut self, _ns: u32) {}
}

/// Drops every frame (the telemetry of the ticks before the record, on a board whose
/// power-up is not logged).
pub(super) struct Discard;

impl FrameSink for Discard {
    fn write_frame(&mut self, _bytes: &[u8]) {}
}

pub(super) type Stack = BoardStack<Icm42688Emulator, NoDelay>;

/// One record's board, emulator and transmitter.
pub(super) struct Board {
    pub(super) stack: Stack,
    /// The board's µs clock.
    pub(super) now_us: u32,
    /// When the transmitter starts its next frame.
    pub(super) next_frame_us: u32,
    /// Bytes on the wire not yet read by a control tick.
    pub(super) wire: Vec<u8>,
    /// IMU samples per control tick.
    pub(super) samples_per_tick: u32,
    /// Control tick period \[s\].
    pub(super) dt: f64,
    /// Ticks of the record so far.
    pub(super) record_ticks: u64,
    /// The output of the last tick.
    pub(super) last: Option<TickOutput>,
    /// The pilot's Level sticks at the trim attitude (lat, lon).
    pub(super) level_neutral: [f32; 2],
    /// The fly loop's trim sticks.
    pub(super) trim_sticks: [f32; 4],
    /// The transmitter sends frames.
    pub(super) transmitting: bool,
    /// Board time since power-on \[µs\] (not wrapping).
    pub(super) elapsed_us: u64,
    /// The pulses the servos hold between their frames.
    pub(super) servos: FrameHold,
    /// The aircraft's servo geometry.
    pub(super) geometry: ServoGeometry,
    /// What the rotor gets over the current tick (lat, lon, ped, col).
    pub(super) flown: [f64; 4],
    /// The IMU's truth (rates, specific force) at the end of the last tick and at the
    /// end of this one: the chip samples in between lie on the line joining them.
    pub(super) truth: Option<[Truth; 2]>,
    /// The transmitter's channel map: the board's default one, with its selector channel.
    pub(super) map: ChannelMap,
    /// The selector's position (the record's entry), if the board has a selector.
    pub(super) selector: Option<f32>,
    /// The board's log of this power-up, every frame from power-on (a logger's file), when
    /// the link keeps one ([`super::PowerUp::Once`]).
    pub(super) log: Option<Vec<u8>>,
    /// The flight's shared test settings: the board's single test, set at power-up.
    pub(super) single_test: sweephold_protocol::TestConfig,
    /// The configuration the board was powered up for (the first record's).
    pub(super) powered_for: sweephold_firmware::Config,
}

/// Body rates \[rad/s\] and specific force \[m/s²\] the emulated chip senses.
pub(super) type Truth = ([f32; 3], [f32; 3]);

impl Board {
    pub(super) fn emulator(&mut self) -> &mut Icm42688Emulator {
        self.stack.imu_spi_mut()
    }

    /// What the chip senses at the end of the next tick. The simulator gives the truth
    /// once per tick; a real chip samples the motion in between, so the samples of the
    /// tick are interpolated from the last tick's truth to this one (the newest sample,
    /// the one the tick reads, is this truth itself). Holding the truth for the whole
    /// tick instead would make the IMU filter bank's lag look half a tick shorter than on
    /// a board.
    pub(super) fn set_truth(&mut self, rates: [f32; 3], force: [f32; 3]) {
        let previous = self.truth.map_or((rates, force), |[_, end]| end);
        self.truth = Some([previous, (rates, force)]);
    }

    /// One control tick with the transmitter sending `rc` (if transmitting): the
    /// samples and frames that fall due, then the stack's control tick.
    pub(super) fn tick(&mut self, rc: &RcInput, sink: &mut impl FrameSink) -> TickOutput {
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

    /// One tick whose telemetry no record receives: into the power-up's log if the board
    /// keeps one, dropped otherwise.
    pub(super) fn unrecorded_tick(&mut self, rc: &RcInput) -> TickOutput {
        match self.log.take() {
            Some(mut log) => {
                let out = self.tick(rc, &mut log);
                self.log = Some(log);
                out
            }
            None => self.tick(rc, &mut Discard),
        }
    }

    /// The pilot's transmitter for the fly loop's `sticks` and test switch.
    pub(super) fn transmitter(&self, sticks: &Controls, test_switch: bool) -> RcInput {
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
