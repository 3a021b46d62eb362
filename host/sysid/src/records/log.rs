//! The typed log both readers produce: one [`Topic`] per message type (DataFlash) or
//! per subscribed topic instance (ULog), each with its fields and their timestamped
//! values, and the error type of reading one.

use std::path::PathBuf;

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
