//! The error of a campaign: which stage failed, and why.

use std::fmt;

use super::stage::Stage;

/// A campaign stopped at `stage`. Everything written before it is kept in the output
/// folder, and `summary.json` records the error (when the folder is writable).
#[derive(Debug)]
pub struct CampaignError {
    /// The stage that failed.
    pub stage: Stage,
    /// The failure, causes included, on one line.
    pub message: String,
}

impl CampaignError {
    /// The error of `stage` from any error (its causes joined on one line).
    pub fn new(stage: Stage, error: &anyhow::Error) -> Self {
        CampaignError {
            stage,
            message: format!("{error:#}").replace('\n', " "),
        }
    }
}

impl fmt::Display for CampaignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "campaign stage `{}` failed: {}",
            self.stage, self.message
        )
    }
}

impl std::error::Error for CampaignError {}
