//! Other tools' flight logs (PX4 ULog, ArduPilot DataFlash) in `decode` and `frf`.
//!
//! A file is taken as a log by its first bytes (`sysid::records::detect`), whatever its
//! name; everything else stays with the telemetry-dump and CSV readers.

use std::io::Write;
use std::path::Path;

use anyhow::{bail, Context};
use clap::Args;
use sysid::frf::Record;
use sysid::records::{self, Log, LogChannels, LogFormat, Topic, Values};

use crate::output::AtomicFile;

/// The format of the log at `path`, or `None` when it is not one (or cannot be read:
/// the reader it falls to then says why).
pub fn log_format(path: &Path) -> Option<LogFormat> {
    use std::io::Read;
    let mut head = [0u8; 8];
    let mut file = std::fs::File::open(path).ok()?;
    let mut filled = 0;
    while filled < head.len() {
        match file.read(&mut head[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(_) => return None,
        }
    }
    records::detect(&head[..filled])
}

fn read(path: &Path) -> anyhow::Result<Log> {
    Ok(records::read_log(path)?)
}

/// `decode LOG`: the list of topics (no `topic`), or one topic's messages, as CSV
/// (`jsonl` false) or JSON lines, to `output` (atomically) or standard output; a
/// summary on stderr unless `quiet`.
pub fn decode(
    path: &Path,
    topic: Option<&str>,
    jsonl: bool,
    output: Option<&Path>,
    quiet: bool,
) -> anyhow::Result<()> {
    let log = read(path)?;
    let mut text = String::new();
    match topic {
        None => list_topics(&log, jsonl, &mut text),
        Some(name) => {
            let topic = find_topic(&log, name)?;
            topic_rows(topic, jsonl, &mut text);
        }
    }
    match output {
        Some(out) => {
            let mut file = AtomicFile::create(out)?;
            file.write_all(text.as_bytes())
                .with_context(|| format!("cannot write {}", out.display()))?;
            file.commit()?;
        }
        None => {
            let mut stdout = std::io::stdout().lock();
            stdout
                .write_all(text.as_bytes())
                .and_then(|()| stdout.flush())
                .context("cannot write output")?;
        }
    }
    if !quiet {
        let with_data = log.topics.iter().filter(|t| !t.is_empty()).count();
        crate::note!(
            "{}: {}, {} bytes, {with_data} topics with messages",
            path.display(),
            log.format.name(),
            log.bytes
        );
        for line in &log.dropped {
            crate::note!("  not read: {line}");
        }
    }
    Ok(())
}

/// `NAME` or `NAME[k]` (a ULog instance).
fn find_topic<'a>(log: &'a Log, name: &str) -> anyhow::Result<&'a Topic> {
    let (base, instance) = match name.strip_suffix(']').and_then(|n| n.split_once('[')) {
        Some((base, k)) => match k.parse::<u8>() {
            Ok(k) => (base, k),
            Err(_) => bail!("--topic `{name}`: expected NAME or NAME[k]"),
        },
        None => (name, 0),
    };
    if log.format == LogFormat::DataFlash && base != name {
        bail!("--topic `{name}`: a DataFlash type is written whole, every instance (its instance column says which): use --topic {base}");
    }
    log.topic_instance(base, instance).with_context(|| {
        format!(
            "{}: no topic `{name}` (run `sweephold decode {}` for the list)",
            log.source, log.source
        )
    })
}

fn quote(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!(
            "\"{}\"",
            text.replace('"', "\"\"").replace(['\n', '\r'], " ")
        )
    } else {
        text.to_string()
    }
}

fn list_topics(log: &Log, jsonl: bool, out: &mut String) {
    if !jsonl {
        out.push_str("topic,messages,rate_hz,start_s,end_s,fields\n");
    }
    for topic in log.topics.iter().filter(|t| !t.is_empty()) {
        let fields: Vec<&str> = topic.fields.iter().map(|f| f.name.as_str()).collect();
        let (start, end) = (topic.time_s.first().copied(), topic.time_s.last().copied());
        let rate = topic.median_rate_hz();
        if jsonl {
            let units: Vec<Option<&str>> = topic.fields.iter().map(|f| f.unit.as_deref()).collect();
            let line = serde_json::json!({
                "topic": topic.label(),
                "messages": topic.len(),
                "rate_hz": rate,
                "start_s": start,
                "end_s": end,
                "fields": fields,
                "units": units,
            });
            out.push_str(&format!("{line}\n"));
        } else {
            let time = |t: Option<f64>| t.map_or(String::new(), |t| t.to_string());
            out.push_str(&format!(
                "{},{},{rate},{},{},{}\n",
                quote(&topic.label()),
                topic.len(),
                time(start),
                time(end),
                quote(&fields.join(" "))
            ));
        }
    }
}

fn topic_rows(topic: &Topic, jsonl: bool, out: &mut String) {
    let timed = topic.time_s.len() == topic.len();
    if !jsonl {
        let mut header: Vec<String> = Vec::new();
        if timed {
            header.push("time_s".into());
        }
        header.extend(topic.fields.iter().map(|f| quote(&f.name)));
        out.push_str(&header.join(","));
        out.push('\n');
    }
    for row in 0..topic.len() {
        if jsonl {
            let mut object = serde_json::Map::new();
            if timed {
                object.insert("time_s".into(), topic.time_s[row].into());
            }
            for field in &topic.fields {
                let value = match &field.values {
                    Values::Numbers(v) => serde_json::Value::from(v[row]),
                    Values::Text(v) => serde_json::Value::from(v[row].clone()),
                };
                object.insert(field.name.clone(), value);
            }
            out.push_str(&format!("{}\n", serde_json::Value::Object(object)));
        } else {
            let mut cells: Vec<String> = Vec::new();
            if timed {
                cells.push(topic.time_s[row].to_string());
            }
            cells.extend(topic.fields.iter().map(|field| match &field.values {
                Values::Numbers(v) => v[row].to_string(),
                Values::Text(v) => quote(&v[row]),
            }));
            out.push_str(&cells.join(","));
            out.push('\n');
        }
    }
}

/// `frf` options that only flight logs read.
#[derive(Args, Debug, Clone, Default)]
pub struct LogFrfArgs {
    /// Flight logs: keep only T0..T1, seconds on the log's clock (default: the SystemID sweep
    /// of an ArduPilot log that has SIDS/SIDD messages, else all the chosen channels share).
    #[arg(long, value_name = "T0,T1", value_parser = parse_window, allow_hyphen_values = true)]
    pub log_window: Option<Window>,
    /// Flight logs: resample at this rate in Hz (default: the median message rate of the
    /// first output's topic).
    #[arg(long, value_name = "HZ", allow_hyphen_values = true)]
    pub log_rate: Option<f64>,
    /// Flight logs: which SystemID sweep (1 = the first) of an ArduPilot log with several.
    #[arg(long, value_name = "N")]
    pub log_sweep: Option<usize>,
}

/// `--log-window T0,T1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window(pub [f64; 2]);

fn parse_window(text: &str) -> Result<Window, String> {
    let (a, b) = text
        .split_once(',')
        .ok_or_else(|| format!("`{text}`: expected T0,T1 in seconds"))?;
    let number = |s: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|_| format!("`{text}`: `{s}` is not a number"))
    };
    let (t0, t1) = (number(a)?, number(b)?);
    if !(t0.is_finite() && t1.is_finite() && t1 > t0) {
        return Err(format!("`{text}`: need T0 < T1"));
    }
    Ok(Window([t0, t1]))
}

/// The record `frf` analyses from the log at `path`: `inputs`, `outputs` as (name,
/// `TOPIC.FIELD`), the swept input and band when given.
pub fn frf_record(
    path: &Path,
    inputs: Vec<(String, String)>,
    outputs: Vec<(String, String)>,
    primary: Option<String>,
    band: Option<[f64; 2]>,
    options: &LogFrfArgs,
) -> anyhow::Result<Record> {
    let log = read(path)?;
    if let Some((name, spec)) = inputs
        .iter()
        .chain(&outputs)
        .find(|(_, spec)| !spec.contains('.'))
    {
        bail!(
            "{}: channels of a {} log are NAME=TOPIC.FIELD (e.g. p=RATE.R, p=vehicle_angular_velocity.xyz[0]) in --inputs and --outputs, not `{name}={spec}`; `sweephold decode {}` lists its topics",
            path.display(),
            log.format.name(),
            path.display()
        );
    }
    let channels = LogChannels {
        inputs,
        outputs,
        primary,
        sample_rate_hz: options.log_rate,
        window: options.log_window.map(|w| w.0),
        sweep: options.log_sweep,
        sweep_band: band,
    };
    Ok(records::record_from_log(&log, &channels)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_parse_or_say_what_is_wrong() {
        assert_eq!(parse_window("1.5, 20"), Ok(Window([1.5, 20.0])));
        for bad in ["3,1", "1", "a,2", "nan,2", "1,inf"] {
            assert!(parse_window(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(quote("a b"), "a b");
        assert_eq!(quote("a,\"b\""), "\"a,\"\"b\"\"\"");
    }
}
