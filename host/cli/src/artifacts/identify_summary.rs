//! `summary.json` of `sweephold identify` (layout in docs/formats.md, "Identify
//! summary.json"): the tests read and what became of each, where the trim and the trim
//! points came from, and the fit and verification sections the campaign writes too,
//! without truth (identify has none: the truth fields of `fit` are null). Here, beside
//! the campaign's documents, because the report reads it too.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::summary::{FitSummary, StageFailure, VerifySummary};
use crate::dump_tests::TestListing;

/// The stages of `identify` as its `summary.json` names them (`timings_s`, `error`), in
/// run order. The report (the last stage, `report`) is drawn from the summary written
/// before it, so neither its time nor `total` counts it.
pub const STAGES: [&str; 6] = [
    stage::FRF,
    stage::FIT_6DOF,
    stage::FIT_9DOF,
    stage::VERIFY,
    stage::MARGINS,
    stage::REPORT,
];

/// Each stage's name, as `identify` runs it and its `summary.json` records it.
pub mod stage {
    /// The frequency responses.
    pub const FRF: &str = "frf";
    /// The quasi-steady 6-DOF fit.
    pub const FIT_6DOF: &str = "fit-6dof";
    /// The 9-DOF hybrid fit.
    pub const FIT_9DOF: &str = "fit-9dof";
    /// The verification on the held-out tests.
    pub const VERIFY: &str = "verify";
    /// The loop margins of the model under the aircraft's board law, with the logs' loop
    /// tests measured beside them (`margins.json`, `margins-loops.json`).
    pub const MARGINS: &str = "margins";
    /// `report.html`.
    pub const REPORT: &str = "report";
}

/// The whole `summary.json` of `identify`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdentifySummary {
    /// Vehicle name: the aircraft file's `name`.
    pub vehicle: String,
    /// The fits' seed.
    pub seed: u64,
    /// Every test of every file read, in the order read, with what became of it.
    pub tests: Vec<TestListing>,
    /// The sweep tests the frequency responses were computed from (`FILE` or
    /// `FILE test N`), in the order analysed.
    pub sweeps: Vec<String>,
    /// The held-out tests (doublets, 3-2-1-1…) the model was verified on.
    pub held_out: Vec<String>,
    /// The trim attitude φ0, θ0 \[rad\] the structure is written about: the mean of the
    /// flight controller's captured trims over the sweep tests; null when none captured
    /// one (then the structure file's own).
    pub captured_trim_rad: Option<[f64; 2]>,
    /// The trim points file the hybrid's `trim_derived` parameters came from; null when
    /// none was given (then they are fitted like the others).
    pub trim_points: Option<String>,
    /// Where the trim points came from: `file` (`--trim-points`), `flight` (the steady
    /// segments of `--steady-flights` with the velocities of `--gnss`) or `none`.
    #[serde(default = "no_source")]
    pub trim_points_source: String,
    /// The steady segments the trim points were averaged over (`flight` only).
    #[serde(default)]
    pub steady_segments: Vec<SteadySegmentSummary>,
    /// True without any velocity source (no trim points): the hover derivatives (the
    /// hybrid's `trim_derived` parameters) are fitted from the responses alone, which
    /// inform them poorly; the report flags it.
    #[serde(default)]
    pub hover_derivatives_unanchored: bool,
    /// What the run could not do and how it went on instead (no trim points, no
    /// held-out test…), one sentence each.
    pub notes: Vec<String>,
    /// The final (9-DOF hybrid, reduced) fit; its truth fields are null. Null until fitted.
    pub fit: Option<FitSummary>,
    /// The verification on the held-out tests; null without them or until verified.
    pub verify: Option<VerifySummary>,
    /// Wall time per completed stage \[s\], plus `total`.
    pub timings_s: BTreeMap<String, f64>,
    /// Null when every stage completed.
    pub error: Option<StageFailure>,
}

/// `trim_points_source` of a summary written before it existed.
fn no_source() -> String {
    "none".to_string()
}

/// One steady segment of `--steady-flights` (`summary.json` `steady_segments`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SteadySegmentSummary {
    /// Its label in `trim-points.csv` (`steady N`).
    pub label: String,
    /// Ticks of its first and last Sample.
    pub ticks: [u32; 2],
    /// Its one-second blocks.
    pub blocks: usize,
    /// Body velocity u, v, w [m/s] and their standard errors.
    pub velocity_m_s: [f64; 3],
    /// Standard errors of `velocity_m_s`.
    pub velocity_se_m_s: [f64; 3],
}
