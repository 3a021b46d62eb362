//! `sweephold`: see `sweephold --help`. Without arguments: `sweephold campaign`.
use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    // No arguments: the main job on its defaults.
    let cli = if std::env::args_os().len() <= 1 {
        sweephold::Cli::parse_from(["sweephold", "campaign"])
    } else {
        sweephold::Cli::parse()
    };
    match sweephold::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // One line: the error and its causes, outermost first.
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
