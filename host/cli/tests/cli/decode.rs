//! `sweephold decode` as a user runs it: output, summary and every error path.

use std::path::PathBuf;
use std::process::Output;

use sweephold_protocol::{codec, synthetic, Event, Frame, ProtocolVersion, PROTOCOL_VERSION};

use crate::support::{sweephold, Scratch};

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("test-{name}")))
    }
    fn file(&self, name: &str, bytes: &[u8]) -> String {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        path.display().to_string()
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

fn encode(frames: &[Frame]) -> Vec<u8> {
    frames
        .iter()
        .flat_map(|f| codec::encode_to_vec(f).unwrap().to_vec())
        .collect()
}

fn good_dump(samples: u32) -> Vec<u8> {
    let mut frames = vec![Frame::Header(synthetic::header())];
    for tick in 0..samples {
        frames.push(Frame::Sample(synthetic::sample(tick)));
    }
    frames.push(Frame::Event(Event::Abort {
        tick: samples,
        reason: sweephold_protocol::AbortReason::PilotOverride,
    }));
    encode(&frames)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// An error is one line starting with `error:`, and the exit status is non-zero.
fn assert_one_line_error(out: &Output, needle: &str) {
    let err = stderr(out);
    assert!(!out.status.success(), "expected failure, stderr: {err}");
    assert_eq!(err.lines().count(), 1, "one line: {err:?}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(needle), "{err:?} should mention {needle:?}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn csv_has_a_header_row_and_one_row_per_sample() {
    let dir = TempDir::new("csv");
    let dump = dir.file("lat-1.bin", &good_dump(400));
    let out = sweephold(&["decode", &dump]);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = String::from_utf8(out.stdout.clone()).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 36);
    assert_eq!(&header[..3], &["tick", "time_s", "phase"]);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 400);
    assert!(rows.iter().all(|r| r.len() == 36));
    // Row 200: tick 200 at 200 Hz is one second after the first Sample.
    assert_eq!(rows[200][0], "200");
    assert_eq!(rows[200][1].parse::<f64>().unwrap(), 1.0);
    assert_eq!(rows[200][2], "sweep");
    let az: f32 = rows[200][35].parse().unwrap();
    assert_eq!(
        az,
        synthetic::sample(200).meas.az,
        "values print round-trip exact"
    );
    let err = stderr(&out);
    assert!(err.contains("402 good frames"), "{err}");
    assert!(err.contains("0 corrupt frames skipped"), "{err}");
    assert!(err.contains("vehicle bo105"), "{err}");
    assert!(
        err.contains(&format!("protocol {PROTOCOL_VERSION}")),
        "{err}"
    );
    assert!(err.contains("duration 1.995 s"), "{err}");
    assert!(
        err.contains("ABORT (pilot_override)"),
        "events listed: {err}"
    );
}

#[test]
fn jsonl_to_a_file_with_events_inline() {
    let dir = TempDir::new("jsonl");
    let dump = dir.file("d.bin", &good_dump(10));
    let out_path = dir.path("out.jsonl");
    let out = sweephold(&[
        "decode",
        "--format",
        "jsonl",
        "-o",
        out_path.to_str().unwrap(),
        &dump,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&out_path).unwrap();
    let values: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(values.len(), 12);
    assert_eq!(values[0]["type"], "header");
    assert_eq!(values[0]["vehicle"], "bo105");
    assert_eq!(values[1]["type"], "sample");
    assert_eq!(values[1]["tick"], 0);
    assert_eq!(values[11]["event"], "abort");
    assert_eq!(values[11]["reason"], "pilot_override");
}

#[test]
fn corrupt_frames_are_skipped_and_counted() {
    let dir = TempDir::new("corrupt");
    let mut bytes = good_dump(100);
    // Flip a bit in the middle of the stream and cut the tail.
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x10;
    bytes.truncate(bytes.len() - 5);
    let dump = dir.file("c.bin", &bytes);
    let out = sweephold(&["decode", &dump]);
    assert!(out.status.success());
    let err = stderr(&out);
    assert!(err.contains("2 corrupt frames skipped"), "{err}");
    assert!(err.contains("1 tick gaps"), "{err}");
}

#[test]
fn missing_file() {
    let out = sweephold(&["decode", "/nonexistent/dump.bin"]);
    assert_one_line_error(&out, "cannot open /nonexistent/dump.bin");
}

#[test]
fn missing_file_among_good_ones_writes_nothing() {
    let dir = TempDir::new("missing2");
    let dump = dir.file("d.bin", &good_dump(10));
    let out_path = dir.path("out.csv");
    let out = sweephold(&[
        "decode",
        "-o",
        out_path.to_str().unwrap(),
        &dump,
        "/nonexistent/x.bin",
    ]);
    assert_one_line_error(&out, "/nonexistent/x.bin");
    assert!(!out_path.exists(), "no partial output created");
}

#[test]
fn empty_file() {
    let dir = TempDir::new("empty");
    let dump = dir.file("e.bin", b"");
    let out = sweephold(&["decode", &dump]);
    assert_one_line_error(&out, "no valid frame");
}

#[test]
fn random_bytes() {
    let dir = TempDir::new("random");
    let mut x = 0x1234_5678_9abc_def0u64;
    let bytes: Vec<u8> = (0..100_000)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect();
    let dump = dir.file("r.bin", &bytes);
    let out = sweephold(&["decode", "--quiet", &dump]);
    assert_one_line_error(&out, "no valid frame");
}

#[test]
fn another_protocol_major_version_is_refused() {
    let dir = TempDir::new("version");
    let mut header = synthetic::header();
    header.protocol = ProtocolVersion {
        major: PROTOCOL_VERSION.major + 1,
        minor: 0,
    };
    let bytes = encode(&[Frame::Header(header), Frame::Sample(synthetic::sample(0))]);
    let dump = dir.file("v.bin", &bytes);
    let out = sweephold(&["decode", &dump]);
    assert_one_line_error(
        &out,
        &format!("protocol version {}.0", PROTOCOL_VERSION.major + 1),
    );
    assert!(stderr(&out).contains(&PROTOCOL_VERSION.to_string()));
}

#[test]
fn help_explains_the_verb() {
    let out = sweephold(&["decode", "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    for needle in ["--format", "csv", "jsonl", "Exit status", "corrupt"] {
        assert!(help.contains(needle), "help mentions {needle}");
    }
}
