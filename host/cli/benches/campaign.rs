//! The whole default `sweephold campaign` (Bo-105: 3 modes × 8 records of 90 s, held-out
//! doublets, frequency responses, 6-DOF and 9-DOF fits, truth, verification, report) on
//! this 2-core machine. Target: at most 30 s of wall time.
//!
//! `cargo bench -p sweephold --bench campaign [-- --vehicle trex700l] [-- --runs N]`.
//! Prints the median over the runs (default 3) of the total and of every stage, and the
//! ratio of the total to the 30 s target.

use std::collections::BTreeMap;

use clap::Parser;
use sweephold::artifacts::stage::Stage;
use sweephold::{Cli, Command};

const TARGET_S: f64 = 30.0;

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

fn main() {
    // `cargo bench` passes `--bench`; our own options follow `--`.
    let argv: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let option = |name: &str| {
        argv.iter()
            .position(|a| a == name)
            .and_then(|i| argv.get(i + 1).cloned())
    };
    let vehicle = option("--vehicle").unwrap_or_else(|| "bo105".to_string());
    let runs: usize = option("--runs")
        .and_then(|n| n.parse().ok())
        .unwrap_or(3)
        .max(1);
    let out = std::env::temp_dir().join(format!("sweephold-bench-campaign-{}", std::process::id()));
    let cli = Cli::parse_from([
        "sweephold",
        "campaign",
        "--quiet",
        "--vehicle",
        &vehicle,
        "--out",
        out.to_str().expect("temp path is UTF-8"),
    ]);
    let Command::Campaign(args) = cli.command else {
        unreachable!()
    };
    let mut stages: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut last = None;
    for run in 0..runs {
        let outcome = sweephold::campaign::campaign(&args).expect("the campaign completes");
        for (stage, seconds) in &outcome.summary.timings_s {
            stages.entry(stage.clone()).or_default().push(*seconds);
        }
        eprintln!(
            "run {}: {:.2} s",
            run + 1,
            outcome.summary.timings_s["total"]
        );
        last = Some(outcome.summary);
    }
    println!("campaign --vehicle {vehicle}: median of {runs} run(s), per stage:");
    for stage in Stage::ALL.map(Stage::name) {
        if let Some(values) = stages.get_mut(stage) {
            println!("  {stage:<17} {:>7.2} s", median(values));
        }
    }
    let total = median(stages.get_mut("total").expect("total timing"));
    println!(
        "  {:<17} {total:>7.2} s  ({:.2}x the {TARGET_S} s target)",
        "total",
        total / TARGET_S
    );
    if let Some(summary) = last {
        let coherence = |m: &Option<sweephold::artifacts::summary::ModeSummary>| {
            m.as_ref()
                .and_then(|m| m.cross_coherence_lat_lon)
                .map_or("-".to_string(), |c| format!("{c:.3}"))
        };
        println!(
            "  lat-lon coherence cah {} standard {} noise {}; J_ave {}; TIC p q r {}",
            coherence(&summary.modes.cah),
            coherence(&summary.modes.standard),
            coherence(&summary.modes.noise),
            summary
                .fit
                .as_ref()
                .map_or("-".to_string(), |f| format!("{:.1}", f.cost_ave)),
            summary
                .verify
                .as_ref()
                .map_or("-".to_string(), |v| ["p", "q", "r"]
                    .iter()
                    .map(|o| v.tic.get(*o).map_or("-".to_string(), |t| format!("{t:.3}")))
                    .collect::<Vec<_>>()
                    .join(" "))
        );
    }
    std::fs::remove_dir_all(&out).ok();
}
