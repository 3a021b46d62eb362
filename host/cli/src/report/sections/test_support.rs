//! What the sections' tests share: report inputs holding only a fit, and fits with modes.

use sysid::fit::modes::{HoverModeScore, ModeRecord, TruthModeRecord};

use crate::artifacts::summary::FitSummary;
use crate::report::inputs::{FolderSummary, ReportInputs};

/// A report's inputs holding only a summary with `fit`.
pub fn inputs_with_fit(fit: FitSummary) -> ReportInputs {
    use crate::artifacts::summary::{CampaignSummary, Modes};
    ReportInputs {
        dir: std::path::PathBuf::from("campaign"),
        summary: FolderSummary::Campaign(CampaignSummary {
            vehicle: "bo105".into(),
            link: "in-process".into(),
            seed: 1,
            verification_seed: 2,
            t_rec_s: 90.0,
            quick: false,
            modes: Modes::default(),
            fit: Some(fit),
            verify: None,
            timings_s: Default::default(),
            error: None,
        }),
        frf: None,
        model: None,
        truth_model: None,
        verify: None,
        margins: None,
        margins_loops: None,
        flown: Default::default(),
    }
}

/// A report's inputs of an identify folder whose summary holds `fit` and one test read.
pub fn identify_inputs_with_fit(fit: FitSummary) -> ReportInputs {
    use crate::artifacts::identify_summary::IdentifySummary;
    use crate::dump_tests::TestListing;
    let campaign = inputs_with_fit(fit.clone());
    ReportInputs {
        dir: std::path::PathBuf::from("identified"),
        summary: FolderSummary::Identify(IdentifySummary {
            vehicle: "trex700l".into(),
            seed: 1,
            tests: vec![TestListing {
                file: "log.bin".into(),
                test: "test 1: lat Sweep, ConditionalAttitudeHold, 20.0 s, completed".into(),
                verdict: "used".into(),
            }],
            sweeps: vec!["log.bin".into()],
            held_out: Vec::new(),
            captured_trim_rad: None,
            trim_points: None,
            trim_points_source: "none".into(),
            steady_segments: Vec::new(),
            hover_derivatives_unanchored: true,
            notes: vec!["no held-out test (doublet, 3-2-1-1) in the logs: not verified".into()],
            fit: Some(fit),
            verify: None,
            timings_s: Default::default(),
            error: None,
        }),
        ..campaign
    }
}

/// An identified mode, paired with a truth mode and its error when `truth` is given.
pub fn mode(name: &str, eigenvalue: [f64; 2], truth: Option<([f64; 2], f64)>) -> ModeRecord {
    ModeRecord {
        name: name.into(),
        eigenvalue,
        omega_n: Some(eigenvalue[0].hypot(eigenvalue[1])),
        zeta: None,
        time_to_double_s: None,
        time_to_half_s: Some(1.0),
        poles: if eigenvalue[1] == 0.0 { 1 } else { 2 },
        shares: Default::default(),
        truth: truth.map(|t| t.0),
        truth_name: truth.map(|_| name.to_string()),
        error_percent: truth.map(|t| t.1),
    }
}

/// A scored 9-DOF fit with these modes.
pub fn fit_with_modes(
    modes: Vec<ModeRecord>,
    truth_modes: Vec<TruthModeRecord>,
    hover: HoverModeScore,
    poles: usize,
) -> FitSummary {
    FitSummary {
        structure: "bo105-9dof-hybrid".into(),
        cost_ave: 16.0,
        truth_cost_ave: Some(10.0),
        start_cost_ave: 17.0,
        pairs: Vec::new(),
        params: Vec::new(),
        model_file: "model9.json".into(),
        modes,
        truth_modes,
        hover_modes_matched: Some(hover),
        poles_at_origin: Some(poles),
        speed_derivatives: Vec::new(),
        trim: None,
        priors: Vec::new(),
        degenerate: Vec::new(),
    }
}
