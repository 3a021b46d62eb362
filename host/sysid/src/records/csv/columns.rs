//! Which CSV columns to read, and how ([`CsvColumns`]); its default reads the CSV
//! `sweephold decode` writes.

use super::units::{TimeUnit, Unit};

/// Which CSV columns to read, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct CsvColumns {
    /// Time column: a header name or a position (1 = first).
    pub time: String,
    /// Inputs as (channel name, column).
    pub inputs: Vec<(String, String)>,
    /// Outputs as (channel name, column).
    pub outputs: Vec<(String, String)>,
    /// References as (input name, column): the excitation injected into that input (the
    /// sweep), for [`ResponseEstimator::SweepReference`](crate::frf::ResponseEstimator::SweepReference).
    pub references: Vec<(String, String)>,
    /// The swept input (a channel name, `frf --swept`); it overrides the file's primary
    /// column. `None`: the primary column names it, else the input with the largest RMS
    /// about its trend line does.
    pub primary: Option<String>,
    /// Column naming the swept axis on each row, read when the file has it and `primary`
    /// is `None`. Its value must be the same on every kept row and name an input, by its
    /// channel name or by the decode command column it is read from (`lat` names the
    /// input read from `cmd_lat`, whatever that input is called).
    pub primary_column: Option<String>,
    /// Phase column used to keep only excitation rows, when the file has it.
    pub phase_column: Option<String>,
    /// Sweep band [rad/s], if known.
    pub sweep_band: Option<[f64; 2]>,
    /// Units of channels, by channel name (a reference takes its input's); channels not
    /// named are used as written.
    pub units: Vec<(String, Unit)>,
    /// Unit of the time column; `None`: told from its median step ([`units`](super::units)).
    pub time_unit: Option<TimeUnit>,
    /// Keep only the rows whose time \[s\] lies in [t0, t1].
    pub window_s: Option<[f64; 2]>,
}

impl Default for CsvColumns {
    /// The columns of `sweephold decode` CSV output.
    fn default() -> Self {
        let same = |names: &[&str]| {
            names
                .iter()
                .map(|n| (n.to_string(), n.to_string()))
                .collect()
        };
        CsvColumns {
            time: "time_s".into(),
            inputs: vec![
                ("lat".into(), "cmd_lat".into()),
                ("lon".into(), "cmd_lon".into()),
                ("ped".into(), "cmd_ped".into()),
                ("col".into(), "cmd_col".into()),
            ],
            outputs: same(&[
                "u", "v", "w", "p", "q", "r", "ax", "ay", "az", "phi", "theta",
            ]),
            references: Vec::new(),
            primary: None,
            primary_column: Some(PRIMARY_COLUMN.into()),
            phase_column: Some("phase".into()),
            sweep_band: None,
            units: Vec::new(),
            time_unit: None,
            window_s: None,
        }
    }
}

/// The column `sweephold decode` writes the swept axis into.
pub const PRIMARY_COLUMN: &str = "primary";
