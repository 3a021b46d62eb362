//! Real-time factor of the Bo-105 simulation: 1 ms internal RK4 steps, a 5 ms loop
//! (`step(0.005, …)`), 20 s of simulated hover with small stick inputs per repetition.
//! Prints the median ratio of simulated time to wall time over the repetitions and its
//! ratio to the 2000× target. On a shared machine the wall clock also counts time the
//! thread spent waiting for a core, so the ratio to the thread's own CPU time (Linux
//! `/proc/thread-self/schedstat`, nanoseconds on a core) is printed beside it.
//! Run: `cargo bench -p rotorsim --bench realtime`.

use std::hint::black_box;
use std::time::Instant;

use rotorsim::{trim, Helicopter, Sim, SimOptions};

const SIMULATED_S: f64 = 20.0;
const LOOP_DT: f64 = 0.005;
const REPETITIONS: usize = 15;
const TARGET: f64 = 2000.0;

/// Nanoseconds this thread has spent on a CPU (Linux), if readable.
fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() {
    let heli = Helicopter::bo105();
    let trimmed = trim(&heli, 0.0).expect("Bo-105 hover trim");
    let ticks = (SIMULATED_S / LOOP_DT).round() as usize;
    let mut ratios = Vec::with_capacity(REPETITIONS);
    let mut cpu_ratios = Vec::with_capacity(REPETITIONS);
    for repetition in 0..REPETITIONS {
        let options = SimOptions {
            seed: repetition as u64,
            ..SimOptions::default()
        };
        let mut sim = Sim::at_trim(heli.clone(), &trimmed, options);
        let cpu_start = thread_cpu_ns();
        let start = Instant::now();
        for tick in 0..ticks {
            // A small 1 Hz lateral/longitudinal doublet-like input keeps the rotor working.
            let phase = (tick as f64 * LOOP_DT * std::f64::consts::TAU).sin() * 0.01;
            let mut controls = trimmed.controls;
            controls[0] += phase;
            controls[1] -= phase;
            black_box(sim.step(LOOP_DT, black_box(controls)));
        }
        let wall = start.elapsed().as_secs_f64();
        ratios.push(sim.time() / wall);
        if let (Some(a), Some(b)) = (cpu_start, thread_cpu_ns()) {
            cpu_ratios.push(sim.time() / ((b - a) as f64 * 1e-9));
        }
    }
    let wall_median = median(&mut ratios);
    println!(
        "bo105 realtime: {SIMULATED_S} s simulated per run, 1 ms RK4 steps, 5 ms loop, \
         {REPETITIONS} runs"
    );
    println!(
        "  wall clock: median {wall_median:.0}x real time (min {:.0}x, max {:.0}x); \
         target {TARGET}x -> ratio {:.2}",
        ratios[0],
        ratios[ratios.len() - 1],
        wall_median / TARGET
    );
    if !cpu_ratios.is_empty() {
        let cpu_median = median(&mut cpu_ratios);
        println!(
            "  thread CPU time: median {cpu_median:.0}x real time; target {TARGET}x -> ratio {:.2}",
            cpu_median / TARGET
        );
    }
}
