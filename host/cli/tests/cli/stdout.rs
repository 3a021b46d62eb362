//! Standard output that cannot be written (`> /dev/full`): every verb that prints ends in
//! the one line `error: cannot write to standard output: …` and exit status 1, never a
//! panic (exit 101) and never exit 0; `--help` and `--version` too. A reader that went
//! away (`| head`) is not a failure.

use std::fs::File;
use std::path::Path;
use std::process::{Command, Output, Stdio};

use crate::support::Scratch;

fn sweephold(dir: &Path, args: &[&str], stdout: Stdio) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(dir)
        .args(args)
        .stdout(stdout)
        .output()
        .expect("the binary runs")
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("stdout-{name}"))
}

fn full() -> Stdio {
    Stdio::from(File::options().write(true).open("/dev/full").unwrap())
}

#[test]
fn every_verb_that_prints_fails_in_one_line_when_stdout_is_full() {
    let dir = scratch("full");
    let campaign = sweephold(
        &dir,
        // Seed 2: its responses fit the 6-DOF from the file's start (the quick campaign of
        // seed 1 lands in a degenerate minimum, which is refused before anything prints).
        &[
            "campaign", "--quick", "--quiet", "--seed", "2", "--out", "c",
        ],
        Stdio::piped(),
    );
    assert!(
        campaign.status.success(),
        "{}",
        String::from_utf8_lossy(&campaign.stderr)
    );
    let cases: &[&[&str]] = &[
        &["--help"],
        &["--version"],
        &["sim", "--help"],
        &["sim", "trim", "--help"],
        &["help", "fly"],
        &["sim", "trim"],
        &["sim", "trim", "--json"],
        &["sim", "linearize", "--vehicle", "trex700l"],
        &["sim", "trim-points"],
        &["decode", "c/fly-cah/lat-1.bin"],
        &["decode", "--format", "jsonl", "-q", "c/fly-cah/lat-1.bin"],
        &[
            "verify",
            "--model",
            "c/model9.json",
            "c/verify-doublet/lat-1.bin",
        ],
        &["fit", "--frf", "c/frf.json", "--model", "bo105-6dof"],
        &["report", "c"],
        &["margins", "c/model9.json"],
        &["margins", "c/model9.json", "--json"],
        &["margins", "--help"],
        &["fc", "params", "--help"],
        &["campaign", "--quick", "--quiet", "--out", "c2"],
    ];
    for args in cases {
        let output = sweephold(&dir, args, full());
        let stderr = String::from_utf8_lossy(&output.stderr);
        let case = args.join(" ");
        assert_eq!(output.status.code(), Some(1), "{case}: {stderr}");
        assert_eq!(
            stderr.trim(),
            "error: cannot write to standard output: No space left on device",
            "{case}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_reader_that_stops_early_is_not_a_failure() {
    let dir = scratch("pipe");
    for args in [&["sim", "trim"][..], &["--help"], &["sim", "trim-points"]] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_sweephold"))
            .current_dir(&dir)
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Close the reading end before the child writes: its write meets a broken pipe.
        drop(child.stdout.take());
        let output = child.wait_with_output().unwrap();
        let case = args.join(" ");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(0), "{case}: {stderr}");
        assert!(stderr.is_empty(), "{case}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
