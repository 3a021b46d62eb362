//! Two runs on one `--out`: the second, started while the first runs, is refused with a
//! one-line error and exit status 1 and touches nothing; the first completes and its
//! result is whole (every file from its seed). A lock file left by a killed run does
//! not block the next one.

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::support::Scratch;

fn command(dir: &Path, args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_sweephold"));
    command.current_dir(dir).args(args);
    command
}

fn sweephold(dir: &Path, args: &[&str]) -> Output {
    command(dir, args).output().expect("the binary runs")
}

fn start(dir: &Path, args: &[&str]) -> Child {
    command(dir, args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts")
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("lock-{name}"))
}

/// Wait until `path` exists (the first run holds its lock), at most 60 s.
fn wait_for(path: &Path) {
    let started = Instant::now();
    while !path.exists() {
        assert!(started.elapsed() < Duration::from_secs(60), "{path:?}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn seed_of(summary: &Path) -> u64 {
    let text = std::fs::read_to_string(summary).unwrap();
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["seed"].as_u64().unwrap()
}

/// Start `first` on `out`, then `second` on the same `out` while the first runs.
fn second_is_refused(dir: &Path, out: &str, first: &[&str], second: &[&str]) {
    let lock = dir.join(format!("{out}.lock"));
    let running = start(dir, first);
    wait_for(&lock);
    let refused = sweephold(dir, second);
    let stderr = String::from_utf8_lossy(&refused.stderr).trim().to_string();
    assert_eq!(refused.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "output folder {out} is in use by another sweephold run (pid {})",
            running.id()
        )),
        "{stderr}"
    );
    let finished = running.wait_with_output().unwrap();
    assert!(
        finished.status.success(),
        "{}",
        String::from_utf8_lossy(&finished.stderr)
    );
    assert!(!lock.exists(), "the lock goes with the run");
    assert!(!dir.join(format!("{out}.partial")).exists());
    assert!(!dir.join(format!("{out}.failed")).exists());
}

#[test]
fn a_second_campaign_on_the_same_folder_is_refused() {
    let dir = scratch("campaign");
    second_is_refused(
        &dir,
        "c",
        &[
            "campaign", "--quick", "--quiet", "--seed", "11", "--out", "c",
        ],
        &[
            "campaign", "--quick", "--quiet", "--seed", "12", "--out", "c",
        ],
    );
    // Every document is the first run's.
    for summary in [
        "c/summary.json",
        "c/fly-cah/summary.json",
        "c/fly-standard/summary.json",
        "c/fly-noise/summary.json",
    ] {
        assert_eq!(seed_of(&dir.join(summary)), 11, "{summary}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_fly_on_the_same_folder_is_refused() {
    let dir = scratch("fly");
    let first = [
        "fly", "--axes", "lat", "--t-rec", "400", "-q", "--seed", "11", "--out", "o",
    ];
    let second = [
        "fly", "--axes", "lat", "--t-rec", "20", "-q", "--seed", "12", "--out", "o",
    ];
    second_is_refused(&dir, "o", &first, &second);
    assert_eq!(seed_of(&dir.join("o/summary.json")), 11);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_lock_file_left_by_a_killed_run_does_not_block() {
    let dir = scratch("stale");
    // What a SIGKILLed run leaves: the file, but no process holding its lock.
    std::fs::write(dir.join("o.lock"), "4000000\n").unwrap();
    let output = sweephold(
        &dir,
        &["fly", "--axes", "lat", "--t-rec", "20", "-q", "--out", "o"],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(dir.join("o/summary.json").is_file());
    assert!(!dir.join("o.lock").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Start `args` in `dir` paused at `point` of the test hook; return once it says so (the
/// caller waits for it; a run that never pauses is killed and waited for here).
#[allow(clippy::zombie_processes)]
fn start_paused(dir: &Path, args: &[&str], point: &str) -> Child {
    use std::io::{BufRead, BufReader};
    let mut child = command(dir, args)
        .env("SWEEPHOLD_TEST_PAUSE_AT", point)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    loop {
        line.clear();
        if stderr.read_line(&mut line).unwrap() == 0 {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} never paused at {point}");
        }
        if line.trim() == format!("paused at {point}") {
            return child;
        }
    }
}

#[test]
fn a_report_is_refused_while_a_campaign_runs_on_its_folder() {
    use nix::sys::signal::{kill, Signal};
    use nix::unistd::Pid;
    let dir = scratch("report");
    let done = sweephold(
        &dir,
        &[
            "campaign", "--quick", "--quiet", "--seed", "11", "--out", "c",
        ],
    );
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    // Alone, the report takes the lock and releases it.
    let alone = sweephold(&dir, &["report", "c"]);
    assert!(
        alone.status.success(),
        "{}",
        String::from_utf8_lossy(&alone.stderr)
    );
    assert!(!dir.join("c.lock").exists());
    let report = std::fs::read(dir.join("c/report.html")).unwrap();

    // A second campaign on c, held at its 6-DOF stage: the report is refused.
    let running = start_paused(
        &dir,
        &[
            "campaign", "--quick", "--quiet", "--seed", "12", "--out", "c",
        ],
        "fit_6dof",
    );
    let refused = sweephold(&dir, &["report", "c"]);
    let stderr = String::from_utf8_lossy(&refused.stderr).trim().to_string();
    assert_eq!(refused.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains(&format!(
            "error: output folder c is in use by another sweephold run (pid {})",
            running.id()
        )),
        "{stderr}"
    );
    // `report .` inside the folder names the same lock.
    let inside = command(&dir.join("c"), &["report", "."]).output().unwrap();
    assert_eq!(inside.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&inside.stderr).contains("is in use"));
    // The campaign ended by SIGTERM: the earlier result and its report untouched.
    let pid = Pid::from_raw(i32::try_from(running.id()).unwrap());
    kill(pid, Signal::SIGTERM).unwrap();
    let ended = running.wait_with_output().unwrap();
    assert!(!ended.status.success());
    assert!(std::fs::read(dir.join("c/report.html")).unwrap() == report);
    assert_eq!(seed_of(&dir.join("c/summary.json")), 11);
    assert!(!dir.join("c.lock").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
