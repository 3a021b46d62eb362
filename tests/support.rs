//! Shared helpers of the cross-crate integration tests in this folder.
//!
//! The tests may import every crate of the workspace; nothing imports them.

use std::path::{Path, PathBuf};

use clap::Parser;
use sweephold::fly::{FlyArgs, FlyOutcome};
use sweephold::{Cli, Command};

/// A scratch folder removed on drop.
pub struct Scratch(PathBuf);

impl Scratch {
    /// A fresh folder named after `name` and the process.
    pub fn new(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("sweephold-it-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch folder");
        Scratch(dir)
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
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
