//! Chosen fields of a [`Log`] as one uniformly sampled [`Record`].
//!
//! **Channels** are named `NAME=TOPIC.FIELD`: `p=vehicle_angular_velocity.xyz[0]` (ULog),
//! `p=RATE.R` (DataFlash). `TOPIC[k]` picks instance k: the ULog multi id (default 0),
//! or for a DataFlash type with an instance column (`IMU.I`) the rows whose instance is
//! k (without `[k]` such a type must hold only one instance).
//!
//! **Units.** ULog fields are taken as logged (PX4 logs SI units: rad, rad/s, m/s²).
//! DataFlash fields are multiplied by their FMTU multiplier where the log gives one, and
//! fields in degrees (units `deg`, `degheading`, `deg/s`, `deg/s/s`) are converted to
//! radians, so `RATE.R` (deg/s) becomes rad/s. Every conversion applied is listed in the
//! record's notes.
//!
//! **Time base.** Each channel is interpolated linearly onto one uniform grid: from the
//! latest first sample of the chosen channels to the earliest last one (within the time
//! window), at [`LogChannels::sample_rate_hz`] or else at the median message rate of the
//! first output's topic over that span.
//!
//! **Window.** [`LogChannels::window`] (seconds on the log's clock) when given. Else,
//! for an ArduPilot log with SystemID messages, the sweep found by [`sweep_window`]:
//! each `SIDS` message (SystemID settings, written when a sweep starts) opens a sweep
//! and the `SIDD` messages (SystemID data, written while the chirp runs) up to the next
//! `SIDS` are its samples; the window runs from the first to the last of them, the
//! `SIDS` start and stop frequencies `FSt`, `FSp` (Hz) give the band (unless one is
//! given) and its `Ax` the excited axis (reported in the notes). The first sweep is
//! used unless [`LogChannels::sweep`] picks another. Otherwise the whole overlap.

use super::log::{median_rate_hz, Log, LogError, LogFormat, Topic, Values};
use super::record::{Channel, Record};

/// Which fields of a log make the record, and how it is sampled.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LogChannels {
    /// Inputs as (channel name, `TOPIC.FIELD`).
    pub inputs: Vec<(String, String)>,
    /// Outputs as (channel name, `TOPIC.FIELD`).
    pub outputs: Vec<(String, String)>,
    /// The swept input (a channel name); `None`: the first input, marked guessed when
    /// there are several.
    pub primary: Option<String>,
    /// Sample rate of the record \[Hz\]; `None`: the median rate of the first output's
    /// topic.
    pub sample_rate_hz: Option<f64>,
    /// Time window [t0, t1] \[s\] on the log's clock; `None`: the SystemID sweep where the
    /// log has one, else everything.
    pub window: Option<[f64; 2]>,
    /// Which SystemID sweep (1-based) when the log has several; `None`: the first.
    pub sweep: Option<usize>,
    /// Sweep band [rad/s]; `None`: from the SystemID settings where the log has them.
    pub sweep_band: Option<[f64; 2]>,
}

/// A SystemID sweep found in an ArduPilot log.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepWindow {
    /// Which sweep (1-based) and how many the log holds.
    pub index: usize,
    /// Number of sweeps in the log.
    pub count: usize,
    /// First and last SIDD time \[s\].
    pub window: [f64; 2],
    /// SIDS `Ax`: the excited axis, when a SIDS message opened the sweep.
    pub axis: Option<u8>,
    /// SIDS `FSt`..`FSp` as rad/s, when a SIDS message opened the sweep.
    pub band: Option<[f64; 2]>,
}

impl SweepWindow {
    /// ArduCopter's name of the excited axis (`AxisType` of its SystemID mode).
    pub fn axis_name(&self) -> String {
        const NAMES: [&str; 14] = [
            "none",
            "input roll",
            "input pitch",
            "input yaw",
            "recover roll",
            "recover pitch",
            "recover yaw",
            "rate roll",
            "rate pitch",
            "rate yaw",
            "mixer roll",
            "mixer pitch",
            "mixer yaw",
            "mixer throttle",
        ];
        match self.axis {
            Some(a) => NAMES
                .get(usize::from(a))
                .map_or_else(|| format!("axis {a}"), |n| format!("{n} (axis {a})")),
            None => "unknown (no SIDS message)".into(),
        }
    }
}

/// The SystemID sweep `which` (1-based; `None`: the first) of an ArduPilot log, or `None`
/// when the log has no SIDD messages.
pub fn sweep_window(log: &Log, which: Option<usize>) -> Result<Option<SweepWindow>, LogError> {
    let Some(sidd) = log.topic("SIDD").filter(|t| t.time_s.len() >= 2) else {
        return Ok(None);
    };
    let starts: Vec<(f64, Option<u8>, Option<[f64; 2]>)> = match log.topic("SIDS") {
        Some(sids) => {
            let number = |name: &str, i: usize| sids.numbers(name).and_then(|v| v.get(i).copied());
            (0..sids.time_s.len())
                .map(|i| {
                    let axis = number("Ax", i).map(|a| a as u8);
                    let band = match (number("FSt", i), number("FSp", i)) {
                        (Some(lo), Some(hi)) if lo > 0.0 && hi > lo => {
                            Some([lo * std::f64::consts::TAU, hi * std::f64::consts::TAU])
                        }
                        _ => None,
                    };
                    (sids.time_s[i], axis, band)
                })
                .collect()
        }
        None => Vec::new(),
    };
    // Sweeps: the SIDD times between one SIDS and the next (and any before the first).
    let mut sweeps: Vec<Sweep> = Vec::new();
    let mut bounds = vec![(f64::NEG_INFINITY, None, None)];
    bounds.extend(starts);
    for (k, (start, axis, band)) in bounds.iter().enumerate() {
        let end = bounds.get(k + 1).map_or(f64::INFINITY, |b| b.0);
        let times: Vec<f64> = sidd
            .time_s
            .iter()
            .copied()
            .filter(|t| *t >= *start && *t < end)
            .collect();
        if let (Some(first), Some(last)) = (times.first(), times.last()) {
            if last > first {
                sweeps.push(([*first, *last], *axis, *band));
            }
        }
    }
    let count = sweeps.len();
    if count == 0 {
        return Ok(None);
    }
    let index = which.unwrap_or(1);
    let Some((window, axis, band)) = index.checked_sub(1).and_then(|i| sweeps.get(i)) else {
        return Err(LogError::Select {
            path: log.source.clone(),
            message: format!("sweep {index}: the log holds {count} SystemID sweep(s)"),
        });
    };
    Ok(Some(SweepWindow {
        index,
        count,
        window: *window,
        axis: *axis,
        band: *band,
    }))
}

/// A sweep's window, axis and band, before it is chosen.
type Sweep = ([f64; 2], Option<u8>, Option<[f64; 2]>);

/// One chosen channel: its time stamps and values in the units the record uses.
struct Series {
    time: Vec<f64>,
    values: Vec<f64>,
    topic_rate_hz: f64,
    note: Option<String>,
}

/// Split `TOPIC[k].FIELD` into (topic, instance, field).
fn split_channel(spec: &str) -> Option<(&str, Option<u8>, &str)> {
    let (topic, field) = spec.split_once('.')?;
    let (topic, instance) = match topic.strip_suffix(']').and_then(|t| t.split_once('[')) {
        Some((name, k)) => (name, Some(k.parse().ok()?)),
        None => (topic, None),
    };
    (!topic.is_empty() && !field.is_empty()).then_some((topic, instance, field))
}

/// Degrees to radians for the DataFlash units in degrees.
fn radians(unit: &str) -> Option<&'static str> {
    Some(match unit {
        "deg" | "degheading" => "rad",
        "deg/s" => "rad/s",
        "deg/s/s" => "rad/s/s",
        _ => return None,
    })
}

fn series(log: &Log, name: &str, spec: &str) -> Result<Series, LogError> {
    let fail = |message: String| LogError::Select {
        path: log.source.clone(),
        message: format!("{name}={spec}: {message}"),
    };
    let (topic_name, instance, field_name) =
        split_channel(spec).ok_or_else(|| fail("expected TOPIC.FIELD or TOPIC[k].FIELD".into()))?;
    let topic: &Topic = match log.format {
        LogFormat::ULog => log.topic_instance(topic_name, instance.unwrap_or(0)),
        LogFormat::DataFlash => log.topic(topic_name),
    }
    .ok_or_else(|| match instance {
        Some(k) if log.topic(topic_name).is_some() => {
            fail(format!("no instance {k} of `{topic_name}`"))
        }
        _ => fail(format!(
            "no topic `{topic_name}` in this log (`sweephold decode` lists them)"
        )),
    })?;
    let field = topic.field(field_name).ok_or_else(|| {
        let names: Vec<&str> = topic
            .fields
            .iter()
            .map(|f| f.name.as_str())
            .take(24)
            .collect();
        fail(format!(
            "no field `{field_name}` in `{topic_name}` (it has {})",
            names.join(", ")
        ))
    })?;
    let Values::Numbers(values) = &field.values else {
        return Err(fail("a text field".into()));
    };
    if topic.time_s.len() != values.len() {
        return Err(fail(format!("`{topic_name}` messages carry no time stamp")));
    }
    let mut rows: Vec<usize> = (0..values.len()).collect();
    if log.format == LogFormat::DataFlash {
        match (&topic.instance_field, instance) {
            (Some(column), Some(k)) => {
                let ids = topic.numbers(column).unwrap_or(&[]);
                rows.retain(|&i| ids.get(i) == Some(&f64::from(k)));
            }
            (Some(column), None) => {
                let mut ids: Vec<i64> = topic
                    .numbers(column)
                    .unwrap_or(&[])
                    .iter()
                    .map(|v| *v as i64)
                    .collect();
                ids.sort_unstable();
                ids.dedup();
                if ids.len() > 1 {
                    let list: Vec<String> = ids.iter().map(i64::to_string).collect();
                    return Err(fail(format!(
                        "`{topic_name}` has instances {} (column {column}): name one, as `{topic_name}[{}].{field_name}`",
                        list.join(", "),
                        ids[0]
                    )));
                }
            }
            (None, Some(k)) => {
                return Err(fail(format!(
                    "`{topic_name}` has no instances, so no instance {k}"
                )));
            }
            (None, None) => {}
        }
    }
    let mut scale = 1.0;
    let mut conversions = Vec::new();
    if let Some(m) = field.multiplier.filter(|m| *m != 1.0) {
        scale *= m;
        conversions.push(format!("× {m} (FMTU multiplier)"));
    }
    if let Some(unit) = &field.unit {
        if let Some(to) = radians(unit) {
            scale *= std::f64::consts::PI / 180.0;
            conversions.push(format!("{unit} → {to}"));
        }
    }
    let time: Vec<f64> = rows.iter().map(|&i| topic.time_s[i]).collect();
    let values: Vec<f64> = rows.iter().map(|&i| values[i] * scale).collect();
    if let Some(i) = time.windows(2).position(|w| w[1] < w[0] || w[1].is_nan()) {
        return Err(fail(format!(
            "time goes back at message {} ({} s after {} s)",
            i + 1,
            time[i + 1],
            time[i]
        )));
    }
    Ok(Series {
        topic_rate_hz: median_rate_hz(&time),
        time,
        values,
        note: (!conversions.is_empty())
            .then(|| format!("{name}={spec}: {}", conversions.join(", "))),
    })
}

/// Linear interpolation of (`time`, `values`) at the sorted times `grid`.
fn interpolate(time: &[f64], values: &[f64], grid: &[f64]) -> Vec<f64> {
    let mut j = 0;
    grid.iter()
        .map(|&t| {
            while j + 2 < time.len() && time[j + 1] <= t {
                j += 1;
            }
            let (t0, t1) = (time[j], time[j + 1]);
            if t1 > t0 {
                let a = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
                values[j] + a * (values[j + 1] - values[j])
            } else {
                values[j + 1]
            }
        })
        .collect()
}

/// The record that `channels` choose from `log` (see the module documentation).
pub fn record_from_log(log: &Log, channels: &LogChannels) -> Result<Record, LogError> {
    let fail = |message: String| LogError::Select {
        path: log.source.clone(),
        message,
    };
    if channels.inputs.is_empty() || channels.outputs.is_empty() {
        return Err(fail("name at least one input and one output".into()));
    }
    let mut notes = Vec::new();
    let mut band = channels.sweep_band;
    let window = match channels.window {
        Some(w) => {
            if !(w[0].is_finite() && w[1].is_finite() && w[1] > w[0]) {
                return Err(fail(format!("window {}..{} s: need T0 < T1", w[0], w[1])));
            }
            Some(w)
        }
        None => match sweep_window(log, channels.sweep)? {
            Some(sweep) => {
                notes.push(format!(
                    "SystemID sweep {} of {}: {:.3}–{:.3} s, axis {}{}",
                    sweep.index,
                    sweep.count,
                    sweep.window[0],
                    sweep.window[1],
                    sweep.axis_name(),
                    sweep.band.map_or(String::new(), |b| format!(
                        ", band {:.3}–{:.3} rad/s (SIDS)",
                        b[0], b[1]
                    ))
                ));
                band = band.or(sweep.band);
                Some(sweep.window)
            }
            None if channels.sweep.is_some() => {
                return Err(fail(
                    "--sweep: the log has no SystemID (SIDD) messages".into(),
                ));
            }
            None => None,
        },
    };
    let inputs = channels
        .inputs
        .iter()
        .map(|(name, spec)| series(log, name, spec))
        .collect::<Result<Vec<_>, _>>()?;
    let outputs = channels
        .outputs
        .iter()
        .map(|(name, spec)| series(log, name, spec))
        .collect::<Result<Vec<_>, _>>()?;
    let all = || inputs.iter().chain(&outputs);
    if let Some((s, (name, spec))) = all()
        .zip(channels.inputs.iter().chain(&channels.outputs))
        .find(|(s, _)| s.time.len() < 2)
    {
        return Err(fail(format!(
            "{name}={spec}: {} message(s), need at least 2",
            s.time.len()
        )));
    }
    let mut start = all().map(|s| s.time[0]).fold(f64::NEG_INFINITY, f64::max);
    let mut end = all()
        .map(|s| s.time[s.time.len() - 1])
        .fold(f64::INFINITY, f64::min);
    if let Some([t0, t1]) = window {
        start = start.max(t0);
        end = end.min(t1);
    }
    if end.partial_cmp(&start) != Some(std::cmp::Ordering::Greater) {
        return Err(fail(format!(
            "the chosen channels have no time in common{}",
            window.map_or(String::new(), |w| format!(" within {}–{} s", w[0], w[1]))
        )));
    }
    let rate = match channels.sample_rate_hz {
        Some(r) if r.is_finite() && r > 0.0 => r,
        Some(r) => return Err(fail(format!("sample rate {r} Hz: need a rate > 0"))),
        None => {
            let first = &outputs[0];
            let inside: Vec<f64> = first
                .time
                .iter()
                .copied()
                .filter(|t| *t >= start && *t <= end)
                .collect();
            let r = match median_rate_hz(&inside) {
                r if r > 0.0 => r,
                _ => first.topic_rate_hz,
            };
            if r.is_nan() || r <= 0.0 {
                return Err(fail("cannot find a sample rate: give one".into()));
            }
            r
        }
    };
    let n = ((end - start) * rate + 1e-9).floor() as usize + 1;
    if n < 2 {
        return Err(fail(format!(
            "{:.3} s in common: too short at {rate} Hz",
            end - start
        )));
    }
    let grid: Vec<f64> = (0..n).map(|k| start + k as f64 / rate).collect();
    notes.push(format!(
        "{} resampled: {n} samples at {rate:.3} Hz{} from {start:.6} s to {:.6} s (linear interpolation)",
        log.format.name(),
        if channels.sample_rate_hz.is_some() { "" } else { " (median rate of the first output)" },
        grid[n - 1]
    ));
    notes.extend(all().filter_map(|s| s.note.clone()));
    notes.extend(log.dropped.iter().map(|line| format!("not read: {line}")));
    let to_channels = |chosen: &[(String, String)], series: &[Series]| {
        chosen
            .iter()
            .zip(series)
            .map(|((name, _), s)| {
                Channel::new(name.clone(), interpolate(&s.time, &s.values, &grid))
            })
            .collect::<Vec<_>>()
    };
    let primary = channels
        .primary
        .clone()
        .unwrap_or_else(|| channels.inputs[0].0.clone());
    let record = Record {
        source: log.source.clone(),
        sample_rate_hz: rate,
        primary,
        primary_guessed: channels.primary.is_none() && channels.inputs.len() > 1,
        sweep_band: band,
        inputs: to_channels(&channels.inputs, &inputs),
        outputs: to_channels(&channels.outputs, &outputs),
        references: Vec::new(),
        notes,
        trim_samples: 0,
        measurement_filter: None,
    };
    record.validate().map_err(|e| fail(e.to_string()))?;
    Ok(record)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_names_split_into_topic_instance_and_field() {
        assert_eq!(
            split_channel("vehicle_angular_velocity.xyz[0]"),
            Some(("vehicle_angular_velocity", None, "xyz[0]"))
        );
        assert_eq!(split_channel("IMU[1].GyrX"), Some(("IMU", Some(1), "GyrX")));
        assert_eq!(split_channel("RATE"), None);
        assert_eq!(split_channel("IMU[x].GyrX"), None);
    }

    #[test]
    fn interpolation_is_linear_between_samples_and_exact_on_them() {
        let time = [0.0, 1.0, 3.0];
        let values = [0.0, 10.0, 30.0];
        assert_eq!(
            interpolate(&time, &values, &[0.0, 0.5, 1.0, 2.0, 3.0]),
            [0.0, 5.0, 10.0, 20.0, 30.0]
        );
    }
}
