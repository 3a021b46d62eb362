//! The verification stage: the identified model simulated on the held-out doublet records
//! as `sweephold verify` simulates it (its arguments; CIFER's VERIFID, method in
//! `sysid::fit::verify`), each record kept decimated in `verify.json`, and the summary's
//! `verify` section.

use std::ffi::OsString;
use std::path::Path;

use anyhow::anyhow;
use sysid::fit::verify::{verify_record_in_segments, BiasMode, Verification};
use sysid::fit::Model;
use sysid::records::load_test_dump;

use super::{verb_args, Campaign};
use crate::artifacts::files;
use crate::artifacts::verification::{VerifiedOutput, VerifiedRecord, VerifyDocument};
use crate::output::write_json;
use crate::verify::VerifyArgs;

/// Every `DECIMATION`-th sample is kept in `verify.json` (200 Hz → 50 Hz): the doublets'
/// content is below 10 rad/s, and the file stays small.
pub const DECIMATION: usize = 4;

impl Campaign<'_> {
    /// The verify stage: `model` (the final fit) on the `doublets` (files relative to the
    /// campaign folder).
    pub(super) fn verify(
        &mut self,
        model: &Model,
        doublets: &[String],
    ) -> anyhow::Result<((), String)> {
        let mut argv: Vec<OsString> =
            vec!["--model".into(), self.dir().join(files::MODEL_9DOF).into()];
        argv.extend(doublets.iter().map(|file| self.dir().join(file).into()));
        // The verb's defaults: each doublet simulated open loop over its whole record (a
        // few seconds: the hover instabilities do not run away in that time), as VERIFID
        // does; each output's bias its mean over the trim capture before the doublet (and
        // each input's trim likewise), not fitted to the prediction.
        let args: VerifyArgs = verb_args("verify", argv)?;
        let (segment_s, bias) = (args.segment, args.bias.mode());
        // Outputs a record does not measure (the board's u, v, w) are left out of the
        // scores by `verify_record_in_segments` and listed in `not_measured`.
        let records = doublets
            .iter()
            .map(|file| verify_dump(model, self.dir(), file, segment_s, bias))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let document = VerifyDocument {
            model_file: files::MODEL_9DOF.to_string(),
            segment_s,
            bias,
            records,
        };
        write_json(&self.dir().join(files::VERIFY), &document)?;
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
        self.summary.verify = Some(summary);
        Ok(((), line))
    }
}

/// Verify `model` on the dump `file` in `dir` (`file` relative to it).
pub fn verify_dump(
    model: &Model,
    dir: &Path,
    file: &str,
    segment_s: Option<f64>,
    bias: BiasMode,
) -> anyhow::Result<VerifiedRecord> {
    let record = load_test_dump(dir.join(file)).map_err(|e| anyhow!("{e}"))?;
    let verification =
        verify_record_in_segments(model, &record, segment_s, bias).map_err(|e| anyhow!("{e}"))?;
    Ok(verified_record(file, &verification))
}

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
