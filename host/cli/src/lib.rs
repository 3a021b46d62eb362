//! The `sweephold` command-line tool, as a library so that integration tests and
//! benchmarks drive the same code the binary runs.

use clap::{Parser, Subcommand};

pub mod decode;
pub mod table;

/// Identify helicopter dynamics from automated frequency sweeps flown under conditional
/// attitude hold (Jung, Shim & Kim).
#[derive(Parser, Debug)]
#[command(name = "sweephold", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The verbs of `sweephold`.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Decode telemetry dumps into CSV or JSON lines (one row per Sample).
    Decode(decode::DecodeArgs),
}

/// Run one parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Decode(args) => decode::run(&args),
    }
}
