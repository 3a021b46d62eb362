//! `sweephold frf` refuses to join telemetry dumps whose Headers name different vehicles,
//! protocol versions or rates (issue #42): one line naming both files and what differs,
//! exit status 1, and no document written. Dumps of one origin are still joined.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::support::{sweephold, Scratch};

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("frf-origin-{name}")))
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

/// Fly one short lateral sweep with `extra` arguments into `dir/name`; its first dump.
fn fly(dir: &TempDir, name: &str, extra: &[&str]) -> PathBuf {
    let out = dir.path(name);
    let mut args = vec![
        "fly",
        "--axes",
        "lat",
        "--t-rec",
        "20",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let run = sweephold(&args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    out.join("lat-1.bin")
}

fn frf(first: &Path, other: &Path, out: &Path) -> Output {
    sweephold(&[
        "frf",
        first.to_str().unwrap(),
        other.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ])
}

#[test]
fn dumps_of_two_vehicles_protocol_versions_or_rates_are_not_joined() {
    let dir = TempDir::new("mixed");
    let bo105 = fly(&dir, "bo105", &["--vehicle", "bo105"]);
    let cases = [
        (
            fly(&dir, "trex700l", &["--vehicle", "trex700l"]),
            "vehicle bo105 vs trex700l",
        ),
        (
            fly(&dir, "board", &["--vehicle", "bo105", "--fc", "board-sim"]),
            "protocol version 1.2 vs 1.7",
        ),
        (
            fly(&dir, "slow", &["--vehicle", "bo105", "--rate", "100"]),
            "rate 200 Hz vs 100 Hz",
        ),
    ];
    let out = dir.path("frf.json");
    for (other, what) in cases {
        let run = frf(&bo105, &other, &out);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{stderr}");
        assert_eq!(
            stderr,
            format!(
                "error: {} and {} cannot be joined: their Headers name {what}\n",
                bo105.display(),
                other.display()
            )
        );
        assert!(!out.exists(), "a document was written for {what}");
    }
    // Two dumps of one origin are still one response.
    let second = dir.path("bo105").join("lat-2.bin");
    let run = frf(&bo105, &second, &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(out.exists());
}
