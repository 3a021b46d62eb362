//! `sweephold margins`: the table and margins.json of an identified model, byte-identical
//! on a second run, the model untouched; bad inputs end in one `error:` line.

use crate::support::{control_fixture as fixture, sweephold, Scratch};

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

/// A short loop test flown on board-sim (`fly --input loop`) is measured by `margins
/// --measured` beside the prediction of the identified model: per loop its margins from
/// the measured broken loop, within the 1.5 dB and 10° of the predicted ones; the
/// dumps untouched, the document the same on a second run. A dump of another test and a
/// loop test without board-sim or on the collective end in one `error:` line.
#[test]
fn a_board_sim_loop_test_is_measured_beside_the_prediction() {
    let model = fixture("trex700l-quick-seed1-model9.json");
    let dir = Scratch::new("margins-measured");
    let flown = dir.join("loops");
    let output = sweephold(&[
        "fly",
        "--vehicle",
        "trex700l",
        "--fc",
        "board-sim",
        "--input",
        "loop",
        "--axes",
        "lat,ped",
        "--t-rec",
        "40",
        "--seed",
        "2",
        "--quiet",
        "--out",
        flown.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let dumps = [flown.join("lat-1.bin"), flown.join("ped-1.bin")];
    let before: Vec<Vec<u8>> = dumps.iter().map(|d| std::fs::read(d).unwrap()).collect();
    let (a, b) = (dir.join("a.json"), dir.join("b.json"));
    for out in [&a, &b] {
        let output = sweephold(&[
            "margins",
            model.to_str().unwrap(),
            "--vehicle",
            "trex700l",
            "--samples",
            "0",
            "--measured",
            dumps[0].to_str().unwrap(),
            "--measured",
            dumps[1].to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let table = String::from_utf8(output.stdout).unwrap();
        assert!(
            table.contains("measured (loop tests; ± one standard deviation"),
            "{table}"
        );
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    for (dump, bytes) in dumps.iter().zip(&before) {
        assert_eq!(&std::fs::read(dump).unwrap(), bytes);
    }
    // Nor is a loop test an open-loop record: frf and identify list it and leave it out.
    for verb in [
        &["frf", dumps[0].to_str().unwrap()][..],
        &[
            "identify",
            dumps[0].to_str().unwrap(),
            "--vehicle",
            "trex700l",
            "--out",
            dir.join("identified").to_str().unwrap(),
        ][..],
    ] {
        let output = sweephold(verb);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{verb:?}: {stderr}");
        let why = if verb[0] == "frf" {
            "a loop test: `sweephold margins --measured` reads it"
        } else {
            "only loop tests: nothing to identify"
        };
        assert!(stderr.contains(why), "{verb:?}: {stderr}");
    }
    let document: serde_json::Value = serde_json::from_slice(&std::fs::read(&a).unwrap()).unwrap();
    let measured = document["measured"].as_array().unwrap();
    let names: Vec<&str> = measured
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["roll_attitude", "heading"]);
    for loop_ in measured {
        let name = loop_["name"].as_str().unwrap();
        assert!(loop_["valid_points"].as_u64().unwrap() > 80, "{name}");
        let gm = loop_["gain_margin_difference_db"].as_f64().unwrap();
        let pm = loop_["phase_margin_difference_deg"].as_f64().unwrap();
        assert!(gm.abs() < 1.5 && pm.abs() < 10.0, "{name}: {gm} dB, {pm}°");
        let wc = loop_["crossover_rad_s"].as_f64().unwrap();
        let predicted = loop_["predicted"]["crossover_rad_s"].as_f64().unwrap();
        assert!(
            (wc / predicted - 1.0).abs() < 0.1,
            "{name}: {wc} vs {predicted}"
        );
    }

    // Not a loop test; a loop test the in-process link cannot fly; one on the collective.
    let doublets = dir.join("doublets");
    let output = sweephold(&[
        "fly",
        "--vehicle",
        "trex700l",
        "--input",
        "doublet",
        "--axes",
        "lat",
        "--t-rec",
        "5",
        "--quiet",
        "--out",
        doublets.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let doublet = doublets.join("lat-1.bin");
    let (x, y) = (dir.join("x"), dir.join("y"));
    let cases: [&[&str]; 3] = [
        &[
            "margins",
            model.to_str().unwrap(),
            "--measured",
            doublet.to_str().unwrap(),
        ],
        &[
            "fly",
            "--input",
            "loop",
            "--axes",
            "lat",
            "--out",
            x.to_str().unwrap(),
        ],
        &[
            "fly",
            "--fc",
            "board-sim",
            "--input",
            "loop",
            "--axes",
            "col",
            "--out",
            y.to_str().unwrap(),
        ],
    ];
    for case in cases {
        let output = sweephold(case);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{case:?}: {stderr}");
        assert!(stderr.starts_with("error: "), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
}
