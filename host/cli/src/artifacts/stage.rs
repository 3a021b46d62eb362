//! The stages of a campaign in the order they run, and their names: the keys of
//! `summary.json`'s `timings_s` and its `error.stage`.

use std::fmt;

/// One step of `sweephold campaign`, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Stage {
    /// Create the output folder.
    Setup,
    /// Fly the default sweep records in conditional-attitude-hold mode (the fit data).
    FlyCah,
    /// Fly the same records with the hold always on (the paper's correlated case).
    FlyStandard,
    /// Fly the same records with the hold always on plus off-axis noise.
    FlyNoise,
    /// Fly the held-out doublets (another seed) for the verification.
    FlyVerification,
    /// `--fc board-sim` only: fly the steady flights (`fly --steady-flights`): the board's
    /// log and the simulated GNSS's file, for `identify --steady-flights`.
    FlySteady,
    /// Frequency responses of the `cah` records.
    Frf,
    /// Trim points (the simulator's steady flights), `trim-points.csv`.
    TrimPoints,
    /// Quasi-steady 6-DOF fit (start values of the hybrid).
    Fit6Dof,
    /// 9-DOF hybrid fit with reduction.
    Fit9Dof,
    /// Scoring against the simulator's linearization.
    Truth,
    /// Time-domain verification on the held-out doublets.
    Verify,
    /// Loop margins and handling qualities of the 9-DOF fit under the board's law.
    Margins,
    /// `report.html`.
    Report,
}

impl Stage {
    /// Every stage, in the order a campaign runs them.
    pub const ALL: [Stage; 14] = [
        Stage::Setup,
        Stage::FlyCah,
        Stage::FlyStandard,
        Stage::FlyNoise,
        Stage::FlyVerification,
        Stage::FlySteady,
        Stage::Frf,
        Stage::TrimPoints,
        Stage::Fit6Dof,
        Stage::Fit9Dof,
        Stage::Truth,
        Stage::Verify,
        Stage::Margins,
        Stage::Report,
    ];

    /// The stage's name in `summary.json` (`timings_s` keys, `error.stage`).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Setup => "setup",
            Stage::FlyCah => "fly_cah",
            Stage::FlyStandard => "fly_standard",
            Stage::FlyNoise => "fly_noise",
            Stage::FlyVerification => "fly_verification",
            Stage::FlySteady => "fly_steady",
            Stage::Frf => "frf",
            Stage::TrimPoints => "trim_points",
            Stage::Fit6Dof => "fit_6dof",
            Stage::Fit9Dof => "fit_9dof",
            Stage::Truth => "truth",
            Stage::Verify => "verify",
            Stage::Margins => "margins",
            Stage::Report => "report",
        }
    }

    /// What the stage does, for the progress line.
    pub fn description(self) -> &'static str {
        match self {
            Stage::Setup => "output folder",
            Stage::FlyCah => "flying the sweeps, conditional attitude hold",
            Stage::FlyStandard => "flying the sweeps, standard attitude hold",
            Stage::FlyNoise => "flying the sweeps, hold plus off-axis noise",
            Stage::FlyVerification => "flying the held-out doublets",
            Stage::FlySteady => "flying the steady flights (board-sim)",
            Stage::Frf => "frequency responses of the cah records",
            Stage::TrimPoints => "trim points (steady flights)",
            Stage::Fit6Dof => "6-DOF quasi-steady fit (start values)",
            Stage::Fit9Dof => "9-DOF hybrid fit with reduction",
            Stage::Truth => "scoring against the simulator's truth",
            Stage::Verify => "verification on the doublets",
            Stage::Margins => "loop margins and handling qualities of the 9-DOF fit",
            Stage::Report => "report.html",
        }
    }
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_names_are_unique_snake_case() {
        let stages = Stage::ALL;
        let mut names: Vec<&str> = stages.iter().map(|s| s.name()).collect();
        assert!(names.iter().all(|n| n
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')));
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), stages.len());
    }
}
