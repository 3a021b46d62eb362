//! `sweephold decode` and `sweephold frf` on other tools' flight logs: a real PX4 ULog, a
//! real ArduCopter DataFlash log and a generated DataFlash log with SystemID sweeps
//! (`host/sysid/tests/fixtures/logs/`, whose README says where each came from).

use std::path::{Path, PathBuf};

use sysid::document::FrfDocument;

use crate::support::{sweephold, Scratch};

fn fixture(name: &str) -> String {
    format!(
        "{}/../sysid/tests/fixtures/logs/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("logs-{name}")))
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

fn arg(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn decode_lists_a_logs_topics_and_writes_one_as_csv() {
    let ulg = fixture("sample_log_small.ulg");
    let out = sweephold(&["decode", &ulg]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let listing = text(&out.stdout);
    let lines: Vec<&str> = listing.lines().collect();
    assert_eq!(lines[0], "topic,messages,rate_hz,start_s,end_s,fields");
    // pyulog finds 70 topic instances with data in this file (ulog_reference.json).
    assert_eq!(lines.len(), 1 + 70);
    assert!(lines
        .iter()
        .any(|l| l.starts_with("vehicle_angular_velocity,1812,")));
    assert!(lines.iter().any(|l| l.starts_with("vehicle_imu[2],12,")));
    assert!(text(&out.stderr).contains("PX4 ULog, 921631 bytes, 70 topics with messages"));

    // One DataFlash type as CSV, written atomically to a file.
    let dir = TempDir::new("decode");
    let csv = dir.path("rate.csv");
    let bin = fixture("backend_log_80k.bin");
    let out = sweephold(&["decode", &bin, "--topic", "RATE", "-o", arg(&csv), "-q"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let rows = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = rows.lines().collect();
    assert_eq!(
        rows[0],
        "time_s,TimeUS,RDes,R,ROut,PDes,P,POut,YDes,Y,YOut,ADes,A,AOut,AOutSlew"
    );
    // pymavlink reads 5 RATE messages, the first at TimeUS 140184892 with R
    // 0.09067144989967346 (dataflash_reference.json).
    assert_eq!(rows.len(), 1 + 5);
    assert!(
        rows[1].starts_with("140.184892,140184892,17.30408477783203,0.09067144989967346,"),
        "{}",
        rows[1]
    );

    // Errors: one line, non-zero exit, nothing written.
    let missing = dir.path("none.csv");
    for (args, expected) in [
        (
            vec!["decode", &ulg, "--topic", "nope", "-o", arg(&missing)],
            "no topic `nope`",
        ),
        (vec!["decode", &ulg, &bin], "a flight log is decoded alone"),
        (vec!["decode", &bin, "--topic", "IMU[1]"], "use --topic IMU"),
        (vec!["decode", &ulg, "-o", &ulg], "--output"),
    ] {
        let out = sweephold(&args);
        assert!(!out.status.success());
        let message = text(&out.stderr);
        assert!(
            message.starts_with("error: ") && message.contains(expected),
            "{message}"
        );
        assert_eq!(message.trim_end().lines().count(), 1, "{message}");
    }
    assert!(!missing.exists());
}

#[test]
fn frf_reads_the_systemid_sweep_of_a_dataflash_log() {
    let dir = TempDir::new("frf");
    let out_json = dir.path("frf.json");
    let bin = fixture("sysid_synthetic.bin");
    let out = sweephold(&[
        "frf",
        &bin,
        "--inputs",
        "lat=RATE.RDes",
        "--outputs",
        "p=RATE.R",
        "--out",
        arg(&out_json),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let summary = text(&out.stderr);
    assert!(summary.contains("SystemID sweep 1 of 2: 13.020–25.000 s, axis input roll (axis 1), band 3.142–25.133 rad/s (SIDS)"), "{summary}");
    let document: FrfDocument =
        serde_json::from_str(&std::fs::read_to_string(&out_json).unwrap()).unwrap();
    let pair = document.pair("lat", "p").unwrap();
    // The generator's R is RDes through R[k] = 0.8·R[k−1] + 0.2·RDes[k] at 50 Hz:
    // H(z) = 0.2 / (1 − 0.8 z⁻¹). Compare over the valid range.
    let [lo, hi] = pair.valid_range.expect("a valid range");
    let mut errors_db = Vec::new();
    let mut errors_deg = Vec::new();
    for (k, w) in pair
        .omega
        .iter()
        .enumerate()
        .filter(|(_, w)| **w >= lo && **w <= hi)
    {
        // 1 − 0.8 e^(−jθ), θ = ω/50.
        let (re, im) = (1.0 - 0.8 * (w / 50.0).cos(), 0.8 * (w / 50.0).sin());
        let magnitude = 0.2 / re.hypot(im);
        errors_db.push((pair.mag_db[k] - 20.0 * magnitude.log10()).abs());
        let mut d = pair.phase_deg[k] + im.atan2(re).to_degrees();
        d -= 360.0 * (d / 360.0).round();
        errors_deg.push(d.abs());
    }
    errors_db.sort_by(f64::total_cmp);
    errors_deg.sort_by(f64::total_cmp);
    let (db, deg) = (
        errors_db[errors_db.len() / 2],
        errors_deg[errors_deg.len() / 2],
    );
    assert!(errors_db.len() > 100, "{} valid points", errors_db.len());
    assert!(db < 0.1 && deg < 1.0, "median error {db} dB, {deg}°");

    // The second sweep, a window and a rate given, and the errors a user meets.
    let out = sweephold(&[
        "frf",
        &bin,
        "--inputs",
        "lat=RATE.RDes",
        "--outputs",
        "p=RATE.R",
        "--out",
        arg(&out_json),
        "--log-sweep",
        "3",
    ]);
    let message = text(&out.stderr);
    assert!(
        message.contains("sweep 3: the log holds 2 SystemID sweep(s)"),
        "{message}"
    );
    let out = sweephold(&["frf", &bin, "--out", arg(&out_json)]);
    let message = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        message.contains("channels of a ArduPilot DataFlash log are NAME=TOPIC.FIELD"),
        "{message}"
    );
    assert_eq!(message.trim_end().lines().count(), 1, "{message}");
}

#[test]
fn frf_reads_a_ulog_with_instances_and_a_window() {
    let dir = TempDir::new("frf-ulog");
    let out_json = dir.path("frf.json");
    let ulg = fixture("sample_log_small.ulg");
    // No sweep in this log: the point is the reading, so a band is given.
    let out = sweephold(&[
        "frf",
        &ulg,
        "--inputs",
        "lat=actuator_controls_0.control[0]",
        "--outputs",
        "p=vehicle_angular_velocity.xyz[0]",
        "--band",
        "5,100",
        "--log-window",
        "20.5,26.5",
        "--log-rate",
        "200",
        "--out",
        arg(&out_json),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let summary = text(&out.stderr);
    assert!(
        summary.contains(
            "PX4 ULog resampled: 1201 samples at 200.000 Hz from 20.500000 s to 26.500000 s"
        ),
        "{summary}"
    );
    assert!(
        summary.contains("not read: the logger reported 1 dropouts"),
        "{summary}"
    );
}
