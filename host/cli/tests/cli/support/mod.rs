//! What more than one module of the CLI tests needs.

pub mod scratch;
#[cfg(unix)]
pub mod signals;

pub use scratch::Scratch;

use std::process::{Command, Output};

/// Run the `sweephold` binary under test with `args` and wait for it.
pub fn sweephold(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// A fixture of the control crate's tests (identified models the loop verbs read).
pub fn control_fixture(name: &str) -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../control/tests/fixtures/{name}"))
}
