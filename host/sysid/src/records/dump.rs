//! Records from telemetry dumps.
//!
//! The excitation record of a dump is every Sample whose phase is fade-in, sweep or
//! fade-out, of the first test (Header) that has any ([`load_dump`]; every test's, each
//! on its own: [`load_dump_tests`], the tests split by [`super::dump_tests`]), plus up to [`SETTLE_S`] of trim
//! on either side. Inputs are the applied commands
//! `lat lon ped col`; outputs are `u v w p q r ax ay az phi theta`; the references are
//! what the firmware injected into each control (`sweep` + `noise`). The rate and the
//! swept axis come from the Header, the sweep band from its ω_min..ω_max. Ticks lost in
//! transmission are filled by linear interpolation (and noted); a record missing more
//! than 10 % of its ticks is refused, and so is one whose ticks step back (a tick not
//! after the previous Sample's, see [`sweephold_protocol::tick_step`]; a wrap of the
//! counter at 2³² is a step forward).

use std::path::Path;

use sweephold_protocol::{tick_step, Header, Phase, Sample, TickStep};

#[cfg(test)]
use super::dump_tests::TestEnd;
use super::dump_tests::{is_excitation, split_tests, TestRecord};
use super::error::RecordError;
use super::measurement_filter::MeasurementFilter;
use super::origin::DumpOrigin;
use super::record::{Channel, Record};

/// Names of the dump's input channels, in wire order.
pub const DUMP_INPUTS: [&str; 4] = ["lat", "lon", "ped", "col"];

/// Names of the dump's output channels.
pub const DUMP_OUTPUTS: [&str; 11] = [
    "u", "v", "w", "p", "q", "r", "ax", "ay", "az", "phi", "theta",
];

/// Largest fraction of missing ticks that is filled rather than refused.
const MAX_MISSING_FRACTION: f64 = 0.1;

/// Load the excitation record of a telemetry dump file.
pub fn load_dump(path: impl AsRef<Path>) -> Result<Record, RecordError> {
    load_dump_with(path, Excitation::Sweep)
}

/// Like [`load_dump`], but the test may be any excitation (sweep, doublet, 3-2-1-1): the
/// records time-domain verification replays.
pub fn load_test_dump(path: impl AsRef<Path>) -> Result<Record, RecordError> {
    load_dump_with(path, Excitation::Any)
}

/// Which tests a loader accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Excitation {
    /// Frequency sweeps only (frequency responses need one).
    Sweep,
    /// Any input the firmware flies.
    Any,
}

/// Like [`load_dump`], with what the record's Header says about where it came from: the
/// vehicle, protocol version and rate that [`check_one_origin`](super::origin::check_one_origin)
/// compares before dumps are joined.
pub fn load_dump_with_origin(path: impl AsRef<Path>) -> Result<(Record, DumpOrigin), RecordError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|error| RecordError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let source = path.display().to_string();
    let (record, header) = load_dump_bytes_with(&bytes, &source, Excitation::Sweep)?;
    Ok((record, DumpOrigin::of(&source, &header)))
}

fn load_dump_with(path: impl AsRef<Path>, excitation: Excitation) -> Result<Record, RecordError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|error| RecordError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    load_dump_bytes_with(&bytes, &path.display().to_string(), excitation).map(|(r, _)| r)
}

/// The commands `lat lon ped col`, then the excitation injected into each (sweep +
/// off-axis noise): the reference channels.
fn input_row(sample: &Sample) -> [f64; 8] {
    let command = sample.command.to_array();
    let sweep = sample.sweep.to_array();
    let noise = sample.noise.to_array();
    let mut row = [0.0; 8];
    for i in 0..4 {
        row[i] = f64::from(command[i]);
        row[4 + i] = f64::from(sweep[i]) + f64::from(noise[i]);
    }
    row
}

fn outputs_of(sample: &Sample) -> [f64; 11] {
    let m = &sample.meas;
    [
        m.u, m.v, m.w, m.p, m.q, m.r, m.ax, m.ay, m.az, m.phi, m.theta,
    ]
    .map(f64::from)
}

/// Seconds of trim kept on either side of the excitation: contiguous trim-capture
/// samples before the fade-in and done samples after the fade-out (the commands there are
/// the pilot's sticks passed through, so inputs and outputs still match). Windows that
/// cover the first and last seconds of the sweep — where it passes ω_min and ω_max —
/// then see that data with both halves of their taper; without it the band edges are
/// biased by a few degrees.
pub const SETTLE_S: f64 = 2.0;

/// Load the excitation record from the bytes of a dump; `source` names it in messages.
pub fn load_dump_bytes(bytes: &[u8], source: &str) -> Result<Record, RecordError> {
    load_dump_bytes_with(bytes, source, Excitation::Sweep).map(|(record, _)| record)
}

/// The record and the Header of its test: the first test (Header) with excitation.
fn load_dump_bytes_with(
    bytes: &[u8],
    source: &str,
    excitation: Excitation,
) -> Result<(Record, Header), RecordError> {
    let split = split_tests(bytes, source)?;
    let chosen = split
        .tests
        .iter()
        .find(|test| test.samples.iter().any(|s| is_excitation(s.phase)));
    let Some(test) = chosen else {
        return Err(split.no_record_error(source));
    };
    let mut record =
        record_from_samples_at(&test.header, &test.samples, test.offset, source, excitation)?;
    record.measurement_filter = test
        .measurement_filter
        .as_ref()
        .map(MeasurementFilter::of_imu);
    Ok((record, test.header))
}

/// Every test of the dump file `path` ([`split_tests`]) with its record of an `excitation`
/// test, and its first Header's origin; no valid frame or Header is an error ([`load_dump`]).
pub fn load_dump_tests(
    path: impl AsRef<Path>,
    excitation: Excitation,
) -> Result<(Vec<TestRecord>, DumpOrigin), RecordError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|error| RecordError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let file = path.display().to_string();
    let split = split_tests(&bytes, &file)?;
    let Some(first) = split.tests.first() else {
        return Err(split.no_record_error(&file));
    };
    let origin = DumpOrigin::of(&file, &first.header);
    let several = split.tests.len() > 1;
    let tests = split
        .tests
        .into_iter()
        .map(|test| {
            let source = if several {
                format!("{file} test {}", test.number)
            } else {
                file.clone()
            };
            let record = record_from_samples_at(
                &test.header,
                &test.samples,
                test.offset,
                &source,
                excitation,
            )
            .map(|mut record| {
                record.measurement_filter = test
                    .measurement_filter
                    .as_ref()
                    .map(MeasurementFilter::of_imu);
                record
            });
            TestRecord { test, record }
        })
        .collect();
    Ok((tests, origin))
}

/// The excitation record of one test from its Header and its Samples in stream order
/// (for callers that hold decoded frames, e.g. a campaign flown in-process): the samples
/// in the fade-in, sweep and fade-out phases plus up to [`SETTLE_S`] of trim either side,
/// with lost ticks filled. `source` names the record in messages.
pub fn record_from_samples(
    header: &Header,
    all: &[Sample],
    source: &str,
) -> Result<Record, RecordError> {
    record_from_samples_at(header, all, 0, source, Excitation::Sweep)
}

/// Like [`record_from_samples`] for any excitation (doublet, 3-2-1-1 or sweep): the
/// records time-domain verification replays.
pub fn test_record_from_samples(
    header: &Header,
    all: &[Sample],
    source: &str,
) -> Result<Record, RecordError> {
    record_from_samples_at(header, all, 0, source, Excitation::Any)
}

/// The first step back of `samples`: its index in `samples` and the two ticks.
fn first_step_back(samples: &[Sample]) -> Option<(usize, u32, u32)> {
    samples
        .windows(2)
        .position(|pair| tick_step(pair[0].tick, pair[1].tick) == TickStep::Back)
        .map(|at| (at + 1, samples[at].tick, samples[at + 1].tick))
}

/// `all[0]` is the dump's Sample number `offset` (0-based), for messages.
fn record_from_samples_at(
    header: &Header,
    all: &[Sample],
    offset: usize,
    source: &str,
    excitation: Excitation,
) -> Result<Record, RecordError> {
    let Some(first) = all.iter().position(|s| is_excitation(s.phase)) else {
        return Err(RecordError::NoSweep {
            path: source.into(),
            detail: "no Sample in the fade-in, sweep or fade-out phases".into(),
        });
    };
    let last = all
        .iter()
        .rposition(|s| is_excitation(s.phase))
        .unwrap_or(0);
    let settle = (SETTLE_S * f64::from(header.rate_hz)).round() as usize;
    let before = all[..first]
        .iter()
        .rev()
        .take(settle)
        .take_while(|s| s.phase == Phase::TrimCapture)
        .count();
    let after = all[last + 1..]
        .iter()
        .take(settle)
        .take_while(|s| s.phase == Phase::Done)
        .count();
    let samples = &all[first - before..=last + after];
    let test = header.test;
    if excitation == Excitation::Sweep && !test.input.is_sweep() {
        return Err(RecordError::NoSweep {
            path: source.into(),
            detail: format!("the test is a {:?}, not a sweep", test.input),
        });
    }
    if header.rate_hz == 0 {
        return Err(RecordError::InvalidRecord {
            record: source.into(),
            message: "Header rate is 0 Hz".into(),
        });
    }

    // A tick that does not move forward cannot be put on the time grid: refuse the record
    // rather than drop samples (or read a step back as ~4·10⁹ missing ticks).
    if let Some((at, before_tick, tick)) = first_step_back(samples) {
        let index = offset + (first - before) + at;
        return Err(RecordError::InvalidRecord {
            record: source.into(),
            message: format!("ticks step back at sample {index} (tick {before_tick} → {tick})"),
        });
    }
    // Every step moves forward by less than 2³¹: the span is their sum (+1).
    let span = samples
        .windows(2)
        .map(|pair| u64::from(pair[1].tick.wrapping_sub(pair[0].tick)))
        .sum::<u64>()
        .saturating_add(1);
    let span = usize::try_from(span).unwrap_or(usize::MAX);
    let missing = span.saturating_sub(samples.len());
    if missing as f64 > MAX_MISSING_FRACTION * span as f64 {
        return Err(RecordError::InvalidRecord {
            record: source.into(),
            message: format!("{missing} of {span} sweep ticks are missing"),
        });
    }

    // Rows on the tick grid, with gaps filled by linear interpolation. Each input row is
    // the four commands followed by the four references (sweep + noise injected).
    let mut inputs: Vec<Vec<f64>> = (0..8).map(|_| Vec::with_capacity(span)).collect();
    let mut outputs: Vec<Vec<f64>> = (0..11).map(|_| Vec::with_capacity(span)).collect();
    let mut previous: Option<(u32, [f64; 8], [f64; 11])> = None;
    for sample in samples {
        let row = input_row(sample);
        let output = outputs_of(sample);
        if let Some((tick, last_in, last_out)) = previous {
            // Forward: steps back were refused above.
            let step = sample.tick.wrapping_sub(tick);
            for k in 1..step {
                let t = f64::from(k) / f64::from(step);
                for (channel, (&a, &b)) in inputs.iter_mut().zip(last_in.iter().zip(&row)) {
                    channel.push(a + t * (b - a));
                }
                for (channel, (&a, &b)) in outputs.iter_mut().zip(last_out.iter().zip(&output)) {
                    channel.push(a + t * (b - a));
                }
            }
        }
        for (channel, &v) in inputs.iter_mut().zip(&row) {
            channel.push(v);
        }
        for (channel, &v) in outputs.iter_mut().zip(&output) {
            channel.push(v);
        }
        previous = Some((sample.tick, row, output));
    }
    let references = inputs.split_off(4);
    // The trim-capture samples in front of the excitation, counted on the tick grid (lost
    // ticks among them are filled like any others).
    let trim_samples = samples[before].tick.wrapping_sub(samples[0].tick) as usize;

    let mut notes = Vec::new();
    if missing > 0 {
        notes.push(format!(
            "{source}: {missing} missing ticks filled by linear interpolation"
        ));
    }
    let record = Record {
        source: source.into(),
        sample_rate_hz: f64::from(header.rate_hz),
        primary: test.primary.name().to_string(),
        primary_guessed: false,
        sweep_band: Some([
            f64::from(test.sweep.omega_min),
            f64::from(test.sweep.omega_max),
        ]),
        inputs: DUMP_INPUTS
            .iter()
            .zip(inputs)
            .map(|(name, values)| Channel::new(*name, values))
            .collect(),
        outputs: DUMP_OUTPUTS
            .iter()
            .zip(outputs)
            .map(|(name, values)| Channel::new(*name, values))
            .collect(),
        references: DUMP_INPUTS
            .iter()
            .zip(references)
            .map(|(name, values)| Channel::new(*name, values))
            .collect(),
        notes,
        trim_samples,
        measurement_filter: None,
    };
    record.validate()?;
    Ok(record)
}

#[cfg(test)]
#[path = "dump_reader_tests.rs"]
mod tests;
