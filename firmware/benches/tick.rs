//! Benchmark: one control tick of the flight controller, telemetry encoding included, in
//! the Sweep phase. Target ≤ 2 µs per tick on the host CPU.
//!
//! The controller is driven through arming and trim capture into the sweep, then timed in
//! batches of ticks (one `Instant` pair per batch keeps the timer's own cost out of the
//! figure); the per-tick mean of each batch is collected and the median reported. The
//! sensor input moves the roll attitude through the hold band so that the hysteresis and
//! the PID run too, and the sink copies the encoded bytes like a UART DMA buffer would.

use std::hint::black_box;
use std::time::Instant;

use sweephold_firmware::{Config, FlightController, FrameSink};
use sweephold_protocol::{Axis, Phase, SensorIn};

/// Target time per tick [ns].
const TARGET_NS: f64 = 2000.0;
const TICKS_PER_BATCH: u32 = 100;
const BATCHES: usize = 400;

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

fn sensor(seq: u32, rate_hz: f64) -> SensorIn {
    let t = f64::from(seq) / rate_hz;
    let mut input = SensorIn {
        seq,
        ..SensorIn::default()
    };
    input.pilot.test_switch = true;
    // Roll swinging ±8° at 0.5 rad/s: crosses the 4°/6° band both ways.
    input.meas.phi = (0.14 * (0.5 * t).sin()) as f32;
    input.meas.p = (0.07 * (0.5 * t).cos()) as f32;
    input.meas.theta = 0.03;
    input.meas.az = -9.81;
    input
}

fn main() {
    let mut config = Config::bo105_default(Axis::Lat);
    // Long record, so that every timed tick is inside the Sweep phase.
    config.test.sweep.t_rec_s = 600.0;
    let rate = f64::from(config.rate_hz);
    let mut fc = match FlightController::new(config) {
        Ok(fc) => fc,
        Err(error) => {
            eprintln!("configuration refused: {error}");
            std::process::exit(1);
        }
    };
    let mut sink = CopySink {
        buffer: [0; 4096],
        used: 0,
    };
    let mut seq = 0u32;
    while fc.phase() != Phase::Sweep {
        seq += 1;
        let mut input = sensor(seq, rate);
        // Calm attitude while the trim is captured.
        input.meas.phi = 0.0;
        input.meas.p = 0.0;
        fc.step(&input, &mut sink);
        if seq > 10_000 {
            eprintln!("never reached the Sweep phase");
            std::process::exit(1);
        }
    }

    let mut per_tick_ns = Vec::with_capacity(BATCHES);
    for _ in 0..BATCHES {
        let inputs: Vec<SensorIn> = (0..TICKS_PER_BATCH)
            .map(|_| {
                seq += 1;
                sensor(seq, rate)
            })
            .collect();
        let start = Instant::now();
        for input in &inputs {
            black_box(fc.step(black_box(input), &mut sink));
        }
        let elapsed = start.elapsed().as_nanos() as f64;
        per_tick_ns.push(elapsed / f64::from(TICKS_PER_BATCH));
    }
    assert_eq!(
        fc.phase(),
        Phase::Sweep,
        "left the Sweep phase while timing"
    );
    per_tick_ns.sort_by(f64::total_cmp);
    let median = per_tick_ns[per_tick_ns.len() / 2];
    println!(
        "tick (Sweep phase, CAH + noise, Sample encoded): median {median:.0} ns per tick \
         over {BATCHES} batches of {TICKS_PER_BATCH} ticks; {:.3} x the 2 µs target",
        median / TARGET_NS
    );
}
