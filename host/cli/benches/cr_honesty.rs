//! Are the Cramér–Rao bounds honest? Fly the default Bo-105 campaign (mode cah) with 20
//! seeds, identify each one the way `sweephold campaign` does (frequency responses, 6-DOF
//! fit, 9-DOF hybrid fit started from it with `--reduce`), and compare, per key parameter,
//! the spread of the 20 estimates (sample standard deviation σ) with the mean Cramér–Rao
//! bound the fits reported for it (CR_abs = CR % · |value| / 100). A bound is honest when
//! σ / mean(CR_abs) lies within [1/3, 3] (issue 7). Prints the table; exits non-zero when a
//! ratio is outside.
//!
//! Run: `cargo bench -p sweephold --bench cr_honesty` (about 2 minutes on 2 cores).
//! `SWEEPHOLD_CR_SEEDS=N` changes the number of seeds.

use std::path::Path;
use std::time::Instant;

const KEY_PARAMETERS: [&str; 9] = [
    "tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Mf_lat", "Mf_lon", "Lf_lat", "Lf_lon",
];

mod support;
use support::run_sweephold as run;

/// (value, CR bound in absolute units) of each key parameter in a model.json.
fn key_estimates(model_json: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(model_json).expect("model.json written");
    let document: serde_json::Value = serde_json::from_str(&text).expect("model.json parses");
    let parameters = document["parameters"].as_array().expect("parameters");
    KEY_PARAMETERS
        .iter()
        .map(|name| {
            let entry = parameters
                .iter()
                .find(|p| p["name"] == *name)
                .unwrap_or_else(|| panic!("{name} in model.json"));
            let value = entry["value"].as_f64().expect("value");
            let cramer_rao = entry["cramer_rao_percent"].as_f64().unwrap_or(f64::NAN);
            (value, cramer_rao * value.abs() / 100.0)
        })
        .collect()
}

fn main() {
    let binary = env!("CARGO_BIN_EXE_sweephold");
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sysid/models");
    let six = models.join("bo105-6dof.toml");
    let nine = models.join("bo105-9dof-hybrid.toml");
    let seeds: u64 = std::env::var("SWEEPHOLD_CR_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let scratch = std::env::temp_dir().join(format!("sweephold-cr-honesty-{}", std::process::id()));
    let mut estimates: Vec<Vec<(f64, f64)>> = Vec::new();
    let started = Instant::now();
    for seed in 1..=seeds {
        let dir = scratch.join(format!("seed-{seed}"));
        let d = |name: &str| dir.join(name).display().to_string();
        let seed_text = seed.to_string();
        run(
            binary,
            &["fly", "--seed", &seed_text, "--quiet", "--out", &d("")],
        );
        // Sorted: records of an axis are joined in the order given, and read_dir's order
        // is the file system's (seed 18 fitted differently in another order).
        let mut dumps: Vec<String> = std::fs::read_dir(&dir)
            .expect("fly wrote its folder")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "bin"))
            .map(|p| p.display().to_string())
            .collect();
        dumps.sort();
        let mut frf_args = vec!["frf", "--quiet", "--out"];
        let frf = d("frf.json");
        frf_args.push(&frf);
        frf_args.extend(dumps.iter().map(String::as_str));
        run(binary, &frf_args);
        let (m6, m9) = (d("m6.json"), d("m9.json"));
        let six_text = six.display().to_string();
        let nine_text = nine.display().to_string();
        run(
            binary,
            &["fit", "--frf", &frf, "--model", &six_text, "--out", &m6],
        );
        run(
            binary,
            &[
                "fit",
                "--frf",
                &frf,
                "--model",
                &nine_text,
                "--start-from",
                &m6,
                "--reduce",
                "--out",
                &m9,
            ],
        );
        let keys = key_estimates(Path::new(&m9));
        eprintln!(
            "seed {seed}/{seeds} ({:.0} s): {}",
            started.elapsed().as_secs_f64(),
            KEY_PARAMETERS
                .iter()
                .zip(&keys)
                .map(|(name, (value, _))| format!("{name} {value:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        estimates.push(keys);
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&scratch);

    println!(
        "{:<8} {:>12} {:>12} {:>14} {:>8}",
        "param", "mean", "std (σ)", "mean CR bound", "σ / CR"
    );
    let mut honest = true;
    for (k, name) in KEY_PARAMETERS.iter().enumerate() {
        let values: Vec<f64> = estimates.iter().map(|e| e[k].0).collect();
        let bounds: Vec<f64> = estimates.iter().map(|e| e[k].1).collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        // Sample standard deviation: √(Σ(x − x̄)² / (n − 1)).
        let std = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let mean_bound = bounds.iter().sum::<f64>() / n;
        let ratio = std / mean_bound;
        let ok = ratio.is_finite() && (1.0 / 3.0..=3.0).contains(&ratio);
        honest &= ok;
        println!(
            "{name:<8} {mean:>12.5} {std:>12.5} {mean_bound:>14.5} {ratio:>8.2}{}",
            if ok { "" } else { "  outside [1/3, 3]" }
        );
    }
    println!(
        "{seeds} seeds in {:.0} s; bounds {}",
        started.elapsed().as_secs_f64(),
        if honest { "honest" } else { "NOT honest" }
    );
    if !honest {
        std::process::exit(1);
    }
}
