//! The control loop: boot sequence, the two run modes, and the tick itself.
//!
//! **Board application** (from boot): TIM5 ticks at the IMU rate (1 kHz). Every tick
//! reads the ICM-42688-P over SPI1 into the board stack (monitor, boot calibration,
//! filters, attitude estimate); every fifth, at the flight logic's 200 Hz, the control
//! tick takes the SBUS bytes USART2 received, runs the board application (Disarmed →
//! stabilised pilot mode → Test → pilot mode, with the receiver and IMU failsafes), puts
//! its pulses on the four servos and the ESC, and streams its telemetry: a Header at
//! boot, one Sample per tick, the sequencer's Events and the board's own (mode changes,
//! the IMU's health, refused requests; protocol 1.4). An image whose IMU does not answer
//! (or under QEMU, where nothing is on the bus) reports it missing on its first tick and
//! refuses to arm. The board's clock for the receiver's timeouts is the tick count.
//!
//! Each processed IMU sample feeds the independent watchdog ([`crate::chip::watchdog`]),
//! which the first one starts: a loop that stops processing fresh samples resets the
//! board into Disarmed with the throttle cut (while the IMU failsafe flies, its control
//! ticks feed it instead).
//!
//! **In the loop** (hardware in the loop, entered by the host's first SensorIn or
//! Configure frame **while the board application is disarmed**): the host is the clock.
//! Every SensorIn is exactly one tick of the in-the-loop flight logic (a sequencer of
//! its own, separate from the board application's): its Sample and Events go out, then
//! an ActuatorOut answering the SensorIn's `seq` — the last frame of the tick, so the
//! host knows the tick's telemetry is complete when it arrives. Lockstep keeps a
//! simulation deterministic whatever the emulator's or the host's speed. A Header goes
//! out when the mode is entered, so a dump recorded from that point on starts with one.
//! From then on the receiver is not read, the ESC stays at the throttle cut, and the
//! servos follow the host's simulation until the next reset. TIM5 keeps running as the
//! link watchdog: after [`LINK_TIMEOUT_S`] without a SensorIn the loop steps on its own
//! again at the control rate, on the last SensorIn, whose unchanging `seq` makes the
//! flight logic's stale-sensor check abort any running test to pilot pass-through; the
//! next SensorIn resumes lockstep. Every SensorIn feeds the watchdog.
//!
//! **Armed, a host frame is ignored.** A SensorIn or Configure arriving while the board
//! application is armed (any mode but Disarmed) is dropped: hardware in the loop is
//! chosen on the ground, never a takeover in flight. The first such frame of each armed
//! period is reported with an Event (`HostLinkIgnored`), every one is counted.
//!
//! **Parameters** (protocol 1.5): the board application (and the in-the-loop flight
//! logic's first configuration) is built from the typed view of the table the store held
//! at boot, its servo timers run at the table's frame rates, and the store's status goes
//! out as an Event after the boot Header. ParamRequest frames are answered through
//! [`crate::image::params`] in the board application while it is disarmed (refused as
//! armed otherwise, and in the loop); a List is answered one reply per control tick. A
//! Set or Reset is applied on the next disarmed control tick (`Runner::apply_params`);
//! a Save stretches the watchdog around the flash erase.
//!
//! **Bench tools**: after every control tick the status LED shows the board
//! application's pilot cue (`sweephold_firmware::app::cues`). A ServoTest frame
//! (protocol 1.8) puts one servo at a pulse while the board application is disarmed with a
//! valid parameter set (`sweephold_firmware::servo_test`): the control tick replaces that
//! servo's pulse until the request's hold passes without another request, and never on an
//! armed tick (a test running when the board arms ends there, reported).
//!
//! **Configure** (protocol 1.1): a [`LinkConfig`] from the host replaces the in-the-loop
//! configuration at run time. The image builds the preset of the frame's vehicle for
//! its test's primary axis, puts the frame's rate and test in, and restarts the flight
//! logic on it (tick 0); a configuration the flight logic refuses leaves the running
//! one in place. Either way a [`ConfigureResult`] answers, preceded by the new Header
//! when accepted, and the loop is in the loop from then on (the Header is the mode
//! entry's, so the first SensorIn does not send another).

use embedded_hal::pwm::SetDutyCycle;
use sweephold_firmware::app::cues::StatusLed;
use sweephold_firmware::app::Mode as AppMode;
use sweephold_firmware::board_stack::{BoardStack, BootState, ImuStep, IMU_RATE_HZ};
use sweephold_firmware::params::Params;
use sweephold_firmware::servo_test::ServoTester;
use sweephold_firmware::FlightController;
use sweephold_protocol::{
    ActuatorOut, ConfigureResult, Controls, Event, Frame, FrameError, Header, HostFrame,
    LinkConfig, ParamRequest, SensorIn, ServoTest, ServoTestRefusal,
};

use crate::boards::BOARD;
use crate::chip::clocks::{ClockSource, Clocks};
use crate::chip::delay::BusyDelay;
use crate::chip::devices::{self, Devices};
use crate::chip::dividers;
use crate::chip::gpio::GpioOutput;
use crate::chip::imu_device::{self, ImuDevice};
use crate::chip::logport;
use crate::chip::nvic::{self, Irq};
use crate::chip::sbus_uart::{self, SbusRx};
use crate::chip::servo::{self, ServoChannel, Servos, ESC_CUT_US};
use crate::chip::ticker::Ticker;
use crate::chip::usart::{self, UsartTx};
use crate::chip::watchdog::Watchdog;
use crate::image::config::{fallback_params, link_config};
use crate::image::link::{self, FrameScratch, Inbound, Telemetry};
use crate::image::log;
use crate::image::params::HostParams;
use crate::image::semihosting;

mod host_frames;

/// Host silence after which the loop steps on its own again [s].
pub const LINK_TIMEOUT_S: u32 = 1;

/// Seconds between two status lines in the defmt log.
const STATUS_PERIOD_S: u32 = 10;

/// The loop timer's rate: the IMU's sample rate [Hz].
const TIMER_HZ: u32 = IMU_RATE_HZ as u32;

/// Microseconds per loop-timer tick: the board's clock advances by this much per tick.
const US_PER_TIMER_TICK: u32 = 1_000_000 / TIMER_HZ;

/// The board's stack on its devices.
type Stack = BoardStack<ImuDevice, BusyDelay>;

/// How the loop is paced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Mode {
    /// The board application: TIM5 paces the IMU and the control tick.
    BoardApplication,
    /// Host in the loop: one tick per SensorIn.
    InTheLoop {
        /// Timer ticks since the last SensorIn.
        silent_ticks: u32,
    },
}

/// Counters for the status log.
#[derive(Clone, Copy, Debug, Default, defmt::Format)]
pub struct LoopStats {
    /// Flight-logic steps run (either mode).
    pub steps: u32,
    /// Timer ticks that came while the previous one was still being served.
    pub overruns: u32,
    /// Times the host went quiet for longer than the link timeout.
    pub link_timeouts: u32,
    /// Good frames from the host that are not obeyed (other kinds, or armed).
    pub ignored_frames: u32,
    /// Frames from the host that failed COBS, CRC or decoding.
    pub bad_frames: u32,
    /// Configure frames accepted.
    pub reconfigured: u32,
    /// Configure frames refused.
    pub refused: u32,
    /// IMU polls that failed on the bus.
    pub imu_errors: u32,
}

/// The flight logic and its outputs.
pub struct Runner {
    /// The board application on the IMU and the receiver.
    stack: Stack,
    sbus: SbusRx,
    /// The SBUS bytes a control tick takes from the receive ring: kept here, so that a
    /// tick does not clear a fresh 256-byte stack buffer (~130 instructions).
    sbus_bytes: [u8; sbus_uart::RX_CAPACITY],
    /// The in-the-loop flight logic.
    fc: FlightController,
    servos: Servos<ServoChannel>,
    esc: ServoChannel,
    tx: UsartTx,
    mode: Mode,
    /// The in-the-loop input of the last tick.
    input: SensorIn,
    /// Timer ticks per control tick.
    control_period: u32,
    /// Timer ticks since the last control tick.
    since_control: u32,
    /// The board's clock [µs] (wraps after 71 min; its users take differences).
    now_us: u32,
    link_timeout_ticks: u32,
    status_period_ticks: u32,
    ticks_since_status: u32,
    stats: LoopStats,
    /// A host frame was ignored and reported in this armed period.
    host_ignored_reported: bool,
    /// Where frames are encoded before they go into the transmit ring.
    scratch: FrameScratch,
    /// Fed by every fresh sample (board application: an IMU sample; in the loop: a
    /// SensorIn).
    watchdog: Watchdog,
    /// The parameter table the host's ParamRequest frames read and set.
    params: HostParams,
    /// The clock tree (the servo timers' dividers).
    clocks: Clocks,
    /// The status LED: the board application's pilot cue after every control tick.
    led: Option<StatusLed<GpioOutput>>,
    /// The bench servo test (protocol 1.8), disarmed only.
    servo_test: ServoTester,
}

impl Runner {
    /// Send the Header of the mode's flight logic.
    fn announce(&mut self) {
        match self.mode {
            Mode::BoardApplication => self.send_header(self.stack.app().header()),
            Mode::InTheLoop { .. } => self.announce_in_the_loop(),
        }
    }

    /// Send the Header of the in-the-loop flight logic.
    fn announce_in_the_loop(&mut self) {
        self.send_header(self.fc.header());
    }

    fn send_header(&mut self, header: Header) {
        if !link::send(&mut self.tx, &mut self.scratch, &Frame::Header(header)) {
            defmt::warn!("header frame dropped");
        }
    }

    /// One timer tick's IMU sample for the board stack. Never inlined: a symbol of its
    /// own for `docs/board_tick_instructions.py`.
    #[inline(never)]
    fn imu_tick(&mut self, due: u32) {
        imu_device::before_poll(
            self.stack.imu_spi_mut(),
            due.saturating_mul(US_PER_TIMER_TICK),
        );
        match self.stack.imu_sample(self.now_us) {
            ImuStep::Estimated(_) => self.watchdog.fed_by_fresh_sample(),
            ImuStep::Error(_) => self.stats.imu_errors = self.stats.imu_errors.wrapping_add(1),
            ImuStep::NotPolled | ImuStep::NotReady | ImuStep::Calibration(_) => {}
        }
    }

    /// One control tick of the board application. Never inlined: a symbol of its own for
    /// `docs/board_tick_instructions.py`.
    #[inline(never)]
    fn control_tick(&mut self) {
        self.apply_params();
        let count = self.sbus.take(&mut self.sbus_bytes);
        let tick = self.stack.app().flight_controller().tick();
        log::set_tick(tick);
        let out = self.stack.control_tick(
            self.now_us,
            self.sbus_bytes.get(..count).unwrap_or(&[]),
            &mut Telemetry::new(&mut self.tx, &mut self.scratch),
        );
        // A bench servo test replaces one pulse while disarmed, never armed.
        let mut servo_us = out.servo_us;
        if let Some(end) = self.servo_test.apply(!out.mode.is_armed(), &mut servo_us) {
            link::send_waiting(&mut self.tx, &mut self.scratch, &Frame::ServoTestReply(end));
        }
        // Infallible: the channels write compare registers.
        let _ = self.servos.apply(servo_us);
        let _ = self.esc.set_duty_cycle(out.esc_us);
        if let Some(led) = &mut self.led {
            led.show(self.stack.app().status_led());
        }
        self.stats.steps = self.stats.steps.wrapping_add(1);
        if !out.mode.is_armed() {
            self.host_ignored_reported = false;
        }
        if out.mode == AppMode::ImuFailsafe {
            // The IMU is gone and the failsafe flies without it: see `crate::chip::watchdog`.
            self.watchdog.fed_by_failsafe_tick();
        }
        if let Some(reason) = out.abort {
            defmt::warn!("test aborted: {=str}", reason.name());
        }
        if out.refused.is_some() {
            defmt::warn!("request refused in mode {=str}", out.mode.name());
        }
    }

    /// On the ground, the parameters as the host left them: the pre-arm flag (a save
    /// makes the set valid), and a table changed by a Set or Reset rebuilt into the
    /// board application (restarted Disarmed on it, its Header sent, the failsafe
    /// pulses its mixer's). Armed, nothing changes: a change waits for the ground (the
    /// link refuses them armed anyway). A set the typed view or the stack refuses (a
    /// push half-way through, servo limits crossing their centre for a moment) keeps
    /// the running configuration until a later change makes it whole.
    fn apply_params(&mut self) {
        if !self.stack.app().host_link_allowed() {
            return;
        }
        self.stack.set_params_valid(self.params.valid());
        if !self.params.take_changed() {
            return;
        }
        let applied = self
            .params
            .params()
            .map_err(|error| error.message())
            .and_then(|params| {
                self.stack
                    .reconfigure(params.stack)
                    .map_err(|error| error.message())?;
                self.apply_frame_rates(&params);
                Ok(())
            });
        match applied {
            Ok(()) => {
                let neutral = sweephold_firmware::mix(
                    &self.stack.config().app.flight.mixer,
                    &Controls::default(),
                );
                servo::set_failsafe(neutral);
                defmt::info!("parameters applied");
                self.send_header(self.stack.app().header());
            }
            Err(message) => defmt::warn!("parameters not applied yet: {=str}", message),
        }
    }

    /// The servo frame rates of `params` on the output timers (a rate the dividers
    /// refuse, never expected for 50–333 Hz, keeps the running ones and is logged).
    fn apply_frame_rates(&mut self, params: &Params) {
        let (swash_hz, tail_hz) = (
            u32::from(params.swash_frame_hz),
            u32::from(params.tail_frame_hz),
        );
        match self.servos.set_frame_rates(&self.clocks, swash_hz, tail_hz) {
            Ok(()) => defmt::info!(
                "servo frames: swash {=u32} Hz, tail {=u32} Hz",
                swash_hz,
                tail_hz
            ),
            Err(error) => defmt::warn!("servo frame rates refused: {}", error),
        }
    }

    /// One in-the-loop tick on the last input; answers the SensorIn `reply_to` with an
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
        self.since_control = self.since_control.saturating_add(due);
        let control_due = self.since_control >= self.control_period;
        if control_due {
            self.since_control = 0;
            let disarmed = self.params_allowed();
            self.params
                .on_control_tick(disarmed, &mut self.tx, &mut self.scratch);
        }
        match self.mode {
            Mode::BoardApplication => {
                self.now_us = self
                    .now_us
                    .wrapping_add(due.saturating_mul(US_PER_TIMER_TICK));
                self.imu_tick(due);
                if control_due {
                    self.control_tick();
                }
            }
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
                    if control_due {
                        self.step(None);
                    }
                }
            }
        }
        self.ticks_since_status = self.ticks_since_status.saturating_add(due);
        if self.ticks_since_status >= self.status_period_ticks {
            self.ticks_since_status = 0;
            self.log_status();
        }
    }

    /// The periodic status line of the defmt log.
    fn log_status(&self) {
        let app = self.stack.app();
        defmt::info!(
            "mode {} app {=str} imu samples {=u32} sbus frames {=u32} line errors {=u32} lost {=u32} {} tx dropped {=u32} rx lost {=u32} log dropped {=u32}",
            self.mode,
            app.mode().name(),
            self.stack.samples(),
            self.stack.sbus().stats().frames,
            sbus_uart::line_errors(),
            sbus_uart::lost(),
            self.stats,
            self.tx.dropped_frames(),
            usart::rx_lost(),
            logport::dropped()
        );
    }
}

/// Bring the board up and run the loop forever.
pub fn run() -> ! {
    let Devices {
        mut boot,
        servos,
        esc,
        tx,
        rx,
        sbus,
        imu,
        watchdog,
        flash,
        tim5,
        led,
    } = devices::bring_up(&BOARD);
    let clocks = boot.clocks;

    let params = HostParams::boot(flash);
    defmt::info!(
        "parameter store: {}",
        sweephold_firmware::params::link::store_status(params.status())
    );
    let flown = params.params().unwrap_or_else(|error| {
        defmt::error!("parameter set refused: {=str}", error.message());
        fallback_params()
    });
    let fc = match FlightController::new(flown.stack.app.flight) {
        Ok(fc) => fc,
        Err(error) => defmt::panic!("flight configuration refused: {=str}", error.message()),
    };
    let mut stack = match Stack::new(imu, BusyDelay::new(clocks.hclk_hz), flown.stack) {
        Ok(stack) => stack,
        Err(error) => defmt::panic!("board configuration refused: {=str}", error.message()),
    };
    stack.set_params_valid(params.valid());
    if !params.valid() {
        defmt::warn!("no valid parameter set stored: defaults, arming refused until a save");
    }
    // From now on a panic or fault puts the servos where the mixer puts centred sticks:
    // the board application's disarmed output.
    let neutral = sweephold_firmware::mix(&fc.config().mixer, &Controls::default());
    servo::set_failsafe(neutral);
    defmt::info!("failsafe pulses {} us", neutral);
    let rate_hz = u32::from(stack.app().header().rate_hz);
    let Some(control_period) = dividers::ticks_per_control(TIMER_HZ, rate_hz) else {
        defmt::panic!(
            "control rate {=u32} Hz does not divide the IMU rate",
            rate_hz
        )
    };
    match stack.boot() {
        Ok(()) => defmt::info!("IMU up: calibrating the gyro (keep the aircraft still)"),
        Err(_) => defmt::error!("IMU does not answer: arming refused"),
    }
    if let BootState::InitFailed(_) = stack.boot_state() {
        defmt::warn!("no IMU: the board streams telemetry but will not arm");
    }
    let mut runner = Runner {
        stack,
        sbus,
        sbus_bytes: [0; sbus_uart::RX_CAPACITY],
        fc,
        servos,
        esc,
        tx,
        mode: Mode::BoardApplication,
        input: SensorIn::default(),
        control_period,
        since_control: 0,
        now_us: 0,
        link_timeout_ticks: LINK_TIMEOUT_S * TIMER_HZ,
        status_period_ticks: STATUS_PERIOD_S * TIMER_HZ,
        ticks_since_status: 0,
        stats: LoopStats::default(),
        host_ignored_reported: false,
        scratch: [0; sweephold_protocol::MAX_FRAME_LEN],
        watchdog,
        params,
        clocks,
        led,
        servo_test: ServoTester::default(),
    };
    runner.apply_frame_rates(&flown);
    runner.announce();
    let event = runner.params.store_event(0);
    link::send(&mut runner.tx, &mut runner.scratch, &Frame::Event(event));

    let ticker = match Ticker::start(tim5, &mut boot, TIMER_HZ) {
        Ok(ticker) => ticker,
        Err(error) => defmt::panic!("tick timer: {}", error),
    };
    defmt::info!(
        "loop timer at {=u32} Hz (timer gives {=u64} mHz), control tick every {=u32}",
        TIMER_HZ,
        ticker.achieved_millihz,
        control_period
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
        // What QEMU's USARTs need from thread mode (no TXE interrupt there); on silicon
        // the interrupts have sent the bytes already.
        usart::drain();
        logport::drain();
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
    // The boot Header went to the USART before the switch: this one, the in-the-loop
    // flight logic's, tells the host the link is up.
    runner.announce_in_the_loop();
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
    // The onboard log's UART too, outside the tick (see `crate::chip::usart`).
    logport::drain();
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
