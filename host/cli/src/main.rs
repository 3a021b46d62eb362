//! `sweephold`: see `sweephold --help`. Without arguments: `sweephold campaign`.
//!
//! **Its room and what it may import.** The binary parses the command line and runs the
//! verb through the `sweephold` library crate, the only workspace crate it imports (with
//! clap); all the work is in the library.

use std::io::Write;
use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::Parser;

/// Exit status of a command line that does not parse (clap's convention).
const EXIT_USAGE: u8 = 2;

fn main() -> ExitCode {
    // No arguments: the main job on its defaults.
    let parsed = if std::env::args_os().len() <= 1 {
        sweephold::Cli::try_parse_from(["sweephold", "campaign"])
    } else {
        sweephold::Cli::try_parse()
    };
    let cli = match parsed {
        Ok(cli) => cli,
        Err(error) => return usage_error(&error),
    };
    match sweephold::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // One line: the error and its causes, outermost first.
            report(&format!(
                "error: {}",
                format!("{error:#}").replace('\n', " ")
            ));
            ExitCode::FAILURE
        }
    }
}

/// One line on stderr; a stderr that cannot be written loses it (no panic).
fn report(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// `--help` and `--version` as clap prints them (on standard output through the path
/// every verb uses, so a full one is an error: exit 1); a command-line error on one line
/// (clap's first line, without its tips and usage block) and exit status 2.
fn usage_error(error: &clap::Error) -> ExitCode {
    match error.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            if error.use_stderr() {
                let _ = error.print();
                return ExitCode::from(EXIT_USAGE);
            }
            let text = error.render().to_string();
            match sweephold::output::stdout_outcome(sweephold::output::print(&text)) {
                Ok(()) => ExitCode::SUCCESS,
                Err(failed) => {
                    report(&format!("error: {failed}"));
                    ExitCode::FAILURE
                }
            }
        }
        _ => {
            // clap's message is its first paragraph (a list of missing arguments
            // continues it on indented lines); tips and usage follow a blank line.
            let text = error.render().to_string();
            let message: Vec<&str> = text
                .lines()
                .skip_while(|line| line.trim().is_empty())
                .take_while(|line| !line.trim().is_empty())
                .map(str::trim)
                .collect();
            let message = if message.is_empty() {
                "error: bad command line".to_string()
            } else {
                message.join(" ")
            };
            report(&format!("{message} (see --help)"));
            ExitCode::from(EXIT_USAGE)
        }
    }
}
