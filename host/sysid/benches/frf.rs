//! Benchmark of the frequency-response chain (FRESPID → MISOSA → COMPOSITE).
//!
//! Workload: two record groups (a lateral and a longitudinal sweep), each one 180 s
//! record at 200 Hz (the paper's two 90 s runs joined), 4 controls — the swept one plus
//! off-axis noise on the three others, all excited so all four enter the conditioning —
//! and 9 outputs; 5 window lengths, 200 frequencies, MISO conditioning and composite.
//! Target: at most 0.5 s on one core. Prints the median of the repetitions and the
//! ratio median/target. A second line times the other reading of the workload: one
//! axis whose two 180 s records are joined into 360 s.
//!
//! Run: `cargo bench -p sysid --bench frf`

use std::time::{Duration, Instant};

use sysid::frf::{compute_frequency_responses, Channel, FrfOptions, Record, RecordGroup};

const RATE: f64 = 200.0;
const SECONDS: f64 = 180.0;
const TARGET: Duration = Duration::from_millis(500);
const REPETITIONS: usize = 9;

/// Uniform noise in [−1, 1): reproducible, from the crate's generator.
struct Noise(sysid::random::SplitMix64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0.symmetric()
    }
}

/// Tischler's exponential sweep, closed form, 0.3–31.4 rad/s over `SECONDS`.
fn sweep(t: f64) -> f64 {
    let (w0, w1, c1) = (0.3, 31.4, 4.0f64);
    let c2 = 1.0 / (c1.exp() - 1.0);
    let theta = w0 * t + (w1 - w0) * c2 * ((SECONDS / c1) * ((c1 * t / SECONDS).exp() - 1.0) - t);
    0.05 * theta.sin()
}

/// One record: `primary` swept, the other controls low-pass noise; each output a
/// different first-order lag of a mix of the controls, plus noise.
fn record(primary: usize, seed: u64) -> Record {
    let names = ["lat", "lon", "ped", "col"];
    let len = (SECONDS * RATE) as usize;
    let mut noise = Noise(sysid::random::SplitMix64::new(seed));
    let mut inputs: Vec<Vec<f64>> = (0..4).map(|_| Vec::with_capacity(len)).collect();
    let mut filtered = [0.0f64; 4];
    for k in 0..len {
        for (i, input) in inputs.iter_mut().enumerate() {
            filtered[i] += 0.05 * (noise.next() - filtered[i]);
            let value = if i == primary {
                sweep(k as f64 / RATE)
            } else {
                0.2 * filtered[i]
            };
            input.push(value);
        }
    }
    let outputs = ["u", "v", "w", "p", "q", "r", "ax", "ay", "az"]
        .iter()
        .enumerate()
        .map(|(o, name)| {
            let pole = (-(1.0 + o as f64) / RATE).exp();
            let mut state = 0.0;
            let values = (0..len)
                .map(|k| {
                    let drive: f64 = (0..4)
                        .map(|i| inputs[i][k] * (1.0 + ((o + i) % 3) as f64))
                        .sum();
                    state = pole * state + (1.0 - pole) * drive;
                    state + 0.001 * noise.next()
                })
                .collect();
            Channel::new(*name, values)
        })
        .collect();
    Record {
        source: format!("bench-{}", names[primary]),
        sample_rate_hz: RATE,
        primary: names[primary].into(),
        primary_guessed: false,
        sweep_band: Some([0.3, 31.4]),
        inputs: names
            .iter()
            .zip(inputs)
            .map(|(n, v)| Channel::new(*n, v))
            .collect(),
        outputs,
        references: Vec::new(),
        notes: Vec::new(),
        trim_samples: 0,
        measurement_filter: None,
    }
}

/// Time `compute_frequency_responses` on `groups`; returns (median, min, max, pairs).
fn measure(groups: &[RecordGroup], opts: &FrfOptions) -> (Duration, Duration, Duration, usize) {
    let mut times = Vec::with_capacity(REPETITIONS);
    let mut pairs = 0;
    for _ in 0..REPETITIONS {
        let start = Instant::now();
        let document = compute_frequency_responses(groups, opts).expect("responses");
        times.push(start.elapsed());
        pairs = document.pairs.len();
        assert_eq!(
            document.cross_coherence.len(),
            6 * groups.len(),
            "all four controls excited"
        );
    }
    times.sort();
    (
        times[REPETITIONS / 2],
        times[0],
        times[REPETITIONS - 1],
        pairs,
    )
}

fn report(label: &str, (median, min, max, pairs): (Duration, Duration, Duration, usize)) {
    println!(
        "frf [{label}]: median {:.1} ms over {REPETITIONS} runs (min {:.1}, max {:.1}), {pairs} MISO pairs; target {} ms; ratio {:.2}",
        median.as_secs_f64() * 1e3,
        min.as_secs_f64() * 1e3,
        max.as_secs_f64() * 1e3,
        TARGET.as_millis(),
        median.as_secs_f64() / TARGET.as_secs_f64()
    );
}

fn main() {
    let opts = FrfOptions::default();
    println!(
        "frf: 180 s records @ 200 Hz, 4 controls × 9 outputs, {} windows, {} frequencies, MISO + composite, one core",
        opts.windows, opts.points
    );
    // The target workload: a lateral and a longitudinal group, one 180 s record each.
    let two_axes = vec![
        RecordGroup::new(vec![record(0, 1)]).expect("valid record"),
        RecordGroup::new(vec![record(1, 2)]).expect("valid record"),
    ];
    report("2 axes × 1 record of 180 s", measure(&two_axes, &opts));
    // The other reading of "two 180 s records": one axis, both records joined (360 s).
    let one_axis = vec![RecordGroup::new(vec![record(0, 1), record(0, 3)]).expect("valid records")];
    report(
        "1 axis × 2 records of 180 s joined",
        measure(&one_axis, &opts),
    );
}
