//! Tests of the dump reader (`dump.rs`).

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
