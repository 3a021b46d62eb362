//! `sweephold fly` stopped by SIGINT and by SIGTERM at each of its stages, on the
//! in-process flight controller and on the emulated board (`--fc board-sim`): the earlier
//! `--out` folder stays byte for byte, no temporary file, staging folder or lock is left,
//! and no process is left running in the run's folder. The run is stopped at an exact
//! place by the test hook `SWEEPHOLD_TEST_PAUSE_AT` (see `sweephold::interrupt`).
//!
//! Stages: `setup` (lock held, staging folder made), `fly` (a record started), `write` (a
//! dump about to be committed), `summary` (every record written, `summary.json` not yet),
//! `complete` (just before the staging folder is swapped in). One signal stops the run at
//! its next safe point (exit 1, its files kept as `OUT.failed`); a second one, sent while
//! the run is held at the point (`POINT!`), ends it at once (exit 130, nothing kept).

use std::path::{Path, PathBuf};

use nix::sys::signal::Signal;

use crate::support::signals::{interrupted_by, run_ok, snapshot};

use crate::support::Scratch;

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("fly-signals-{name}"))
}

/// The `fly` command line on `fc` with `seed` into `o`.
fn fly_args(fc: &str, seed: &str) -> Vec<String> {
    [
        "fly", "--fc", fc, "--axes", "lat", "--t-rec", "20", "--seed", seed, "-q", "--out", "o",
    ]
    .map(String::from)
    .to_vec()
}

/// Every path below `dir` (recursively) other than the earlier result `o` and the kept
/// failed run `o.failed`: temporary files, staging folders, locks.
fn leftovers(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            let top = folder == dir;
            if (top && name != "o" && name != "o.failed")
                || name.ends_with(".partial")
                || name.ends_with(".lock")
                || name.ends_with(".tmp")
                || name.ends_with(".previous")
            {
                found.push(path.clone());
            }
            if path.is_dir() {
                stack.push(path);
            }
        }
    }
    found
}

/// Processes (other than this test) whose working folder is `dir`: what a run started
/// there and left running (a flight controller's emulator, a worker).
fn processes_in(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let own = std::process::id().to_string();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if name == own || !name.bytes().all(|b| b.is_ascii_digit()) {
            continue;
        }
        if std::fs::read_link(entry.path().join("cwd")).is_ok_and(|cwd| cwd == dir) {
            let cmdline = std::fs::read(entry.path().join("cmdline")).unwrap_or_default();
            found.push(format!(
                "{name}: {}",
                String::from_utf8_lossy(&cmdline).replace('\0', " ")
            ));
        }
    }
    found
}

const POINTS: [&str; 5] = ["setup", "fly", "write", "summary", "complete"];

fn table(fc: &str) {
    let dir = scratch(fc);
    run_ok(&dir, &fly_args(fc, "1"));
    let before = snapshot(&dir.join("o"));
    let second = fly_args(fc, "7");
    for signal in [Signal::SIGINT, Signal::SIGTERM] {
        for point in POINTS {
            let case = format!("{fc}: {signal} at {point}");
            let (code, stderr) = interrupted_by(&dir, &second, point, &[signal]);
            assert_eq!(code, Some(1), "{case}: {stderr}");
            let last = stderr.lines().last().unwrap_or_default();
            assert!(
                last.starts_with("error: fly failed") && last.contains("interrupted"),
                "{case}: {stderr}"
            );
            assert!(snapshot(&dir.join("o")) == before, "{case}: o changed");
            assert_eq!(leftovers(&dir), Vec::<PathBuf>::new(), "{case}");
            assert_eq!(processes_in(&dir), Vec::<String>::new(), "{case}");
            // The stopped run's files are kept aside.
            assert!(dir.join("o.failed").is_dir(), "{case}: no o.failed");
            std::fs::remove_dir_all(dir.join("o.failed")).unwrap();
        }
        // A second signal while held at the point ends the run at once: nothing kept.
        for point in POINTS {
            let case = format!("{fc}: {signal} twice at {point}");
            let held = format!("{point}!");
            let (code, stderr) = interrupted_by(&dir, &second, &held, &[signal, signal]);
            assert_eq!(code, Some(130), "{case}: {stderr}");
            assert!(snapshot(&dir.join("o")) == before, "{case}: o changed");
            assert_eq!(leftovers(&dir), Vec::<PathBuf>::new(), "{case}");
            assert!(!dir.join("o.failed").exists(), "{case}: ended at once");
            assert_eq!(processes_in(&dir), Vec::<String>::new(), "{case}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fly_in_process_interrupted_at_every_stage_keeps_the_earlier_folder() {
    table("in-process");
}

#[test]
fn fly_on_the_board_sim_interrupted_at_every_stage_keeps_the_earlier_folder() {
    table("board-sim");
}
