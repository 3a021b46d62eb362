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
use super::origin::DumpOrigin;
use super::record::{Channel, Record};
use super::RecordError;

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
    let record =
        record_from_samples_at(&test.header, &test.samples, test.offset, source, excitation)?;
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
            );
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
    };
    record.validate()?;
    Ok(record)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frf::testing::{dump_bytes, DumpSpec};
    use sweephold_protocol::{Decoder, Frame};

    #[test]
    fn every_test_of_a_concatenation_gives_the_record_of_its_own_file() {
        let lat = DumpSpec::default();
        let lon = DumpSpec {
            primary: sweephold_protocol::Axis::Lon,
            sweep_samples: 500,
            ..DumpSpec::default()
        };
        let dir = std::env::temp_dir().join(format!("sysid-dump-tests-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let both = dir.join("both.dump");
        std::fs::write(&both, [dump_bytes(&lat), dump_bytes(&lon)].concat()).unwrap();
        let (tests, origin) = load_dump_tests(&both, Excitation::Sweep).unwrap();
        assert_eq!(
            origin,
            DumpOrigin::of(&both.display().to_string(), &tests[0].test.header)
        );
        assert_eq!(tests.len(), 2);
        for (test, spec) in tests.iter().zip([&lat, &lon]) {
            let alone = load_dump_bytes(&dump_bytes(spec), "alone").unwrap();
            let record = test.record.as_ref().unwrap();
            assert_eq!(record.primary, spec.primary.name());
            let name = format!("{} test {}", both.display(), test.test.number);
            assert_eq!(
                *record,
                Record {
                    source: name,
                    ..alone
                }
            );
            assert_eq!(test.test.end(), TestEnd::Completed);
        }
        // A file of one test names its record by the file alone.
        let one = dir.join("one.dump");
        std::fs::write(&one, dump_bytes(&lat)).unwrap();
        let (one_test, _) = load_dump_tests(&one, Excitation::Sweep).unwrap();
        let record = one_test[0].record.as_ref().unwrap();
        assert_eq!(record.source, one.display().to_string());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reads_the_excitation_of_a_dump() {
        let spec = DumpSpec::default();
        let bytes = dump_bytes(&spec);
        let record = load_dump_bytes(&bytes, "test.dump").unwrap();
        assert_eq!(record.primary, "lat");
        assert_eq!(record.sample_rate_hz, 100.0);
        assert_eq!(record.len(), spec.sweep_samples);
        // No trim capture in front of this one's excitation.
        assert_eq!(record.trim_samples, 0);
        assert_eq!(record.inputs.len(), 4);
        assert_eq!(record.outputs.len(), 11);
        // References: sweep + noise of each control (the synthetic dump injects 1.5 ×
        // the command).
        assert_eq!(record.references.len(), 4);
        let (lat, reference) = (
            record.input("lat").unwrap(),
            record.reference("lat").unwrap(),
        );
        assert!(lat.iter().any(|&v| v != 0.0));
        for (command, reference) in lat.iter().zip(reference) {
            assert!(
                (reference - 1.5 * command).abs() < 1e-6,
                "{reference} vs {command}"
            );
        }
        let band = record.sweep_band.unwrap();
        assert!((band[0] - 0.5).abs() < 1e-6 && (band[1] - 20.0).abs() < 1e-5);
        // The first excitation sample carries its own tick value in `p` (see DumpSpec).
        assert_eq!(
            record.output("p").unwrap()[0],
            f64::from(spec.first_sweep_tick())
        );
    }

    #[test]
    fn keeps_two_seconds_of_trim_on_either_side() {
        let spec = DumpSpec {
            settle_samples: 300,
            ..DumpSpec::default()
        };
        let record = load_dump_bytes(&dump_bytes(&spec), "settle.dump").unwrap();
        assert_eq!(record.len(), spec.sweep_samples + 2 * 200);
        assert_eq!(record.trim_samples, 200);
        let p = record.output("p").unwrap();
        assert_eq!(p[0], f64::from(spec.first_sweep_tick() - 200));
        assert_eq!(p[200], f64::from(spec.first_sweep_tick()));
        assert!(p.windows(2).all(|w| w[1] - w[0] == 1.0));
    }

    #[test]
    fn fills_lost_ticks() {
        let spec = DumpSpec {
            drop_every: Some(50),
            ..DumpSpec::default()
        };
        let record = load_dump_bytes(&dump_bytes(&spec), "lossy.dump").unwrap();
        assert_eq!(record.len(), spec.sweep_samples);
        assert_eq!(record.notes.len(), 1);
        // `p` carries the tick: interpolation restores it exactly.
        let p = record.output("p").unwrap();
        for pair in p.windows(2) {
            assert!((pair[1] - pair[0] - 1.0).abs() < 1e-3);
        }
    }

    /// `bytes` with every Sample's tick replaced by `tick(index, tick)`, `index` counting
    /// the dump's Samples from 0.
    fn with_ticks(bytes: &[u8], tick: impl Fn(usize, u32) -> u32) -> Vec<u8> {
        let mut out = Vec::new();
        let mut index = 0;
        for frame in Decoder::new().feed(bytes).flatten() {
            let frame = match frame {
                Frame::Sample(mut sample) => {
                    sample.tick = tick(index, sample.tick);
                    index += 1;
                    Frame::Sample(sample)
                }
                other => other,
            };
            let mut buffer = [0u8; sweephold_protocol::MAX_FRAME_LEN];
            let n = sweephold_protocol::encode(&frame, &mut buffer).unwrap();
            out.extend_from_slice(&buffer[..n]);
        }
        out
    }

    #[test]
    fn refuses_ticks_that_step_back() {
        let spec = DumpSpec::default();
        let bytes = dump_bytes(&spec);
        // 30 idle Samples come before the Header; the sweep starts at tick 1030.
        let first = spec.first_sweep_tick();
        assert_eq!(first, 1030);
        // One Sample 60 ticks early: 1032 → 972 at the dump's Sample 33.
        let early = with_ticks(&bytes, |i, t| if i == 33 { t - 60 } else { t });
        for error in [
            load_dump_bytes(&early, "early.bin").unwrap_err(),
            load_dump_bytes_with(&early, "early.bin", Excitation::Any)
                .map(|(r, _)| r)
                .unwrap_err(),
        ] {
            assert_eq!(
                error.to_string(),
                "early.bin: ticks step back at sample 33 (tick 1032 → 973)"
            );
        }
        // A repeated tick is no step forward either.
        let repeat = with_ticks(&bytes, |i, t| if i == 40 { t - 1 } else { t });
        let error = load_dump_bytes(&repeat, "repeat.bin").unwrap_err();
        assert!(
            error
                .to_string()
                .ends_with("at sample 40 (tick 1039 → 1039)"),
            "{error}"
        );
        // Reversed ticks: refused at their first step, not read as 4·10⁹ missing ticks.
        let reversed = with_ticks(&bytes, |i, _| 5000 - i as u32);
        let error = load_dump_bytes(&reversed, "reversed.bin").unwrap_err();
        assert!(
            error
                .to_string()
                .ends_with("at sample 31 (tick 4970 → 4969)"),
            "{error}"
        );
        // A step back outside the record (in the idle Samples before the test) is no
        // business of the record's.
        let idle = with_ticks(&bytes, |i, t| if i == 5 { 1 } else { t });
        assert_eq!(
            load_dump_bytes(&idle, "idle.bin").unwrap().len(),
            spec.sweep_samples
        );
    }

    #[test]
    fn a_tick_counter_wrapping_at_2_pow_32_is_no_step_back() {
        let spec = DumpSpec::default();
        let plain = load_dump_bytes(&dump_bytes(&spec), "plain.bin").unwrap();
        // The counter passes u32::MAX → 0 in the middle of the sweep.
        let shift = u32::MAX - spec.first_sweep_tick() - 300;
        let bytes = with_ticks(&dump_bytes(&spec), |_, t| t.wrapping_add(shift));
        let wrapped = load_dump_bytes(&bytes, "wrapped.bin").unwrap();
        assert_eq!(wrapped.len(), plain.len());
        assert!(wrapped.notes.is_empty(), "{:?}", wrapped.notes);
        assert_eq!(wrapped.input("lat"), plain.input("lat"));
        // Lost ticks across the wrap are filled as anywhere else.
        let lossy = DumpSpec {
            drop_every: Some(50),
            ..DumpSpec::default()
        };
        let bytes = with_ticks(&dump_bytes(&lossy), |_, t| t.wrapping_add(shift));
        let record = load_dump_bytes(&bytes, "lossy.bin").unwrap();
        assert_eq!(record.len(), lossy.sweep_samples);
        assert_eq!(record.notes.len(), 1);
    }

    #[test]
    fn record_from_decoded_samples() {
        let spec = DumpSpec::default();
        let mut decoder = Decoder::new();
        let mut header = None;
        let mut samples = Vec::new();
        for frame in decoder.feed(&dump_bytes(&spec)).flatten() {
            match frame {
                Frame::Header(h) => header = Some(h),
                Frame::Sample(s) => samples.push(s),
                _ => {}
            }
        }
        let header = header.unwrap();
        let record = record_from_samples(&header, &samples, "in-process").unwrap();
        assert_eq!(record.len(), spec.sweep_samples);
        let idle: Vec<Sample> = samples
            .iter()
            .filter(|s| s.phase == Phase::Idle)
            .copied()
            .collect();
        let err = record_from_samples(&header, &idle, "idle").unwrap_err();
        assert!(matches!(err, RecordError::NoSweep { .. }), "{err}");
    }

    #[test]
    fn refuses_dumps_without_a_sweep() {
        let no_sweep = DumpSpec {
            sweep_samples: 0,
            ..DumpSpec::default()
        };
        let err = load_dump_bytes(&dump_bytes(&no_sweep), "idle.dump").unwrap_err();
        assert!(matches!(err, RecordError::NoSweep { .. }), "{err}");
        let headless = DumpSpec {
            with_header: false,
            ..DumpSpec::default()
        };
        let err = load_dump_bytes(&dump_bytes(&headless), "x.dump").unwrap_err();
        assert!(matches!(err, RecordError::NoHeader { .. }), "{err}");
        let err = load_dump_bytes(b"not a dump at all", "junk").unwrap_err();
        assert!(matches!(err, RecordError::NoSweep { .. }), "{err}");
        let doublet = DumpSpec {
            input: sweephold_protocol::InputKind::Doublet,
            ..DumpSpec::default()
        };
        let err = load_dump_bytes(&dump_bytes(&doublet), "d.dump").unwrap_err();
        assert!(err.to_string().contains("not a sweep"), "{err}");
        // Verification replays any excitation: the same doublet loads there, whole.
        let bytes = dump_bytes(&doublet);
        let (swept, _) = load_dump_bytes_with(&bytes, "d.dump", Excitation::Any).unwrap();
        let sweep = load_dump_bytes(&dump_bytes(&DumpSpec::default()), "s.dump").unwrap();
        assert_eq!(swept.len(), sweep.len());
    }
}
