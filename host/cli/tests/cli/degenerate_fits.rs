//! Degenerate minima (issue 42): a fit whose parameters land orders of magnitude outside
//! what a helicopter's model can hold is never written as a success. Two valid command
//! lines that were refused with a misleading trim-point message ("the trim points do not
//! vary what `Nr` multiplies") now run again with those parameters held and give a model
//! inside the physical ranges; where that fails, one line names the worst parameters.

use std::path::Path;

use sysid::fit::plausible::implausible_parameters;

use crate::support::{sweephold, Scratch};

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("degenerate-{name}")))
    }
}

/// The parameters of `model.json` at `path` outside the physical ranges of its shipped
/// structure (judged by the library's rule on the file's values).
fn outside_physical_ranges(path: &Path) -> Vec<String> {
    let document: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let name = document["structure"].as_str().unwrap();
    let structure = sysid::models::shipped(name)
        .unwrap_or_else(|| panic!("{name} is shipped"))
        .parse()
        .unwrap();
    let mut values = structure.values();
    for parameter in document["parameters"].as_array().unwrap() {
        if let Some(index) = structure.parameter_index(parameter["name"].as_str().unwrap()) {
            values[index] = parameter["value"].as_f64().unwrap();
        }
    }
    implausible_parameters(&structure, &values)
        .into_iter()
        .map(|p| format!("{} = {}", p.name, p.value))
        .collect()
}

#[test]
fn an_adaptive_board_sim_campaign_whose_hybrid_went_degenerate_completes() {
    // Seed 4: on main the hybrid's trim rounds drove it into a degenerate minimum and the
    // rank check blamed the points ("do not vary what `Nv` multiplies"), exit 1.
    let dir = TempDir::new("campaign");
    let out = dir.0.join("c");
    let run = sweephold(&[
        "campaign",
        "--quick",
        "--amplitude",
        "adaptive",
        "--fc",
        "board-sim",
        "--seed",
        "4",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    let outside = outside_physical_ranges(&out.join("model9.json"));
    assert!(outside.is_empty(), "{outside:?}");
}

#[test]
fn the_six_dof_from_an_equation_error_start_with_trim_points_is_recovered_or_refused() {
    let dir = TempDir::new("fit");
    let campaign = dir.0.join("c");
    let run = sweephold(&["campaign", "--quick", "--out", campaign.to_str().unwrap()]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let frf = campaign.join("frf.json");
    let points = campaign.join("trim-points.csv");
    let fit = |seed: &str, out: &Path| {
        sweephold(&[
            "fit",
            "--frf",
            frf.to_str().unwrap(),
            "--model",
            "bo105-6dof",
            "--equation-error-start",
            "--trim-points",
            points.to_str().unwrap(),
            "--seed",
            seed,
            "--out",
            out.to_str().unwrap(),
        ])
    };

    // Seed 5: the search lands outside (X_ped, M_ped, M_lat, L_col of 10⁵–10⁶ among 14);
    // held at the file's values, the fit gives a model inside every range, the held ones
    // reported. (Of fit seeds 1–8 on this campaign, 3, 5, 7 and 8 are recovered so, the
    // others refused as seed 1 below; held at the equation-error start's values instead,
    // only 5 and 8 were.)
    let model = dir.0.join("m6.json");
    let run = fit("5", &model);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("a degenerate minimum put parameters outside their physical range"),
        "{stdout}"
    );
    let outside = outside_physical_ranges(&model);
    assert!(outside.is_empty(), "{outside:?}");
    let document: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert!(document["average_cost"].as_f64().unwrap() <= 100.0);
    assert!(!document["implausible_held"].as_array().unwrap().is_empty());

    // Seed 1: the runs with held parameters land outside too: refused in one line naming
    // the worst parameters, no model written.
    let refused = dir.0.join("refused.json");
    let run = fit("1", &refused);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: the fit is degenerate: `"),
        "{stderr}"
    );
    assert!(stderr.contains("(|value| <= "), "{stderr}");
    assert!(!refused.exists());
}

/// The shipped TREX 700L's aircraft file with its servo's natural frequency put on the
/// upper bound of its structure's `servo_omega` (1000 rad/s) with a σ of 0.01 rad/s: the
/// prior holds the estimate on the bound from any start, so the 9-DOF model stays
/// degenerate after its restarts elsewhere (a model no search can bring off the bound).
fn servo_on_its_bound() -> String {
    let shipped = aircraft::SHIPPED
        .iter()
        .find(|(name, _)| *name == "trex700l")
        .expect("the TREX 700L is shipped")
        .1;
    let from = "natural_frequency = \"60 rad/s\"";
    assert!(
        shipped.contains(from),
        "the shipped file's servo line moved"
    );
    shipped.replace(from, "natural_frequency = \"1000 +- 0.01 rad/s\"")
}

#[test]
fn a_degenerate_model_is_marked_and_strict_runs_exit_non_zero() {
    let dir = TempDir::new("strict");
    let priors = dir.0.join("servo-on-bound.toml");
    std::fs::write(&priors, servo_on_its_bound()).unwrap();
    let campaign = |out: &Path, strict: bool| {
        let mut args = vec![
            "campaign",
            "--vehicle",
            "trex700l",
            "--priors",
            priors.to_str().unwrap(),
            "--quick",
            "-q",
            "--out",
            out.to_str().unwrap(),
        ];
        if strict {
            args.push("--strict");
        }
        sweephold(&args)
    };

    // Without --strict: written, marked in model9.json, summary.json and the report, and
    // one warning line.
    let out = dir.0.join("c");
    let run = campaign(&out, false);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("warning: ")
            && stderr.contains(
                "model9.json is degenerate: `servo_omega` = 1000 on its upper bound 1000"
            ),
        "{stderr}"
    );
    let read = |path: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    };
    let model = read(&out.join("model9.json"));
    let reasons = model["degenerate"]
        .as_array()
        .expect("model9.json `degenerate`");
    assert_eq!(reasons.len(), 1, "{reasons:?}");
    assert_eq!(reasons[0]["parameter"], "servo_omega");
    assert_eq!(reasons[0]["reason"], "on_upper_bound");
    assert_eq!(reasons[0]["limit"], 1000.0);
    // The search ran again elsewhere before giving up, with the seeds recorded.
    assert_eq!(model["degenerate_restarts"].as_array().unwrap().len(), 3);
    let summary = read(&out.join("summary.json"));
    assert_eq!(summary["fit"]["degenerate"], model["degenerate"]);
    // The report: the degenerate row, and no bar of the model marked met.
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("degenerate minimum"), "no degenerate row");
    let bars = report
        .split("id=\"campaign-summary\"")
        .nth(1)
        .expect("the campaign summary section");
    let model_bars = &bars
        [bars.find("degenerate minimum").unwrap()..bars.find("wall time of the campaign").unwrap()];
    assert!(model_bars.contains("J_ave"), "{model_bars}");
    assert!(!model_bars.contains("class=\"good\""), "{model_bars}");

    // With --strict: the same files, exit 1 with one `error:` line.
    let strict = dir.0.join("strict");
    let run = campaign(&strict, true);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: ")
            && stderr.contains("is degenerate")
            && stderr.contains("--strict"),
        "{stderr}"
    );
    assert!(strict.join("model9.json").is_file());

    // identify on the campaign's dumps with the same aircraft file: the same model,
    // marked; --strict exits 1.
    let logs: Vec<String> = ["fly-cah", "verify-doublet"]
        .iter()
        .map(|d| out.join(d).to_str().unwrap().to_string())
        .collect();
    let identify = |out: &Path, strict: bool| {
        let mut args = vec!["identify", logs[0].as_str(), logs[1].as_str()];
        args.extend(["--vehicle", priors.to_str().unwrap(), "-q", "--out"]);
        args.push(out.to_str().unwrap());
        if strict {
            args.push("--strict");
        }
        sweephold(&args)
    };
    let identified = dir.0.join("i");
    let run = identify(&identified, false);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("warning: "), "{stderr}");
    let summary = read(&identified.join("summary.json"));
    assert_eq!(summary["fit"]["degenerate"][0]["parameter"], "servo_omega");
    let run = identify(&dir.0.join("i-strict"), true);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
}
