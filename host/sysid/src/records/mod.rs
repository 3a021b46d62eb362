//! Flight records, read from the files they come in: the sweep [`Record`] every reader
//! produces, and the readers.
//!
//! * [`record`] — the [`Record`] (named, uniformly sampled input, output and reference
//!   channels of one excitation);
//! * [`dump`] — the project's telemetry dumps (the firmware's frames, decoded), with
//!   [`dump_tests`]: a dump split into its tests at its Headers, and [`origin`]: what a
//!   dump's Header says of where it was flown, and [`measurement_filter`]: the filter a
//!   board ran on its IMU outputs before logging them;
//! * [`csv`] — other loggers' CSV files, with their time and unit rules;
//! * [`ulog`] — PX4 ULog files (`.ulg`);
//! * [`dataflash`] — ArduPilot DataFlash binary logs (`.bin`, `.BIN`);
//! * [`select`] — chosen fields of either log, resampled onto one uniform time base, as a
//!   [`Record`] for the frequency-response analysis.
//!
//! Dumps and CSV files fail with a [`RecordError`]; the two log readers parse the whole
//! file into the same typed [`Log`] ([`log`]) and fail with a [`LogError`]. A log file
//! is recognised by its first bytes ([`detect`]), not by its name.
//!
//! **Its room.** This module reads files into records and nothing else: it imports no
//! other module of the crate (the frequency responses in `crate::frf` and the
//! verification in `crate::fit::verify` import it).
//!
//! **Damaged logs.** A log reader keeps every message that is whole and says in
//! [`Log::dropped`] what it could not read (a truncated last message, bytes skipped to
//! find the next message, messages of unknown types), each with its byte offset. Only a
//! file whose header cannot be read at all is an error.
//!
//! **Why hand-written.** The crates on crates.io were checked (2026-11): for ULog,
//! `px4-ulog` 0.6.1 (MIT) reads by path into hash maps keyed by name and its unpack
//! helpers `expect` on slice lengths; `yule_log` 0.4.0 (MIT) is a streaming parser that
//! pulls `env_logger`, `regex` and `lazy_static` into a crate that is "numerics and file
//! formats, nothing else"; `ulog-rs` 0.0.4 is an early release. None reports where in
//! the file a damaged message sat. No crate reads ArduPilot DataFlash logs. Both formats
//! are small and published (PX4's "ULog File Format", ArduPilot's `LogStructure.h`
//! FMT/FMTU/UNIT/MULT messages), so each reader is one short module, checked value for
//! value against pyulog and pymavlink on real files (`tests/log_readers.rs`).

mod binary;
pub mod csv;
pub mod dataflash;
pub mod dump;
pub mod dump_tests;
mod error;
pub mod log;
pub mod measurement_filter;
pub mod origin;
pub mod record;
pub mod select;
pub mod ulog;

pub use csv::units::{TimeUnit, Unit};
pub use csv::{load_csv, load_csv_records, parse_csv_records, CsvColumns};
pub use dump::{
    load_dump, load_dump_bytes, load_dump_tests, load_dump_with_origin, load_test_dump,
    record_from_samples, test_record_from_samples, Excitation,
};
pub use dump_tests::{
    split_tests, test_line, DumpTest, SplitDump, TestEnd, TestProgress, TestRecord,
};
pub use error::RecordError;
pub use log::{Field, Log, LogError, LogFormat, Topic, Values};
pub use measurement_filter::MeasurementFilter;
pub use origin::{check_one_origin, DumpOrigin};
pub(crate) use record::{remove_line, rms};
pub use record::{Channel, Record};
pub use select::{record_from_log, sweep_window, LogChannels, SweepWindow};

use std::path::Path;

/// The format of a file from its first bytes: `ULog` + `01 12 35` for ULog, a DataFlash
/// message header `A3 95` followed by the FMT message id 128 for DataFlash.
pub fn detect(bytes: &[u8]) -> Option<LogFormat> {
    if bytes.starts_with(ulog::MAGIC) {
        Some(LogFormat::ULog)
    } else if bytes.starts_with(&[dataflash::HEAD1, dataflash::HEAD2, dataflash::FMT_ID]) {
        Some(LogFormat::DataFlash)
    } else {
        None
    }
}

/// Read a ULog or DataFlash log, whichever the file's first bytes say it is.
pub fn read_log(path: impl AsRef<Path>) -> Result<Log, LogError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|error| LogError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let source = path.display().to_string();
    match detect(&bytes) {
        Some(LogFormat::ULog) => ulog::parse(&bytes, &source),
        Some(LogFormat::DataFlash) => dataflash::parse(&bytes, &source),
        None => Err(LogError::Format {
            path: source,
            offset: 0,
            message: "neither a PX4 ULog (`ULog` magic) nor an ArduPilot DataFlash log (FMT message first)".into(),
        }),
    }
}
