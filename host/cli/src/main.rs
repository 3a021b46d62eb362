//! `sweephold`: see `sweephold --help`.
use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = sweephold::Cli::parse();
    match sweephold::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // One line: the error and its causes, outermost first.
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
