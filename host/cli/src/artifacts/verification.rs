//! `verify.json`: the verification of the campaign's final model on the held-out doublets
//! (CIFER's VERIFID; method in `sysid::fit::verify`), with the measured and predicted time
//! histories the report draws.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use sysid::fit::verify::BiasMode;

use super::summary::{
    bias_of_older_files, mean_tic, VerifyRecordSummary, VerifySummary, ANGULAR_RATES,
};

/// One output of one record: scores and the decimated time histories.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VerifiedOutput {
    /// Output name.
    pub name: String,
    /// Theil's inequality coefficient.
    pub tic: f64,
    /// Bias b (trim value plus sensor bias) removed from `measured`: the output's mean over
    /// the trim samples before the doublet, or the least-squares mean(y − ŷ), as the
    /// document's `bias` says.
    pub bias: f64,
    /// Measured perturbation y − b, decimated.
    pub measured: Vec<f64>,
    /// Predicted ŷ, decimated.
    pub predicted: Vec<f64>,
}

/// One held-out record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VerifiedRecord {
    /// Dump file, relative to the campaign folder.
    pub file: String,
    /// Time step of the stored series \[s\].
    pub step_s: f64,
    /// Mean TIC over the outputs.
    pub tic_mean: f64,
    /// When the simulated model overflowed \[s\]; null otherwise.
    pub diverged_at_s: Option<f64>,
    /// The compared outputs, model order.
    pub outputs: Vec<VerifiedOutput>,
    /// Model outputs the record does not measure (absent, or zeros throughout as a board
    /// without air data logs u, v, w): not scored, not in `tic_mean`. Left out of the
    /// file when empty.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub not_measured: Vec<String>,
}

/// `verify.json`: the verification of the campaign's final model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VerifyDocument {
    /// Model file verified, relative to the campaign folder.
    pub model_file: String,
    /// Simulation restarted from the measured state every this many seconds (null: open
    /// loop over the whole record).
    pub segment_s: Option<f64>,
    /// Where the output biases came from: `trim` or `fitted` (files written before it:
    /// `fitted`).
    #[serde(default = "bias_of_older_files")]
    pub bias: BiasMode,
    /// One entry per held-out record.
    pub records: Vec<VerifiedRecord>,
}

impl VerifyDocument {
    /// The `verify` section of `summary.json`: TIC per output averaged over the records.
    pub fn summary(&self) -> VerifySummary {
        let mut sums: BTreeMap<String, (f64, usize)> = BTreeMap::new();
        for record in &self.records {
            for output in &record.outputs {
                let entry = sums.entry(output.name.clone()).or_insert((0.0, 0));
                entry.0 += output.tic;
                entry.1 += 1;
            }
        }
        let tic: BTreeMap<String, f64> = sums
            .into_iter()
            .map(|(name, (sum, n))| (name, sum / n as f64))
            .collect();
        let tic_mean_all = mean_tic(&tic, None);
        VerifySummary {
            bias: self.bias,
            tic_mean_pqr: mean_tic(&tic, Some(&ANGULAR_RATES)),
            tic_mean_all,
            tic_mean: tic_mean_all.unwrap_or(1.0),
            tic,
            records: self
                .records
                .iter()
                .map(|record| VerifyRecordSummary {
                    file: record.file.clone(),
                    tic: record
                        .outputs
                        .iter()
                        .map(|o| (o.name.clone(), o.tic))
                        .collect(),
                    tic_mean: record.tic_mean,
                    diverged_at_s: record.diverged_at_s,
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn output(name: &str, tic: f64) -> VerifiedOutput {
        VerifiedOutput {
            name: name.into(),
            tic,
            bias: 0.0,
            measured: vec![],
            predicted: vec![],
        }
    }

    #[test]
    fn summary_averages_each_output_over_the_records() {
        let document = VerifyDocument {
            model_file: "model9.json".into(),
            segment_s: None,
            bias: BiasMode::Trim,
            records: vec![
                VerifiedRecord {
                    file: "a.bin".into(),
                    step_s: 0.02,
                    tic_mean: 0.2,
                    diverged_at_s: None,
                    outputs: vec![output("p", 0.1), output("q", 0.3)],
                    not_measured: vec![],
                },
                VerifiedRecord {
                    file: "b.bin".into(),
                    step_s: 0.02,
                    tic_mean: 0.5,
                    diverged_at_s: None,
                    outputs: vec![output("p", 0.3), output("w", 0.7)],
                    not_measured: vec![],
                },
            ],
        };
        let summary = document.summary();
        assert!((summary.tic["p"] - 0.2).abs() < 1e-12);
        assert!((summary.tic["q"] - 0.3).abs() < 1e-12);
        assert!((summary.tic["w"] - 0.7).abs() < 1e-12);
        assert!((summary.tic_mean - 0.4).abs() < 1e-12);
        assert_eq!(summary.tic_mean_all, Some(summary.tic_mean));
        assert!((summary.tic_mean_pqr.unwrap() - 0.25).abs() < 1e-12);
        assert_eq!(summary.bias, BiasMode::Trim);
        assert_eq!(summary.records.len(), 2);
        let json = serde_json::to_value(&summary).unwrap();
        assert_eq!(json["bias"], "trim");
        assert_eq!(serde_json::to_value(&document).unwrap()["bias"], "trim");
        assert!(
            summary
                .headline()
                .ends_with("; mean p q r 0.250, all 3 outputs 0.400 (trim bias)"),
            "{}",
            summary.headline()
        );
    }

    #[test]
    fn files_written_before_the_bias_was_recorded_read_as_fitted() {
        let old_document = r#"{"model_file": "model9.json", "segment_s": null, "records": []}"#;
        let document: VerifyDocument = serde_json::from_str(old_document).unwrap();
        assert_eq!(document.bias, BiasMode::Fitted);
        let old_summary = r#"{"tic": {"p": 0.1, "q": 0.2, "r": 0.3, "w": 0.8},
            "tic_mean": 0.35, "records": []}"#;
        let summary: VerifySummary = serde_json::from_str(old_summary).unwrap();
        assert_eq!(summary.bias, BiasMode::Fitted);
        assert_eq!(summary.tic_mean_pqr, None);
        assert!((summary.mean_pqr().unwrap() - 0.2).abs() < 1e-12);
        assert_eq!(summary.mean_all(), 0.35);
    }
}
