//! `sweephold fly --fc board-sim` with a fault from record time 0 (issue #42): the board
//! leaves the pilot mode before its test begins, so the record has no Header. The error
//! says which fault ended the record before it began (and the board's mode change), not
//! that the dump lacks a Header; the run fails (exit 1) and `--out` is not created.

use std::process::Command;

use crate::support::Scratch;

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("fault-at-start-{name}")))
    }
}

#[test]
fn a_fault_at_time_0_ended_the_record_before_it_began() {
    let dir = TempDir::new("table");
    let cases = [
        ("--rc-loss", "0", "pilot → rc_failsafe"),
        ("--imu-fault", "stuck@0", "pilot → imu_failsafe"),
        ("--imu-fault", "saturate@0", "pilot → imu_failsafe"),
        ("--imu-fault", "missing@0", "pilot → imu_failsafe"),
    ];
    for (flag, value, mode_change) in cases {
        let out = dir.0.join(value.replace('@', "-"));
        let run = Command::new(env!("CARGO_BIN_EXE_sweephold"))
            .args(["fly", "--fc", "board-sim", "--axes", "lat", "--t-rec", "20"])
            .args([flag, value, "--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{flag} {value}: {stderr}");
        let last = stderr.lines().last().unwrap_or_default();
        assert!(last.starts_with("error: "), "{flag} {value}: {stderr}");
        assert!(
            last.contains(&format!(
                "record lat-1.bin: {flag} {value} ended the record before it began \
                 (no test started: the board went {mode_change} at tick "
            )),
            "{flag} {value}: {last}"
        );
        assert!(!last.contains("Header"), "{flag} {value}: {last}");
        assert!(!out.exists(), "{flag} {value}: {} written", out.display());
    }
}
