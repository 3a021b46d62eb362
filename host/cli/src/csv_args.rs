//! The options that say how to read a CSV log (columns, units, window, swept input), for
//! `frf` and `verify` alike; the rules are in `sysid::records::csv` and docs/formats.md.

use anyhow::bail;
use clap::Args;
use sysid::records::{CsvColumns, TimeUnit, Unit};

/// How to read CSV files.
#[derive(Args, Clone, Debug)]
pub struct CsvArgs {
    /// CSV: the time column (a header name, or a position: 1 = first).
    #[arg(long, value_name = "COLUMN", default_value = "time_s")]
    pub time: String,
    /// CSV: input columns, `NAME=COLUMN` or `COLUMN`, comma-separated.
    #[arg(
        long = "inputs",
        value_name = "LIST",
        default_value = "lat=cmd_lat,lon=cmd_lon,ped=cmd_ped,col=cmd_col"
    )]
    pub input_columns: String,
    /// CSV: output columns, `NAME=COLUMN` or `COLUMN`, comma-separated.
    #[arg(
        long = "outputs",
        value_name = "LIST",
        default_value = "u,v,w,p,q,r,ax,ay,az,phi,theta"
    )]
    pub output_columns: String,
    /// CSV: the excitation injected into an input (the sweep), `NAME=COLUMN` with NAME
    /// from --inputs, comma-separated: the instrument of `--estimator sweep-reference`.
    #[arg(long = "reference", value_name = "LIST")]
    pub reference_columns: Option<String>,
    /// CSV: units, `NAME=UNIT` comma-separated: NAME from --inputs or --outputs with
    /// rad/s, deg/s, rad or deg (converted to rad/s, rad), or `time` with s, ms or us.
    /// Channels not named are used as written. May be given more than once; a later unit
    /// for the same name wins.
    #[arg(long, value_name = "LIST")]
    pub units: Vec<String>,
    /// CSV: keep only the rows whose time lies in [T0, T1] seconds (on the file's time
    /// axis, after its unit).
    #[arg(long, value_name = "T0,T1", value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<Window>,
    /// CSV: the swept input (a name from --inputs); overrides the file's primary column.
    /// Default: the primary column, else the most active input. `--primary` is an alias.
    #[arg(long = "swept", alias = "primary", value_name = "NAME")]
    pub swept: Option<String>,
    /// CSV: column naming the swept axis on each row (`decode` writes `primary`), by an
    /// input name or the axis of a `cmd_AXIS` input column; read when the file has it and
    /// --swept is not given.
    #[arg(long, value_name = "COLUMN", default_value = "primary")]
    pub primary_column: String,
    /// CSV: column whose value keeps a row only in the fade_in, sweep and fade_out
    /// phases (ignored when the file has no such column).
    #[arg(long, value_name = "COLUMN", default_value = "phase")]
    pub phase_column: String,
}

/// A time window \[s\] as given on the command line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window(pub [f64; 2]);

fn parse_window(text: &str) -> Result<Window, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [t0, t1] = parts.as_slice() else {
        return Err(format!("`{text}`: expected T0,T1"));
    };
    let number = |s: &str| {
        s.parse::<f64>()
            .map_err(|_| format!("`{s}` is not a number"))
    };
    let (t0, t1) = (number(t0)?, number(t1)?);
    if !(t0.is_finite() && t1.is_finite() && t1 > t0) {
        return Err(format!("`{text}`: need T0 < T1"));
    }
    Ok(Window([t0, t1]))
}

/// The units `--units` gives: the time column's, if given, and the channels'.
type Units = (Option<TimeUnit>, Vec<(String, Unit)>);

/// `--units`: the time column's unit and the channels' units.
fn parse_units(list: &str) -> anyhow::Result<Units> {
    let mut time = None;
    let mut channels = Vec::new();
    for (name, unit) in parse_columns(list, "--units")? {
        if name == "time" {
            let Some(unit) = TimeUnit::parse(&unit) else {
                bail!("--units `time={unit}`: the time unit is s, ms or us");
            };
            time = Some(unit);
        } else {
            let Some(unit) = Unit::parse(&unit) else {
                bail!(
                    "--units `{name}={unit}`: a unit is rad/s, deg/s, rad or deg (time: s, ms, us)"
                );
            };
            channels.retain(|(n, _): &(String, Unit)| *n != name);
            channels.push((name, unit));
        }
    }
    Ok((time, channels))
}

/// `NAME=COLUMN` or `COLUMN` (name = column), comma-separated.
fn parse_columns(list: &str, option: &str) -> anyhow::Result<Vec<(String, String)>> {
    let columns: Vec<(String, String)> = list
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|item| match item.split_once('=') {
            Some((name, column)) => (name.trim().to_string(), column.trim().to_string()),
            None => (item.to_string(), item.to_string()),
        })
        .collect();
    if columns.is_empty() || columns.iter().any(|(n, c)| n.is_empty() || c.is_empty()) {
        bail!("{option} `{list}`: expected NAME=COLUMN or COLUMN, comma-separated");
    }
    Ok(columns)
}

impl Default for CsvArgs {
    /// The command line's defaults (the columns `sweephold decode` writes).
    fn default() -> Self {
        #[derive(clap::Parser)]
        struct Defaults {
            #[command(flatten)]
            csv: CsvArgs,
        }
        <Defaults as clap::Parser>::parse_from(["defaults"]).csv
    }
}

impl CsvArgs {
    /// The columns to read, with `sweep_band` (`frf --band`) as the records' band.
    pub fn columns(&self, sweep_band: Option<[f64; 2]>) -> anyhow::Result<CsvColumns> {
        let inputs = parse_columns(&self.input_columns, "--inputs")?;
        if let Some(swept) = &self.swept {
            if !inputs.iter().any(|(name, _)| name == swept) {
                let names: Vec<&str> = inputs.iter().map(|(name, _)| name.as_str()).collect();
                bail!(
                    "--swept `{swept}`: not one of the --inputs names ({})",
                    names.join(", ")
                );
            }
        }
        let references = match &self.reference_columns {
            Some(list) => parse_columns(list, "--reference")?,
            None => Vec::new(),
        };
        for (name, _) in &references {
            if !inputs.iter().any(|(input, _)| input == name) {
                let names: Vec<&str> = inputs.iter().map(|(name, _)| name.as_str()).collect();
                bail!(
                    "--reference `{name}`: not one of the --inputs names ({})",
                    names.join(", ")
                );
            }
        }
        let (time_unit, units) = if self.units.is_empty() {
            (None, Vec::new())
        } else {
            parse_units(&self.units.join(","))?
        };
        Ok(CsvColumns {
            time: self.time.clone(),
            inputs,
            references,
            units,
            time_unit,
            window_s: self.window.map(|w| w.0),
            outputs: parse_columns(&self.output_columns, "--outputs")?,
            primary: self.swept.clone(),
            primary_column: Some(self.primary_column.clone()),
            phase_column: Some(self.phase_column.clone()),
            sweep_band,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_and_units_parse() {
        assert_eq!(parse_window("-1,5"), Ok(Window([-1.0, 5.0])));
        for bad in ["5,1", "1", "a,2", "0,inf"] {
            assert!(parse_window(bad).is_err(), "{bad}");
        }
        let (time, channels) = parse_units("p=deg/s,time=ms,p=rad/s,phi=deg").unwrap();
        assert_eq!(time, Some(TimeUnit::Milliseconds));
        assert_eq!(
            channels,
            [
                ("p".to_string(), Unit::RadPerS),
                ("phi".to_string(), Unit::Deg)
            ]
        );
        assert!(parse_units("time=h").is_err() && parse_units("p").is_err());
    }
}
