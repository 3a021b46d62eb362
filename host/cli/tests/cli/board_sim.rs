//! `fly --fc board-sim`: the board's sensor-to-servo stack (firmware `board_stack`) flown
//! against the emulated IMU and an SBUS stream. The figures checked here are the board
//! application's bars (estimator error, attitude after the test, abort reasons and latency); the values
//! measured are in docs/board-application.md.

use std::path::Path;

use serde_json::Value;

use crate::support::{sweephold, Scratch};

fn scratch(name: &str) -> Scratch {
    Scratch::unmade(&format!("board-sim-{name}"))
}

/// Fly `args` (plus `--fc board-sim --axes lat --t-rec 30 -q --out DIR`) and return the
/// summary.
fn fly(dir: &Path, args: &[&str]) -> Value {
    let out = dir.to_str().unwrap();
    let mut all = vec![
        "fly",
        "--fc",
        "board-sim",
        "--axes",
        "lat",
        "--t-rec",
        "30",
        "-q",
        "--out",
        out,
    ];
    all.extend_from_slice(args);
    let output = sweephold(&all);
    assert!(
        output.status.success(),
        "{all:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let summary: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(summary["link"], "board-sim");
    assert_eq!(summary["runs"].as_array().unwrap().len(), 2);
    summary
}

fn deg(run: &Value, section: &str, field: &str, axis: &str) -> f64 {
    run[section][field][axis].as_f64().unwrap()
}

/// The lateral sweeps fly to the end; the estimate stays within 1.5° of the simulated
/// aircraft through the excitation (rotor vibration on), and the pilot mode holds the
/// aircraft within 10° for the 10 s after the test. The dumps decode and give frequency
/// responses as the in-process link's do.
#[test]
fn lateral_sweeps_fly_with_the_board_stack_and_the_pilot_mode_holds_after() {
    let dir = scratch("lat");
    let summary = fly(&dir, &["--seed", "3", "--fly-on", "10"]);
    for run in summary["runs"].as_array().unwrap() {
        let file = run["file"].as_str().unwrap();
        assert_eq!(run["aborted"], false, "{file}: {}", run["abort_reason"]);
        for axis in ["phi", "theta"] {
            let error = deg(run, "estimator", "max_error_deg", axis);
            assert!(error <= 1.5, "{file}: estimator {axis} error {error} deg");
            let after = deg(run, "after", "max_abs_deg", axis);
            assert!(after <= 10.0, "{file}: after the test |{axis}| {after} deg");
        }
        assert_eq!(run["after"]["mode"], "pilot", "{file}");
        assert_eq!(run["after"]["duration_s"], 10.0, "{file}");
        let decoded = sweephold(&["decode", dir.join(file).to_str().unwrap(), "-q"]);
        assert!(decoded.status.success(), "{file} decodes");
    }
    let frf = sweephold(&[
        "frf",
        dir.join("lat-1.bin").to_str().unwrap(),
        dir.join("lat-2.bin").to_str().unwrap(),
        "--out",
        dir.join("frf.json").to_str().unwrap(),
    ]);
    assert!(
        frf.status.success(),
        "frf: {}",
        String::from_utf8_lossy(&frf.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// No SBUS frame from 15 s on: the receiver's 100 ms timeout aborts the test with
/// `rc_lost`, and the receiver failsafe holds the aircraft within 15° for 10 s.
#[test]
fn receiver_loss_aborts_with_rc_lost_and_the_failsafe_holds_the_aircraft() {
    let dir = scratch("rc-loss");
    let summary = fly(&dir, &["--seed", "3", "--rc-loss", "15", "--fly-on", "10"]);
    for run in summary["runs"].as_array().unwrap() {
        let file = run["file"].as_str().unwrap();
        assert_eq!(run["abort_reason"], "rc_lost", "{file}");
        let at = run["duration_s"].as_f64().unwrap();
        assert!((15.09..=15.12).contains(&at), "{file}: aborted at {at} s");
        assert_eq!(run["after"]["mode"], "rc_failsafe", "{file}");
        for axis in ["phi", "theta"] {
            let after = deg(run, "after", "max_abs_deg", axis);
            assert!(after <= 15.0, "{file}: after the loss |{axis}| {after} deg");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The IMU's data registers freeze at 15 s: the monitor's stuck check aborts the test
/// with `imu_fault` within 50 ms.
#[test]
fn a_stuck_imu_aborts_with_imu_fault_within_50_ms() {
    let dir = scratch("stuck");
    let summary = fly(&dir, &["--seed", "3", "--imu-fault", "stuck@15"]);
    for run in summary["runs"].as_array().unwrap() {
        let file = run["file"].as_str().unwrap();
        assert_eq!(run["abort_reason"], "imu_fault", "{file}");
        let latency = run["duration_s"].as_f64().unwrap() - 15.0;
        assert!(
            (0.0..=0.05).contains(&latency),
            "{file}: {latency} s after the fault"
        );
        assert!(run.get("after").is_none(), "{file}: no --fly-on, no after");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same seed gives the same bytes through the whole stack.
#[test]
fn the_same_seed_gives_byte_identical_dumps() {
    let (a, b) = (scratch("seed-a"), scratch("seed-b"));
    for dir in [&a, &b] {
        let output = sweephold(&[
            "fly",
            "--fc",
            "board-sim",
            "--axes",
            "lon",
            "--t-rec",
            "5",
            "--seed",
            "11",
            "-q",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert!(output.status.success());
    }
    for name in ["lon-1.bin", "lon-2.bin", "summary.json"] {
        let (x, y) = (
            std::fs::read(a.join(name)).unwrap(),
            std::fs::read(b.join(name)).unwrap(),
        );
        assert!(x.len() > 1000, "{name}: {} bytes", x.len());
        assert_eq!(x, y, "{name} differs between two runs of seed 11");
    }
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

/// Board-only flags without the board, bad fault specs and rates, and a board without an
/// IMU: one-line errors with their exit statuses.
#[test]
fn bad_board_sim_command_lines_are_one_line_errors() {
    let dir = scratch("errors");
    let out = dir.to_str().unwrap();
    let cases: [(&[&str], i32, &str); 9] = [
        (
            &["--vibration", "none"],
            1,
            "--vibration is for --fc board-sim only",
        ),
        (
            &["--rc-loss", "3"],
            1,
            "--rc-loss is for --fc board-sim only",
        ),
        (
            &["--imu-fault", "stuck@1"],
            1,
            "--imu-fault is for --fc board-sim only",
        ),
        (&["--fly-on", "3"], 1, "--fly-on is for --fc board-sim only"),
        (
            &["--fc", "board-sim", "--imu-fault", "hot@3"],
            2,
            "unknown IMU fault",
        ),
        (
            &["--fc", "board-sim", "--imu-fault", "stuck"],
            2,
            "needs a time",
        ),
        (&["--fc", "board-sim", "--fly-on", "-1"], 2, "from 0 to 600"),
        (
            &["--fc", "board-sim", "--rate", "300"],
            1,
            "divides the IMU's 1000 Hz",
        ),
        (
            &[
                "--fc",
                "board-sim",
                "--imu-fault",
                "missing",
                "--t-rec",
                "5",
            ],
            1,
            "IMU did not start",
        ),
    ];
    for (args, code, needle) in cases {
        let mut all = vec!["fly", "--axes", "lat", "-q", "--out", out];
        all.extend_from_slice(args);
        let output = sweephold(&all);
        let stderr = String::from_utf8_lossy(&output.stderr).trim().to_string();
        assert_eq!(output.status.code(), Some(code), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.starts_with("error"), "{args:?}: {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
