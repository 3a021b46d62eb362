//! `fly --fc board-sim` and the airborne rule and the test's collective: a test switched
//! on with the collective down is refused `not_airborne` and nothing is excited; the
//! collective lowered during a lateral sweep aborts it with `landed`; with the collective
//! the pilot's (`[flight_controller] collective = "pilot"`), a collective stick step
//! during a lateral sweep reaches the servos (the command steps and the simulated
//! aircraft's vertical specific force answers), and with the trim collective it does not.

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

use crate::support::{sweephold, Scratch};

fn scratch(name: &str) -> Scratch {
    Scratch::unmade(&format!("board-sim-air-{name}"))
}

/// The shipped Bo-105 with the collective the pilot's during a test (the file of the
/// measurement in docs/results.md).
const PILOT_COLLECTIVE_BO105: &str = "../../docs/aircraft/bo105-pilot-collective.toml";

fn pilot_collective_bo105() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(PILOT_COLLECTIVE_BO105)
}

/// The shipped TREX 700L with the collective the pilot's (the file of the one-power-up
/// measurement in docs/results.md).
const PILOT_COLLECTIVE_TREX: &str = "../../docs/aircraft/trex700l-pilot-collective.toml";

#[test]
fn the_pilot_collective_files_are_the_shipped_files_but_for_the_collective() {
    for (file, first_line, shipped) in [
        (PILOT_COLLECTIVE_BO105, "# MBB Bo-105", 0),
        (PILOT_COLLECTIVE_TREX, "# A TREX 700L-class", 1),
    ] {
        let name = aircraft::SHIPPED[shipped].0;
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let text = std::fs::read_to_string(path).unwrap();
        let body: String = text
            .lines()
            .skip_while(|line| !line.starts_with(first_line))
            .map(|line| format!("{line}\n"))
            .collect();
        let back = body
            .replacen(
                &format!("name = \"{name}-pilot-collective\""),
                &format!("name = \"{name}\""),
                1,
            )
            .replacen(
                &format!("preset = \"{name}\"\ncollective = \"pilot\"\n"),
                &format!("preset = \"{name}\"\n"),
                1,
            );
        assert_eq!(back, aircraft::SHIPPED[shipped].1, "{file}");
    }
}

/// `fly --fc board-sim --axes lat --t-rec 10 -q --out OUT` plus `args`.
fn fly(out: &Path, args: &[&str]) -> Output {
    let mut all = vec![
        "fly",
        "--fc",
        "board-sim",
        "--axes",
        "lat",
        "--t-rec",
        "10",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    sweephold(&all)
}

fn summary(out: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap()
}

/// The dump's rows (`decode --format jsonl`).
fn rows(dump: &Path) -> Vec<Value> {
    let output = sweephold(&["decode", "--format", "jsonl", "-q", dump.to_str().unwrap()]);
    assert!(output.status.success(), "{dump:?} decodes");
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|line| serde_json::from_str(line).unwrap())
        .collect()
}

fn samples(rows: &[Value]) -> Vec<&Value> {
    rows.iter().filter(|r| r["type"] == "sample").collect()
}

fn f(row: &Value, key: &str) -> f64 {
    row[key].as_f64().unwrap()
}

#[test]
fn a_test_switched_on_with_the_collective_down_is_refused_not_airborne() {
    let out = scratch("ground");
    let output = fly(&out, &["--collective-step=-1@0"]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: ")
            && stderr.contains("refused the test (not_airborne): no test started"),
        "{stderr}"
    );
    let failed = out.with_extension("failed");
    let rows = rows(&failed.join("lat-1.bin"));
    assert!(rows.iter().all(|r| r["type"] != "header"), "no test began");
    let refusals: Vec<&Value> = rows.iter().filter(|r| r["event"] == "refused").collect();
    assert_eq!(refusals.len(), 1);
    assert_eq!(refusals[0]["request"], "test");
    assert_eq!(refusals[0]["check"], "not_airborne");
    let samples = samples(&rows);
    assert!(!samples.is_empty());
    for sample in samples {
        assert_eq!(sample["phase"], "idle");
        for axis in ["lat", "lon", "ped", "col"] {
            assert_eq!(f(sample, &format!("sweep_{axis}")), 0.0, "nothing excited");
        }
    }
    let _ = std::fs::remove_dir_all(&failed);
}

#[test]
fn lowering_the_collective_during_a_lateral_sweep_aborts_with_landed() {
    let out = scratch("landing");
    let file = pilot_collective_bo105();
    let output = fly(
        &out,
        &[
            "--vehicle",
            file.to_str().unwrap(),
            "--collective-step=-1@8",
        ],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for run in summary(&out)["runs"].as_array().unwrap() {
        let name = run["file"].as_str().unwrap();
        assert_eq!(run["abort_reason"], "landed", "{name}");
        // Lowered at 8 s, below AIR_COL_MIN for AIR_TIME (1 s).
        let at = f(run, "duration_s");
        assert!((9.0..=9.02).contains(&at), "{name}: aborted at {at} s");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The record's rows around record time 8 s (tick 1600 at 200 Hz): the collective
/// command just before and after the step, and the vertical specific force 0.1 s after.
fn around_the_step(dump: &Path) -> (f64, f64, f64, f64, Vec<String>) {
    let rows = rows(dump);
    let samples = samples(&rows);
    // Record ticks count from the record's first Sample.
    let at = |k: usize| samples[k];
    let before = at(1599);
    let after = at(1600);
    let later = at(1620);
    let phases = [before, after, later]
        .iter()
        .map(|s| s["phase"].as_str().unwrap().to_string())
        .collect();
    (
        f(before, "cmd_col"),
        f(after, "cmd_col"),
        f(before, "az"),
        f(later, "az"),
        phases,
    )
}

#[test]
fn with_the_pilot_collective_a_stick_step_during_a_lateral_sweep_reaches_the_servos() {
    let out = scratch("pilot-step");
    let file = pilot_collective_bo105();
    let output = fly(
        &out,
        &[
            "--vehicle",
            file.to_str().unwrap(),
            "--collective-step=0.1@8",
        ],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for run in summary(&out)["runs"].as_array().unwrap() {
        let name = run["file"].as_str().unwrap();
        assert_eq!(run["aborted"], false, "{name}: {}", run["abort_reason"]);
        let (before, after, az_before, az_later, phases) = around_the_step(&out.join(name));
        assert!(phases.iter().all(|p| p == "sweep"), "{name}: {phases:?}");
        assert!(
            (after - before - 0.1).abs() < 0.002,
            "{name}: collective {before} → {after}"
        );
        // Bo-105: Z_col ≈ −14.6 m/s² per stick: 0.1 stick ≈ −1.5 m/s² of specific force.
        assert!(
            az_later - az_before < -0.8,
            "{name}: a_z {az_before} → {az_later} m/s²"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn with_the_trim_collective_the_stick_does_not_reach_the_servos() {
    let out = scratch("trim-step");
    let output = fly(&out, &["--collective-step=0.05@8"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for run in summary(&out)["runs"].as_array().unwrap() {
        let name = run["file"].as_str().unwrap();
        assert_eq!(run["aborted"], false, "{name}");
        let (before, after, _, _, phases) = around_the_step(&out.join(name));
        assert!(phases.iter().all(|p| p == "sweep"), "{name}: {phases:?}");
        // The log holds the collective the three swash pulses express: the lateral
        // sweep's pulses round apart by up to half a µs each, 0.004 of collective at
        // most (the plate's inverse); the step would be 0.05.
        assert!(
            (after - before).abs() < 0.004,
            "{name}: the trim collective {before} → {after}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}
