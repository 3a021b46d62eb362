//! Why a record could not be read.

use std::path::PathBuf;

/// Why a dump or CSV file gave no usable record. Every message fits on one line and
/// names the file.
///
/// No variant has a `source()`: where one wraps an error (the I/O cause), its message is
/// part of this one already (`path: cause`), and error chains printed with `{:#}` would
/// say it twice.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
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
}

/// `:N` after a CSV file's name for a problem on line N (none for the whole file, 0).
fn csv_line(line: &usize) -> String {
    if *line > 0 {
        format!(":{line}")
    } else {
        String::new()
    }
}
