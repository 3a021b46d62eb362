//! The `sweephold` command-line tool, as a library so that integration tests and
//! benchmarks drive the same code the binary runs.
//!
//! **Its room and what it may import.** The command-line program: the verbs, the files
//! they read and write, their console text, plots and report.
//! Every library crate of the workspace: the protocol, the
//! firmware (with `std`, flown in-process), the aircraft files (`aircraft`), the
//! simulator (`rotorsim`), the identification (`sysid`), the `truth` mapping and the
//! loop margins (`control`). Nothing imports it but the integration tests. The console
//! text of the library's results (tables, summary lines) is written here
//! (`fit_tables`, `mode_text`); the libraries return data.
//! Inside it, the verbs (`fly`, `frf`, `fit`, `verify`, `decode`, `sim`) own their
//! options; `campaign` runs them as stages and writes `artifacts`, which `report`
//! only reads; `plot` draws every figure.
// Standard error through `note!` (it never panics on a full or closed stderr).
#![deny(clippy::print_stderr)]

use clap::{Parser, Subcommand};

pub mod arg_values;
pub mod artifacts;
pub mod campaign;
pub mod csv_args;
pub mod decode;
pub mod dump_tests;
pub mod fc;
pub mod fit;
pub mod fit_tables;
pub mod fly;
pub mod frf;
pub mod identify;
pub mod interrupt;
pub mod logs;
pub mod margins;
pub mod measured_loop;
pub mod mode_text;
pub mod output;
pub mod plot;
pub mod report;
pub mod run_lock;
pub mod sim;
pub mod structures;
pub mod table;
pub mod tune;
pub mod vehicle;
pub mod verify;

/// Identify helicopter dynamics from automated frequency sweeps flown under conditional
/// attitude hold (Jung, Shim & Kim).
#[derive(Parser, Debug)]
#[command(
    name = "sweephold",
    version,
    about,
    long_about = None,
    after_help = "Without arguments, `sweephold` runs `sweephold campaign` on the defaults \
(Bo-105, out/campaign) and prints where the report is."
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The verbs of `sweephold`.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// The whole job: fly the three modes, identify, verify, score against the truth,
    /// and write summary.json and report.html.
    Campaign(campaign::CampaignArgs),
    /// Decode telemetry dumps into CSV or JSON lines (one row per Sample).
    Decode(decode::DecodeArgs),
    /// Set up the flight controller over its link: `fc params list|get|set|save|reset|pull|push|diff`.
    Fc(fc::FcArgs),
    /// Fit a state-space model structure to frequency responses (CIFER DERIVID-like).
    Fit(fit::FitArgs),
    /// Fly sweep records with the flight controller in the loop and the simulator as the aircraft.
    Fly(fly::FlyArgs),
    /// Frequency responses (Chirp-Z, multi-window, MISO, composite) from dumps or CSV.
    Frf(frf::FrfArgs),
    /// From logs to a model with no simulator: frequency responses, 6-DOF and 9-DOF fits,
    /// verification on the held-out tests.
    Identify(identify::IdentifyArgs),
    /// Loop margins and handling qualities of the board's pilot-mode loops on an identified model.
    Margins(margins::MarginsArgs),
    /// Regenerate report.html of a campaign folder from its files.
    Report(report::ReportArgs),
    /// Trim and linearize a simulated helicopter (a shipped aircraft or an aircraft file).
    Sim(sim::SimArgs),
    /// Pilot-mode gains designed on an identified model for crossovers with margins.
    Tune(tune::TuneArgs),
    /// Simulate an identified model on recorded inputs and score it (Theil's inequality coefficient).
    Verify(verify::VerifyArgs),
}

/// Run one parsed command line. Whatever the verb, a failed write to standard output
/// ends as one line (`output::stdout_outcome`).
pub fn run(cli: Cli) -> anyhow::Result<()> {
    // Verbs with safe points stop there on a signal; the others end at once (`interrupt`).
    let handling = match cli.command {
        Command::Campaign(_) | Command::Fly(_) | Command::Decode(_) => {
            interrupt::Handling::Deferred
        }
        // A watch ends cleanly (exit 0) on the first signal.
        Command::Fc(ref fc) if matches!(fc.command, fc::FcCommand::Watch(_)) => {
            interrupt::Handling::Deferred
        }
        _ => interrupt::Handling::AtOnce,
    };
    interrupt::install(handling);
    output::stdout_outcome(run_verb(cli))
}

fn run_verb(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Campaign(args) => campaign::run(&args),
        Command::Decode(args) => decode::run(&args),
        Command::Fc(args) => fc::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Fly(args) => fly::run(&args),
        Command::Frf(args) => frf::run(&args),
        Command::Identify(args) => identify::run(&args),
        Command::Margins(args) => margins::run(&args),
        Command::Report(args) => report::run(&args),
        Command::Sim(args) => sim::run(&args),
        Command::Tune(args) => tune::run(&args),
        Command::Verify(args) => verify::run(&args),
    }
}
