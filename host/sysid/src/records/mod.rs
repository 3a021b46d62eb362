//! Readers of other tools' flight logs, and the step from a log to a sweep [`Record`](crate::frf::Record).
//!
//! * [`ulog`] — PX4 ULog files (`.ulg`);
//! * [`dataflash`] — ArduPilot DataFlash binary logs (`.bin`, `.BIN`);
//! * [`select`] — chosen fields of either, resampled onto one uniform time base, as a
//!   [`Record`](crate::frf::Record) for the frequency-response analysis.
//!
//! Both readers parse the whole file into the same typed [`Log`]: one [`Topic`] per
//! message type (DataFlash) or per subscribed topic instance (ULog), each with its
//! fields and their timestamped values. A file is recognised by its first bytes
//! ([`detect`]), not by its name.
//!
//! **Damaged files.** A reader keeps every message that is whole and says in
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

pub mod dataflash;
pub mod select;
pub mod ulog;

pub use select::{record_from_log, sweep_window, LogChannels, SweepWindow};

use std::path::{Path, PathBuf};

/// Which format a log is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogFormat {
    /// PX4 ULog.
    ULog,
    /// ArduPilot DataFlash (binary).
    DataFlash,
}

impl LogFormat {
    /// The format's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            LogFormat::ULog => "PX4 ULog",
            LogFormat::DataFlash => "ArduPilot DataFlash",
        }
    }
}

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

/// The values of one field, one per message of its topic.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// Numbers (every integer and floating type, converted exactly to f64 where they fit).
    Numbers(Vec<f64>),
    /// Text (DataFlash `n`, `N`, `Z` fields), trailing NULs removed.
    Text(Vec<String>),
}

impl Values {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            Values::Numbers(v) => v.len(),
            Values::Text(v) => v.len(),
        }
    }

    /// `true` when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One field of a topic.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// Name as the format's own tools write it: pyulog's flattened names for ULog
    /// (`xyz[0]`, `previous.lat`), the FMT column names for DataFlash (`R`, `GyrX`).
    pub name: String,
    /// Unit label, when the log gives one (DataFlash FMTU/UNIT).
    pub unit: Option<String>,
    /// Multiplier from the logged number to the unit (DataFlash FMTU/MULT), when the log
    /// gives one and it is not already applied by the field's type.
    pub multiplier: Option<f64>,
    /// The values.
    pub values: Values,
}

/// One message type (DataFlash) or one topic instance (ULog) and its messages.
#[derive(Clone, Debug, PartialEq)]
pub struct Topic {
    /// Name: the ULog topic (`vehicle_angular_velocity`) or DataFlash type (`RATE`).
    pub name: String,
    /// ULog multi-instance id; `None` for DataFlash.
    pub instance: Option<u8>,
    /// DataFlash: the field that numbers the instances (FMTU unit `#`), if any.
    pub instance_field: Option<String>,
    /// Time of each message \[s\] (ULog `timestamp`, DataFlash `TimeUS`); empty when the
    /// messages carry no time (DataFlash FMT, for one).
    pub time_s: Vec<f64>,
    /// The fields, in the order of the format.
    pub fields: Vec<Field>,
}

impl Topic {
    /// Number of messages.
    pub fn len(&self) -> usize {
        self.fields.first().map_or(0, |f| f.values.len())
    }

    /// `true` when no message was read.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The field called `name`.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The numbers of the field called `name` (`None` for a missing or text field).
    pub fn numbers(&self, name: &str) -> Option<&[f64]> {
        match &self.field(name)?.values {
            Values::Numbers(v) => Some(v),
            Values::Text(_) => None,
        }
    }

    /// The topic's name as channel lists write it: `NAME`, or `NAME[k]` for ULog
    /// instance k > 0.
    pub fn label(&self) -> String {
        match self.instance {
            Some(k) if k > 0 => format!("{}[{k}]", self.name),
            _ => self.name.clone(),
        }
    }

    /// Median message rate \[Hz\]: the inverse of the median step between time stamps,
    /// that step rounded to the microsecond both formats' clocks count in (0 with fewer
    /// than two distinct time stamps).
    pub fn median_rate_hz(&self) -> f64 {
        median_rate_hz(&self.time_s)
    }
}

/// A whole log: its topics and what could not be read.
#[derive(Clone, Debug, PartialEq)]
pub struct Log {
    /// Where it came from (file name), for messages.
    pub source: String,
    /// Its format.
    pub format: LogFormat,
    /// The topics, in the order their definitions appear in the file.
    pub topics: Vec<Topic>,
    /// ULog information messages (`sys_name`, `ver_sw`, …) as text, and parameters
    /// (ULog `P` messages) as `(name, value)`; DataFlash keeps its parameters in the
    /// `PARM` topic.
    pub info: Vec<(String, String)>,
    /// ULog parameters.
    pub parameters: Vec<(String, f64)>,
    /// What was not read, one line each with its byte offset.
    pub dropped: Vec<String>,
    /// File length \[bytes\].
    pub bytes: usize,
}

impl Log {
    /// The topic called `name` (instance 0 for ULog).
    pub fn topic(&self, name: &str) -> Option<&Topic> {
        self.topic_instance(name, 0)
    }

    /// The topic called `name` with ULog instance `instance` (DataFlash topics match any).
    pub fn topic_instance(&self, name: &str, instance: u8) -> Option<&Topic> {
        self.topics
            .iter()
            .find(|t| t.name == name && t.instance.is_none_or(|k| k == instance))
    }
}

/// Why a log could not be read. Every message fits on one line and names the file.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The file could not be read.
    #[error("{}: {error}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        error: std::io::Error,
    },
    /// The file is not a log this module reads, or its header is damaged.
    #[error("{path}: byte {offset}: {message}")]
    Format {
        /// The file.
        path: String,
        /// Byte offset of the problem.
        offset: usize,
        /// What is wrong.
        message: String,
    },
    /// A chosen channel or option does not fit the log.
    #[error("{path}: {message}")]
    Select {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
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

/// A little-endian reader over a byte slice that never panics: every read past the end
/// is `None`.
#[derive(Clone, Copy)]
pub(crate) struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Bytes<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Bytes { data, pos: 0 }
    }

    pub(crate) fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.pos.checked_add(n)?;
        let slice = self.data.get(self.pos..end)?;
        self.pos = end;
        Some(slice)
    }

    pub(crate) fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        self.take(N)?.try_into().ok()
    }

    pub(crate) fn u8(&mut self) -> Option<u8> {
        Some(self.array::<1>()?[0])
    }

    pub(crate) fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.array()?))
    }

    pub(crate) fn rest(&self) -> &'a [u8] {
        self.data.get(self.pos..).unwrap_or(&[])
    }
}

/// A primitive number type of either format, read little-endian.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Primitive {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Primitive {
    pub(crate) fn size(self) -> usize {
        match self {
            Primitive::I8 | Primitive::U8 => 1,
            Primitive::I16 | Primitive::U16 => 2,
            Primitive::I32 | Primitive::U32 | Primitive::F32 => 4,
            Primitive::I64 | Primitive::U64 | Primitive::F64 => 8,
        }
    }

    /// The value at the start of `b` (`None` when `b` is too short).
    pub(crate) fn read(self, b: &[u8]) -> Option<f64> {
        let mut r = Bytes::new(b);
        Some(match self {
            Primitive::I8 => f64::from(i8::from_le_bytes(r.array()?)),
            Primitive::U8 => f64::from(r.u8()?),
            Primitive::I16 => f64::from(i16::from_le_bytes(r.array()?)),
            Primitive::U16 => f64::from(r.u16()?),
            Primitive::I32 => f64::from(i32::from_le_bytes(r.array()?)),
            Primitive::U32 => f64::from(u32::from_le_bytes(r.array()?)),
            // Exact up to 2⁵³ (time stamps in µs: 285 years).
            Primitive::I64 => i64::from_le_bytes(r.array()?) as f64,
            Primitive::U64 => u64::from_le_bytes(r.array()?) as f64,
            Primitive::F32 => f64::from(f32::from_le_bytes(r.array()?)),
            Primitive::F64 => f64::from_le_bytes(r.array()?),
        })
    }
}

/// The inverse of the median step between `time_s` \[s\], the step rounded to 1 µs.
pub(crate) fn median_rate_hz(time_s: &[f64]) -> f64 {
    let mut steps: Vec<f64> = time_s
        .windows(2)
        .map(|w| ((w[1] - w[0]) * 1e6).round())
        .filter(|d| *d > 0.0)
        .collect();
    if steps.is_empty() {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    1e6 / steps[steps.len() / 2]
}

/// Text from NUL-padded bytes: up to the first NUL, invalid UTF-8 replaced.
pub(crate) fn text(bytes: &[u8]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}
