//! The error of a campaign: which stage failed, and why.

use std::fmt;
use std::path::PathBuf;

use crate::artifacts::stage::Stage;

/// A campaign stopped at `stage`. The output folder keeps the previous complete
/// campaign; what this one wrote is kept in `DIR.failed`, whose `summary.json` records
/// the error (when the folder is writable).
#[derive(Debug)]
pub struct CampaignError {
    /// The stage that failed.
    pub stage: Stage,
    /// The failure, causes included, on one line.
    pub message: String,
    /// Where the stopped campaign's files were kept (`DIR.failed`), or why they could
    /// not be; `None` when nothing was written yet.
    pub kept: Option<Result<PathBuf, String>>,
}

impl CampaignError {
    /// The error of `stage` from any error (its causes joined on one line).
    pub fn new(stage: Stage, error: &anyhow::Error) -> Self {
        CampaignError {
            stage,
            message: format!("{error:#}").replace('\n', " "),
            kept: None,
        }
    }
}

impl fmt::Display for CampaignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "campaign stage `{}` failed: {}",
            self.stage, self.message
        )?;
        match &self.kept {
            Some(Ok(folder)) => write!(
                f,
                " (its files are in {}; the previous campaign, if any, is unchanged)",
                folder.display()
            ),
            Some(Err(why)) => write!(f, " (its files could not be kept: {why})"),
            None => Ok(()),
        }
    }
}

impl std::error::Error for CampaignError {}
