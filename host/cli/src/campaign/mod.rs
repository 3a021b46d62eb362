//! `sweephold campaign`: the paper's whole job in one command — fly the three excitation
//! modes, compute the frequency responses of the conditional-attitude-hold records, fit
//! the 6-DOF then the 9-DOF hybrid model (with reduction), score it against the
//! simulator's truth, verify it on held-out doublets, and write `summary.json` and
//! `report.html`.
//!
//! [`campaign`] runs one function per stage, each as the verb it stands for would do it
//! (`fly`, `frf`, `fit`, `verify`: their own arguments, parsed with their defaults), handing
//! over in memory what the next stages need. Each sweep is decoded once, as it is flown,
//! and its record passed on (the 9-DOF stage still reads the trim the flight controller
//! captured from the events of the `cah` dumps).

pub mod error;
pub mod fits;
pub mod flights;
pub mod margins;
pub mod progress;
pub mod scoring;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::mode_text::hover_summary;
use anyhow::anyhow;
use clap::Args;
use sysid::fit::modes::HOVER_MODE_LIMIT_RAD_S;
use sysid::frf::analysis::CoherenceCurve;
use sysid::frf::Record;

use crate::artifacts::files;
use crate::artifacts::flown::{lateral_coherence, FlownRecords, ModeCoherence};
use crate::artifacts::stage::Stage;
use crate::artifacts::summary::{CampaignSummary, Modes, StageFailure};
use crate::fit::TrimBalanceArg;
use crate::fly::plan::PAPER_T_REC_S;
use crate::fly::{AmplitudeArg, ModeArg};
use crate::output::{write_json, StagedFolder};
use crate::vehicle::Vehicle;
use error::CampaignError;
use flights::FlownMode;
use progress::StageProgress;

/// Sweep record length of `--quick` \[s\]: long enough for the frequency responses above
/// ~0.6 rad/s, short enough for a test.
pub const QUICK_T_REC_S: f64 = 20.0;

/// Arguments of `sweephold campaign`.
#[derive(Args, Debug, Clone)]
#[command(
    after_help = "Writes into DIR: fly-cah/, fly-standard/, fly-noise/ (the sweep \
dumps and fly's summary.json per mode), verify-doublet/ (held-out doublets), frf.json, \
model6.json, model9.json, truth-model9.json, verify.json, margins.json and \
margins-loops.json (loop margins and handling qualities of model9.json), summary.json \
(layout in docs/formats.md) and report.html. The campaign is built in DIR.partial and replaces DIR only \
when it completes. A failing stage, or SIGINT (Ctrl-C) or SIGTERM (the campaign stops \
after the current stage, or within a second in a flight; a second signal quits at once, \
removing DIR.partial), stops it with the stage's name and exit status 1: DIR keeps the previous complete campaign, and \
the stopped one's files, with the error in its summary.json, are kept in DIR.failed. \
DIR must be new, empty or an earlier campaign's folder."
)]
pub struct CampaignArgs {
    /// Aircraft flown: a shipped one (bo105, trex700l, fbl700) or the path of an aircraft file
    /// (docs/formats.md, "Aircraft files"); the file names its firmware preset, sweep
    /// bands, 9-DOF structure, trim balance and valid-range source.
    #[arg(long, value_name = "NAME|FILE", default_value = "bo105", value_parser = Vehicle::parse)]
    pub vehicle: Vehicle,
    /// Output folder (built in DIR.partial, swapped in when complete; DIR.lock held
    /// meanwhile: a second run on DIR is refused).
    #[arg(long, value_name = "DIR", default_value = "out/campaign")]
    pub out: PathBuf,
    /// Campaign seed (the held-out doublets use SEED + 1).
    #[arg(long, default_value_t = 1, value_parser = crate::arg_values::seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Short records (20 s instead of 90 s) for tests and a first look.
    #[arg(long)]
    pub quick: bool,
    /// Derive the hybrid's hover derivatives (its file's `trim_derived`: M_fu, L_fu, N_v,
    /// Z_w, and N_r on the Bo-105) from trim points, the simulator's steady flights
    /// (`trim-points.csv`): `on` (the default for both vehicles) or `off` (fitted like the
    /// others).
    #[arg(long, value_enum, default_value_t = TrimPointsArg::On, value_name = "WHEN")]
    pub trim_points: TrimPointsArg,
    /// How the trim points enter the 9-DOF fit (as `fit --trim-balance`): `hold` keeps
    /// the derived parameters at the balance's values (status `trim`), `joint` releases
    /// them into one cost with the balances, `default` is `hold` for the Bo-105 and
    /// `joint` for the TREX 700L, whose key parameters held balances pull by 10–27 %
    /// (docs/decisions/2026-11-25-trex700l-hover-body-terms.md).
    #[arg(long, value_enum, default_value_t = CampaignTrimBalance::Default, value_name = "HOW")]
    pub trim_balance: CampaignTrimBalance,
    /// Sweep amplitude of the fit records (cah, standard, noise): `fixed` (the paper's)
    /// or `adaptive` (see `fly --amplitude`); the held-out doublets are never shaped.
    #[arg(long, value_enum, default_value_t = AmplitudeArg::Fixed)]
    pub amplitude: AmplitudeArg,
    /// The flight controller that flies every record: `in-process` (the firmware's flight
    /// logic on the simulator's exact states) or `board-sim` (the board application on an
    /// emulated ICM-42688-P and SBUS receiver, as `fly --fc board-sim`). The board
    /// measures no air data (u = v = w = 0), so with `board-sim` the frequency responses
    /// have no pair of those outputs, the fits leave their pairs out as `fit` does, and the
    /// verification scores the outputs the board measures.
    /// `board-sim:FLASH`: the board boots the parameter set saved in FLASH (`sweephold fc
    /// params push FILE --fc board-sim:FLASH`, then `save`; refused if FLASH holds none)
    /// and flies the aircraft --vehicle describes; the campaign chooses only each
    /// record's test (axis, input, mode, seed, band, length, amplitude).
    #[arg(long, default_value = "in-process", value_name = "LINK", value_parser = CampaignLink::parse)]
    pub fc: CampaignLink,
    /// The aircraft file whose a-priori knowledge the identification takes (its 9-DOF
    /// structure's constants and priors, valid-range source, trim balance) instead of
    /// --vehicle's; the simulator still flies --vehicle, and the truth is its. For
    /// measuring what a wrong prior does (docs/decisions/2026-11-27-priors-with-sigma.md).
    #[arg(long, value_name = "NAME|FILE", value_parser = Vehicle::parse)]
    pub priors: Option<Vehicle>,
    /// Exit with status 1 (`error: …`) when the model written (`model9.json`) is
    /// degenerate (parameters outside their physical range, or free ones on a range bound
    /// of the structure file, after the fit's restarts elsewhere); without it, a warning
    /// line on stderr. The campaign's files are written either way.
    #[arg(long)]
    pub strict: bool,
    /// No progress on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

impl CampaignArgs {
    /// Sweep record length \[s\].
    pub fn t_rec_s(&self) -> f64 {
        if self.quick {
            QUICK_T_REC_S
        } else {
            PAPER_T_REC_S
        }
    }

    /// The aircraft the identification takes its a-priori knowledge from: `--priors`,
    /// else the one flown.
    pub fn priors_vehicle(&self) -> &Vehicle {
        self.priors.as_ref().unwrap_or(&self.vehicle)
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
    let outcome = campaign(args)?;
    if !args.quiet {
        crate::note_text!("{}", headline(&outcome.summary));
    }
    crate::output::print(&format!("report: {}\n", outcome.report.display()))?;
    crate::identify::stages::judge_degenerate(outcome.summary.fit.as_ref(), &args.out, args.strict)
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
            let from_trim = mode.max_from_trim_deg.map_or(String::new(), |m| {
                format!(" (from trim {:.1}°, {:.1}°)", m.phi, m.theta)
            });
            text += &format!(
                "{name:<9} lat–lon cross-coherence {}, max |phi| {:.1}°, |theta| {:.1}°{from_trim}, {} abort(s)\n",
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

/// `campaign --fc`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CampaignLink {
    /// The firmware's flight logic in process on the simulator's exact states.
    InProcess,
    /// The board application on the emulated IMU and receiver (`fly --fc board-sim`),
    /// set up from the aircraft file or booted from a flash file (`board-sim:FLASH`).
    BoardSim(Option<std::path::PathBuf>),
}

impl CampaignLink {
    /// Parse `in-process`, `board-sim` or `board-sim:FLASH`.
    pub fn parse(text: &str) -> Result<CampaignLink, String> {
        match text {
            "in-process" => Ok(CampaignLink::InProcess),
            "board-sim" => Ok(CampaignLink::BoardSim(None)),
            _ => match text.strip_prefix("board-sim:") {
                Some(flash) if !flash.is_empty() => Ok(CampaignLink::BoardSim(Some(flash.into()))),
                _ => Err(format!(
                    "unknown flight controller `{text}` (expected in-process, board-sim or \
                     board-sim:FLASH)"
                )),
            },
        }
    }

    /// The name `--fc` and `summary.json` know it by.
    pub fn name(&self) -> String {
        match self {
            CampaignLink::InProcess => "in-process".to_string(),
            CampaignLink::BoardSim(None) => "board-sim".to_string(),
            CampaignLink::BoardSim(Some(flash)) => format!("board-sim:{}", flash.display()),
        }
    }
}

/// `campaign --trim-points`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TrimPointsArg {
    /// Derive from trim points.
    On,
    /// Fit like the other parameters.
    Off,
}

/// `campaign --trim-balance`: the fit's [`TrimBalanceArg`], or the vehicle's default.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CampaignTrimBalance {
    /// The aircraft file's `identification.trim_balance` (`hold` for the Bo-105,
    /// `joint` for the TREX 700L).
    Default,
    /// Derived from the balance and held (status `trim`).
    Hold,
    /// Held until they settle, then fitted with the others under the balances' cost.
    Joint,
}

impl CampaignTrimBalance {
    /// The fit's setting for `vehicle`.
    pub fn for_vehicle(self, vehicle: &Vehicle) -> TrimBalanceArg {
        match self {
            CampaignTrimBalance::Hold => TrimBalanceArg::Hold,
            CampaignTrimBalance::Joint => TrimBalanceArg::Joint,
            CampaignTrimBalance::Default => TrimBalanceArg::of_vehicle(vehicle),
        }
    }
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
    /// Where the stages write: `DIR.partial` until the campaign completes.
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
        // A signal is honoured between stages: before this one and after it (and inside
        // the flights, every second of a record). After the stage that swapped the folder
        // in (the report's), nothing is left to stop.
        let result = crate::interrupt::check().and_then(|()| {
            crate::interrupt::pause_point(stage.name());
            work(self)
        });
        let result = result.and_then(|done| match self.staged {
            Some(_) => crate::interrupt::check().map(|()| done),
            None => Ok(done),
        });
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

    /// Write `summary.json` as it stands, with the total time so far.
    fn write_summary(&mut self) -> anyhow::Result<()> {
        self.summary
            .timings_s
            .insert("total".to_string(), self.started.elapsed().as_secs_f64());
        write_json(&self.dir().join(files::SUMMARY), &self.summary)
    }
}

impl<'a> Campaign<'a> {
    fn new(args: &'a CampaignArgs) -> Campaign<'a> {
        Campaign {
            args,
            summary: CampaignSummary {
                vehicle: args.vehicle.name().to_string(),
                link: args.fc.name().to_string(),
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

pub use crate::identify::stages::verb_args;

/// Run the whole campaign of `args` (see the module documentation).
pub fn campaign(args: &CampaignArgs) -> Result<CampaignOutcome, CampaignError> {
    let mut run = Campaign::new(args);
    run.stage(Stage::Setup, Campaign::set_up)?;
    let mut cah = run.stage(Stage::FlyCah, |run| run.fly_sweeps(ModeArg::Cah))?;
    // Of the other modes, the report draws the lateral sweeps alone.
    let standard = run
        .stage(Stage::FlyStandard, |run| run.fly_sweeps(ModeArg::Standard))?
        .lateral_only();
    let noise = run
        .stage(Stage::FlyNoise, |run| run.fly_sweeps(ModeArg::Noise))?
        .lateral_only();
    let doublets = run.stage(Stage::FlyVerification, Campaign::fly_doublets)?;
    if matches!(args.fc, CampaignLink::BoardSim(_)) {
        run.stage(Stage::FlySteady, Campaign::fly_steady)?;
    }
    // The report's sweep time history, before the frequency responses take the records.
    let sweep = cah.lateral().next().cloned();
    let frf = run.stage(Stage::Frf, |run| {
        run.frequency_responses(cah.take_records())
    })?;
    let trim_points = run.trim_points()?;
    let six = run.stage(Stage::Fit6Dof, |run| run.fit_6dof(&frf.document))?;
    let nine = run.stage(Stage::Fit9Dof, |run| {
        run.fit_9dof(cah.captured_trim(), &frf.document, &six, &trim_points)
    })?;
    run.stage(Stage::Truth, |run| run.score(&nine))?;
    run.stage(Stage::Verify, |run| run.verify(&nine.model, &doublets))?;
    run.stage(Stage::Margins, Campaign::margins)?;
    run.report(sweep, frf.lateral_coherence, [standard, noise])
}

impl Campaign<'_> {
    /// The report stage: the report from the folder's documents and the records flown —
    /// the first lateral `cah` sweep, the `cah` coherence curves of the frequency-response
    /// stage, those of the `others` modes' lateral sweeps computed here — then the folder
    /// completed.
    fn report(
        mut self,
        sweep: Option<Record>,
        cah_coherence: Vec<CoherenceCurve>,
        others: [FlownMode; 2],
    ) -> Result<CampaignOutcome, CampaignError> {
        self.write_summary()
            .map_err(|e| CampaignError::new(Stage::Report, &e))?;
        self.stage(Stage::Report, |run| {
            let mut coherence = Vec::new();
            // Without a lateral cah sweep there is no lateral group, nor curves.
            if sweep.is_some() {
                coherence.push(ModeCoherence {
                    mode: ModeArg::Cah.name().to_string(),
                    curves: cah_coherence,
                });
            }
            for flown in others.into_iter().filter(|f| !f.records.is_empty()) {
                coherence.push(ModeCoherence {
                    mode: flown.mode.name().to_string(),
                    curves: lateral_coherence(flown.records)?,
                });
            }
            crate::report::write_report_with(run.dir(), FlownRecords { sweep, coherence })?;
            run.write_summary()?;
            // The last safe point: a signal up to here leaves DIR as it was.
            crate::interrupt::pause_point("complete");
            crate::interrupt::check()?;
            let staged = run
                .staged
                .take()
                .ok_or_else(|| anyhow!("the campaign folder was not set up"))?;
            staged.complete()?;
            let line = run.args.out.join(files::REPORT).display().to_string();
            Ok(((), line))
        })?;
        // Again in the completed folder, with the report stage's time and the total.
        self.write_summary()
            .map_err(|e| CampaignError::new(Stage::Report, &e))?;
        Ok(CampaignOutcome {
            summary: self.summary,
            report: self.args.out.join(files::REPORT),
        })
    }
}

#[cfg(test)]
mod tests;
