//! `sweephold tune`: the tuned gains and figures written the same twice, the model
//! untouched; a crossover no gains can meet refused in one line naming the loop and the
//! constraint; bad arguments end in one `error:` line.

use crate::support::{control_fixture as fixture, sweephold, Scratch};

#[test]
fn tune_writes_the_same_gains_twice_and_meets_the_margins() {
    let model = fixture("trex700l-quick-seed1-model9.json");
    let before = std::fs::read(&model).unwrap();
    let dir = Scratch::new("tune-twice");
    let (a, b) = (dir.join("a.json"), dir.join("b.json"));
    for out in [&a, &b] {
        let output = sweephold(&[
            "tune",
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
        for name in [
            "roll_rate",
            "pitch_attitude",
            "heading",
            "K_lvl",
            "servo rate",
        ] {
            assert!(table.contains(name), "{table}");
        }
    }
    let (first, second) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(first, second);
    assert_eq!(std::fs::read(&model).unwrap(), before);
    let document: serde_json::Value = serde_json::from_slice(&first).unwrap();
    for check in document["tuned_loops"].as_array().unwrap() {
        assert!(check["violation"].is_null(), "{check}");
        assert!(check["phase_margin_deg"]["percentile"].as_f64().unwrap() >= 45.0);
        let gm = &check["gain_margin_db"]["percentile"];
        assert!(gm.is_null() || gm.as_f64().unwrap() >= 6.0, "{check}");
    }
    // Roll and pitch cross over higher than with the preset's gains.
    for (shipped, tuned) in document["shipped_loops"]
        .as_array()
        .unwrap()
        .iter()
        .zip(document["tuned_loops"].as_array().unwrap())
        .take(2)
    {
        let w = |c: &serde_json::Value| c["crossover_rad_s"]["value"].as_f64().unwrap();
        assert!(w(tuned) > w(shipped), "{tuned}");
    }
}

#[test]
fn tune_refuses_a_crossover_beyond_the_margins_and_bad_arguments() {
    let model = fixture("trex700l-quick-seed1-model9.json");
    let model = model.to_str().unwrap();
    let output = sweephold(&["tune", model, "--samples", "10", "--crossover", "roll=60"]);
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: roll_rate: no gains meet the constraints: "),
        "{stderr}"
    );
    assert!(stderr.contains("crossover 60.00 rad/s"), "{stderr}");
    for (args, expected) in [
        (vec!["--crossover", "tail=3"], "unknown axis `tail`"),
        (vec!["--crossover", "roll=-1"], "rad/s > 0"),
        (
            vec!["--crossover", "roll=3", "--crossover", "roll=4"],
            "given twice",
        ),
    ] {
        let mut all = vec!["tune", model];
        all.extend(args);
        let output = sweephold(&all);
        assert_ne!(output.status.code(), Some(0));
        let stderr = String::from_utf8(output.stderr).unwrap();
        assert!(stderr.contains(expected), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    let missing = sweephold(&["tune", "/nonexistent/model.json"]);
    assert_eq!(missing.status.code(), Some(1));
    let stderr = String::from_utf8(missing.stderr).unwrap();
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}
