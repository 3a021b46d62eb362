//! Ctrl-C during long work: the first press asks the work to stop at its next safe point
//! (a campaign between stages), so that it can record why it stopped and leave the
//! previous results as they were; a second press ends the process at once.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

static REQUESTED: AtomicBool = AtomicBool::new(false);
static INSTALL: Once = Once::new();

/// Exit status of a process ended by a second Ctrl-C (128 + SIGINT, as shells report it).
const EXIT_INTERRUPTED: i32 = 130;

/// Install the Ctrl-C handler (once per process; later calls do nothing). If the
/// handler cannot be installed, Ctrl-C keeps its default effect.
pub fn install() {
    INSTALL.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            if REQUESTED.swap(true, Ordering::SeqCst) {
                std::process::exit(EXIT_INTERRUPTED);
            }
            // A person at a terminal is told the press was seen; a log gets the error only.
            if std::io::stderr().is_terminal() {
                eprintln!(
                    "\ninterrupted: stopping after the current stage (Ctrl-C again to quit now)"
                );
            }
        });
    });
}

/// An error when a stop was requested.
pub fn check() -> anyhow::Result<()> {
    if REQUESTED.load(Ordering::SeqCst) {
        anyhow::bail!("interrupted (Ctrl-C)");
    }
    Ok(())
}
