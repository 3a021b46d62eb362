//! The full default `sweephold fly` campaign: all 8 Bo-105 records of one mode (two 90 s
//! sweeps per axis at 200 Hz, firmware in the loop, frequency-response summaries), on
//! this 2-core machine. Target: at most 5 s of wall time.
//!
//! `cargo bench -p sweephold --bench fly`. Prints the median of three campaigns per mode.

use std::time::Instant;

use clap::Parser;
use sweephold::fly::link::InProcessLink;
use sweephold::{Cli, Command};

fn main() {
    let out = std::env::temp_dir().join(format!("sweephold-bench-fly-{}", std::process::id()));
    for mode in ["cah", "standard", "noise"] {
        let argv = [
            "sweephold",
            "fly",
            "--quiet",
            "--mode",
            mode,
            "--out",
            out.to_str().unwrap(),
        ];
        let Command::Fly(args) = Cli::parse_from(argv).command else {
            unreachable!()
        };
        let mut times = Vec::new();
        let mut flown_s = 0.0;
        for _ in 0..3 {
            let start = Instant::now();
            let outcome = sweephold::fly::fly(&args, &|| Box::new(InProcessLink::new()))
                .expect("campaign flies");
            times.push(start.elapsed().as_secs_f64());
            flown_s = outcome.summary.runs.iter().map(|r| r.duration_s).sum();
            assert_eq!(outcome.summary.runs.len(), 8);
        }
        times.sort_by(f64::total_cmp);
        let median = times[1];
        println!(
            "fly --mode {mode}: 8 records, {flown_s:.0} s of flight, median {median:.2} s wall ({:.0}x real time), {:.2}x the 5 s budget",
            flown_s / median,
            median / 5.0
        );
    }
    std::fs::remove_dir_all(&out).ok();
}
