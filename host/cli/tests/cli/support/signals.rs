//! Running `sweephold` held at a pause point of the test hook `SWEEPHOLD_TEST_PAUSE_AT`
//! (see `sweephold::interrupt`), signalling it there, and comparing folders before and
//! after: shared by the campaign's and `fly`'s signal tests.

use std::ffi::OsStr;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use nix::sys::signal::{kill, Signal};
use nix::unistd::Pid;

/// Run `args` in `dir` to completion; it must succeed.
pub fn run_ok<S: AsRef<OsStr>>(dir: &Path, args: &[S]) {
    let output = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Run `args` in `dir` paused at `point` (`POINT!`: held there through the first signal),
/// send `signals` there a tenth of a second apart; the exit code and stderr.
pub fn interrupted_by<S: AsRef<OsStr> + std::fmt::Debug>(
    dir: &Path,
    args: &[S],
    point: &str,
    signals: &[Signal],
) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(dir)
        .args(args)
        .env("SWEEPHOLD_TEST_PAUSE_AT", point)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        let n = stderr.read_line(&mut line).unwrap();
        if n == 0 {
            let _ = child.kill();
            panic!("{args:?} never paused at {point}: {seen}");
        }
        seen += &line;
        if line.trim() == format!("paused at {}", point.trim_end_matches('!')) {
            break;
        }
    }
    let pid = Pid::from_raw(i32::try_from(child.id()).unwrap());
    for (i, signal) in signals.iter().enumerate() {
        if i > 0 {
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        kill(pid, *signal).unwrap();
    }
    stderr.read_to_string(&mut seen).unwrap();
    let status = child.wait().unwrap();
    (status.code(), seen)
}

/// The bytes of every file below `dir`, by path.
pub fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                files.push((path.clone(), std::fs::read(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}
