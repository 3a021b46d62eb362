//! Benchmark: one tick of the board application, telemetry encoding included, in the
//! stabilised pilot mode and in a test's Sweep phase. Target ≤ 20 µs per tick on the host
//! CPU.
//!
//! The application is armed, spooled up and (for the second figure) driven through trim
//! capture into the sweep, then timed in batches of ticks (one `Instant` pair per batch
//! keeps the timer's own cost out of the figure); the per-tick mean of each batch is
//! collected and the median reported. The inputs move the attitude, the rates and the
//! sticks so that the loops, the heading hold and (in the sweep) the conditional hold
//! all run, and the sink copies the encoded bytes like a UART DMA buffer would.

use std::hint::black_box;
use std::time::Instant;

use sweephold_firmware::app::{AppConfig, BoardApp, ImuInput, Mode, RcInput, Receiver, TickInput};
use sweephold_firmware::FrameSink;
use sweephold_protocol::{Axis, Phase};

/// Target time per tick [ns].
const TARGET_NS: f64 = 20_000.0;
const TICKS_PER_BATCH: u32 = 100;
const BATCHES: usize = 400;
const RATE_HZ: f64 = 200.0;

/// A sink that copies the frame into a reused buffer (the work a DMA ring would cost).
struct CopySink {
    buffer: [u8; 4096],
    used: usize,
}

impl FrameSink for CopySink {
    fn write_frame(&mut self, bytes: &[u8]) {
        if self.used + bytes.len() > self.buffer.len() {
            self.used = 0;
        }
        if let Some(target) = self.buffer.get_mut(self.used..self.used + bytes.len()) {
            target.copy_from_slice(bytes);
            self.used += bytes.len();
        }
    }
}

/// The input of tick `n`: roll swinging ±8° at 0.5 rad/s (through the hold band), small
/// rates, pilot sticks near centre, pedal in the dead band (heading hold active).
fn input(n: u32, test_switch: bool) -> TickInput {
    let t = f64::from(n) / RATE_HZ;
    let mut imu = ImuInput::AT_REST;
    imu.phi = (0.14 * (0.5 * t).sin()) as f32;
    imu.p = (0.07 * (0.5 * t).cos()) as f32;
    imu.q = (0.02 * (0.3 * t).sin()) as f32;
    imu.r = (0.01 * (0.7 * t).sin()) as f32;
    imu.theta = 0.03;
    imu.psi = (0.05 * (0.2 * t).sin()) as f32;
    let mut rc = RcInput::NEUTRAL;
    rc.sticks.lat = (0.05 * (0.9 * t).sin()) as f32;
    rc.sticks.lon = -0.02;
    rc.sticks.ped = 0.01;
    rc.sticks.col = 0.3;
    rc.throttle = 0.8;
    rc.arm = true;
    rc.test_switch = test_switch;
    TickInput {
        imu,
        rc: Receiver::Valid(rc),
    }
}

/// Calm input for arming, spool-up and trim capture.
fn calm(arm: bool, throttle: f32, test_switch: bool) -> TickInput {
    let mut rc = RcInput::NEUTRAL;
    rc.sticks.col = 0.3;
    rc.throttle = throttle;
    rc.arm = arm;
    rc.test_switch = test_switch;
    TickInput {
        imu: ImuInput::AT_REST,
        rc: Receiver::Valid(rc),
    }
}

fn fail(message: &str) -> ! {
    eprintln!("{message}");
    std::process::exit(1);
}

/// Median time per tick [ns] of ticks with `test_switch`, from tick `n` on.
fn time_ticks(app: &mut BoardApp, sink: &mut CopySink, n: &mut u32, test_switch: bool) -> f64 {
    let mut per_tick_ns = Vec::with_capacity(BATCHES);
    for _ in 0..BATCHES {
        let inputs: Vec<TickInput> = (0..TICKS_PER_BATCH)
            .map(|_| {
                *n += 1;
                input(*n, test_switch)
            })
            .collect();
        let start = Instant::now();
        for tick_input in &inputs {
            black_box(app.tick(black_box(tick_input), sink));
        }
        let elapsed = start.elapsed().as_nanos() as f64;
        per_tick_ns.push(elapsed / f64::from(TICKS_PER_BATCH));
    }
    per_tick_ns.sort_by(f64::total_cmp);
    per_tick_ns[per_tick_ns.len() / 2]
}

fn main() {
    let mut config = AppConfig::trex700l(Axis::Lat);
    // Long record, so that every timed tick of the test is inside the Sweep phase.
    config.flight.test.sweep.t_rec_s = 600.0;
    let mut app = match BoardApp::new(config) {
        Ok(app) => app,
        Err(error) => fail(&format!("configuration refused: {error}")),
    };
    let mut sink = CopySink {
        buffer: [0; 4096],
        used: 0,
    };
    // Arm (switch off → on, throttle low), then spool up past the soft start.
    app.tick(&calm(false, 0.0, false), &mut sink);
    app.tick(&calm(true, 0.0, false), &mut sink);
    for _ in 0..1200 {
        app.tick(&calm(true, 0.8, false), &mut sink);
    }
    if app.mode() != Mode::Pilot {
        fail("not in the pilot mode after arming");
    }

    let mut n = 0u32;
    let pilot_ns = time_ticks(&mut app, &mut sink, &mut n, false);
    if app.mode() != Mode::Pilot {
        fail("left the pilot mode while timing");
    }

    // Test switch on; trim capture on calm input, then into the sweep.
    for _ in 0..10_000 {
        app.tick(&calm(true, 0.8, true), &mut sink);
        if app.flight_controller().phase() == Phase::Sweep {
            break;
        }
    }
    if app.flight_controller().phase() != Phase::Sweep {
        fail("never reached the Sweep phase");
    }
    let sweep_ns = time_ticks(&mut app, &mut sink, &mut n, true);
    if app.mode() != Mode::Test || app.flight_controller().phase() != Phase::Sweep {
        fail("left the Sweep phase while timing");
    }

    for (what, median) in [
        ("pilot mode (rate loops, heading hold)", pilot_ns),
        ("test, Sweep phase (CAH + noise)", sweep_ns),
    ] {
        println!(
            "app tick, {what}, Sample encoded: median {median:.0} ns per tick over \
             {BATCHES} batches of {TICKS_PER_BATCH} ticks; {:.3} x the 20 µs target",
            median / TARGET_NS
        );
    }
}
