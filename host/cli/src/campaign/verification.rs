//! The verification stage: the identified model simulated on held-out doublet records
//! (CIFER's VERIFID; method in `sysid::fit::verify`), each kept decimated for `verify.json`.

use std::path::Path;

use anyhow::anyhow;
use sysid::fit::verify::{verify_record_in_segments, BiasMode, Verification};
use sysid::fit::Model;
use sysid::frf::load_test_dump;

use crate::artifacts::verification::{VerifiedOutput, VerifiedRecord};

/// Every `DECIMATION`-th sample is kept in `verify.json` (200 Hz → 50 Hz): the doublets'
/// content is below 10 rad/s, and the file stays small.
pub const DECIMATION: usize = 4;

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
    }
}
