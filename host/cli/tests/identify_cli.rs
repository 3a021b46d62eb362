//! From a board's logs to a model: `verify` on every test of a logger's file, and
//! `sweephold identify` (frequency responses, fits and verification with no simulator)
//! on the records `fly --fc board-sim` writes, joined as a logger's file per power-up.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn sweephold(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn ok(args: &[&str]) -> (String, String) {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert!(output.status.success(), "{args:?}: {stderr}");
    (String::from_utf8_lossy(&output.stdout).to_string(), stderr)
}

/// The one-line error of a run that must fail with exit status 1.
fn one_line_error(args: &[&str]) -> String {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    stderr
}

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("sweephold-identify-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `fly --fc board-sim -q --out DIR` plus `args`.
fn fly(dir: &Path, args: &[&str]) {
    let mut all = vec!["fly", "--fc", "board-sim", "-q", "--out"];
    all.push(dir.to_str().unwrap());
    all.extend_from_slice(args);
    ok(&all);
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A logger's file: the records `parts` one after the other.
fn concatenate(out: &Path, parts: &[PathBuf]) {
    let bytes: Vec<u8> = parts
        .iter()
        .flat_map(|p| std::fs::read(p).unwrap())
        .collect();
    std::fs::write(out, bytes).unwrap();
}

/// A first-order lag from each cyclic stick to its rate: a model `verify` can replay on
/// any record of the board.
const LAG_MODEL: &str = r#"{"version": 1, "structure": "lag", "description": "",
 "states": ["p", "q"], "controls": ["lat", "lon"], "outputs": ["p", "q"],
 "matrices": {"M": {"rows": 2, "cols": 2, "data": [1.0, 0.0, 0.0, 1.0]},
  "F": {"rows": 2, "cols": 2, "data": [-2.0, 0.0, 0.0, -2.0]},
  "G": {"rows": 2, "cols": 2, "data": [3.0, 0.0, 0.0, 3.0]},
  "H0": {"rows": 2, "cols": 2, "data": [1.0, 0.0, 0.0, 1.0]},
  "H1": {"rows": 2, "cols": 2, "data": [0.0, 0.0, 0.0, 0.0]}},
 "delays": [0.0, 0.0], "parameters": [], "pairs": [], "average_cost": 0.0,
 "correlation": null, "starts": [], "minimum_confirmed": true, "reduction": []}"#;

/// The score tables of a `verify` report, one per record: its heading line and its rows.
fn tables(report: &str) -> Vec<(String, Vec<String>)> {
    let mut found = Vec::new();
    for block in report.split("\n\n").skip(1) {
        let mut lines = block.lines();
        let Some(heading) = lines.next() else {
            continue;
        };
        if !heading.contains(" samples at ") {
            continue;
        }
        let rows = lines
            .skip_while(|l| !l.starts_with("output"))
            .skip(1)
            .map(str::to_string)
            .collect();
        found.push((heading.to_string(), rows));
    }
    found
}

#[test]
fn verify_replays_every_test_of_a_log_and_leaves_out_aborted_ones() {
    let dir = scratch("verify");
    let doublets = dir.join("doublets");
    fly(
        &doublets,
        &["--seed", "2", "--axes", "lat,lon", "--input", "doublet"],
    );
    let aborted = dir.join("aborted");
    fly(
        &aborted,
        &[
            "--seed",
            "1",
            "--axes",
            "ped",
            "--t-rec",
            "30",
            "--rc-loss",
            "15",
        ],
    );
    let model = dir.join("lag.json");
    std::fs::write(&model, LAG_MODEL).unwrap();
    let (lat, lon) = (doublets.join("lat-1.bin"), doublets.join("lon-1.bin"));
    let log = dir.join("log.bin");
    concatenate(&log, &[lat.clone(), aborted.join("ped-1.bin"), lon.clone()]);

    let (report, listing) = ok(&["verify", "--model", s(&model), s(&log)]);
    let (separate, _) = ok(&["verify", "--model", s(&model), s(&lat), s(&lon)]);
    // Each test is listed with what became of it: the aborted sweep left out.
    for (number, what, verdict) in [
        (1, "lat Doublet", "completed: used"),
        (
            2,
            "ped Sweep",
            "aborted: left out (--include-aborted uses it)",
        ),
        (3, "lon Doublet", "completed: used"),
    ] {
        let line = format!("log.bin: test {number}: {what}, ");
        let found = listing.lines().find(|l| l.contains(&line));
        assert!(
            found.is_some_and(|l| l.ends_with(verdict)),
            "{line}\n{listing}"
        );
    }
    // The tests of the file score as the files they came from.
    let (joined, apart) = (tables(&report), tables(&separate));
    assert_eq!(joined.len(), 2, "{report}");
    assert!(
        joined[0].0.starts_with(&format!("{} test 1: ", s(&log))),
        "{report}"
    );
    assert!(
        joined[1].0.starts_with(&format!("{} test 3: ", s(&log))),
        "{report}"
    );
    assert_eq!(
        joined.iter().map(|t| &t.1).collect::<Vec<_>>(),
        apart.iter().map(|t| &t.1).collect::<Vec<_>>()
    );
    let mean = |text: &str| {
        text.lines()
            .last()
            .unwrap()
            .rsplit(' ')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(mean(&report), mean(&separate));

    // --include-aborted replays the aborted test too.
    let (all, _) = ok(&["verify", "--model", s(&model), s(&log), "--include-aborted"]);
    let replayed = tables(&all);
    assert_eq!(replayed.len(), 3, "{all}");
    assert!(replayed[1].0.contains("test 2: "), "{all}");

    // A file of aborted tests only is a one-line error.
    let error = one_line_error(&[
        "verify",
        "--model",
        s(&model),
        s(&aborted.join("ped-1.bin")),
    ]);
    assert!(error.contains("test 1 aborted: left out"), "{error}");
    std::fs::remove_dir_all(&dir).ok();
}
