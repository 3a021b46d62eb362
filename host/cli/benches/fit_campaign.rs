//! The fit stage on real campaign data, as `sweephold fit` runs it: fly the default Bo-105
//! campaign (mode cah, seed 1) and compute its frequency responses once (with the built
//! `sweephold`), then time, in process, the 6-DOF fit followed by the 9-DOF hybrid fit from
//! its Eq. 26–27 starts and from the file's starts, with `--reduce`. Prints the median of
//! the pair of fits over the repeats and its ratio to the 5 s target (one core), with the
//! J_ave reached.
//!
//! Run: `cargo bench -p sweephold --bench fit_campaign`

use std::path::Path;
use std::time::{Duration, Instant};

use sysid::document::FrfDocument;
use sysid::fit::{
    fit, fit_from_alternative_starts, start_from_quasi_steady, FitOptions, ModelStructure,
};

const TARGET: Duration = Duration::from_secs(5);
const REPEATS: usize = 3;

mod support;
use support::run_sweephold as run;

fn main() {
    let binary = env!("CARGO_BIN_EXE_sweephold");
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sysid/models");
    let dir = std::env::temp_dir().join(format!("sweephold-fit-bench-{}", std::process::id()));
    let dir_text = dir.display().to_string();
    run(
        binary,
        &["fly", "--quiet", "--out", &dir_text].map(String::from),
    );
    let mut frf_args: Vec<String> = ["frf", "--quiet", "--out"].map(String::from).to_vec();
    let frf_path = dir.join("frf.json");
    frf_args.push(frf_path.display().to_string());
    for entry in std::fs::read_dir(&dir).expect("fly wrote its folder") {
        let path = entry.expect("folder entry").path();
        if path.extension().is_some_and(|x| x == "bin") {
            frf_args.push(path.display().to_string());
        }
    }
    run(binary, &frf_args);
    let data: FrfDocument =
        serde_json::from_str(&std::fs::read_to_string(&frf_path).expect("frf.json"))
            .expect("frf.json parses");
    let _ = std::fs::remove_dir_all(&dir);
    let six = ModelStructure::from_path(&models.join("bo105-6dof.toml")).expect("6-DOF file");
    let nine =
        ModelStructure::from_path(&models.join("bo105-9dof-hybrid.toml")).expect("9-DOF file");

    let mut totals = Vec::with_capacity(REPEATS);
    let mut six_times = Vec::with_capacity(REPEATS);
    let mut costs = (0.0, 0.0);
    for _ in 0..REPEATS {
        let start = Instant::now();
        let six_fit = fit(&six, &data, &FitOptions::default()).expect("6-DOF fit");
        six_times.push(start.elapsed());
        let (started, _) =
            start_from_quasi_steady(&nine, &six_fit.to_document()).expect("start values");
        let options = FitOptions {
            reduce: true,
            ..FitOptions::default()
        };
        let starts = [
            ("6-DOF".to_string(), started),
            ("file".to_string(), nine.clone()),
        ];
        let (nine_fit, _) =
            fit_from_alternative_starts(&starts, &data, &options).expect("9-DOF fit");
        totals.push(start.elapsed());
        costs = (six_fit.average_cost, nine_fit.average_cost);
    }
    totals.sort();
    six_times.sort();
    let median = totals[REPEATS / 2];
    println!(
        "6-DOF J_ave {:.1}, 9-DOF (reduced) J_ave {:.1}",
        costs.0, costs.1
    );
    println!(
        "fit 6-DOF + 9-DOF on campaign data: median {:.3} s over {REPEATS} runs (6-DOF part {:.3} s), target {:.1} s, ratio {:.3}",
        median.as_secs_f64(),
        six_times[REPEATS / 2].as_secs_f64(),
        TARGET.as_secs_f64(),
        median.as_secs_f64() / TARGET.as_secs_f64()
    );
}
