//! SIGINT and SIGTERM at every stage of a campaign, in a record of `fly`, in `decode` and
//! in the write of `frf`: the earlier result stays byte for byte, no `.partial`, `.lock`
//! or `.tmp` is left, the exit status is non-zero. The run is stopped at an exact place
//! by the documented test hook `SWEEPHOLD_TEST_PAUSE_AT` (see `sweephold::interrupt`).

use std::path::{Path, PathBuf};

use nix::sys::signal::Signal;

use crate::support::signals::{interrupted_by, run_ok, snapshot};

use crate::support::Scratch;

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("signals-{name}"))
}

/// Run `args` paused at `point`, send `signal` there; the exit code and stderr.
fn interrupted_at(dir: &Path, args: &[&str], point: &str, signal: Signal) -> (Option<i32>, String) {
    interrupted_by(dir, args, point, &[signal])
}

/// Every path below `dir` (recursively) whose name says it is a leftover.
fn leftovers(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if name.ends_with(".partial")
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

const SIGNALS: [Signal; 2] = [Signal::SIGINT, Signal::SIGTERM];

#[test]
fn a_campaign_interrupted_at_any_stage_keeps_the_earlier_one() {
    let dir = scratch("campaign");
    run_ok(&dir, &["campaign", "--quick", "--quiet", "--out", "c"]);
    let before = snapshot(&dir.join("c"));
    let second = [
        "campaign", "--quick", "--quiet", "--seed", "5", "--out", "c",
    ];
    // Stages by name, `fly` inside a record, `write` in the first file's commit,
    // `complete` just before the new folder would be swapped in.
    let points = [
        "setup",
        "write",
        "fly",
        "fly_noise",
        "frf",
        "fit_9dof",
        "verify",
        "report",
        "complete",
    ];
    for signal in SIGNALS {
        for point in points {
            let case = format!("{signal} at {point}");
            let (code, stderr) = interrupted_at(&dir, &second, point, signal);
            assert_eq!(code, Some(1), "{case}: {stderr}");
            assert!(stderr.contains("interrupted"), "{case}: {stderr}");
            assert!(snapshot(&dir.join("c")) == before, "{case}: c changed");
            assert_eq!(leftovers(&dir), Vec::<PathBuf>::new(), "{case}");
            // The stopped run's files, with the reason, are kept aside.
            let failed = std::fs::read_to_string(dir.join("c.failed/summary.json")).unwrap();
            assert!(failed.contains("interrupted"), "{case}: {failed}");
            std::fs::remove_dir_all(dir.join("c.failed")).unwrap();
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_signal_ends_a_campaign_at_once_leaving_nothing_behind() {
    let dir = scratch("twice");
    run_ok(&dir, &["campaign", "--quick", "--quiet", "--out", "c"]);
    let before = snapshot(&dir.join("c"));
    let second = [
        "campaign", "--quick", "--quiet", "--seed", "5", "--out", "c",
    ];
    for (point, signals) in [
        ("fly!", [Signal::SIGTERM, Signal::SIGINT]),
        ("frf!", [Signal::SIGINT, Signal::SIGINT]),
        ("write!", [Signal::SIGTERM, Signal::SIGTERM]),
    ] {
        let (code, stderr) = interrupted_by(&dir, &second, point, &signals);
        assert_eq!(code, Some(130), "{point}: {stderr}");
        assert!(snapshot(&dir.join("c")) == before, "{point}: c changed");
        assert_eq!(leftovers(&dir), Vec::<PathBuf>::new(), "{point}");
        assert!(!dir.join("c.failed").exists(), "{point}: ended at once");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fly_decode_and_frf_interrupted_leave_nothing_behind() {
    let dir = scratch("verbs");
    let fly = ["fly", "--axes", "lat", "--t-rec", "30", "-q", "--out", "o"];
    run_ok(&dir, &fly);
    run_ok(&dir, &["decode", "o/lat-1.bin", "-o", "o.csv", "-q"]);
    run_ok(
        &dir,
        &["frf", "o/lat-1.bin", "o/lat-2.bin", "--out", "f.json", "-q"],
    );
    let flown = snapshot(&dir.join("o"));
    let csv = std::fs::read(dir.join("o.csv")).unwrap();
    let frf = std::fs::read(dir.join("f.json")).unwrap();
    assert!(csv.len() > 300_000, "decode pauses after its first chunk");
    for signal in SIGNALS {
        // fly: stopped in its first second of flight; the earlier folder stays.
        let second = [
            "fly", "--axes", "lat", "--t-rec", "30", "--seed", "7", "-q", "--out", "o",
        ];
        let (code, stderr) = interrupted_at(&dir, &second, "fly", signal);
        assert_eq!(code, Some(1), "fly {signal}: {stderr}");
        assert!(stderr.contains("interrupted"), "fly {signal}: {stderr}");
        assert!(snapshot(&dir.join("o")) == flown, "fly {signal}: o changed");
        std::fs::remove_dir_all(dir.join("o.failed")).unwrap();
        // decode: stopped after its first chunk; the temporary file goes.
        let decode = ["decode", "o/lat-1.bin", "o/lat-2.bin", "-o", "o.csv", "-q"];
        let (code, stderr) = interrupted_at(&dir, &decode, "decode", signal);
        assert_eq!(code, Some(1), "decode {signal}: {stderr}");
        assert_eq!(std::fs::read(dir.join("o.csv")).unwrap(), csv);
        // frf ends at once, between its temporary file and the rename.
        let frf_args = ["frf", "o/lat-1.bin", "--out", "f.json", "-q"];
        let (code, stderr) = interrupted_at(&dir, &frf_args, "write", signal);
        assert_eq!(code, Some(130), "frf {signal}: {stderr}");
        assert_eq!(std::fs::read(dir.join("f.json")).unwrap(), frf);
        assert_eq!(leftovers(&dir), Vec::<PathBuf>::new(), "{signal}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
