//! `sweephold campaign`: the paper's whole job in one command — fly the three excitation
//! modes, compute the frequency responses of the conditional-attitude-hold records, fit
//! the 6-DOF then the 9-DOF hybrid model (with reduction), score it against the
//! simulator's truth, verify it on held-out doublets, and write `summary.json` and
//! `report.html`.

pub mod error;
pub mod progress;
pub mod structures;
pub mod verification;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::anyhow;
use clap::Args;
use sweephold_protocol::Axis;
use sysid::document::FrfDocument;
use sysid::fit::modes::{hover_summary, mode_records, poles_at_origin, HOVER_MODE_LIMIT_RAD_S};
use sysid::fit::report::ScoredModelDocument;
use sysid::fit::trim::TrimPoints;
use sysid::fit::verify::BiasMode;
use sysid::fit::{
    fit, fit_from_alternative_starts, start_from_quasi_steady, FitOptions, FitResult,
};
use sysid::frf::{analyse, group_by_primary, load_dump, FrfOptions};

use crate::artifacts::files;
use crate::artifacts::stage::Stage;
use crate::artifacts::summary::{
    CampaignSummary, FitSummary, ModeSummary, Modes, PairSummary, ParameterSummary,
    PeakAttitudeDeg, SpeedDerivativeSummary, StageFailure,
};
use crate::artifacts::truth_model::TruthModelDocument;
use crate::artifacts::verification::VerifyDocument;
use crate::fly::link::InProcessLink;
use crate::fly::plan::PAPER_T_REC_S;
use crate::fly::summary::FlySummary;
use crate::fly::{self, AmplitudeArg, FcArg, FlyArgs, FlyOutcome, InputArg, ModeArg, VehicleArg};
use crate::output::{write_atomic, write_json, StagedFolder};
use error::CampaignError;
use progress::StageProgress;
use verification::verify_dump;

/// Sweep record length of `--quick` [s]: long enough for the frequency responses above
/// ~0.6 rad/s, short enough for a test.
pub const QUICK_T_REC_S: f64 = 20.0;

/// The held-out doublets are simulated open loop over their whole record (a few seconds:
/// the hover instabilities do not run away in that time), as VERIFID does.
pub const VERIFY_SEGMENT_S: Option<f64> = None;

/// Each output's bias is its mean over the trim capture before the doublet (and each
/// input's trim likewise), not fitted to the prediction.
pub const VERIFY_BIAS: BiasMode = BiasMode::Trim;

/// Arguments of `sweephold campaign`.
#[derive(Args, Debug, Clone)]
#[command(
    after_help = "Writes into DIR: fly-cah/, fly-standard/, fly-noise/ (the sweep \
dumps and fly's summary.json per mode), verify-doublet/ (held-out doublets), frf.json, \
model6.json, model9.json, truth-model9.json, verify.json, summary.json (layout in \
docs/formats.md) and report.html. The campaign is built in DIR.partial and replaces DIR only \
when it completes. A failing stage, or Ctrl-C (the campaign stops after the current \
stage), stops it with the stage's name: DIR keeps the previous complete campaign, and \
the stopped one's files, with the error in its summary.json, are kept in DIR.failed. \
DIR must be new, empty or an earlier campaign's folder."
)]
pub struct CampaignArgs {
    /// Aircraft simulated.
    #[arg(long, value_enum, default_value_t = VehicleArg::Bo105)]
    pub vehicle: VehicleArg,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/campaign")]
    pub out: PathBuf,
    /// Campaign seed (the held-out doublets use SEED + 1).
    #[arg(long, default_value_t = 1, value_parser = crate::arg_values::seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Short records (20 s instead of 90 s) for tests and a first look.
    #[arg(long)]
    pub quick: bool,
    /// Derive the hybrid's hover derivatives (M_fu, L_fu, N_v, Z_w, N_r) from trim points,
    /// the simulator's steady flights (`trim-points.csv`): `on`, `off` (fitted like the
    /// others), or `default`: on for the Bo-105, off for the TREX 700L, whose fit they make
    /// worse today (docs/decisions/2026-11-24-trim-points.md).
    #[arg(long, value_enum, default_value_t = TrimPointsArg::Default, value_name = "WHEN")]
    pub trim_points: TrimPointsArg,
    /// Sweep amplitude of the fit records (cah, standard, noise): `fixed` (the paper's)
    /// or `adaptive` (see `fly --amplitude`); the held-out doublets are never shaped.
    #[arg(long, value_enum, default_value_t = AmplitudeArg::Fixed)]
    pub amplitude: AmplitudeArg,
    /// No progress on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

impl CampaignArgs {
    /// Sweep record length [s].
    pub fn t_rec_s(&self) -> f64 {
        if self.quick {
            QUICK_T_REC_S
        } else {
            PAPER_T_REC_S
        }
    }

    /// Seed of the held-out doublets: another seed than the fit data's, so that the
    /// verification sees other noise and gusts.
    pub fn verification_seed(&self) -> u64 {
        self.seed.wrapping_add(1)
    }
}

/// A completed campaign.
#[derive(Debug)]
pub struct CampaignOutcome {
    /// What was written to `summary.json`.
    pub summary: CampaignSummary,
    /// The report.
    pub report: PathBuf,
}

/// Run `sweephold campaign`: the campaign, then the path of the report on stdout.
pub fn run(args: &CampaignArgs) -> anyhow::Result<()> {
    crate::interrupt::install();
    let outcome = campaign(args)?;
    if !args.quiet {
        eprint!("{}", headline(&outcome.summary));
    }
    println!("report: {}", outcome.report.display());
    Ok(())
}

/// The figures a user looks at first, for stderr.
fn headline(summary: &CampaignSummary) -> String {
    let mut text = String::new();
    let modes = [
        ("cah", &summary.modes.cah),
        ("standard", &summary.modes.standard),
        ("noise", &summary.modes.noise),
    ];
    for (name, mode) in modes {
        if let Some(mode) = mode {
            text += &format!(
                "{name:<9} lat–lon cross-coherence {}, max |phi| {:.1}°, |theta| {:.1}°, {} abort(s)\n",
                mode.cross_coherence_lat_lon
                    .map_or("-".to_string(), |c| format!("{c:.3}")),
                mode.max_abs_deg.phi,
                mode.max_abs_deg.theta,
                mode.aborts
            );
        }
    }
    if let Some(fit) = &summary.fit {
        text += &format!(
            "fit       {}: J_ave {:.1} (vs truth {})\n",
            fit.structure,
            fit.cost_ave,
            fit.truth_cost_ave
                .map_or("-".to_string(), |c| format!("{c:.1}"))
        );
    }
    if let Some(fit) = &summary.fit {
        if let (Some(hover), Some(poles)) = (&fit.hover_modes_matched, fit.poles_at_origin) {
            text += &format!(
                "modes     {} (hover: |λ| < {HOVER_MODE_LIMIT_RAD_S} rad/s)\n",
                hover_summary(hover, poles)
            );
        }
    }
    if let Some(verify) = &summary.verify {
        text += &format!("verify    TIC {}\n", verify.headline());
    }
    if let Some(total) = summary.timings_s.get("total") {
        text += &format!("total     {total:.1} s\n");
    }
    text
}

/// Everything a campaign holds between stages.
struct Campaign<'a> {
    args: &'a CampaignArgs,
    summary: CampaignSummary,
    started: Instant,
    /// Where the stages write: `DIR.partial` until the campaign completes.
    staged: Option<StagedFolder>,
}

impl Campaign<'_> {
    fn dir(&self) -> &Path {
        self.staged
            .as_ref()
            .map_or(self.args.out.as_path(), StagedFolder::path)
    }

    /// Run one stage: progress, timing, and on failure the error in `summary.json`.
    fn stage<T>(
        &mut self,
        stage: Stage,
        work: impl FnOnce(&mut Self) -> anyhow::Result<(T, String)>,
    ) -> Result<T, CampaignError> {
        let progress = StageProgress::start(stage, self.args.quiet);
        // A Ctrl-C is honoured between stages: before this one and after it.
        let result = crate::interrupt::check()
            .and_then(|()| work(self))
            .and_then(|done| crate::interrupt::check().map(|()| done));
        match result {
            Ok((value, outcome)) => {
                let seconds = progress.finish(&outcome);
                self.summary
                    .timings_s
                    .insert(stage.name().to_string(), seconds);
                Ok(value)
            }
            Err(error) => {
                progress.finish("FAILED");
                let mut error = CampaignError::new(stage, &error);
                self.summary.error = Some(StageFailure {
                    stage: stage.name().to_string(),
                    message: error.message.clone(),
                });
                if let Some(staged) = self.staged.take() {
                    // Best effort: the folder may be what failed.
                    let _ = write_json(&staged.path().join(files::SUMMARY), &self.summary);
                    error.kept = Some(staged.fail().map_err(|e| format!("{e:#}")));
                }
                Err(error)
            }
        }
    }

    /// The setup stage: the staging folder, and a first summary to check it takes files.
    fn set_up(&mut self) -> anyhow::Result<((), String)> {
        // The previous campaign in DIR stays as it is until this one completes.
        self.staged = Some(StagedFolder::begin(&self.args.out)?);
        self.write_summary()?;
        Ok(((), self.dir().display().to_string()))
    }

    fn write_summary(&mut self) -> anyhow::Result<()> {
        self.summary
            .timings_s
            .insert("total".to_string(), self.started.elapsed().as_secs_f64());
        write_json(&self.dir().join(files::SUMMARY), &self.summary)
    }

    fn fly_args(&self, mode: ModeArg, input: InputArg, seed: u64, folder: &str) -> FlyArgs {
        FlyArgs {
            vehicle: self.args.vehicle,
            mode,
            axes: Axis::ALL.to_vec(),
            input,
            amplitude: if input == InputArg::Sweep {
                self.args.amplitude
            } else {
                AmplitudeArg::Fixed
            },
            seed,
            t_rec_s: self.args.t_rec_s(),
            rate_hz: 200,
            out: self.dir().join(folder),
            gust: 0.0,
            sensor_dropout: 0.0,
            sensor_spike: 0.0,
            pilot_override_at_s: None,
            pilot_noise: 0.0,
            perfect_sensors: false,
            linearized_plant: false,
            quiet: true,
            fc: FcArg::InProcess,
            elf: None,
            vibration: None,
            rc_loss_at_s: None,
            imu_fault: None,
            fly_on_s: None,
        }
    }
}

fn fly_in_process(args: &FlyArgs) -> anyhow::Result<FlyOutcome> {
    fly::fly(args, &|| Box::new(InProcessLink::new()))
}

/// The mode's figures from `fly`'s summary of its records written into `folder`.
pub fn mode_summary(summary: &FlySummary, folder: &str) -> ModeSummary {
    let peak = |value: fn(&crate::fly::summary::MaxAbsDeg) -> f64| {
        summary
            .runs
            .iter()
            .map(|run| value(&run.max_abs_deg))
            .fold(0.0, f64::max)
    };
    ModeSummary {
        cross_coherence_lat_lon: summary.mean_cross_coherence("lat", "lon"),
        max_abs_deg: PeakAttitudeDeg {
            phi: peak(|m| m.phi),
            theta: peak(|m| m.theta),
        },
        aborts: summary.runs.iter().filter(|run| run.aborted).count(),
        records: summary.runs.len(),
        folder: folder.to_string(),
    }
}

/// The `fit` section of the summary from the final fit (truth filled in later).
fn fit_summary(result: &FitResult, start_cost_ave: f64) -> FitSummary {
    let identified_modes = mode_records(&result.model);
    FitSummary {
        structure: result.structure.name.clone(),
        cost_ave: result.average_cost,
        truth_cost_ave: None,
        start_cost_ave,
        pairs: result
            .pairs
            .iter()
            .map(|p| PairSummary {
                output: p.output.clone(),
                input: p.input.clone(),
                cost: p.cost,
                range: p.range,
                truth_cost: None,
            })
            .collect(),
        params: result
            .to_document()
            .parameters
            .iter()
            .map(|p| ParameterSummary {
                name: p.name.clone(),
                value: p.value,
                status: serde_json::to_value(p.status)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default(),
                cr_percent: p.cramer_rao_percent,
                insensitivity_percent: p.insensitivity_percent,
                truth: None,
                error_percent: None,
                flags: p.flags.iter().map(flag_name).collect(),
            })
            .collect(),
        model_file: files::MODEL_9DOF.to_string(),
        // Without the truth yet; the truth stage pairs them. An error (a model without
        // eigenvalues) leaves them empty here and is reported by the truth stage.
        modes: identified_modes.clone().unwrap_or_default(),
        truth_modes: Vec::new(),
        hover_modes_matched: None,
        poles_at_origin: identified_modes.as_deref().ok().map(poles_at_origin),
        speed_derivatives: speed_derivatives(&result.model, None),
        trim: result.trim.clone(),
    }
}

/// The quasi-static M_u, L_v, N_v of `model`, beside `truth`'s when given.
pub fn speed_derivatives(
    model: &sysid::fit::Model,
    truth: Option<&sysid::fit::Model>,
) -> Vec<SpeedDerivativeSummary> {
    use sysid::fit::trim::{quasi_static_derivative, SPEED_DERIVATIVES};
    SPEED_DERIVATIVES
        .iter()
        .map(|&(name, row, column)| {
            let value = quasi_static_derivative(model, row, column);
            let truth = truth.and_then(|t| quasi_static_derivative(t, row, column));
            let error_percent = match (value, truth) {
                (Some(v), Some(t)) if t != 0.0 => Some(100.0 * (v - t) / t.abs()),
                _ => None,
            };
            SpeedDerivativeSummary {
                name: name.to_string(),
                value,
                truth,
                error_percent,
            }
        })
        .collect()
}

/// `cr`, `insensitive` or `correlated:OTHER`.
pub fn flag_name(flag: &sysid::fit::AccuracyFlag) -> String {
    match flag {
        sysid::fit::AccuracyFlag::CramerRao => "cr".to_string(),
        sysid::fit::AccuracyFlag::Insensitive => "insensitive".to_string(),
        sysid::fit::AccuracyFlag::Correlated { with, .. } => format!("correlated:{with}"),
        sysid::fit::AccuracyFlag::Needed { .. } => "needed".to_string(),
    }
}

/// `campaign --trim-points`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TrimPointsArg {
    /// On for the Bo-105, off for the TREX 700L.
    Default,
    /// Derive from trim points.
    On,
    /// Fit like the other parameters.
    Off,
}

impl<'a> Campaign<'a> {
    fn new(args: &'a CampaignArgs) -> Campaign<'a> {
        Campaign {
            args,
            summary: CampaignSummary {
                vehicle: args.vehicle.name().to_string(),
                seed: args.seed,
                verification_seed: args.verification_seed(),
                t_rec_s: args.t_rec_s(),
                quick: args.quick,
                modes: Modes::default(),
                fit: None,
                verify: None,
                timings_s: BTreeMap::new(),
                error: None,
            },
            started: Instant::now(),
            staged: None,
        }
    }
}

/// Run the whole campaign of `args` (see the module documentation).
pub fn campaign(args: &CampaignArgs) -> Result<CampaignOutcome, CampaignError> {
    let mut run = Campaign::new(args);
    run.stage(Stage::Setup, Campaign::set_up)?;

    let mut cah_dumps = Vec::new();
    for (stage, mode) in [
        (Stage::FlyCah, ModeArg::Cah),
        (Stage::FlyStandard, ModeArg::Standard),
        (Stage::FlyNoise, ModeArg::Noise),
    ] {
        let dumps = run.stage(stage, |run| {
            let folder = files::fly_folder(mode.name());
            let fly_args = run.fly_args(mode, InputArg::Sweep, run.args.seed, &folder);
            let outcome = fly_in_process(&fly_args)?;
            let summary = mode_summary(&outcome.summary, &folder);
            let line = format!(
                "{} records, {} abort(s), lat–lon coherence {}",
                summary.records,
                summary.aborts,
                summary
                    .cross_coherence_lat_lon
                    .map_or("-".to_string(), |c| format!("{c:.3}"))
            );
            let slot = match mode {
                ModeArg::Cah => &mut run.summary.modes.cah,
                ModeArg::Standard => &mut run.summary.modes.standard,
                ModeArg::Noise => &mut run.summary.modes.noise,
            };
            *slot = Some(summary);
            Ok((outcome, line))
        })?;
        if mode == ModeArg::Cah {
            cah_dumps = dumps
                .summary
                .runs
                .iter()
                .zip(&dumps.dumps)
                .filter(|(run, _)| !run.aborted)
                .map(|(_, path)| path.clone())
                .collect();
        }
    }

    let doublets: Vec<String> = run.stage(Stage::FlyVerification, |run| {
        let fly_args = run.fly_args(
            ModeArg::Cah,
            InputArg::Doublet,
            run.args.verification_seed(),
            files::VERIFICATION_FOLDER,
        );
        let outcome = fly_in_process(&fly_args)?;
        let files: Vec<String> = outcome
            .summary
            .runs
            .iter()
            .filter(|r| !r.aborted)
            .map(|r| format!("{}/{}", files::VERIFICATION_FOLDER, r.file))
            .collect();
        let line = format!(
            "{} doublets, seed {}",
            files.len(),
            run.args.verification_seed()
        );
        Ok((files, line))
    })?;

    let frf: FrfDocument = run.stage(Stage::Frf, |run| {
        if cah_dumps.is_empty() {
            return Err(anyhow!("every cah record aborted: nothing to identify"));
        }
        let records = cah_dumps
            .iter()
            .map(load_dump)
            .collect::<Result<Vec<_>, _>>()?;
        let analysis = analyse(&group_by_primary(records)?, &FrfOptions::default())?;
        write_json(&run.dir().join(files::FRF), &analysis.document)?;
        let valid = analysis
            .document
            .pairs
            .iter()
            .filter(|p| p.valid_range.is_some())
            .count();
        let line = format!(
            "{} pairs, {} with a coherent range",
            analysis.document.pairs.len(),
            valid
        );
        Ok((analysis.document, line))
    })?;

    let use_trim_points = match args.trim_points {
        TrimPointsArg::On => true,
        TrimPointsArg::Off => false,
        TrimPointsArg::Default => args.vehicle == VehicleArg::Bo105,
    };
    let trim_points: Option<TrimPoints> = if !use_trim_points {
        None
    } else {
        Some(run.stage(Stage::TrimPoints, |run| {
            let points = crate::sim::simulator_trim_points(run.args.vehicle.sim())?;
            write_atomic(
                &run.dir().join(files::TRIM_POINTS),
                points.to_csv().as_bytes(),
            )?;
            let line = format!("{} steady flights", points.points.len());
            Ok((points, line))
        })?)
    };
    let fit_options = |reduce: bool| FitOptions {
        seed: args.seed,
        reduce,
        trim_points: trim_points.clone(),
        ..FitOptions::default()
    };
    let six: FitResult = run.stage(Stage::Fit6Dof, |run| {
        let structure = structures::six_dof()?;
        // The 6-DOF fit only supplies start values (paper Eq. 26–27): it is not reduced.
        // Reducing it cost 3.9 s instead of 1.3 s on the default campaign for the same
        // 9-DOF J_ave (113.1 vs 113.3).
        // Nor does it take the trim points: its derivatives only start the hybrid, and on
        // most seeds it lands in a degenerate minimum (X_ped, Z_ped of 10⁶–10⁸ with long
        // delays) whose steady balance gives no usable Z_w.
        let options = FitOptions {
            trim_points: None,
            ..fit_options(false)
        };
        let result = fit(&structure, &frf, &options)?;
        write_json(&run.dir().join(files::MODEL_6DOF), &result.to_document())?;
        let line = format!(
            "{}: J_ave {:.1}, {} pairs",
            result.structure.name,
            result.average_cost,
            result.pairs.len()
        );
        Ok((result, line))
    })?;

    let nine: FitResult = run.stage(Stage::Fit9Dof, |run| {
        // As `sweephold fit --start-from`: the 6-DOF's Eq. 26–27 starts and the file's
        // own, the lower J_ave kept and then reduced.
        // Kinematics and gravity about the trim the flight controller captured.
        let trim = structures::TrimAttitude::captured(&cah_dumps)?;
        let hybrid = structures::nine_dof_hybrid(run.args.vehicle.sim(), trim)?;
        let (started, _notes) = start_from_quasi_steady(&hybrid, &six.to_document())?;
        let starts = [
            (files::MODEL_6DOF.to_string(), started),
            ("bo105-9dof-hybrid.toml".to_string(), hybrid),
        ];
        let (result, _outcomes) = fit_from_alternative_starts(&starts, &frf, &fit_options(true))?;
        write_json(&run.dir().join(files::MODEL_9DOF), &result.to_document())?;
        run.summary.fit = Some(fit_summary(&result, six.average_cost));
        let line = format!(
            "{}: J_ave {:.1}, {} reduction step(s)",
            result.structure.name,
            result.average_cost,
            result.reduction.len()
        );
        Ok((result, line))
    })?;

    run.stage(Stage::Truth, |run| {
        let vehicle = run.args.vehicle.sim();
        let truth = crate::truth::VehicleTruth::at_hover(vehicle)?;
        let scored = crate::truth::score_fit_with_modes(&nine, &truth)?;
        let (section, mapped) = (scored.section, scored.mapped);
        write_json(
            &run.dir().join(files::TRUTH_MODEL_9DOF),
            &TruthModelDocument::new(vehicle.name(), &nine.structure.name, &mapped.model),
        )?;
        let modes_line = match &scored.modes {
            Ok(compared) => hover_summary(&compared.hover, compared.poles_at_origin),
            // Reported, not fatal: the model and its scoring are still worth the report.
            Err(error) => format!("modes not computed: {error}"),
        };
        let line = format!(
            "J_ave against the truth {:.1}; {modes_line}",
            section.average_cost
        );
        if let Some(fit) = run.summary.fit.as_mut() {
            match &scored.modes {
                Ok(compared) => {
                    fit.modes = compared.identified.clone();
                    fit.truth_modes = compared.truth.clone();
                    fit.hover_modes_matched = Some(compared.hover);
                    fit.poles_at_origin = Some(compared.poles_at_origin);
                }
                Err(_) => {
                    fit.modes.clear();
                    fit.truth_modes.clear();
                    fit.hover_modes_matched = None;
                    fit.poles_at_origin = None;
                }
            }
            fit.truth_cost_ave = Some(section.average_cost);
            fit.speed_derivatives = speed_derivatives(&nine.model, Some(&mapped.model));
            for pair in &mut fit.pairs {
                pair.truth_cost = section
                    .pairs
                    .iter()
                    .find(|t| t.input == pair.input && t.output == pair.output)
                    .map(|t| t.cost);
            }
            for param in &mut fit.params {
                if let Some(t) = section.parameters.iter().find(|t| t.name == param.name) {
                    param.truth = t.truth;
                    param.error_percent = t.error_percent;
                }
            }
        }
        let document = ScoredModelDocument {
            model: nine.to_document(),
            truth: Some(section),
            modes: scored
                .modes
                .map(|compared| compared.identified)
                .unwrap_or_default(),
        };
        write_json(&run.dir().join(files::MODEL_9DOF), &document)?;
        Ok(((), line))
    })?;

    run.stage(Stage::Verify, |run| {
        let records = doublets
            .iter()
            .map(|file| verify_dump(&nine.model, run.dir(), file, VERIFY_SEGMENT_S, VERIFY_BIAS))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let document = VerifyDocument {
            model_file: files::MODEL_9DOF.to_string(),
            segment_s: VERIFY_SEGMENT_S,
            bias: VERIFY_BIAS,
            records,
        };
        write_json(&run.dir().join(files::VERIFY), &document)?;
        let summary = document.summary();
        let line = format!(
            "{} records, mean TIC p q r {}, all {} outputs {:.3} ({} bias)",
            document.records.len(),
            summary
                .mean_pqr()
                .map_or("-".to_string(), |m| format!("{m:.3}")),
            summary.tic.len(),
            summary.mean_all(),
            summary.bias
        );
        run.summary.verify = Some(summary);
        Ok(((), line))
    })?;

    run.write_summary()
        .map_err(|e| CampaignError::new(Stage::Report, &e))?;
    run.stage(Stage::Report, |run| {
        crate::report::write_report(run.dir())?;
        run.write_summary()?;
        let staged = run
            .staged
            .take()
            .ok_or_else(|| anyhow!("the campaign folder was not set up"))?;
        staged.complete()?;
        let line = run.args.out.join(files::REPORT).display().to_string();
        Ok(((), line))
    })?;
    // Again in the completed folder, with the report stage's time and the total.
    run.write_summary()
        .map_err(|e| CampaignError::new(Stage::Report, &e))?;
    Ok(CampaignOutcome {
        summary: run.summary,
        report: args.out.join(files::REPORT),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fly::summary::{HoldFraction, MaxAbsDeg, RunSummary};

    #[test]
    fn a_failed_stage_keeps_the_previous_campaign_and_its_own_files() {
        let dir = std::env::temp_dir().join(format!("sweephold-stage-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let out = dir.join("campaign");
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join(files::SUMMARY), "previous").unwrap();
        std::fs::write(out.join(files::REPORT), "previous report").unwrap();
        let args = CampaignArgs {
            vehicle: VehicleArg::Bo105,
            out: out.clone(),
            seed: 7,
            quick: true,
            trim_points: TrimPointsArg::Default,
            amplitude: AmplitudeArg::Fixed,
            quiet: true,
        };
        let mut run = Campaign::new(&args);
        run.stage(Stage::Setup, Campaign::set_up).unwrap();
        std::fs::write(run.dir().join(files::FRF), "this run's").unwrap();
        let error = run
            .stage(Stage::Frf, |_| -> anyhow::Result<((), String)> {
                Err(anyhow!("no coherent pair"))
            })
            .unwrap_err();
        let message = error.to_string();
        assert!(
            message.contains("`frf` failed: no coherent pair"),
            "{message}"
        );
        assert!(message.contains("campaign.failed"), "{message}");
        assert_eq!(
            std::fs::read_to_string(out.join(files::SUMMARY)).unwrap(),
            "previous"
        );
        assert_eq!(
            std::fs::read_to_string(out.join(files::REPORT)).unwrap(),
            "previous report"
        );
        assert!(!out.join(files::FRF).exists());
        let failed = dir.join("campaign.failed");
        assert_eq!(
            std::fs::read_to_string(failed.join(files::FRF)).unwrap(),
            "this run's"
        );
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(failed.join(files::SUMMARY)).unwrap())
                .unwrap();
        assert_eq!(summary["error"]["stage"], "frf");
        assert_eq!(summary["seed"], 7);
        assert!(!dir.join("campaign.partial").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn run(axis: &str, phi: f64, aborted: bool, lon: Option<f64>) -> RunSummary {
        RunSummary {
            axis: axis.into(),
            index: 1,
            file: format!("{axis}-1.bin"),
            omega_min: 0.2,
            omega_max: 31.4,
            duration_s: 90.0,
            frames: 1,
            aborted,
            abort_reason: aborted.then(|| "attitude_limit".into()),
            max_abs_deg: MaxAbsDeg {
                phi,
                theta: phi / 2.0,
                psi: 0.0,
            },
            hold_fraction: HoldFraction::default(),
            cross_coherence: lon.map(|c| ("lon".to_string(), c)).into_iter().collect(),
            estimator: None,
            after: None,
        }
    }

    #[test]
    fn mode_summary_takes_peaks_aborts_and_lateral_coherence() {
        let fly = FlySummary {
            vehicle: "bo105".into(),
            mode: "cah".into(),
            rate_hz: 200,
            seed: 1,
            link: "in-process".into(),
            plant: "nonlinear".into(),
            runs: vec![
                run("lat", 3.0, false, Some(0.1)),
                run("lat", 5.0, false, Some(0.3)),
                run("lon", 9.0, true, Some(0.9)),
            ],
        };
        let mode = mode_summary(&fly, "fly-cah");
        assert!((mode.cross_coherence_lat_lon.unwrap() - 0.2).abs() < 1e-12);
        assert_eq!(mode.max_abs_deg.phi, 9.0);
        assert_eq!(mode.max_abs_deg.theta, 4.5);
        assert_eq!(mode.aborts, 1);
        assert_eq!(mode.records, 3);
    }
}
