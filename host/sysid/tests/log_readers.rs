//! The ULog and DataFlash readers against pyulog and pymavlink on the same files
//! (`tests/fixtures/logs/`, whose README says where each came from; the reference JSON
//! files are written by `make_references.py` there), their behaviour on damaged files,
//! and the SystemID sweep window.

use std::path::PathBuf;

use serde_json::Value;
use sysid::records::{
    self, dataflash, record_from_log, sweep_window, ulog, Log, LogChannels, Values,
};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/logs")
        .join(name)
}

fn reference(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(fixture(name)).unwrap()).unwrap()
}

/// A reference number: JSON numbers, or "nan"/"inf"/"-inf".
fn number(v: &Value) -> f64 {
    match v {
        Value::Number(n) => n.as_f64().unwrap(),
        Value::String(s) => match s.as_str() {
            "nan" => f64::NAN,
            "inf" => f64::INFINITY,
            "-inf" => f64::NEG_INFINITY,
            other => panic!("not a number: {other}"),
        },
        other => panic!("not a number: {other}"),
    }
}

fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

/// Every reference row of every reference field equals the reader's value exactly.
fn compare_rows(topic: &records::Topic, entry: &Value, what: &str) -> usize {
    let index: Vec<usize> = entry["index"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i.as_u64().unwrap() as usize)
        .collect();
    let mut compared = 0;
    for (name, values) in entry["values"].as_object().unwrap() {
        let field = topic
            .field(name)
            .unwrap_or_else(|| panic!("{what}: no field {name}"));
        for (row, expected) in index.iter().zip(values.as_array().unwrap()) {
            match (&field.values, expected) {
                (Values::Text(v), Value::String(s)) => {
                    assert_eq!(&v[*row], s, "{what}.{name} row {row}")
                }
                (Values::Numbers(v), e) => {
                    let e = number(e);
                    assert!(
                        same(v[*row], e),
                        "{what}.{name} row {row}: {} vs {e}",
                        v[*row]
                    );
                }
                (values, e) => panic!("{what}.{name} row {row}: {values:?} vs {e}"),
            }
            compared += 1;
        }
    }
    compared
}

#[test]
fn ulog_values_equal_pyulogs() {
    let log = records::read_log(fixture("sample_log_small.ulg")).unwrap();
    let reference = reference("ulog_reference.json");
    // Every topic instance pyulog found, with as many messages; no other.
    let counts = reference["counts"].as_array().unwrap();
    for entry in counts {
        let (name, multi_id, count) = (
            entry[0].as_str().unwrap(),
            entry[1].as_u64().unwrap() as u8,
            entry[2].as_u64().unwrap() as usize,
        );
        let topic = log
            .topic_instance(name, multi_id)
            .unwrap_or_else(|| panic!("no {name}[{multi_id}]"));
        assert_eq!(topic.len(), count, "{name}[{multi_id}]");
        assert_eq!(topic.time_s.len(), count, "{name}[{multi_id}] time");
    }
    // pyulog lists only the subscriptions that have data.
    let with_data = log.topics.iter().filter(|t| !t.is_empty()).count();
    assert_eq!(with_data, counts.len());
    for (key, value) in reference["info"].as_object().unwrap() {
        let ours = log.info.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        assert_eq!(ours.map(String::as_str), value.as_str(), "info {key}");
    }
    let parameters = reference["parameters"].as_object().unwrap();
    assert!(parameters.len() > 900);
    for (key, value) in parameters {
        let ours = log
            .parameters
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| *v);
        assert_eq!(ours, Some(number(value)), "parameter {key}");
    }
    let mut compared = 0;
    for (key, entry) in reference["topics"].as_object().unwrap() {
        let (name, multi_id) = key.trim_end_matches(']').split_once('[').unwrap();
        let topic = log.topic_instance(name, multi_id.parse().unwrap()).unwrap();
        let fields: Vec<&str> = topic.fields.iter().map(|f| f.name.as_str()).collect();
        let expected: Vec<&str> = entry["fields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        assert_eq!(fields, expected, "{key}: field names and order");
        compared += compare_rows(topic, entry, key);
        // The time axis is the timestamp field in seconds.
        let stamps = topic.numbers("timestamp").unwrap();
        assert!(topic
            .time_s
            .iter()
            .zip(stamps)
            .all(|(t, us)| *t == us / 1e6));
    }
    assert!(compared > 1200, "{compared} values compared");
    // pyulog reports one dropout in this file; so does the reader.
    assert_eq!(log.dropped.len(), 1, "{:?}", log.dropped);
    assert!(log.dropped[0].contains("1 dropouts"), "{:?}", log.dropped);
}

fn compare_dataflash(log: &Log, reference: &Value) -> usize {
    let counts = reference["counts"].as_object().unwrap();
    for (name, count) in counts {
        let topic = log.topic(name).unwrap_or_else(|| panic!("no {name}"));
        assert_eq!(topic.len() as u64, count.as_u64().unwrap(), "{name}");
    }
    for topic in log.topics.iter().filter(|t| !t.is_empty()) {
        assert!(
            counts.contains_key(&topic.name),
            "{} not in pymavlink's",
            topic.name
        );
    }
    let mut compared = 0;
    for (name, entry) in reference["topics"].as_object().unwrap() {
        let topic = log.topic(name).unwrap();
        let mut ours: Vec<&str> = topic.fields.iter().map(|f| f.name.as_str()).collect();
        let mut theirs: Vec<&str> = entry["values"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        ours.sort_unstable();
        theirs.sort_unstable();
        assert_eq!(ours, theirs, "{name}: fields");
        compared += compare_rows(topic, entry, name);
    }
    // Unit labels where no multiplier prefixes them (pymavlink writes `µs` for s × 1e-6).
    for (name, units) in reference["units"].as_object().unwrap() {
        let topic = log.topic(name).unwrap();
        for (field, label) in units.as_object().unwrap() {
            // An `a` column is 32 fields `NAME[i]` here, one list in pymavlink.
            let field = topic
                .field(field)
                .or_else(|| topic.field(&format!("{field}[0]")))
                .unwrap_or_else(|| panic!("{name}.{field}"));
            if field.multiplier.is_none() {
                let label = label.as_str().unwrap();
                let ours = field.unit.as_deref().unwrap_or("");
                let ours = if ours == "UNKNOWN" { "" } else { ours };
                assert!(
                    ours == label || label.is_empty(),
                    "{name}.{}: {ours} vs {label}",
                    field.name
                );
            }
        }
    }
    compared
}

#[test]
fn dataflash_values_equal_pymavlinks() {
    let log = records::read_log(fixture("backend_log_80k.bin")).unwrap();
    let compared = compare_dataflash(&log, &reference("dataflash_reference.json"));
    assert!(compared > 1500, "{compared} values compared");
    // The file is the first 80 KiB of a flight log: it ends inside a message header.
    assert_eq!(
        log.dropped,
        ["byte 81918: last 2 bytes are a cut-off message header"]
    );
    // The instance column of IMU comes from FMTU's `#` unit.
    assert_eq!(
        log.topic("IMU").unwrap().instance_field.as_deref(),
        Some("I")
    );
    assert_eq!(
        log.topic("RATE")
            .unwrap()
            .field("R")
            .unwrap()
            .unit
            .as_deref(),
        Some("deg/s")
    );
}

#[test]
fn the_generated_sysid_log_reads_as_pymavlink_reads_it() {
    let log = records::read_log(fixture("sysid_synthetic.bin")).unwrap();
    compare_dataflash(&log, &reference("sysid_synthetic_reference.json"));
    assert!(log.dropped.is_empty(), "{:?}", log.dropped);
}

#[test]
fn the_systemid_sweeps_are_found_from_sids_and_sidd() {
    let log = records::read_log(fixture("sysid_synthetic.bin")).unwrap();
    let first = sweep_window(&log, None).unwrap().unwrap();
    assert_eq!((first.index, first.count), (1, 2));
    assert_eq!(first.window, [13.02, 25.0]);
    assert_eq!(first.axis, Some(1));
    assert_eq!(first.axis_name(), "input roll (axis 1)");
    let tau = std::f64::consts::TAU;
    assert_eq!(first.band, Some([0.5 * tau, 4.0 * tau]));
    let second = sweep_window(&log, Some(2)).unwrap().unwrap();
    assert_eq!((second.window, second.axis), ([27.02, 34.0], Some(2)));
    let message = sweep_window(&log, Some(3)).unwrap_err().to_string();
    assert!(
        message.ends_with("sweep 3: the log holds 2 SystemID sweep(s)"),
        "{message}"
    );

    let channels = LogChannels {
        inputs: vec![("lat".into(), "RATE.RDes".into())],
        outputs: vec![("p".into(), "RATE.R".into())],
        ..LogChannels::default()
    };
    let record = record_from_log(&log, &channels).unwrap();
    // 13.02–25.00 s at the 50 Hz median rate of RATE: 600 samples.
    assert_eq!(record.sample_rate_hz, 50.0);
    assert_eq!(record.len(), 600);
    assert_eq!(record.sweep_band, first.band);
    assert_eq!(record.primary, "lat");
    assert!(!record.primary_guessed);
    // deg/s → rad/s: the samples are on RATE's own time stamps, so they are the logged
    // values (f32) times π/180.
    let rate = log.topic("RATE").unwrap();
    let k = rate.time_s.iter().position(|t| *t == 13.02).unwrap();
    let logged = rate.numbers("R").unwrap()[k + 100];
    let resampled = record.output("p").unwrap()[100];
    // Equal but for the rounding of the grid time 13.02 + 100/50 against the log's.
    assert!(
        (resampled - logged * std::f64::consts::PI / 180.0).abs() < 1e-12,
        "{resampled} vs {logged} deg/s"
    );
    assert!(
        record.notes.iter().any(|n| n.contains("deg/s → rad/s")),
        "{:?}",
        record.notes
    );
    assert!(
        record.notes[0]
            .starts_with("SystemID sweep 1 of 2: 13.020–25.000 s, axis input roll (axis 1)"),
        "{:?}",
        record.notes
    );
    // A window given overrides the markers; a rate given sets the grid.
    let record = record_from_log(
        &log,
        &LogChannels {
            window: Some([11.0, 12.0]),
            sample_rate_hz: Some(200.0),
            ..channels.clone()
        },
    )
    .unwrap();
    assert_eq!(record.len(), 201);
    assert_eq!(record.sweep_band, None);
}

#[test]
fn ulog_channels_resample_onto_the_median_rate() {
    let log = records::read_log(fixture("sample_log_small.ulg")).unwrap();
    let channels = LogChannels {
        inputs: vec![("lat".into(), "actuator_controls_0.control[0]".into())],
        outputs: vec![
            ("p".into(), "vehicle_angular_velocity.xyz[0]".into()),
            ("q".into(), "vehicle_angular_velocity.xyz[1]".into()),
        ],
        ..LogChannels::default()
    };
    let record = record_from_log(&log, &channels).unwrap();
    let rate = log
        .topic("vehicle_angular_velocity")
        .unwrap()
        .median_rate_hz();
    assert_eq!(record.sample_rate_hz, rate);
    assert!(record.len() > 1000, "{}", record.len());
    // Unknown topics, fields and instances are one-line errors that name them.
    for (spec, expected) in [
        ("nothing.x", "no topic `nothing`"),
        (
            "vehicle_angular_velocity.w",
            "no field `w` in `vehicle_angular_velocity`",
        ),
        (
            "vehicle_angular_velocity[3].xyz[0]",
            "no instance 3 of `vehicle_angular_velocity`",
        ),
        ("xyz", "expected TOPIC.FIELD"),
    ] {
        let bad = LogChannels {
            outputs: vec![("p".into(), spec.into())],
            ..channels.clone()
        };
        let message = record_from_log(&log, &bad).unwrap_err().to_string();
        assert!(message.contains(expected), "{message}");
        assert!(!message.contains('\n'));
    }
}

#[test]
fn dataflash_instances_must_be_named_when_there_are_several() {
    let log = records::read_log(fixture("backend_log_80k.bin")).unwrap();
    let imu = log.topic("IMU").unwrap();
    let ids = imu.numbers("I").unwrap();
    assert!(ids.contains(&0.0) && ids.contains(&1.0));
    let channels = |spec: &str| LogChannels {
        inputs: vec![("lat".into(), "RCOU.C1".into())],
        outputs: vec![("p".into(), spec.into())],
        window: None,
        sample_rate_hz: Some(10.0),
        ..LogChannels::default()
    };
    let message = record_from_log(&log, &channels("IMU.GyrX"))
        .unwrap_err()
        .to_string();
    assert!(message.contains("name one, as `IMU[0].GyrX`"), "{message}");
    let record = record_from_log(&log, &channels("IMU[1].GyrX")).unwrap();
    assert!(record.len() >= 2);
}

/// Cut-off and corrupted copies of the real files: never a panic, only whole messages
/// kept (a prefix of the whole file's, for cuts), what was dropped reported.
#[test]
fn damaged_files_keep_what_is_whole() {
    for (name, step) in [
        ("backend_log_80k.bin", 37usize),
        ("sample_log_small.ulg", 4099),
    ] {
        let bytes = std::fs::read(fixture(name)).unwrap();
        let parse = |b: &[u8]| match records::detect(&bytes).unwrap() {
            records::LogFormat::ULog => ulog::parse(b, name),
            records::LogFormat::DataFlash => dataflash::parse(b, name),
        };
        let whole = parse(&bytes).unwrap();
        for cut in (0..bytes.len()).step_by(step) {
            let Ok(part) = parse(&bytes[..cut]) else {
                assert!(
                    cut < 16 || name.ends_with(".bin") && cut < 3,
                    "{name} cut at {cut}"
                );
                continue;
            };
            for topic in &part.topics {
                let full = whole
                    .topics
                    .iter()
                    .find(|t| t.name == topic.name && t.instance == topic.instance)
                    .unwrap();
                assert!(topic.len() <= full.len());
                assert_eq!(
                    topic.time_s[..],
                    full.time_s[..topic.time_s.len()],
                    "{name} cut at {cut}"
                );
            }
        }
        // Bytes overwritten at pseudo-random places (a fixed xorshift sequence).
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..60 {
            let mut damaged = bytes.clone();
            for _ in 0..8 {
                let at = (next() % bytes.len() as u64) as usize;
                damaged[at] = next() as u8;
            }
            if let Ok(log) = parse(&damaged) {
                let messages: usize = log.topics.iter().map(|t| t.len()).sum();
                assert!(messages > 0 || !log.dropped.is_empty());
            }
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

    /// Any bytes after a valid header: a log or an error, never a panic or a hang.
    #[test]
    fn arbitrary_bytes_after_a_header_never_panic(tail in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..4096)) {
        let mut ulg = ulog::MAGIC.to_vec();
        ulg.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0, 0]);
        ulg.extend_from_slice(&tail);
        let _ = ulog::parse(&ulg, "p.ulg");
        let mut bin = vec![dataflash::HEAD1, dataflash::HEAD2, dataflash::FMT_ID];
        bin.extend_from_slice(&tail);
        let _ = dataflash::parse(&bin, "p.bin");
    }

    /// Random ULog format definitions and data for them: flattened and read without a
    /// panic or a hang, whatever they nest.
    #[test]
    fn arbitrary_ulog_formats_never_panic(
        definitions in proptest::collection::vec("[a-c]:((u?int(8|16|32|64)_t|float|double|bool|char|[a-c])(\\[[0-9]{1,5}\\])? [a-z_]{1,3};){0,4}", 1..5),
        data in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..64),
    ) {
        let mut b = ulog::MAGIC.to_vec();
        b.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0, 0]);
        let mut message = |kind: u8, payload: &[u8]| {
            b.extend_from_slice(&(payload.len() as u16).to_le_bytes());
            b.push(kind);
            b.extend_from_slice(payload);
        };
        for d in &definitions {
            message(b'F', d.as_bytes());
        }
        message(b'A', b"\x00\x01\x00a");
        let mut d = vec![1u8, 0];
        d.extend_from_slice(&data);
        message(b'D', &d);
        let _ = ulog::parse(&b, "p.ulg");
    }
}
