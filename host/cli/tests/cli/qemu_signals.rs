//! `fly --fc qemu-usart` ended by SIGTERM or SIGINT in the middle of a record: the QEMU
//! processes it started end with it, it leaves no temporary or staging file, and the
//! earlier result in its `--out` folder is byte-identical. Skipped (saying why) without
//! `qemu-system-arm` or a board image (`cargo fw`, or `SWEEPHOLD_FC_ELF`); with
//! `SWEEPHOLD_REQUIRE_QEMU` set (CI) a skip is a failure.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::signals::{run_ok, snapshot};
use crate::support::Scratch;
use nix::sys::signal::{kill, Signal};
use nix::unistd::Pid;
use sweephold::fly::link_qemu;

/// The board image, or `None` (after saying why) when QEMU or the image is missing.
fn image_or_skip() -> Option<PathBuf> {
    match link_qemu::qemu_available().and_then(|()| link_qemu::default_image()) {
        Ok(image) => Some(image),
        Err(why) => {
            assert!(
                std::env::var_os("SWEEPHOLD_REQUIRE_QEMU").is_none(),
                "SWEEPHOLD_REQUIRE_QEMU is set but the QEMU signal test cannot run: {why}"
            );
            eprintln!("SKIPPED qemu signal test: {why}");
            None
        }
    }
}

/// The pids of the live `qemu-system-arm` processes whose parent is `parent`.
fn qemu_children(parent: u32) -> Vec<u32> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        if let Some((comm, ppid)) = comm_and_parent(pid) {
            if ppid == parent && comm.starts_with("qemu-system-arm") {
                found.push(pid);
            }
        }
    }
    found
}

/// `comm` and parent pid of a live (not zombie) process, from /proc/PID/stat.
fn comm_and_parent(pid: u32) -> Option<(String, u32)> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let open = stat.find('(')?;
    let close = stat.rfind(')')?;
    let comm = stat[open + 1..close].to_string();
    let mut rest = stat[close + 2..].split_whitespace();
    let state = rest.next()?;
    let ppid = rest.next()?.parse().ok()?;
    (state != "Z").then_some((comm, ppid))
}

/// Whether `pid` is still a live `qemu-system-arm` (not reaped, not a zombie).
fn qemu_alive(pid: u32) -> bool {
    comm_and_parent(pid).is_some_and(|(comm, _)| comm.starts_with("qemu-system-arm"))
}

/// Run a QEMU `fly` on `out` in `dir`, paused in its record with QEMU running; send
/// `signal`; return the QEMU pids it had started, its exit code and stderr.
fn interrupt_qemu_fly(dir: &Path, image: &Path, signal: Signal) -> (Vec<u32>, Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(dir)
        .args(["fly", "--fc", "qemu-usart", "--elf"])
        .arg(image)
        .args(["--axes", "lat", "--t-rec", "5", "-q", "--out", "o"])
        .env("SWEEPHOLD_TEST_PAUSE_AT", "fly")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        if stderr.read_line(&mut line).unwrap() == 0 {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the QEMU fly never paused: {seen}");
        }
        seen += &line;
        if line.trim() == "paused at fly" {
            break;
        }
    }
    let started = qemu_children(child.id());
    kill(Pid::from_raw(i32::try_from(child.id()).unwrap()), signal).unwrap();
    stderr.read_to_string(&mut seen).unwrap();
    let status = child.wait().unwrap();
    (started, status.code(), seen)
}

#[test]
fn qemu_processes_end_with_an_interrupted_fly_and_the_earlier_result_stays() {
    let Some(image) = image_or_skip() else {
        return;
    };
    let dir = Scratch::new("qemu-signals");
    // The earlier result (flown in-process: quicker, and any earlier run will do).
    run_ok(
        &dir,
        &["fly", "--axes", "lat", "--t-rec", "5", "-q", "--out", "o"],
    );
    let before = snapshot(&dir);
    for signal in [Signal::SIGTERM, Signal::SIGINT] {
        let (started, code, stderr) = interrupt_qemu_fly(&dir, &image, signal);
        assert!(
            !started.is_empty(),
            "{signal}: no QEMU was running: {stderr}"
        );
        assert!(
            matches!(code, Some(c) if c != 0 && c != 101),
            "{signal}: exit {code:?}: {stderr}"
        );
        // The kernel may take a moment to reap them.
        let deadline = Instant::now() + Duration::from_secs(5);
        while started.iter().any(|&pid| qemu_alive(pid)) && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
        }
        let alive: Vec<u32> = started.iter().copied().filter(|&p| qemu_alive(p)).collect();
        assert!(
            alive.is_empty(),
            "{signal}: QEMU {alive:?} outlived the run"
        );
        // Nothing left beside the result, and the result as it was.
        for leftover in ["o.partial", "o.lock"] {
            assert!(!dir.join(leftover).exists(), "{signal}: {leftover} left");
        }
        // A signal fails the run like any error: its staging folder is kept as
        // o.failed (README), with no temporary file in it; the rest is as it was.
        let failed = dir.join("o.failed");
        if failed.exists() {
            let temporary: Vec<PathBuf> = snapshot(&failed)
                .into_iter()
                .map(|(path, _)| path)
                .filter(|path| path.to_string_lossy().ends_with(".tmp"))
                .collect();
            assert!(temporary.is_empty(), "{signal}: {temporary:?}");
            std::fs::remove_dir_all(&failed).unwrap();
        }
        assert!(
            snapshot(&dir) == before,
            "{signal}: the folder changed: {stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
