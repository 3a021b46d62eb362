//! Are the Cramér–Rao bounds honest? Fly the default Bo-105 campaign (mode cah) with 20
//! seeds, identify each one with the single verbs (`frf`, `fit` 6-DOF, `fit` 9-DOF hybrid
//! started from it with `--reduce`; unlike `sweephold campaign`, no trim points and the
//! `frf` defaults), and compare, per key parameter,
//! the spread of the 20 estimates (sample standard deviation σ) with the mean Cramér–Rao
//! bound the fits reported for it (CR_abs = CR % · |value| / 100). A bound is honest when
//! σ / mean(CR_abs) lies within [1/3, 3]. Prints the table; exits non-zero when a
//! ratio is outside.
//!
//! Beside the ratio it prints each parameter's truth (the simulator's linearization, from
//! `fit --truth bo105`) and the mean error against it: the bias, which no bound covers;
//! and it counts the seeds whose nine key parameters are all within 10 % of the truth and
//! those whose reduced model still keeps a free parameter with a Cramér–Rao bound above
//! 20 % or an insensitivity above 10 % (the per-seed lines name them), and those whose
//! every angular-rate pair (p, q, r) lies within J 20 of the truth's response (the
//! per-seed lines name the farthest).
//!
//! Run: `cargo bench -p sweephold --bench cr_honesty` (about 2 minutes on 2 cores).
//! `SWEEPHOLD_CR_SEEDS=N` changes the number of seeds; `SWEEPHOLD_CR_FLY_ARGS="..."` adds
//! arguments to every `fly` (e.g. `--perfect-sensors`, to see which biases the sensor noise
//! causes), `SWEEPHOLD_CR_FRF_ARGS="..."` to every `frf` (e.g. `--estimator sweep-reference`).

use std::path::Path;
use std::time::Instant;

const KEY_PARAMETERS: [&str; 9] = [
    "tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Mf_lat", "Mf_lon", "Lf_lat", "Lf_lon",
];

mod support;
use support::run_sweephold as run;

/// One key parameter of one fit.
struct Estimate {
    value: f64,
    /// Cramér–Rao bound in the parameter's units.
    bound: f64,
    /// The simulator's value (NaN when the model has no truth section).
    truth: f64,
}

/// A model.json, parsed.
fn read_model(model_json: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(model_json).expect("model.json written");
    serde_json::from_str(&text).expect("model.json parses")
}

/// Value, CR bound (absolute) and truth of each key parameter in a model.json.
fn key_estimates(document: &serde_json::Value) -> Vec<Estimate> {
    let parameters = document["parameters"].as_array().expect("parameters");
    let truths = document["truth"]["parameters"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    KEY_PARAMETERS
        .iter()
        .map(|name| {
            let entry = parameters
                .iter()
                .find(|p| p["name"] == *name)
                .unwrap_or_else(|| panic!("{name} in model.json"));
            let value = entry["value"].as_f64().expect("value");
            let cramer_rao = entry["cramer_rao_percent"].as_f64().unwrap_or(f64::NAN);
            let truth = truths
                .iter()
                .find(|p| p["name"] == *name)
                .and_then(|p| p["truth"].as_f64())
                .unwrap_or(f64::NAN);
            Estimate {
                value,
                bound: cramer_rao * value.abs() / 100.0,
                truth,
            }
        })
        .collect()
}

/// The free parameters of a reduced model.json that still break a guideline (Cramér–Rao
/// bound above 20 % or insensitivity above 10 % of the value).
fn flagged_free_parameters(document: &serde_json::Value) -> Vec<String> {
    let percent = |p: &serde_json::Value, key: &str| p[key].as_f64().unwrap_or(f64::INFINITY);
    document["parameters"]
        .as_array()
        .expect("parameters")
        .iter()
        .filter(|p| p["status"] == "free")
        .filter(|p| {
            percent(p, "cramer_rao_percent") > 20.0 || percent(p, "insensitivity_percent") > 10.0
        })
        .filter_map(|p| p["name"].as_str().map(str::to_string))
        .collect()
}

/// The angular-rate pair (output p, q or r) whose identified response is farthest from
/// the truth's: its name and the cost J between the two over the pair's range (the bar is
/// J ≤ 20 for every such pair).
fn worst_rate_pair_truth_cost(document: &serde_json::Value) -> Option<(String, f64)> {
    document["truth"]["pairs"]
        .as_array()?
        .iter()
        .filter(|p| matches!(p["output"].as_str(), Some("p" | "q" | "r")))
        .filter_map(|p| {
            let name = format!("{}/{}", p["output"].as_str()?, p["input"].as_str()?);
            Some((name, p["cost"].as_f64()?))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
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
    let mut estimates: Vec<Vec<Estimate>> = Vec::new();
    let (mut seeds_all_within_ten, mut seeds_flagged) = (0usize, 0usize);
    let mut seeds_rate_pairs_within_twenty = 0usize;
    let started = Instant::now();
    for seed in 1..=seeds {
        let dir = scratch.join(format!("seed-{seed}"));
        let d = |name: &str| dir.join(name).display().to_string();
        let seed_text = seed.to_string();
        let extra = std::env::var("SWEEPHOLD_CR_FLY_ARGS").unwrap_or_default();
        let out_dir = d("");
        let mut fly_args = vec!["fly", "--seed", &seed_text, "--quiet", "--out", &out_dir];
        fly_args.extend(extra.split_whitespace());
        run(binary, &fly_args);
        // Sorted: records of an axis are joined in the order given, and read_dir's order
        // is the file system's (seed 18 fitted differently in another order).
        let mut dumps: Vec<String> = std::fs::read_dir(&dir)
            .expect("fly wrote its folder")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "bin"))
            .map(|p| p.display().to_string())
            .collect();
        dumps.sort();
        let frf_extra = std::env::var("SWEEPHOLD_CR_FRF_ARGS").unwrap_or_default();
        let mut frf_args = vec!["frf", "--quiet"];
        frf_args.extend(frf_extra.split_whitespace());
        frf_args.push("--out");
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
                "--truth",
                "bo105",
                "--out",
                &m9,
            ],
        );
        let reduced_model = read_model(Path::new(&m9));
        let keys = key_estimates(&reduced_model);
        let flagged = flagged_free_parameters(&reduced_model);
        let all_within_ten = keys
            .iter()
            .all(|e| (e.value - e.truth).abs() <= 0.1 * e.truth.abs());
        seeds_all_within_ten += usize::from(all_within_ten);
        seeds_flagged += usize::from(!flagged.is_empty());
        let worst_rate_pair = worst_rate_pair_truth_cost(&reduced_model);
        seeds_rate_pairs_within_twenty +=
            usize::from(worst_rate_pair.as_ref().is_some_and(|(_, j)| *j <= 20.0));
        eprintln!(
            "seed {seed}/{seeds} ({:.0} s): {}{}{}{}",
            started.elapsed().as_secs_f64(),
            KEY_PARAMETERS
                .iter()
                .zip(&keys)
                .map(|(name, estimate)| format!("{name} {:.4}", estimate.value))
                .collect::<Vec<_>>()
                .join(", "),
            if all_within_ten {
                ""
            } else {
                "; not all within 10 %"
            },
            if flagged.is_empty() {
                String::new()
            } else {
                format!("; flagged {}", flagged.join(" "))
            },
            worst_rate_pair.map_or(String::new(), |(name, j)| format!(
                "; worst rate pair {name}, truth J {j:.1}"
            ))
        );
        estimates.push(keys);
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&scratch);

    println!(
        "{:<8} {:>12} {:>12} {:>14} {:>8} {:>12} {:>8}",
        "param", "mean", "std (σ)", "mean CR bound", "σ / CR", "truth", "bias %"
    );
    let mut honest = true;
    for (k, name) in KEY_PARAMETERS.iter().enumerate() {
        let values: Vec<f64> = estimates.iter().map(|e| e[k].value).collect();
        let bounds: Vec<f64> = estimates.iter().map(|e| e[k].bound).collect();
        let truth = estimates.first().map_or(f64::NAN, |e| e[k].truth);
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        // Sample standard deviation: √(Σ(x − x̄)² / (n − 1)).
        let std = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let mean_bound = bounds.iter().sum::<f64>() / n;
        let ratio = std / mean_bound;
        let ok = ratio.is_finite() && (1.0 / 3.0..=3.0).contains(&ratio);
        honest &= ok;
        let bias_percent = 100.0 * (mean - truth) / truth.abs();
        println!(
            "{name:<8} {mean:>12.5} {std:>12.5} {mean_bound:>14.5} {ratio:>8.2} {truth:>12.5} {bias_percent:>+8.1}{}",
            if ok { "" } else { "  outside [1/3, 3]" }
        );
    }
    println!(
        "seeds with all nine key parameters within 10 % of the truth: {seeds_all_within_ten}/{seeds}; \
         reduced models keeping a free parameter with CR > 20 % or insensitivity > 10 %: {seeds_flagged}/{seeds}"
    );
    println!(
        "seeds whose every angular-rate pair is within truth J 20: {seeds_rate_pairs_within_twenty}/{seeds}"
    );
    println!(
        "{seeds} seeds in {:.0} s; bounds {}",
        started.elapsed().as_secs_f64(),
        if honest { "honest" } else { "NOT honest" }
    );
    if !honest {
        std::process::exit(1);
    }
}
