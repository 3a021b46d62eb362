//! `sweephold margins`: the table and margins.json of an identified model, byte-identical
//! on a second run, the model untouched; bad inputs end in one `error:` line.

use std::path::PathBuf;

use crate::support::{sweephold, Scratch};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../control/tests/fixtures/{name}"))
}

#[test]
fn margins_writes_the_table_and_the_same_json_twice() {
    let model = fixture("trex700l-quick-seed1-model9.json");
    let before = std::fs::read(&model).unwrap();
    let dir = Scratch::new("margins-twice");
    let (a, b) = (dir.join("a.json"), dir.join("b.json"));
    for out in [&a, &b] {
        let output = sweephold(&[
            "margins",
            model.to_str().unwrap(),
            "--vehicle",
            "trex700l",
            "--samples",
            "20",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let table = String::from_utf8(output.stdout).unwrap();
        for name in ["roll_rate", "pitch_attitude", "heading", "wBW"] {
            assert!(table.contains(name), "{table}");
        }
    }
    let (first, second) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(first, second);
    assert_eq!(std::fs::read(&model).unwrap(), before);
    let document: serde_json::Value = serde_json::from_slice(&first).unwrap();
    assert_eq!(document["loops"].as_array().unwrap().len(), 6);
    assert_eq!(document["handling"].as_array().unwrap().len(), 5);
    let heading = &document["loops"][5];
    assert_eq!(heading["name"], "heading");
    assert!(heading["phase_margin_deg"]["spread"].as_f64().unwrap() > 0.0);
    assert_eq!(heading["phase_margin_deg"]["defined_in"], 20);
}

#[test]
fn bad_inputs_end_in_one_error_line() {
    let dir = Scratch::new("margins-bad");
    let not_json = dir.join("not-a-model.json");
    std::fs::write(&not_json, "{\"version\": 1}").unwrap();
    let model = fixture("bo105-quick-seed1-model9.json");
    let cases: Vec<Vec<String>> = vec![
        vec!["margins".into(), "/nonexistent/model.json".into()],
        vec!["margins".into(), not_json.to_str().unwrap().into()],
        vec![
            "margins".into(),
            model.to_str().unwrap().into(),
            "--out".into(),
            model.to_str().unwrap().into(),
        ],
    ];
    for case in cases {
        let args: Vec<&str> = case.iter().map(String::as_str).collect();
        let output = sweephold(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.starts_with("error: "), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
}

#[test]
fn a_servo_frame_rate_that_is_not_positive_is_refused_with_its_range() {
    for bad in ["0", "-50", "nan", "inf", "fast"] {
        let output = sweephold(&["margins", "missing.json", "--servo-frame-hz", bad]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{bad}: {stderr}");
        assert!(
            stderr.contains("expected a frequency in Hz > 0"),
            "{stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
}
