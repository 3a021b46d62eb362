//! Why frequency responses could not be computed: [`FrfError`].

use crate::records::RecordError;

/// Why frequency responses could not be computed. Every message fits on one line.
///
/// No variant has a `source()` of its own: a [`RecordError`] is shown as it is, and its
/// I/O cause is part of its message already (`path: cause`), so error chains printed with
/// `{:#}` would say it twice.
#[derive(Debug, thiserror::Error)]
pub enum FrfError {
    /// A record could not be read or is unusable (its message unchanged).
    #[error(transparent)]
    Record(#[from] RecordError),
    /// Records grouped together disagree (primary axis, rate, channel names).
    #[error("records do not fit together: {0}")]
    InconsistentGroup(String),
    /// Two groups sweep the same axis.
    #[error("two record groups sweep `{0}`: put its records in one group")]
    DuplicateAxis(String),
    /// No record was given.
    #[error("no records given")]
    NoRecords,
    /// The sweep band is unknown (CSV records carry none and no band was given).
    #[error("{0}")]
    NoBand(String),
    /// The records are too short for the band and windows asked for.
    #[error("{axis} sweep: record of {seconds:.1} s is too short: {detail}")]
    RecordTooShort {
        /// Primary axis of the group.
        axis: String,
        /// Length of the (joined) record \[s\].
        seconds: f64,
        /// Why it is too short.
        detail: String,
    },
    /// The swept input of a group does not move.
    #[error("{axis} sweep: the swept input `{axis}` has no excitation (constant)")]
    NoExcitation {
        /// Primary axis of the group.
        axis: String,
    },
    /// An option is out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
}
