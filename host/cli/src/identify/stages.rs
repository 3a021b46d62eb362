//! The identification's stages, shared by `campaign` and `identify` (one pipeline): the
//! frequency responses of the sweeps, the 6-DOF quasi-steady fit that gives the start
//! values, the 9-DOF hybrid fit with reduction, and the verification on held-out
//! records, each as the verb it stands for would run it (`frf`, `fit`, `verify`: their
//! own arguments, parsed with their defaults) on what the previous stage handed over in
//! memory. Nothing here flies or simulates the aircraft: the a-priori constants come
//! from the aircraft file ([`Vehicle`]), the trim points, when there are any, from the
//! caller.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use anyhow::anyhow;
use sysid::document::FrfDocument;
use sysid::fit::degenerate::describe as describe_degenerate;
use sysid::fit::equation_error::equation_error_start;
use sysid::fit::modes::{mode_records, poles_at_origin};
use sysid::fit::plausible::{implausible_parameters, HeldParameter};
use sysid::fit::trim::TrimPoints;
use sysid::fit::verify::{verify_record_in_segments, Verification};
use sysid::fit::{
    fit_from_alternative_starts, measured_outputs, reduce_to_measured, start_from_quasi_steady,
    FitOptions, FitResult, Model, ModelStructure,
};
use sysid::frf::analysis::CoherenceCurve;
use sysid::frf::{analyse, group_by_primary, Record};
use sysid::models;

use crate::artifacts::aircraft_constants::write_model;
use crate::artifacts::files;
use crate::artifacts::flown::LATERAL;
use crate::artifacts::priors::prior_summaries;
use crate::artifacts::summary::{
    FitSummary, PairSummary, ParameterSummary, SpeedDerivativeSummary, VerifySummary,
};
use crate::artifacts::verification::{VerifiedOutput, VerifiedRecord, VerifyDocument};
use crate::fit::{FitArgs, TrimBalanceArg};
use crate::frf::FrfArgs;
use crate::margins::MarginsArgs;
use crate::output::write_json;
use crate::structures::{self, TrimAttitude};
use crate::vehicle::Vehicle;
use crate::verify::VerifyArgs;

/// The arguments of the verb `verb` from the command line `argv` (without the verb): its
/// own parser, so its own defaults and checks.
pub fn verb_args<T: clap::Args + clap::FromArgMatches>(
    verb: &'static str,
    argv: impl IntoIterator<Item = OsString>,
) -> anyhow::Result<T> {
    let matches = T::augment_args(clap::Command::new(verb).no_binary_name(true))
        .try_get_matches_from(argv)
        .map_err(|e| anyhow!("`{verb}` arguments: {}", e.render().to_string().trim()))?;
    Ok(T::from_arg_matches(&matches)?)
}

/// What every stage needs to know: where it writes, the aircraft, the fit's seed and
/// how the trim points enter the 9-DOF fit.
#[derive(Clone, Copy, Debug)]
pub struct Pipeline<'a> {
    /// The folder the stages write into.
    pub dir: &'a Path,
    /// The aircraft identified: its file's structure, a-priori constants, valid-range
    /// source.
    pub vehicle: &'a Vehicle,
    /// The fits' seed (`fit --seed`).
    pub seed: u64,
    /// How the trim points enter the 9-DOF fit (`fit --trim-balance`).
    pub trim_balance: TrimBalanceArg,
}

/// What the frequency-response stage hands on.
pub struct Responses {
    /// `frf.json`, which the fits read.
    pub document: FrfDocument,
    /// The cross-control coherence curves of the lateral sweeps, which the report draws.
    pub lateral_coherence: Vec<CoherenceCurve>,
}

impl Pipeline<'_> {
    /// The margins stage: `margins.json` of the folder's `model9.json` under the aircraft's
    /// board law, with every loop test of `loop_dumps` measured beside the prediction, and
    /// `margins-loops.json` for the report ([`crate::margins::write_stage_files`]).
    pub fn margins(&self, loop_dumps: &[PathBuf]) -> anyhow::Result<String> {
        let model = self.dir.join(files::MODEL_9DOF);
        let mut args: MarginsArgs = verb_args("margins", [model.into_os_string()])?;
        args.vehicle = Some(self.vehicle.clone());
        args.samples = crate::margins::STAGE_SAMPLES;
        args.measured = loop_dumps.to_vec();
        crate::margins::write_stage_files(self.dir, &args)
    }

    /// The frf stage: the responses of the sweeps `records` (at least one), written to
    /// `frf.json`. For the Bo-105 the valid ranges come from the sweep-reference
    /// estimate's random error ([`RangeSource::SweepReference`](sysid::frf::RangeSource::SweepReference)).
    pub fn frequency_responses(&self, records: Vec<Record>) -> anyhow::Result<(Responses, String)> {
        let mut argv: Vec<OsString> = vec![
            "--out".into(),
            self.dir.join(files::FRF).into(),
            "--quiet".into(),
        ];
        argv.extend(records.iter().map(|r| OsString::from(&r.source)));
        let args: FrfArgs = verb_args("frf", argv)?;
        let mut options = args.options();
        // The aircraft file says where the valid ranges come from: for the Bo-105 they
        // leave out where the hold, not the sweep, drives the swept control
        // (docs/decisions/2026-11-24-joint-trim-cost-and-reference-ranges.md).
        options.ranges = self.vehicle.range_source();
        let analysis = analyse(&group_by_primary(records)?, &options)?;
        write_json(&args.out, &analysis.document)?;
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
        let responses = Responses {
            document: analysis.document,
            lateral_coherence: analysis
                .cross_coherence_curves
                .into_iter()
                .filter(|c| c.axis == LATERAL)
                .collect(),
        };
        Ok((responses, line))
    }

    /// `structure` with the pairs of the outputs `frf` holds, as `sweephold fit` reduces
    /// it ([`reduce_to_measured`]): all of them in process, none of the air-data outputs
    /// on the board (`--fc board-sim`), whose u = v = w = 0 give no response.
    fn measured(structure: ModelStructure, frf: &FrfDocument) -> anyhow::Result<ModelStructure> {
        Ok(reduce_to_measured(structure, &measured_outputs(frf))?.0)
    }

    /// `sweephold fit` for this pipeline: the structure `model` on `frf.json`, with the
    /// seed, reduced or not, into `out` of the folder.
    fn fit_args(
        &self,
        model: &str,
        out: &str,
        reduce: bool,
        max_starts: Option<usize>,
    ) -> anyhow::Result<FitArgs> {
        let mut argv: Vec<OsString> = vec![
            "--frf".into(),
            self.dir.join(files::FRF).into(),
            "--model".into(),
            model.into(),
            "--seed".into(),
            self.seed.to_string().into(),
            "--out".into(),
            self.dir.join(out).into(),
        ];
        if reduce {
            argv.push("--reduce".into());
        }
        if let Some(max_starts) = max_starts {
            argv.push("--max-starts".into());
            argv.push(max_starts.to_string().into());
        }
        argv.push("--trim-balance".into());
        argv.push(self.trim_balance.as_arg().into());
        verb_args("fit", argv)
    }

    /// The 6-DOF stage: the quasi-steady structure fitted to `frf`, `model6.json`.
    pub fn fit_6dof(&self, frf: &FrfDocument) -> anyhow::Result<(FitResult, String)> {
        // The 6-DOF fit only supplies start values (paper Eq. 26–27): it is not reduced.
        // Reducing it cost 3.9 s instead of 1.3 s on the default campaign for the same
        // 9-DOF J_ave (113.1 vs 113.3).
        let args = self.fit_args(
            models::BO105_6DOF.name,
            files::MODEL_6DOF,
            false,
            Some(SIX_DOF_MAX_STARTS),
        )?;
        let structure = Self::measured(structures::six_dof()?, frf)?;
        // Nor does it take the trim points: its derivatives only start the hybrid, and on
        // most seeds it lands in a degenerate minimum (X_ped, Z_ped of 10⁶–10⁸ with long
        // delays) whose steady balance gives no usable Z_w.
        // Its starts: an equation-error fit of the same responses (when the structure
        // allows one: with every state measured) and the file's own values.
        let mut starts = Vec::with_capacity(2);
        if let Ok(solved) = equation_error_start(&structure, frf) {
            starts.push(("equation error".to_string(), solved.structure));
        }
        starts.push((format!("{}.toml", models::BO105_6DOF.name), structure));
        // Its minimum is judged neither for physical ranges nor recovered
        // (docs/method.md, physical ranges): it only starts the hybrid, one of two start
        // sets of which the lower J_ave is kept, and the hybrid is judged. Recovering it
        // changed every default campaign's model6.json and refused the TREX 700L's seed 4.
        let options = FitOptions {
            recover_implausible: false,
            ..args.options(None)
        };
        let (result, _outcomes) = fit_from_alternative_starts(&starts, frf, &options)?;
        // Written as it is, but never as a usable model: what lies outside its physical
        // range is named in the file and on the console.
        let outside: Vec<HeldParameter> = implausible_parameters(&result.structure, &result.values)
            .into_iter()
            .map(|found| HeldParameter {
                name: found.name,
                value: found.value,
            })
            .collect();
        let mut document = result.to_document();
        document.outside_physical_range = outside.clone();
        write_json(&out_path(&args)?, &document)?;
        let line = format!(
            "{}: J_ave {:.1}, {} pairs{}{}",
            result.structure.name,
            result.average_cost,
            result.pairs.len(),
            if starts.len() > 1 {
                ", equation-error start"
            } else {
                ""
            },
            if outside.is_empty() {
                String::new()
            } else {
                format!(
                    "; degenerate, a start only ({} outside the physical ranges: {})",
                    outside.len(),
                    outside
                        .iter()
                        .take(3)
                        .map(|held| format!("{} = {:.3e}", held.name, held.value))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        );
        Ok((result, line))
    }

    /// The 9-DOF stage: the hybrid structure (the aircraft file's data, the trim the
    /// flight controller captured, `trim`) fitted to `frf` from the 6-DOF's start values
    /// and the file's own, the lower J_ave kept and reduced; `model9.json` and the
    /// summary's `fit` section (without truth).
    pub fn fit_9dof(
        &self,
        trim: Option<TrimAttitude>,
        frf: &FrfDocument,
        six: &FitResult,
        trim_points: &Option<TrimPoints>,
    ) -> anyhow::Result<(FitResult, FitSummary, String)> {
        // As `sweephold fit --start-from model6.json --reduce`.
        let structure = self.vehicle.structure().to_string();
        let args = self.fit_args(&structure, files::MODEL_9DOF, true, None)?;
        // Kinematics and gravity about the trim the flight controller captured.
        let hybrid = Self::measured(
            structures::nine_dof_hybrid(self.vehicle.aircraft(), trim)?,
            frf,
        )?;
        let (started, _notes) = start_from_quasi_steady(&hybrid, &six.to_document())?;
        let starts = [
            (files::MODEL_6DOF.to_string(), started),
            (format!("{} (the file's start values)", hybrid.name), hybrid),
        ];
        let options = args.options(trim_points.clone());
        let (result, _outcomes) = fit_from_alternative_starts(&starts, frf, &options)?;
        crate::fit::refuse_implausible(&result, &args.frf)?;
        write_model(
            &out_path(&args)?,
            &result.to_document(),
            &self.vehicle.file_constants()?,
        )?;
        let mut summary = fit_summary(&result, six.average_cost);
        summary.priors = prior_summaries(&result, &self.vehicle.file_constants()?);
        let line = format!(
            "{}: J_ave {:.1}, {} reduction step(s){}{}",
            result.structure.name,
            result.average_cost,
            result.reduction.len(),
            restarts_text(&result),
            if result.degenerate.is_empty() {
                String::new()
            } else {
                format!("; DEGENERATE: {}", describe_degenerate(&result.degenerate))
            }
        );
        Ok((result, summary, line))
    }

    /// The verify stage: `model` (the final fit, `model9.json`) on the held-out
    /// `records`, each named by its file relative to the folder (or as given); the
    /// outputs a record does not measure (the board's u, v, w) are left out of the
    /// scores. `verify.json` and the summary's `verify` section.
    pub fn verify(
        &self,
        model: &Model,
        records: &[(String, Record)],
    ) -> anyhow::Result<(VerifySummary, String)> {
        let mut argv: Vec<OsString> =
            vec!["--model".into(), self.dir.join(files::MODEL_9DOF).into()];
        argv.extend(records.iter().map(|(file, _)| OsString::from(file)));
        // The verb's defaults: each doublet simulated open loop over its whole record (a
        // few seconds: the hover instabilities do not run away in that time), as VERIFID
        // does; each output's bias its mean over the trim capture before the doublet (and
        // each input's trim likewise), not fitted to the prediction.
        let args: VerifyArgs = verb_args("verify", argv)?;
        let (segment_s, bias) = (args.segment, args.bias.mode());
        // Outputs a record does not measure (the board's u, v, w) are left out of the
        // scores by `verify_record_in_segments` and listed in `not_measured`.
        let verified = records
            .iter()
            .map(|(file, record)| {
                let verification = verify_record_in_segments(model, record, segment_s, bias)
                    .map_err(|e| anyhow!("{e}"))?;
                Ok(verified_record(file, &verification))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let document = VerifyDocument {
            model_file: files::MODEL_9DOF.to_string(),
            segment_s,
            bias,
            records: verified,
        };
        write_json(&self.dir.join(files::VERIFY), &document)?;
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
        Ok((summary, line))
    }
}

/// Most starts of the 6-DOF fit (the `fit` verb's default is 8). Its minimum lies in a
/// long, flat valley where runs stop at the iteration limit; after three exploring starts
/// the rest polish the best one until it is reached twice. Each start costs about 0.2 s.
/// Measured on the default Bo-105 campaign, seeds 1–10: the minimum confirmed on 5 of 10
/// with 8 starts (`docs/decisions/2026-11-24-6dof-marquardt-scaling.md`).
const SIX_DOF_MAX_STARTS: usize = 16;

/// After a run of `identify` or `campaign` wrote everything: when the final model
/// (`fit`, `model9.json` in `dir`) is degenerate, an error with `--strict` (`strict`),
/// else a warning line on stderr. The 6-DOF model is a start only and not judged here
/// (its `outside_physical_range` says what is wrong with it).
pub fn judge_degenerate(fit: Option<&FitSummary>, dir: &Path, strict: bool) -> anyhow::Result<()> {
    let Some(fit) = fit.filter(|fit| !fit.degenerate.is_empty()) else {
        return Ok(());
    };
    let text = format!(
        "{} is degenerate: {}",
        dir.join(&fit.model_file).display(),
        describe_degenerate(&fit.degenerate)
    );
    if strict {
        anyhow::bail!("{text} (--strict)");
    }
    crate::note!("warning: {text}; it passes no bar");
    Ok(())
}

/// `; N restart(s) elsewhere (degenerate minimum)` when the fit ran its search again
/// because its model was degenerate, else nothing.
pub fn restarts_text(result: &FitResult) -> String {
    match result.degenerate_restarts.len() {
        0 => String::new(),
        n => format!("; {n} restart(s) elsewhere (degenerate minimum)"),
    }
}

/// The model file a fit writes (`--out`).
fn out_path(args: &FitArgs) -> anyhow::Result<PathBuf> {
    args.out
        .clone()
        .ok_or_else(|| anyhow!("the fit has no --out"))
}

/// The `fit` section of the summary from the final fit (truth left null: only the
/// campaign's truth stage fills it in).
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
        // Without the truth; the campaign's truth stage pairs them. An error (a model
        // without eigenvalues) leaves them empty here.
        modes: identified_modes.clone().unwrap_or_default(),
        truth_modes: Vec::new(),
        hover_modes_matched: None,
        poles_at_origin: identified_modes.as_deref().ok().map(poles_at_origin),
        speed_derivatives: speed_derivatives(&result.model, None),
        trim: result.trim.clone(),
        // The caller adds them (it knows the aircraft file).
        priors: Vec::new(),
        degenerate: result.degenerate.clone(),
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

/// Every `DECIMATION`-th sample is kept in `verify.json` (200 Hz → 50 Hz): the doublets'
/// content is below 10 rad/s, and the file stays small.
pub const DECIMATION: usize = 4;

fn verified_record(file: &str, verification: &Verification) -> VerifiedRecord {
    let decimate = |series: &[f64]| -> Vec<f64> {
        series
            .iter()
            .step_by(DECIMATION)
            // JSON has no NaN or infinity: a runaway prediction is clipped for the plot.
            .map(|v| {
                if v.is_finite() {
                    v.clamp(-1e6, 1e6)
                } else {
                    0.0
                }
            })
            .collect()
    };
    VerifiedRecord {
        file: file.to_string(),
        step_s: DECIMATION as f64 / verification.sample_rate_hz,
        tic_mean: verification.theil_mean,
        diverged_at_s: verification.diverged_at_s,
        outputs: verification
            .outputs
            .iter()
            .enumerate()
            .map(|(i, score)| VerifiedOutput {
                name: score.output.clone(),
                tic: score.theil,
                bias: if score.bias.is_finite() {
                    score.bias
                } else {
                    0.0
                },
                measured: verification
                    .measured
                    .get(i)
                    .map_or_else(Vec::new, |s| decimate(s)),
                predicted: verification
                    .predicted
                    .get(i)
                    .map_or_else(Vec::new, |s| decimate(s)),
            })
            .collect(),
        not_measured: verification.not_measured.clone(),
    }
}
