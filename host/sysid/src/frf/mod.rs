//! Frequency responses from sweep records, the way CIFER computes them:
//! FRESPID (windowed Chirp-Z spectra), MISOSA (multi-input conditioning) and COMPOSITE
//! (blending several window lengths).
//!
//! The chain, one module per step:
//!
//! 1. [`records`] — [`Record`]s (from telemetry dumps via [`load_dump`] or from CSV via
//!    [`load_csv`]) are gathered into one [`RecordGroup`] per swept axis; the records of
//!    a group are detrended and joined into one excitation record.
//! 2. [`spectra`] — Hann-tapered, overlapped windows of several lengths; each window of
//!    each channel is transformed once with the [`chirp_z()`] transform and all auto- and
//!    cross-spectra are formed from those transforms, then interpolated onto a
//!    log-spaced frequency grid.
//! 3. [`miso`] — per frequency and window length, the conditioned responses
//!    `H = Guu⁻¹·Guy` (Cholesky solve), partial and multiple coherence.
//!    With a feedback controller in the loop, [`reference`](mod@reference) solves `G_zu·H = G_zy`
//!    with the recorded sweep as instrument z instead (an option).
//! 4. [`composite`] — per frequency, the window-length estimates are blended with
//!    weights 1/εr².
//! 5. [`coherence`] — random error, valid ranges, coherence bias.
//! 6. [`analysis`] — the whole computation into an [`FrfDocument`], and the
//!    cross-control coherence.
//!
//! ```no_run
//! use sysid::frf::{compute_frequency_responses, group_by_primary, load_dump, FrfOptions};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let records = vec![load_dump("lat-1.dump")?, load_dump("lat-2.dump")?, load_dump("lon.dump")?];
//! let groups = group_by_primary(records)?; // lat (two records joined), lon
//! let document = compute_frequency_responses(&groups, &FrfOptions::default())?;
//! if let Some(pair) = document.pair("lat", "p") {
//!     println!("lat → p valid over {:?} rad/s", pair.valid_range);
//! }
//! # Ok(())
//! # }
//! ```
//!
//! [`FrfDocument`]: crate::document::FrfDocument

pub mod analysis;
pub mod chirp_z;
pub mod coherence;
pub mod composite;
pub mod csv;
pub mod dump;
pub mod miso;
pub mod options;
pub mod origin;
pub mod records;
pub mod reference;
pub mod spectra;

#[cfg(test)]
pub(crate) mod testing;

pub use analysis::{
    analyse, compute_frequency_responses, cross_control_coherence, CoherenceCurve, FrfAnalysis,
    GroupSummary, MultipleCoherence,
};
pub use chirp_z::{chirp_z, ChirpZ};
pub use coherence::{debiased_coherence, random_error, valid_range};
pub use csv::units::{TimeUnit, Unit};
pub use csv::{load_csv, load_csv_records, parse_csv_records, CsvColumns};
pub use dump::{
    load_dump, load_dump_bytes, load_dump_with_origin, load_test_dump, record_from_samples,
    test_record_from_samples,
};
pub use options::{FrfOptions, RangeSource, ResponseEstimator, ResponseInputs};
pub use origin::{check_one_origin, DumpOrigin};
pub use records::{group_by_primary, Channel, Record, RecordGroup};
pub use spectra::welch_independent_averages;

use std::path::PathBuf;

/// Why frequency responses could not be computed. Every message fits on one line.
///
/// No variant has a `source()`: where one wraps an error (the I/O cause), its message is
/// part of this one already (`path: cause`), and error chains printed with `{:#}` would
/// say it twice.
#[derive(Debug, thiserror::Error)]
pub enum FrfError {
    /// A file could not be read or written.
    #[error("{}: {error}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        error: std::io::Error,
    },
    /// The dump was written with another protocol major version.
    #[error("{path}: {message}")]
    Protocol {
        /// The dump.
        path: String,
        /// The decoder's message.
        message: String,
    },
    /// The dump has no Header frame: rate and primary axis are unknown.
    #[error("{path}: no Header frame (sample rate and swept axis unknown)")]
    NoHeader {
        /// The dump.
        path: String,
    },
    /// The dump holds no sweep (no Sample in the fade-in, sweep or fade-out phases, or
    /// the test was not a sweep).
    #[error("{path}: no sweep in this dump ({detail})")]
    NoSweep {
        /// The dump.
        path: String,
        /// What was found instead.
        detail: String,
    },
    /// A CSV file is malformed.
    #[error("{path}{}: {message}", csv_line(.line))]
    Csv {
        /// The file.
        path: String,
        /// Line number (1-based), 0 for the whole file.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A record is unusable (inconsistent lengths, non-finite values, bad rate, …).
    #[error("{record}: {message}")]
    InvalidRecord {
        /// The record's source (file name or label).
        record: String,
        /// What is wrong.
        message: String,
    },
    /// Records grouped together disagree (primary axis, rate, channel names).
    #[error("records do not fit together: {0}")]
    InconsistentGroup(String),
    /// Dumps whose Headers name different vehicles, protocol versions or rates.
    #[error("{first} and {other} cannot be joined: their Headers name {what}")]
    MixedDumps {
        /// The first dump.
        first: String,
        /// The dump that differs from it.
        other: String,
        /// What differs, e.g. `vehicle bo105 vs trex700l`.
        what: String,
    },
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

/// `:N` after a CSV file's name for a problem on line N (none for the whole file, 0).
fn csv_line(line: &usize) -> String {
    if *line > 0 {
        format!(":{line}")
    } else {
        String::new()
    }
}
