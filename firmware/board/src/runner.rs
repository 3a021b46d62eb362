//! The control loop: boot sequence, the two run modes, and the tick itself.
//!
//! **Standalone** (from boot): TIM5 paces the loop at the configured rate. There is no
//! sensor or receiver driver on this board yet, so each tick runs the flight logic on a
//! neutral [`SensorIn`] (all zeros, test switch off, `seq` 0): the sequencer stays Idle
//! and passes the (centred) pilot through, and every tick still streams its Sample.
//!
//! **In the loop** (from the first SensorIn frame the host sends, at run time): the host
//! is the clock. Every SensorIn is exactly one tick: the flight logic steps on it, its
//! Sample and Events go out, then an ActuatorOut answering the SensorIn's `seq` — the
//! last frame of the tick, so the host knows the tick's telemetry is complete when it
//! arrives. Lockstep keeps a simulation deterministic whatever the emulator's or the
//! host's speed. A Header goes out when the mode is entered, so a dump recorded from
//! that point on starts with one. TIM5 keeps running as the link watchdog: after
//! [`LINK_TIMEOUT_S`] without a SensorIn the loop steps on its own again, on the last
//! SensorIn, whose unchanging `seq` makes the flight logic's stale-sensor check abort
//! any running test to pilot pass-through; the next SensorIn resumes lockstep.
//!
//! Every SensorIn is also the fresh sample that feeds the independent watchdog
//! ([`crate::watchdog`]), which the first one starts.
//!
//! **Configure** (protocol 1.1): a [`LinkConfig`] from the host replaces the compiled-in
//! configuration at run time. The image builds the preset of the frame's vehicle for
//! its test's primary axis, puts the frame's rate and test in, and restarts the flight
//! logic on it (tick 0); a configuration the flight logic refuses leaves the running
//! one in place. Either way a [`ConfigureResult`] answers, preceded by the new Header
//! when accepted, and the loop is in the loop from then on (the Header is the mode
//! entry's, so the first SensorIn does not send another). TIM5 keeps the boot rate: in
//! the loop it is only the link watchdog, still [`LINK_TIMEOUT_S`] long.

use sweephold_firmware::{Config, FlightController};
use sweephold_protocol::{
    ActuatorOut, Axis, ConfigureResult, Controls, Frame, FrameError, LinkConfig, SensorIn,
    VehicleId,
};

use crate::clocks::{self, ClockSource, Clocks};
use crate::dividers;
use crate::link::{self, FrameScratch, Inbound, Telemetry};
use crate::log;
use crate::logport;
use crate::nvic::{self, Irq};
use crate::semihosting;
use crate::servo::{self, ServoChannel, Servos};
use crate::ticker::Ticker;
use crate::usart::{self, UsartTx};
use crate::watchdog::Watchdog;

/// Host silence after which the loop steps on its own again [s].
pub const LINK_TIMEOUT_S: u32 = 1;

/// Seconds between two status lines in the defmt log.
const STATUS_PERIOD_S: u32 = 10;

/// Vehicle preset of the image, chosen when it is built: `SWEEPHOLD_VEHICLE=trex700l`
/// (the default: the aircraft this board flies) or `bo105` (QEMU in the loop with the
/// Bo-105 simulator).
const VEHICLE: VehicleId = match option_env!("SWEEPHOLD_VEHICLE") {
    None => VehicleId::Trex700l,
    Some(name) => match parse_vehicle(name) {
        Some(vehicle) => vehicle,
        None => panic!("SWEEPHOLD_VEHICLE must be trex700l or bo105"),
    },
};

/// Primary axis of the image's test, chosen when it is built: `SWEEPHOLD_AXIS=lat`
/// (default), `lon`, `ped` or `col`.
const PRIMARY_AXIS: Axis = match option_env!("SWEEPHOLD_AXIS") {
    None => Axis::Lat,
    Some(name) => match parse_axis(name) {
        Some(axis) => axis,
        None => panic!("SWEEPHOLD_AXIS must be lat, lon, ped or col"),
    },
};

/// `a == b` for strings, usable in a constant.
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const fn parse_vehicle(name: &str) -> Option<VehicleId> {
    if same(name, VehicleId::Trex700l.name()) {
        Some(VehicleId::Trex700l)
    } else if same(name, VehicleId::Bo105.name()) {
        Some(VehicleId::Bo105)
    } else {
        None
    }
}

const fn parse_axis(name: &str) -> Option<Axis> {
    let mut i = 0;
    while i < Axis::ALL.len() {
        if same(name, Axis::ALL[i].name()) {
            return Some(Axis::ALL[i]);
        }
        i += 1;
    }
    None
}

/// The preset of `vehicle` flying the paper's test on `axis`.
fn preset(vehicle: VehicleId, axis: Axis) -> Config {
    match vehicle {
        VehicleId::Bo105 => Config::bo105_default(axis),
        VehicleId::Trex700l => Config::trex700l_default(axis),
    }
}

/// The flight-logic configuration the image boots with: the preset of [`VEHICLE`]
/// flying the paper's test on [`PRIMARY_AXIS`]. A host changes it at run time with a
/// Configure frame (protocol 1.1).
fn image_config() -> Config {
    preset(VEHICLE, PRIMARY_AXIS)
}

/// The configuration a Configure frame asks for: the vehicle's preset for the test's
/// primary axis with the frame's rate and test.
fn link_config(request: &LinkConfig) -> Config {
    let mut config = preset(request.vehicle, request.test.primary);
    config.rate_hz = request.rate_hz;
    config.test = request.test;
    config
}

/// How the loop is paced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Mode {
    /// No host: TIM5 paces the loop on the neutral input.
    Standalone,
    /// Host in the loop: one tick per SensorIn.
    InTheLoop {
        /// Timer ticks since the last SensorIn.
        silent_ticks: u32,
    },
}

/// Counters for the status log.
#[derive(Clone, Copy, Debug, Default, defmt::Format)]
pub struct LoopStats {
    /// Flight-logic steps run.
    pub steps: u32,
    /// Timer ticks that came while the previous one was still being served.
    pub overruns: u32,
    /// Times the host went quiet for longer than the link timeout.
    pub link_timeouts: u32,
    /// Good frames from the host that are not SensorIn (ignored).
    pub ignored_frames: u32,
    /// Frames from the host that failed COBS, CRC or decoding.
    pub bad_frames: u32,
    /// Configure frames accepted.
    pub reconfigured: u32,
    /// Configure frames refused.
    pub refused: u32,
}

/// The flight logic and its outputs.
pub struct Runner {
    fc: FlightController,
    servos: Servos<ServoChannel>,
    tx: UsartTx,
    mode: Mode,
    /// The input of the last tick.
    input: SensorIn,
    link_timeout_ticks: u32,
    status_period_ticks: u32,
    ticks_since_status: u32,
    stats: LoopStats,
    /// Where frames are encoded before they go into the transmit ring.
    scratch: FrameScratch,
    /// Fed by every fresh sample (in the loop: every SensorIn).
    watchdog: Watchdog,
}

impl Runner {
    fn new(fc: FlightController, servos: Servos<ServoChannel>, tx: UsartTx, rate_hz: u32) -> Self {
        Runner {
            fc,
            servos,
            tx,
            mode: Mode::Standalone,
            input: SensorIn::default(),
            link_timeout_ticks: LINK_TIMEOUT_S * rate_hz,
            status_period_ticks: STATUS_PERIOD_S * rate_hz,
            ticks_since_status: 0,
            stats: LoopStats::default(),
            scratch: [0; sweephold_protocol::MAX_FRAME_LEN],
            watchdog: Watchdog::new(),
        }
    }

    /// Send the Header of the configured test.
    fn announce(&mut self) {
        let header = self.fc.header();
        if !link::send(&mut self.tx, &mut self.scratch, &Frame::Header(header)) {
            defmt::warn!("header frame dropped");
        }
    }

    /// One flight-logic tick on the last input; answers the SensorIn `reply_to` with an
    /// ActuatorOut. Telemetry that finds the ring full is dropped, but the answer waits
    /// for room: in lockstep the host cannot go on without it.
    fn step(&mut self, reply_to: Option<u32>) {
        // The tick number this step carries (its Sample's `tick`), also the time stamp
        // of the log lines the step writes.
        let tick = self.fc.tick();
        log::set_tick(tick);
        let output = self.fc.step(
            &self.input,
            &mut Telemetry::new(&mut self.tx, &mut self.scratch),
        );
        // Infallible: the channels write compare registers.
        let _ = self.servos.apply(output.servo_us);
        self.stats.steps = self.stats.steps.wrapping_add(1);
        if let Some(seq) = reply_to {
            let answer = ActuatorOut {
                tick,
                seq,
                command: output.command,
                servo_us: output.servo_us,
            };
            link::send_waiting(&mut self.tx, &mut self.scratch, &Frame::ActuatorOut(answer));
        }
    }

    /// `due` timer ticks have elapsed since the last call.
    fn on_timer(&mut self, due: u32) {
        self.stats.overruns = self.stats.overruns.wrapping_add(due.saturating_sub(1));
        match self.mode {
            Mode::Standalone => self.step(None),
            Mode::InTheLoop { silent_ticks } => {
                let silent = silent_ticks.saturating_add(due);
                self.mode = Mode::InTheLoop {
                    silent_ticks: silent,
                };
                if silent > self.link_timeout_ticks {
                    if silent_ticks <= self.link_timeout_ticks {
                        self.stats.link_timeouts = self.stats.link_timeouts.wrapping_add(1);
                        defmt::warn!(
                            "host silent for {=u32} s: stepping on the last SensorIn",
                            LINK_TIMEOUT_S
                        );
                    }
                    self.step(None);
                }
            }
        }
        self.ticks_since_status = self.ticks_since_status.saturating_add(due);
        if self.ticks_since_status >= self.status_period_ticks {
            self.ticks_since_status = 0;
            defmt::info!(
                "mode {} {} tx dropped {=u32} rx lost {=u32} log dropped {=u32}",
                self.mode,
                self.stats,
                self.tx.dropped_frames(),
                usart::rx_lost(),
                logport::dropped()
            );
        }
    }

    /// A Configure frame: restart the flight logic on the requested configuration, or
    /// keep the running one if the flight logic refuses it, and answer.
    fn configure(&mut self, request: &LinkConfig) {
        let result = match FlightController::new(link_config(request)) {
            Ok(fc) => {
                self.fc = fc;
                // A new test starts at tick 0: so do its log lines.
                log::set_tick(self.fc.tick());
                let neutral =
                    sweephold_firmware::mix(&self.fc.config().mixer, &Controls::default());
                servo::set_failsafe(neutral);
                self.stats.reconfigured = self.stats.reconfigured.wrapping_add(1);
                defmt::info!(
                    "configured by the host: {=str}, {=u16} Hz",
                    request.vehicle.name(),
                    request.rate_hz
                );
                self.announce();
                ConfigureResult {
                    accepted: true,
                    refusal: 0,
                }
            }
            Err(error) => {
                self.stats.refused = self.stats.refused.wrapping_add(1);
                defmt::warn!("configuration refused: {=str}", error.message());
                ConfigureResult {
                    accepted: false,
                    // The variant's position: the host names it with the same library.
                    refusal: error as u8,
                }
            }
        };
        self.mode = Mode::InTheLoop { silent_ticks: 0 };
        link::send_waiting(
            &mut self.tx,
            &mut self.scratch,
            &Frame::ConfigureResult(result),
        );
    }

    /// A frame (or a decoding error) from the host.
    fn on_frame(&mut self, frame: Result<Frame, FrameError>) {
        match frame {
            Ok(Frame::SensorIn(input)) => {
                if self.mode == Mode::Standalone {
                    defmt::info!("SensorIn from the host: in-the-loop mode");
                    self.announce();
                }
                self.mode = Mode::InTheLoop { silent_ticks: 0 };
                self.input = input;
                self.step(Some(input.seq));
                // The host's SensorIn is the fresh sample of the loop.
                self.watchdog.fed_by_fresh_sample();
            }
            Ok(Frame::Configure(request)) => self.configure(&request),
            Ok(_) => self.stats.ignored_frames = self.stats.ignored_frames.wrapping_add(1),
            // The decoder has resynchronised on the next delimiter already.
            Err(_) => self.stats.bad_frames = self.stats.bad_frames.wrapping_add(1),
        }
    }
}

/// Bring the board up and run the loop forever.
pub fn run() -> ! {
    let clocks: Clocks = clocks::init();
    defmt::info!("clocks {}", clocks);

    // Servos first: their failsafe pulses are on the pins before anything else runs.
    let servos = match servo::init(&clocks) {
        Ok(servos) => servos,
        Err(error) => defmt::panic!("servo timer: {}", error),
    };
    let (tx, rx) = match usart::init(&clocks) {
        Ok(halves) => halves,
        Err(error) => defmt::panic!("USART1: {}", error),
    };
    defmt::info!(
        "USART1 {=u32} Bd, BRR {=u32:#x}, rate error {=u32} ppm",
        usart::BAUD,
        tx.brr(),
        dividers::baud_error_ppm(clocks.pclk2_hz, usart::BAUD, tx.brr())
    );

    if let Err(error) = logport::init(&clocks) {
        defmt::panic!("USART3 (log): {}", error);
    }

    let fc = match FlightController::new(image_config()) {
        Ok(fc) => fc,
        Err(error) => defmt::panic!("flight configuration refused: {=str}", error.message()),
    };
    // From now on a panic or fault puts the servos where the mixer puts centred sticks.
    let neutral = sweephold_firmware::mix(&fc.config().mixer, &Controls::default());
    servo::set_failsafe(neutral);
    defmt::info!("failsafe pulses {} us", neutral);
    let rate_hz = u32::from(fc.header().rate_hz);
    let mut runner = Runner::new(fc, servos, tx, rate_hz);
    runner.announce();

    let ticker = match Ticker::start(&clocks, rate_hz) {
        Ok(ticker) => ticker,
        Err(error) => defmt::panic!("tick timer: {}", error),
    };
    defmt::info!(
        "loop at {=u32} Hz (timer gives {=u64} mHz)",
        rate_hz,
        ticker.achieved_millihz
    );

    if clocks.source == ClockSource::NoRcc && semihosting::requested() {
        run_semihosting(runner);
    }
    log::to_rtt_only();

    let mut inbound = Inbound::new(rx);
    loop {
        inbound.poll(|frame| runner.on_frame(frame));
        let due = ticker.take_due();
        if due > 0 {
            runner.on_timer(due);
        }
        // Sleep until the next interrupt, with interrupts masked around the check so
        // one that fires in between still wakes the WFI.
        cortex_m::interrupt::free(|_| {
            if !ticker.is_due() && !inbound.has_data() {
                cortex_m::asm::wfi();
            }
        });
    }
}

/// The in-the-loop mode over semihosting (QEMU only, see [`semihosting`]): block in
/// SYS_READ for the host's frames, answer each, and hand the tick's frames to the host in
/// one SYS_WRITE before reading again. The host is the only clock here (no watchdog
/// steps: the read blocks); when it goes away (end of file) QEMU is asked to exit.
fn run_semihosting(mut runner: Runner) -> ! {
    usart::capture();
    // The host is the clock: the loop timer's interrupt would only land in the middle of
    // ticks (and, in QEMU, at host-speed-dependent places).
    nvic::disable(Irq::Tim5);
    let (Some(input), Some(output)) = (
        semihosting::open(b"sweephold-in\0", false),
        semihosting::open(b"sweephold-out\0", true),
    ) else {
        defmt::error!("semihosting FIFOs missing");
        semihosting::exit()
    };
    if !log::to_semihosting() {
        defmt::warn!("no sweephold-log file on the host: defmt stays on RTT");
    }
    defmt::info!("frame link over semihosting");
    // The boot Header went to the USART before the switch: this one tells the host the
    // link is up.
    runner.announce();
    let mut decoder = sweephold_protocol::Decoder::new();
    let mut received = [0u8; 256];
    loop {
        send_captured(output);
        let count = semihosting::read(input, &mut received);
        if count == 0 {
            semihosting::exit();
        }
        decoder.feed_with(received.get(..count).unwrap_or(&[]), |frame| {
            runner.on_frame(frame);
            // After every frame, so the transmit ring (1 KiB, a tick needs ~400 B)
            // never fills: its writer would wait for room forever.
            send_captured(output);
        });
    }
}

/// Hand everything queued in the transmit ring to the host; ask QEMU to exit if the
/// host is gone.
fn send_captured(output: usize) {
    let mut outgoing = [0u8; 512];
    loop {
        let count = usart::take_captured(&mut outgoing);
        if count == 0 {
            return;
        }
        if !semihosting::write(output, outgoing.get(..count).unwrap_or(&[])) {
            semihosting::exit();
        }
    }
}
