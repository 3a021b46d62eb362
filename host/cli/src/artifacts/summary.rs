//! `summary.json` of `sweephold campaign` (layout documented in docs/formats.md,
//! "Campaign summary.json"; later checks read these names). Every section is null until
//! its stage has completed, so a campaign stopped by an error still writes what it has.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use sysid::fit::modes::{HoverModeScore, ModeRecord, TruthModeRecord};
use sysid::fit::verify::BiasMode;

/// Peak |φ| and |θ| over all the records of one mode \[deg\].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PeakAttitudeDeg {
    /// Peak |φ| \[deg\] (absolute attitude, trim included).
    pub phi: f64,
    /// Peak |θ| \[deg\] (absolute attitude, trim included).
    pub theta: f64,
}

/// The flights of one excitation mode.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeSummary {
    /// Average lat–lon cross-control coherence of the lateral sweep records; null when
    /// no lateral record completed.
    pub cross_coherence_lat_lon: Option<f64>,
    /// Peak attitudes over all the records of the mode.
    pub max_abs_deg: PeakAttitudeDeg,
    /// Peak excursions from the trim the flight controller captured, over all the
    /// records of the mode that captured one (|φ − φ_trim|, |θ − θ_trim| \[deg\]); null
    /// when none did.
    #[serde(default)]
    pub max_from_trim_deg: Option<PeakAttitudeDeg>,
    /// Number of records the firmware aborted.
    pub aborts: usize,
    /// Number of records flown.
    pub records: usize,
    /// Folder of the dumps and of `fly`'s own summary.json, relative to the campaign's.
    pub folder: String,
}

/// The three modes, each null until flown.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Modes {
    /// Conditional attitude hold (the paper's method; the fit data).
    pub cah: Option<ModeSummary>,
    /// Hold always on (the correlated case the paper warns about).
    pub standard: Option<ModeSummary>,
    /// Hold always on plus off-axis noise (Tischler's method).
    pub noise: Option<ModeSummary>,
}

/// One fitted pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairSummary {
    /// Output name.
    pub output: String,
    /// Control name.
    pub input: String,
    /// Cost J of the pair.
    pub cost: f64,
    /// Fit range [rad/s].
    pub range: [f64; 2],
    /// J of the identified model against the truth model over the same range (null
    /// without a truth scoring).
    pub truth_cost: Option<f64>,
}

/// One parameter of the final model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterSummary {
    /// Name.
    pub name: String,
    /// Identified value.
    pub value: f64,
    /// `free`, `fixed` or `constrained`.
    pub status: String,
    /// Cramér–Rao bound in % of |value|; null when fixed or infinite.
    pub cr_percent: Option<f64>,
    /// Insensitivity in % of |value|; null when fixed or infinite.
    pub insensitivity_percent: Option<f64>,
    /// The simulator's value; null when the truth mapping does not know it.
    pub truth: Option<f64>,
    /// 100·(value − truth)/|truth|; null without a non-zero truth.
    pub error_percent: Option<f64>,
    /// Accuracy flags: `cr`, `insensitive`, `correlated:OTHER`.
    pub flags: Vec<String>,
}

/// The final (9-DOF hybrid, reduced) fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// Structure name.
    pub structure: String,
    /// J_ave over the fitted pairs.
    pub cost_ave: f64,
    /// J_ave of the identified model against the truth model (null without truth).
    pub truth_cost_ave: Option<f64>,
    /// J_ave of the 6-DOF fit the hybrid started from.
    pub start_cost_ave: f64,
    /// Fitted pairs.
    pub pairs: Vec<PairSummary>,
    /// Every parameter (free, fixed, constrained).
    pub params: Vec<ParameterSummary>,
    /// Model file, relative to the campaign folder.
    pub model_file: String,
    /// The identified model's modes (`sysid::fit::modes`), sorted by |λ|, each with its
    /// truth mode and error once the truth stage has run. Empty in older files.
    #[serde(default)]
    pub modes: Vec<ModeRecord>,
    /// The truth model's modes (the structure at the truth values), each with the
    /// identified mode paired with it. Empty until the truth stage, and in older files.
    #[serde(default)]
    pub truth_modes: Vec<TruthModeRecord>,
    /// Truth hover modes (10⁻⁶ ≤ |λ| < 3 rad/s) with an identified counterpart within
    /// 25 %, of how many, and the worst error; null until the truth stage (or when the
    /// modes could not be computed), and in older files.
    #[serde(default)]
    pub hover_modes_matched: Option<HoverModeScore>,
    /// Poles of the identified model at the origin (|λ| < 10⁻⁶ rad/s; a pair counts 2);
    /// null when its modes could not be computed, and in older files.
    #[serde(default)]
    pub poles_at_origin: Option<usize>,
    /// The quasi-static speed derivatives M_u, L_v, N_v of the identified model (flapping
    /// at its steady value: what the trim points fix, whichever parameters carry it),
    /// with the truth model's once the truth stage has run. Empty in older files.
    #[serde(default)]
    pub speed_derivatives: Vec<SpeedDerivativeSummary>,
    /// What the trim points gave (`trim-points.csv`): null without them.
    #[serde(default)]
    pub trim: Option<sysid::fit::trim::TrimOutcome>,
    /// Every prior: the aircraft file's constants the structure holds and the parameters
    /// estimated under a prior, with how far the data moved them
    /// ([`super::priors`]). Empty in older files.
    #[serde(default)]
    pub priors: Vec<super::priors::PriorSummary>,
    /// Why the model is degenerate (`model.json` `degenerate`: parameters outside their
    /// physical range, free parameters on a range bound of the structure file); empty
    /// when it is not. A degenerate model meets no bar. Empty in older files.
    #[serde(default)]
    pub degenerate: Vec<sysid::fit::degenerate::DegenerateReason>,
}

/// One quasi-static speed derivative of [`FitSummary::speed_derivatives`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpeedDerivativeSummary {
    /// `Mu`, `Lv` or `Nv`.
    pub name: String,
    /// The identified model's value [1/(m·s)].
    pub value: Option<f64>,
    /// The truth model's.
    pub truth: Option<f64>,
    /// 100·(value − truth)/|truth|.
    pub error_percent: Option<f64>,
}

/// Verification of one held-out record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VerifyRecordSummary {
    /// Dump file, relative to the campaign folder.
    pub file: String,
    /// TIC per compared output.
    pub tic: BTreeMap<String, f64>,
    /// Mean TIC over the outputs.
    pub tic_mean: f64,
    /// When the simulated model overflowed \[s\]; null otherwise.
    pub diverged_at_s: Option<f64>,
}

/// The outputs whose verification TIC the bar (≤ 0.25) is read on.
pub const ANGULAR_RATES: [&str; 3] = ["p", "q", "r"];

/// Where the output biases of a verification written before `bias` was recorded came
/// from: they were fitted by least squares.
pub fn bias_of_older_files() -> BiasMode {
    BiasMode::Fitted
}

/// Mean of the values of `tic` named in `outputs` (all of them when `None`); `None` when
/// there are none.
pub fn mean_tic(tic: &BTreeMap<String, f64>, outputs: Option<&[&str]>) -> Option<f64> {
    let values: Vec<f64> = tic
        .iter()
        .filter(|(name, _)| outputs.is_none_or(|names| names.contains(&name.as_str())))
        .map(|(_, value)| *value)
        .collect();
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// Verification of the final model on the held-out doublets.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VerifySummary {
    /// Where each output's bias came from: `trim` (its mean over the trim capture before
    /// the doublet) or `fitted` (least squares). Summaries written before it: `fitted`.
    #[serde(default = "bias_of_older_files")]
    pub bias: BiasMode,
    /// Per output: the mean TIC over the held-out records.
    pub tic: BTreeMap<String, f64>,
    /// Mean of `tic` over p, q, r; null when none of them was compared (and in
    /// summaries written before it).
    #[serde(default)]
    pub tic_mean_pqr: Option<f64>,
    /// Mean of `tic` over every compared output (u v w p q r ax ay az for the 9-DOF
    /// model); null in summaries written before it.
    #[serde(default)]
    pub tic_mean_all: Option<f64>,
    /// Mean over outputs and records: the same number as `tic_mean_all` (kept).
    pub tic_mean: f64,
    /// Per record.
    pub records: Vec<VerifyRecordSummary>,
}

impl VerifySummary {
    /// Mean TIC over p, q, r: `tic_mean_pqr`, or from `tic` for summaries without it.
    pub fn mean_pqr(&self) -> Option<f64> {
        self.tic_mean_pqr
            .or_else(|| mean_tic(&self.tic, Some(&ANGULAR_RATES)))
    }

    /// Mean TIC over every compared output: `tic_mean_all`, or `tic_mean`.
    pub fn mean_all(&self) -> f64 {
        self.tic_mean_all.unwrap_or(self.tic_mean)
    }

    /// `p 0.108, q 0.111, r 0.176; mean p q r 0.132, all 9 outputs 0.302 (trim bias)`.
    pub fn headline(&self) -> String {
        let rates: Vec<String> = ANGULAR_RATES
            .iter()
            .filter_map(|o| self.tic.get(*o).map(|t| format!("{o} {t:.3}")))
            .collect();
        format!(
            "{}; mean p q r {}, all {} outputs {:.3} ({} bias)",
            rates.join(", "),
            self.mean_pqr()
                .map_or("-".to_string(), |m| format!("{m:.3}")),
            self.tic.len(),
            self.mean_all(),
            self.bias
        )
    }
}

/// Where and why a campaign stopped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StageFailure {
    /// Stage name (a `timings_s` key).
    pub stage: String,
    /// The error, one line.
    pub message: String,
}

fn in_process() -> String {
    "in-process".to_string()
}

/// The whole `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignSummary {
    /// Vehicle name: the aircraft file's `name` (`bo105`, `trex700l`, `fbl700`, …).
    pub vehicle: String,
    /// The flight controller the records were flown with: `in-process` (the flight
    /// logic on the simulator's exact states) or `board-sim` (the board application on
    /// emulated IMU and receiver, no air data). A summary without it is `in-process`.
    #[serde(default = "in_process")]
    pub link: String,
    /// Campaign seed (the sweeps; the held-out doublets use `verification_seed`).
    pub seed: u64,
    /// Seed of the held-out doublet records.
    pub verification_seed: u64,
    /// Sweep record length \[s\] (90 by default, shorter with `--quick`).
    pub t_rec_s: f64,
    /// Whether `--quick` was given.
    pub quick: bool,
    /// Per excitation mode.
    pub modes: Modes,
    /// The final fit; null until fitted.
    pub fit: Option<FitSummary>,
    /// The verification; null until verified.
    pub verify: Option<VerifySummary>,
    /// Wall time per completed stage \[s\], plus `total`.
    pub timings_s: BTreeMap<String, f64>,
    /// Null when every stage completed.
    pub error: Option<StageFailure>,
}
