//! The per-stage progress line of a campaign on stderr.

use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::artifacts::stage::Stage;

/// The progress display of one stage: a spinner while it runs when stderr is a terminal
/// (indicatif hides itself otherwise), then one line with its wall time unless quiet.
pub struct StageProgress {
    stage: Stage,
    spinner: ProgressBar,
    started: Instant,
    quiet: bool,
}

impl StageProgress {
    /// Start showing `stage`.
    pub fn start(stage: Stage, quiet: bool) -> Self {
        let target = if quiet {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        let spinner = ProgressBar::with_draw_target(None, target);
        spinner.set_style(
            ProgressStyle::with_template("{spinner} {prefix:<16} {msg} {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        spinner.set_prefix(stage.name());
        spinner.set_message(stage.description());
        spinner.enable_steady_tick(Duration::from_millis(120));
        StageProgress {
            stage,
            spinner,
            started: Instant::now(),
            quiet,
        }
    }

    /// Stop the spinner and print the stage's outcome; returns its wall time \[s\].
    pub fn finish(self, outcome: &str) -> f64 {
        let seconds = self.started.elapsed().as_secs_f64();
        self.spinner.finish_and_clear();
        if !self.quiet {
            crate::note!("{:<16} {:>6.2} s  {}", self.stage.name(), seconds, outcome);
        }
        seconds
    }
}
