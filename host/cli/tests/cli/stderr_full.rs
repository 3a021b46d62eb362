//! A standard error that cannot be written (`2>/dev/full`) never makes a verb panic
//! (exit 101): its error paths keep their exit status (2 for a bad command line, 1 for a
//! failed run) and its successful runs still succeed, their progress and warnings lost.
//! Linux only (`/dev/full`); skipped where it does not exist.

use std::fs::File;
use std::path::Path;
use std::process::{Command, Stdio};

use crate::support::Scratch;

fn full() -> Option<File> {
    File::options().write(true).open("/dev/full").ok()
}

/// Run `args` in `dir` with stderr on /dev/full (stdout discarded): the exit code.
fn with_full_stderr(dir: &Path, args: &[&str]) -> Option<i32> {
    let status = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::from(full().unwrap()))
        .status()
        .expect("the binary runs");
    status.code()
}

fn scratch() -> Scratch {
    Scratch::new("stderr-full")
}

#[test]
fn no_verb_panics_when_its_standard_error_is_full() {
    if full().is_none() {
        eprintln!("skipped: no /dev/full");
        return;
    }
    let dir = scratch();
    // Runs that succeed, their progress and warnings on stderr lost.
    assert_eq!(
        with_full_stderr(
            &dir,
            &["fly", "--axes", "lat", "--t-rec", "20", "--out", "o"]
        ),
        Some(0)
    );
    let dump = std::fs::read_dir(dir.join("o"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "bin"))
        .expect("fly wrote a dump");
    let dump = dump.to_str().unwrap();
    std::fs::create_dir_all(dir.join("junk")).unwrap();
    std::fs::write(dir.join("junk/notes.txt"), "mine").unwrap();
    let cases: Vec<(Vec<&str>, i32)> = vec![
        (vec!["decode", dump, "-o", "d.csv"], 0),
        (vec!["frf", dump, "--out", "frf.json"], 0),
        (vec!["campaign", "--quick", "--out", "c"], 0),
        (vec!["report", "c"], 0),
        // Bad command lines: exit 2.
        (vec!["sim", "trim", "--speed", "nan"], 2),
        (vec!["--bogus"], 2),
        (vec!["fit", "--frf"], 2),
        (vec!["sim", "trim", "--vehicle", "missing.toml"], 2),
        // Failed runs: exit 1.
        (vec!["decode", "missing.bin"], 1),
        (vec!["frf", "missing.bin"], 1),
        (
            vec!["fit", "--frf", "missing.json", "--model", "bo105-6dof"],
            1,
        ),
        (vec!["verify", "--model", "missing.json", dump], 1),
        (vec!["report", "missing"], 1),
        (vec!["margins", "missing.json"], 1),
        (vec!["margins", "c/model9.json", "--out", "m.json"], 0),
        (
            vec!["fc", "params", "list", "--fc", "serial:/nonexistent"],
            1,
        ),
        (
            vec![
                "fly",
                "--axes",
                "lat",
                "--t-rec",
                "20",
                "--out",
                "o/lat-1.bin",
            ],
            1,
        ),
        // A folder of other files is refused before anything is written.
        (vec!["campaign", "--quick", "--out", "junk"], 1),
    ];
    for (args, want) in cases {
        assert_eq!(with_full_stderr(&dir, &args), Some(want), "{args:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
