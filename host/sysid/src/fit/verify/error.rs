//! Why a model cannot be verified against a record: [`VerifyError`].

/// Why a model cannot be verified against a record.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VerifyError {
    /// A control of the model is not among the record's inputs.
    #[error("model control `{control}` is not an input of {record} (inputs: {})", .available.join(" "))]
    MissingInput {
        /// The control.
        control: String,
        /// The record.
        record: String,
        /// The record's inputs.
        available: Vec<String>,
    },
    /// No output of the model is among the record's outputs.
    #[error("no output of the model ({}) is recorded in {record}", .model_outputs.join(" "))]
    NoCommonOutput {
        /// The record.
        record: String,
        /// The model's outputs.
        model_outputs: Vec<String>,
    },
    /// The model's matrices do not fit its names, or M is singular.
    #[error("unusable model: {reason}")]
    BadModel {
        /// What is wrong.
        reason: String,
    },
    /// The record is too short or its rate is not positive.
    #[error("{record}: {reason}")]
    BadRecord {
        /// The record.
        record: String,
        /// What is wrong.
        reason: String,
    },
    /// The simulation left the finite numbers (an unstable model ran away).
    #[error("the simulated model diverged (non-finite at sample {sample})")]
    Diverged {
        /// Sample index where the first non-finite value appeared.
        sample: usize,
    },
    /// The trim bias was asked for, but the record has no trim samples before its
    /// excitation.
    #[error(
        "{record}: no trim samples before the excitation to take the output bias from \
         (the fitted bias needs none)"
    )]
    NoTrim {
        /// The record.
        record: String,
    },
}
