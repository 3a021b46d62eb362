//! Trim points from the flight: `fly --fc board-sim --steady-flights` (the board's log of
//! the steady flights and the simulated GNSS) and `identify --steady-flights LOG --gnss CSV`
//! (the steady segments averaged into trim points), checked against the simulator's own
//! trims (`sim trim-points`), and the flag of a run with no velocity source.

use crate::support::sweephold;
use std::path::{Path, PathBuf};

fn ok(args: &[&str]) -> String {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert!(output.status.success(), "{args:?}: {stderr}");
    String::from_utf8_lossy(&output.stdout).to_string()
}

/// The one-line error of a run that must fail with exit status `code`.
fn one_line_error(args: &[&str], code: i32) -> String {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert_eq!(output.status.code(), Some(code), "{args:?}: {stderr}");
    if code == 1 {
        assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    }
    stderr
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sweephold-steady-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// A trim-point CSV's rows as (label, column → value).
fn rows(path: &Path) -> Vec<(String, std::collections::HashMap<String, f64>)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            let values = header[1..]
                .iter()
                .zip(&cells[1..])
                .map(|(h, c)| (h.to_string(), c.parse().unwrap()))
                .collect();
            (cells[0].to_string(), values)
        })
        .collect()
}

/// TREX 700L, seed 1: the sweeps (30 s, one power-up) and the steady flights.
fn flown(dir: &Path) -> (PathBuf, PathBuf) {
    let sweeps = dir.join("sweeps");
    let trex = [
        "--vehicle",
        "trex700l",
        "--seed",
        "1",
        "--fc",
        "board-sim",
        "-q",
    ];
    let mut args = vec![
        "fly",
        "--out",
        s(&sweeps),
        "--t-rec",
        "30",
        "--power-up",
        "once",
    ];
    args.extend_from_slice(&trex);
    ok(&args);
    let steady = dir.join("steady");
    let mut args = vec!["fly", "--out", s(&steady), "--steady-flights"];
    args.extend_from_slice(&trex);
    ok(&args);
    (sweeps.join("log"), steady)
}

#[test]
fn the_flights_steady_segments_give_the_simulators_trim_points() {
    let dir = scratch("points");
    let (log, steady) = flown(&dir);
    let steady_log = steady.join("log").join("power-up-1.bin");
    let gnss = steady.join("gnss.csv");
    assert!(steady_log.is_file() && gnss.is_file());
    // Deterministic: the same flight again gives the same bytes.
    let again = dir.join("steady-again");
    ok(&[
        "fly",
        "--out",
        s(&again),
        "--steady-flights",
        "--vehicle",
        "trex700l",
        "--seed",
        "1",
        "--fc",
        "board-sim",
        "-q",
    ]);
    for file in ["gnss.csv", "log/power-up-1.bin"] {
        assert_eq!(
            std::fs::read(steady.join(file)).unwrap(),
            std::fs::read(again.join(file)).unwrap(),
            "{file}"
        );
    }
    // 18 s per flight at 10 Hz: 180 fixes each.
    let fixes = std::fs::read_to_string(&gnss).unwrap().lines().count() - 1;
    assert_eq!(fixes, 9 * 180);

    let simulator = dir.join("simulator.csv");
    ok(&[
        "sim",
        "trim-points",
        "--vehicle",
        "trex700l",
        "--out",
        s(&simulator),
    ]);
    let out = dir.join("identified");
    ok(&[
        "identify",
        s(&log),
        "--vehicle",
        "trex700l",
        "--steady-flights",
        s(&steady_log),
        "--gnss",
        s(&gnss),
        "--out",
        s(&out),
        "-q",
    ]);
    let flight = rows(&out.join("trim-points.csv"));
    let truth = rows(&simulator);
    // Every one of the nine steady flights is found, and nothing else.
    assert_eq!(flight.len(), 9, "{flight:?}");
    let hover = |set: &[(String, std::collections::HashMap<String, f64>)]| set[0].1.clone();
    let (flight_hover, truth_hover) = (hover(&flight), hover(&truth));
    let mut matched = Vec::new();
    for (label, point) in &flight {
        // The simulator's point nearest in velocity and turn rate.
        let distance = |t: &std::collections::HashMap<String, f64>| {
            ["u", "v", "w", "r"]
                .iter()
                .map(|c| (point[*c] - t[*c]).powi(2))
                .sum::<f64>()
        };
        let (name, reference) = truth
            .iter()
            .min_by(|a, b| distance(&a.1).total_cmp(&distance(&b.1)))
            .unwrap();
        matched.push(name.clone());
        // Velocities: the GNSS's 0.1 m/s over ≥ 50 fixes averages to ≤ 0.014 m/s (1σ),
        // and the pilot holds the target within a few hundredths: 0.1 m/s is over 5σ
        // of the noise plus the hold.
        for c in ["u", "v", "w"] {
            let error = point[c] - reference[c];
            assert!(error.abs() <= 0.1, "{label} ({name}) {c}: {error:+.4} m/s");
            assert!(point[&format!("{c}_se")] < 0.03, "{label} {c}_se");
        }
        // Rates: the gyros' bias and noise averaged over ≥ 5 s.
        for c in ["p", "q", "r"] {
            let error = point[c] - reference[c];
            assert!(
                error.abs() <= 0.005,
                "{label} ({name}) {c}: {error:+.5} rad/s"
            );
        }
        // Attitude and commands about the hover (only differences enter the balance):
        // the estimator's bias cancels; 0.003 is a tenth of the smallest stick gradient.
        for (c, tolerance) in [
            ("phi", 0.003),
            ("theta", 0.003),
            ("lat", 0.003),
            ("lon", 0.003),
            ("ped", 0.003),
            ("col", 0.003),
        ] {
            let error = (point[c] - flight_hover[c]) - (reference[c] - truth_hover[c]);
            assert!(
                error.abs() <= tolerance,
                "{label} ({name}) {c}: {error:+.5}"
            );
        }
    }
    matched.sort();
    matched.dedup();
    assert_eq!(
        matched.len(),
        9,
        "each steady flight found once: {matched:?}"
    );

    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["trim_points_source"], "flight");
    assert_eq!(summary["trim_points"], "trim-points.csv");
    assert_eq!(summary["hover_derivatives_unanchored"], false);
    assert_eq!(summary["steady_segments"].as_array().unwrap().len(), 9);
    assert!(
        summary["fit"]["trim"]["points"] == 9,
        "{}",
        summary["fit"]["trim"]
    );
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("trim points from the flight: 9 steady segments"));
    assert!(!report.contains("Hover derivatives not anchored"));

    // No velocity source: the hover derivatives fitted, and flagged.
    let bare = dir.join("bare");
    ok(&[
        "identify",
        s(&log),
        "--vehicle",
        "trex700l",
        "--out",
        s(&bare),
        "-q",
    ]);
    let summary = json(&bare.join("summary.json"));
    assert_eq!(summary["trim_points_source"], "none");
    assert_eq!(summary["hover_derivatives_unanchored"], true);
    let report = std::fs::read_to_string(bare.join("report.html")).unwrap();
    assert!(report.contains("Hover derivatives not anchored"), "report");

    // Bad GNSS files: one line naming the file and the line.
    let bad = dir.join("bad.csv");
    let never = dir.join("never");
    let identify_with_bad_gnss = || {
        one_line_error(
            &[
                "identify",
                s(&log),
                "--vehicle",
                "trex700l",
                "--steady-flights",
                s(&steady_log),
                "--gnss",
                s(&bad),
                "--out",
                s(&never),
            ],
            1,
        )
    };
    for (text, message) in [
        (
            "t,vn,ve,vd,heading\n1,0,0,0,0\n",
            "line 1: the header must be `tick,vn,ve,vd,heading`",
        ),
        (
            "tick,vn,ve,vd,heading\n1,0,x,0,0\n",
            "line 2: `ve` is not a finite number: `x`",
        ),
    ] {
        std::fs::write(&bad, text).unwrap();
        let stderr = identify_with_bad_gnss();
        assert!(
            stderr.contains(&format!("{}: {message}", s(&bad))),
            "{stderr}"
        );
    }
    // Fixes that miss the log's steady flights (one, at power-on) leave no segment.
    std::fs::write(&bad, "tick,vn,ve,vd,heading\n1,0,0,0,0\n").unwrap();
    let stderr = identify_with_bad_gnss();
    assert!(
        stderr.contains("0 steady segment(s) of at least 5 s"),
        "{stderr}"
    );
    assert!(!dir.join("never").exists());
    // --gnss goes with --steady-flights, and trim points come from one source.
    one_line_error(
        &[
            "identify",
            s(&log),
            "--vehicle",
            "trex700l",
            "--gnss",
            s(&gnss),
            "--out",
            s(&dir.join("never")),
        ],
        2,
    );
    one_line_error(
        &[
            "identify",
            s(&log),
            "--vehicle",
            "trex700l",
            "--steady-flights",
            s(&steady_log),
            "--gnss",
            s(&gnss),
            "--trim-points",
            s(&simulator),
            "--out",
            s(&dir.join("never")),
        ],
        2,
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn steady_flights_are_for_the_board_sim_only() {
    let dir = scratch("refused");
    let stderr = one_line_error(
        &["fly", "--steady-flights", "--out", s(&dir.join("out"))],
        1,
    );
    assert!(
        stderr.contains("--steady-flights is for --fc board-sim only"),
        "{stderr}"
    );
    let stderr = one_line_error(
        &[
            "fly",
            "--fc",
            "board-sim",
            "--steady-flights",
            "--rc-loss",
            "5",
            "--out",
            s(&dir.join("out")),
        ],
        1,
    );
    assert!(
        stderr.contains("--rc-loss counts record time: --steady-flights flies no record"),
        "{stderr}"
    );
    assert!(!dir.join("out").exists());
    std::fs::remove_dir_all(&dir).ok();
}
