//! Shared helpers of the cross-crate integration tests in this folder.
//!
//! **Its room and what it may import.** The tests that cross crates (the firmware flown
//! in the loop with the simulator in-process, in QEMU and over a pseudo-terminal; whole
//! campaigns through the command-line library) and their helpers. They may import every
//! crate of the workspace (today the protocol, the firmware with `std` and the
//! command-line library `sweephold`); nothing imports them.

use std::path::{Path, PathBuf};

use clap::Parser;
use sweephold::fly::{FlyArgs, FlyOutcome};
use sweephold::{Cli, Command};

/// A test's own folder, removed on drop with everything beside it.
///
/// The path is `TMP/sweephold-it-NAME-XXXXXX/NAME`: the outer folder's name is made unique
/// by the `tempfile` crate (the tests of a binary run in parallel in one process, so the
/// process id cannot tell them apart) and it is the test's alone, so what a run puts beside
/// its `--out` (the `OUT.failed` folder a failed run keeps by design, a staging folder, a
/// lock) goes with it. A test that panics keeps it, and says where.
pub struct Scratch {
    /// The unique folder holding `path` and its siblings.
    root: PathBuf,
    path: PathBuf,
}

impl Scratch {
    /// A fresh empty folder named after `name`.
    pub fn new(name: &str) -> Scratch {
        let root = tempfile::Builder::new()
            .prefix(&format!("sweephold-it-{name}-"))
            .tempdir()
            .expect("create scratch folder")
            .keep();
        let path = root.join(name);
        std::fs::create_dir(&path).expect("create scratch folder");
        Scratch { root, path }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept for a look: {}", self.root.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.root);
        }
    }
}

/// Parse `sweephold fly ARGS` as the binary would.
pub fn fly_args(args: &[&str]) -> FlyArgs {
    let argv = ["sweephold", "fly", "--quiet"].iter().chain(args).copied();
    match Cli::try_parse_from(argv)
        .expect("valid fly arguments")
        .command
    {
        Command::Fly(args) => args,
        other => panic!("not a fly command: {other:?}"),
    }
}

/// Fly `args` in-process and return the outcome.
pub fn fly(args: &FlyArgs) -> FlyOutcome {
    sweephold::fly::fly(args, &|| {
        Box::new(sweephold::fly::link::InProcessLink::new())
    })
    .expect("the campaign flies")
}
