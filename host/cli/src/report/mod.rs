//! `sweephold report DIR`: `report.html` of a campaign folder — one self-contained page
//! (inline SVG, no script, nothing fetched) drawn only from the files in the folder, so
//! that it can be regenerated at any time. It reads the documents the campaign wrote
//! ([`crate::artifacts`]) and computes nothing the campaign has: within a campaign, what
//! it draws from the dumps is handed over as the campaign decoded it; on its own, it
//! decodes the dumps.
//!
//! A folder `sweephold identify` wrote (told apart by its `summary.json`,
//! [`FolderSummary`]) gets its own page from the same sections without their truth
//! parts, drawn from its documents alone: identify writes it as its last stage, and
//! `report DIR` redraws it byte for byte.

pub mod curves;
pub mod html;
pub mod inputs;
pub mod margins_file;
pub mod sections;

use std::path::{Path, PathBuf};

use clap::Args;

use crate::artifacts::files;
use crate::artifacts::flown::FlownRecords;
use crate::artifacts::identify_summary::IdentifySummary;
pub use inputs::{FolderSummary, ReportError, ReportInputs};

/// Arguments of `sweephold report`.
#[derive(Args, Debug, Clone)]
#[command(
    after_help = "DIR is a folder written by `sweephold campaign` or `sweephold identify` \
(told apart by its summary.json; an identify folder's page has no truth in it and is drawn \
from its files alone, as identify drew it). Sections whose \
stage did not complete say so; a file that exists but does not parse is an error. The \
report holds DIR.lock while it runs, as campaign and fly do: it is refused while a run \
writes DIR, and a run on DIR is refused while it runs."
)]
pub struct ReportArgs {
    /// The campaign or identify folder.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

/// Run `sweephold report`: write DIR/report.html and print its path.
pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    // The folder's run lock (`DIR.lock`, as `campaign` and `fly` hold it): a report is
    // refused while a run writes the folder, and a run while a report reads it. Taken only
    // for an existing folder, so that a mistyped DIR creates nothing; `report .` locks
    // the folder by its full name.
    let _lock = if args.dir.is_dir() {
        let lock_path = match crate::output::sibling(&args.dir, "lock") {
            Ok(path) => path,
            Err(_) => {
                let full = std::fs::canonicalize(&args.dir)
                    .map_err(|e| anyhow::anyhow!("cannot resolve {}: {e}", args.dir.display()))?;
                crate::output::sibling(&full, "lock")?
            }
        };
        Some(crate::run_lock::RunLock::acquire(&args.dir, &lock_path)?)
    } else {
        None
    };
    let path = write_report(&args.dir)?;
    crate::output::print(&format!("report: {}\n", path.display()))
}

/// Read the campaign folder `dir` (decoding its dumps), write `dir/report.html`, return its
/// path.
pub fn write_report(dir: &Path) -> Result<PathBuf, ReportError> {
    write(&ReportInputs::load(dir)?)
}

/// Read the documents of the campaign folder `dir`, write `dir/report.html` with `flown`
/// for what the report draws from the dumps, return its path.
pub fn write_report_with(dir: &Path, flown: FlownRecords) -> Result<PathBuf, ReportError> {
    write(&ReportInputs::read(dir, Some(flown))?)
}

fn write(inputs: &ReportInputs) -> Result<PathBuf, ReportError> {
    let dir = &inputs.dir;
    let html = render(inputs);
    let path = dir.join(files::REPORT);
    let write_error = |e: anyhow::Error| ReportError::Write {
        path: path.clone(),
        message: e.root_cause().to_string(),
    };
    refuse_link_into_folder(dir, &path).map_err(write_error)?;
    crate::output::write_file_in_folder(&path, html.as_bytes()).map_err(write_error)?;
    Ok(path)
}

/// The report's inputs are the campaign folder's files: a `report.html` that is a link
/// resolving into the folder (to `model9.json`, `frf.json`, `summary.json`, a dump) is
/// refused, naming both. Any other link is replaced by the report, never written through.
fn refuse_link_into_folder(dir: &Path, report: &Path) -> anyhow::Result<()> {
    let is_link = std::fs::symlink_metadata(report).is_ok_and(|m| m.is_symlink());
    if !is_link {
        return Ok(());
    }
    let (Ok(target), Ok(folder)) = (report.canonicalize(), dir.canonicalize()) else {
        return Ok(());
    };
    if target.starts_with(&folder) {
        anyhow::bail!(
            "it is a symbolic link to {}, one of the report's inputs: refusing to write \
             through it",
            target.display()
        );
    }
    Ok(())
}

/// The whole page: a campaign's, or an identify folder's (`identify_page`).
pub fn render(inputs: &ReportInputs) -> String {
    let summary = match &inputs.summary {
        FolderSummary::Campaign(summary) => summary,
        FolderSummary::Identify(summary) => return identify_page(inputs, summary),
    };
    let title = format!(
        "sweephold campaign: {} seed {}",
        summary.vehicle, summary.seed
    );
    let mut body = format!("<h1>{}</h1>\n", html::escape(&title));
    body += &html::note(
        "Frequency-sweep system identification under conditional attitude hold (Jung, Shim & \
Kim): the firmware flown in the loop with the nonlinear simulator, frequency responses, \
6-DOF then 9-DOF hybrid state-space fit, verification on held-out doublets, and comparison \
with the simulator's truth.",
    );
    body += &sections::summary::summary_section(inputs, summary);
    body += &sections::sweep::sweep_input_section(inputs);
    body += &sections::coherence::coherence_section(inputs);
    body += &sections::bode::bode_section(inputs);
    body += &sections::parameters::parameter_section(inputs);
    body += &sections::modes::modes_section(inputs);
    body += &sections::costs::cost_section(inputs);
    body += &sections::verification::verification_section(inputs);
    body += &sections::loops::loops_section(inputs);
    html::page(&title, &body)
}

/// The page of an identify folder: the tests read, then the campaign's sections of the
/// model without their truth parts, and the loops with the logs' loop tests measured
/// beside them. No sweep time history nor coherence curves (they come from dumps outside
/// the folder).
fn identify_page(inputs: &ReportInputs, summary: &IdentifySummary) -> String {
    let title = format!(
        "sweephold identify: {} seed {}",
        summary.vehicle, summary.seed
    );
    let mut body = format!("<h1>{}</h1>\n", html::escape(&title));
    body += &html::note(
        "Frequency-sweep system identification from flight logs: the frequency responses of \
the sweep tests, 6-DOF then 9-DOF hybrid state-space fit with the aircraft file's priors, \
verification on the held-out tests.",
    );
    body += &sections::identify_summary::identify_summary_section(summary);
    body += &sections::bode::bode_section(inputs);
    body += &sections::parameters::parameter_section(inputs);
    body += &sections::modes::modes_section(inputs);
    body += &sections::costs::cost_section(inputs);
    body += &sections::verification::verification_section(inputs);
    body += &sections::loops::loops_section(inputs);
    html::page(&title, &body)
}
