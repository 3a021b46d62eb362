//! SIGINT (Ctrl-C), SIGTERM and SIGHUP, handled alike by every verb (the `ctrlc` crate
//! with its `termination` feature: one handler thread for the three signals).
//!
//! - **Verbs with safe points** (`campaign` between stages and every second of a flown
//!   record, `fly` every second of a record, `decode` between chunks) are *deferred*: the
//!   first signal asks the work to stop at its next safe point ([`check`] fails), where
//!   it fails like any other error — its temporary file dropped (removed), its staging
//!   folder kept as `DIR.failed` with the reason, the earlier result untouched, exit 1.
//! - **The other verbs** (`fit`, `frf`, `verify`, `sim`, `report`) write only at their end:
//!   the first signal ends them at once.
//! - **Ending at once** (those verbs, or a second signal to a deferred one): what the run
//!   registered is cleaned up first — child processes (QEMU) killed, temporary files and
//!   staging folders removed, the folder lock's file removed — then exit status 130
//!   (128 + SIGINT, as shells report Ctrl-C). The earlier results were never touched.
//!
//! Registrations ([`register_file`], [`register_folder`], [`register_child`]) last as long
//! as the returned [`Registration`]: the owner (an `AtomicFile`, a `StagedFolder`, a QEMU
//! process) drops it when it cleaned up or committed itself.
//!
//! **Test hook.** With `SWEEPHOLD_TEST_PAUSE_AT=POINT` in the environment the run pauses
//! at the named point ([`pause_point`]: a campaign stage's name, `complete` just before a
//! staged folder is swapped in, `fly` at the start of a record, `setup` and `summary` in
//! `sweephold fly` (its staging folder made; its records written), `decode` after the first
//! rows, `write` before an atomic file is committed), says `paused at POINT` on stderr and
//! waits (at most 120 s) for a signal, so that tests can interrupt a run at an exact place.
//! `POINT!` holds there through the first signal too, so that a second one meets a run
//! that has not reached its next safe point.

use std::collections::BTreeMap;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, Once};
use std::time::{Duration, Instant};

static REQUESTED: AtomicBool = AtomicBool::new(false);
static DEFERRED: AtomicBool = AtomicBool::new(false);
static INSTALL: Once = Once::new();
static NEXT_ID: AtomicU64 = AtomicU64::new(0);
static LEFTOVERS: Mutex<BTreeMap<u64, Leftover>> = Mutex::new(BTreeMap::new());

/// Exit status of a run ended by a signal at once (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: i32 = 130;

/// The environment variable of the test hook (see the module doc).
pub const PAUSE_AT_VARIABLE: &str = "SWEEPHOLD_TEST_PAUSE_AT";

/// What a run ended at once must not leave behind.
enum Leftover {
    File(PathBuf),
    Folder(PathBuf),
    Child(u32),
}

/// How the running verb takes a signal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handling {
    /// It stops at its next safe point ([`check`]); a second signal ends it at once.
    Deferred,
    /// The first signal ends it at once.
    AtOnce,
}

/// Install the handler (once per process; later calls only change the handling). If the
/// handler cannot be installed, the signals keep their default effect.
pub fn install(handling: Handling) {
    DEFERRED.store(handling == Handling::Deferred, Ordering::SeqCst);
    INSTALL.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            let again = REQUESTED.swap(true, Ordering::SeqCst);
            if again || !DEFERRED.load(Ordering::SeqCst) {
                clean_up_and_exit();
            }
            // A person at a terminal is told the signal was seen; a log gets the error only.
            let mut stderr = std::io::stderr();
            if stderr.is_terminal() {
                let _ = writeln!(
                    stderr,
                    "\ninterrupted: stopping at the next safe point (Ctrl-C again to quit now)"
                );
            }
        });
    });
}

/// Kill the registered children, remove the registered files and folders, exit 130.
/// Holds the registry's lock to the end, so that nothing registers meanwhile.
fn clean_up_and_exit() -> ! {
    let leftovers = LEFTOVERS.lock().unwrap_or_else(|e| e.into_inner());
    for leftover in leftovers.values() {
        if let Leftover::Child(pid) = leftover {
            if let Ok(pid) = i32::try_from(*pid) {
                let _ = nix::sys::signal::kill(
                    nix::unistd::Pid::from_raw(pid),
                    nix::sys::signal::Signal::SIGKILL,
                );
            }
        }
    }
    for leftover in leftovers.values() {
        match leftover {
            Leftover::File(path) => {
                let _ = std::fs::remove_file(path);
            }
            Leftover::Folder(path) => {
                let _ = std::fs::remove_dir_all(path);
            }
            Leftover::Child(_) => {}
        }
    }
    std::process::exit(EXIT_INTERRUPTED);
}

/// Whether a stop was requested (a verb that ends cleanly on a signal, `fc watch`, asks).
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// An error when a stop was requested.
pub fn check() -> anyhow::Result<()> {
    if REQUESTED.load(Ordering::SeqCst) {
        anyhow::bail!("interrupted (Ctrl-C or SIGTERM)");
    }
    Ok(())
}

/// A registered leftover, unregistered when dropped.
#[must_use = "the registration ends when dropped"]
pub struct Registration(u64);

impl Drop for Registration {
    fn drop(&mut self) {
        LEFTOVERS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&self.0);
    }
}

fn register(leftover: Leftover) -> Registration {
    let id = NEXT_ID.fetch_add(1, Ordering::SeqCst);
    LEFTOVERS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(id, leftover);
    Registration(id)
}

/// A temporary file to remove if the run ends at once.
pub fn register_file(path: &Path) -> Registration {
    register(Leftover::File(path.to_path_buf()))
}

/// A staging folder to remove (with its files) if the run ends at once.
pub fn register_folder(path: &Path) -> Registration {
    register(Leftover::Folder(path.to_path_buf()))
}

/// A child process to kill if the run ends at once.
pub fn register_child(pid: u32) -> Registration {
    register(Leftover::Child(pid))
}

/// The test hook: pause at `point` when `SWEEPHOLD_TEST_PAUSE_AT` names it (see the
/// module doc); otherwise nothing.
pub fn pause_point(point: &str) {
    let Ok(wanted) = std::env::var(PAUSE_AT_VARIABLE) else {
        return;
    };
    let (name, hold) = match wanted.strip_suffix('!') {
        Some(name) => (name, true),
        None => (wanted.as_str(), false),
    };
    if name != point {
        return;
    }
    let _ = writeln!(std::io::stderr(), "paused at {point}");
    let started = Instant::now();
    while (hold || !REQUESTED.load(Ordering::SeqCst))
        && started.elapsed() < Duration::from_secs(120)
    {
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registrations_last_as_long_as_their_owner() {
        let held = |r: &Registration| LEFTOVERS.lock().unwrap().contains_key(&r.0);
        let file = register_file(Path::new("/nonexistent/a.tmp"));
        let child = register_child(1);
        assert!(held(&file) && held(&child));
        let id = file.0;
        drop(file);
        assert!(!LEFTOVERS.lock().unwrap().contains_key(&id));
        assert!(held(&child));
    }
}
