//! A board's logs through `frf`, `fit` and `verify` (`fly --fc board-sim`: the board's own
//! IMU and estimate, no air data, u = v = w = 0): every test of a file made by
//! concatenating records, the structures reduced to the outputs measured, and only the
//! measured outputs scored.

use std::path::{Path, PathBuf};

use crate::support::{sweephold, Scratch};

fn ok(args: &[&str]) -> (String, String) {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert!(output.status.success(), "{args:?}: {stderr}");
    (String::from_utf8_lossy(&output.stdout).to_string(), stderr)
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("board-logs-{name}"))
}

/// `fly --fc board-sim --seed 1 -q --out DIR` plus `args`.
fn fly(dir: &Path, args: &[&str]) {
    let mut all = vec!["fly", "--fc", "board-sim", "--seed", "1", "-q", "--out"];
    all.push(dir.to_str().unwrap());
    all.extend_from_slice(args);
    ok(&all);
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn same_bytes(a: &Path, b: &Path) -> bool {
    std::fs::read(a).unwrap() == std::fs::read(b).unwrap()
}

fn concatenate(out: &Path, parts: &[PathBuf]) {
    let bytes: Vec<u8> = parts
        .iter()
        .flat_map(|p| std::fs::read(p).unwrap())
        .collect();
    std::fs::write(out, bytes).unwrap();
}

#[test]
fn frf_uses_every_completed_test_of_a_log_and_lists_each() {
    let dir = scratch("frf");
    let flights = dir.join("flights");
    fly(&flights, &["--axes", "lat,lon", "--t-rec", "30"]);
    let aborted = dir.join("aborted");
    fly(
        &aborted,
        &["--axes", "ped", "--t-rec", "30", "--rc-loss", "15"],
    );
    let records: Vec<PathBuf> = ["lat-1", "lon-1", "lat-2", "lon-2"]
        .iter()
        .map(|name| flights.join(format!("{name}.bin")))
        .collect();

    // The responses of the tests of one file are those of the files the tests came from.
    let log = dir.join("log.bin");
    concatenate(&log, &records);
    let (cat, sep) = (dir.join("cat.json"), dir.join("sep.json"));
    let (_, listing) = ok(&["frf", s(&log), "--out", s(&cat)]);
    let mut separate = vec!["frf", "-q", "--out", s(&sep)];
    separate.extend(records.iter().map(|p| s(p)));
    ok(&separate);
    assert!(same_bytes(&cat, &sep), "concatenated vs separate");
    for (number, axis) in [(1, "lat"), (2, "lon"), (3, "lat"), (4, "lon")] {
        let line = format!("log.bin: test {number}: {axis} Sweep, ConditionalAttitudeHold, ");
        let found = listing.lines().find(|l| l.contains(&line));
        assert!(
            found.is_some_and(|l| l.ends_with("s, completed: used")),
            "{line}\n{listing}"
        );
    }

    // An aborted test (receiver lost) and one cut off by the end of the file are listed
    // and left out: the responses stay those of the completed tests.
    let lat = std::fs::read(&records[0]).unwrap();
    let cut = dir.join("cut.bin");
    std::fs::write(&cut, &lat[..lat.len() / 2]).unwrap();
    let with_bad = dir.join("with-bad.bin");
    concatenate(
        &with_bad,
        &[log.clone(), aborted.join("ped-1.bin"), cut.clone()],
    );
    let left_out = dir.join("left-out.json");
    let (_, listing) = ok(&["frf", s(&with_bad), "--out", s(&left_out)]);
    assert_eq!(
        std::fs::read(&left_out).unwrap(),
        std::fs::read(&cat).unwrap()
    );
    for (number, what) in [(5, "ped Sweep"), (6, "lat Sweep")] {
        let line = format!("with-bad.bin: test {number}: {what}");
        assert!(listing.contains(&line), "{line}\n{listing}");
    }
    assert!(
        listing.contains(", aborted: left out (--include-aborted uses it)"),
        "{listing}"
    );
    assert!(
        listing.contains(", partial: left out (--include-aborted uses it)"),
        "{listing}"
    );

    // --include-aborted analyses them: the pedal's responses appear.
    let included = dir.join("included.json");
    ok(&[
        "frf",
        s(&with_bad),
        "--include-aborted",
        "-q",
        "--out",
        s(&included),
    ]);
    let document: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&included).unwrap()).unwrap();
    let pairs = document["pairs"].as_array().unwrap();
    assert!(pairs.iter().any(|p| p["input"] == "ped"), "no ped pair");

    // A file of aborted tests only is a one-line error.
    let output = sweephold(&["frf", s(&aborted.join("ped-1.bin")), "--out", s(&included)]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.starts_with("error: ") && stderr.contains("test 1 aborted: left out"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

const TWO_CONTROLS: &str = r#"
name = "two-controls"
states = ["u", "p"]
controls = ["lat", "lon"]
outputs = ["u", "p"]
pairs = [{ output = "u", input = "lat" }, { output = "p", input = "lon" }]
[parameters]
a = -1.0
b = 1.0
c = -1.0
d = 1.0
[F.u]
u = "a"
[F.p]
p = "c"
[G.u]
lat = "b"
[G.p]
lon = "d"
"#;

#[test]
fn fit_and_verify_on_board_logs_leave_out_what_the_board_does_not_measure() {
    let dir = scratch("fit");
    let sweeps = dir.join("sweeps");
    fly(&sweeps, &[]);
    let doublets = dir.join("doublets");
    fly(&doublets, &["--axes", "lat", "--input", "doublet"]);
    let mut frf_args = vec!["frf".to_string(), "-q".into(), "--out".into()];
    let frf = dir.join("frf.json");
    frf_args.push(s(&frf).into());
    for axis in ["lat", "lon", "ped", "col"] {
        for n in 1..=2 {
            frf_args.push(s(&sweeps.join(format!("{axis}-{n}.bin"))).into());
        }
    }
    ok(&frf_args.iter().map(String::as_str).collect::<Vec<_>>());

    // A shipped structure fits without its u, v, w pairs, and says so. (The 9-DOF
    // hybrid: the 6-DOF structure's search on these responses stops in a degenerate
    // minimum with some start budgets, which `fit` refuses — not what this test is about.)
    let model = dir.join("model.json");
    let fit = [
        "fit",
        "--frf",
        s(&frf),
        "--model",
        "bo105-9dof-hybrid",
        "--max-starts",
        "2",
        "--out",
    ];
    let (report, _) = ok(&[&fit[..], &[s(&model)]].concat());
    assert!(
        report.starts_with("pairs of u, v, w left out: "),
        "{report}"
    );
    let document: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&model).unwrap()).unwrap();
    let outputs: Vec<&str> = document["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["output"].as_str().unwrap())
        .collect();
    assert!(!outputs.is_empty());
    assert!(
        outputs.iter().all(|o| !["u", "v", "w"].contains(o)),
        "{outputs:?}"
    );

    // A control left with no measured pair is a one-line error naming it.
    let structure = dir.join("two.toml");
    std::fs::write(&structure, TWO_CONTROLS).unwrap();
    let output = sweephold(&["fit", "--frf", s(&frf), "--model", s(&structure)]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("no pair of control `lat` left"), "{stderr}");

    // verify scores p q r ax ay az, lists u v w as not measured, and averages the scored.
    let (table, _) = ok(&[
        "verify",
        "--model",
        s(&model),
        s(&doublets.join("lat-1.bin")),
    ]);
    assert!(
        table.contains("not measured (not scored, not in the mean): u v w"),
        "{table}"
    );
    let tic = |name: &str| -> Option<f64> {
        table
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
    };
    assert!(["u", "v", "w"].iter().all(|o| tic(o).is_none()), "{table}");
    let scored: Vec<f64> = ["p", "q", "r", "ax", "ay", "az"]
        .iter()
        .map(|o| tic(o).unwrap())
        .collect();
    let mean = scored.iter().sum::<f64>() / scored.len() as f64;
    assert!(
        (tic("mean").unwrap() - mean).abs() < 1e-3,
        "{mean}\n{table}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
