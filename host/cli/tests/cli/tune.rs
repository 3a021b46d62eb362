//! `sweephold tune`: the tuned gains and figures written the same twice, the model
//! untouched; a crossover no gains can meet refused in one line naming the loop and the
//! constraint; bad arguments end in one `error:` line; `--params` a file that `fc params
//! push` loads onto a board-sim board, changing the pilot-mode gains and nothing else.

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
        (vec!["--outer-fraction", "0"], "a fraction > 0 and <= 4"),
        (vec!["--outer-fraction", "nan"], "a fraction > 0 and <= 4"),
        (vec!["--outer-fraction", "5"], "a fraction > 0 and <= 4"),
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

#[test]
fn tune_params_push_to_a_board_and_change_only_the_pilot_mode_gains() {
    let model = fixture("trex700l-quick-seed1-model9.json");
    let dir = Scratch::new("tune-params");
    let (json, params) = (dir.join("tune.json"), dir.join("tuned.toml"));
    let output = sweephold(&[
        "tune",
        model.to_str().unwrap(),
        "--vehicle",
        "trex700l",
        "--samples",
        "0",
        "--out",
        json.to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    // The params file holds the eight tuned gains, each the JSON's value as an f32.
    let document: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let tuned = &document["tuned"];
    let gain = |axis: &str, k: usize| tuned[axis][k].as_f64().unwrap() as f32;
    let expected = [
        ("PM_ROLL_KP", gain("roll", 0)),
        ("PM_ROLL_KI", gain("roll", 1)),
        ("PM_PITCH_KP", gain("pitch", 0)),
        ("PM_PITCH_KI", gain("pitch", 1)),
        ("PM_YAW_KP", gain("yaw", 0)),
        ("PM_YAW_KI", gain("yaw", 1)),
        ("PM_LEVEL_K", tuned["level_gain"].as_f64().unwrap() as f32),
        (
            "PM_HEADING_K",
            tuned["heading_gain"].as_f64().unwrap() as f32,
        ),
    ];
    let text = std::fs::read_to_string(&params).unwrap();
    let file: toml::Table = text.parse().unwrap();
    let values = file["params"].as_table().unwrap();
    assert_eq!(values.len(), expected.len(), "{text}");
    for (name, value) in expected {
        let written = values[name].as_float().unwrap() as f32;
        assert_eq!(written.to_bits(), value.to_bits(), "{name}");
    }
    // A board-sim board set up from the aircraft file, its set pulled; the tuned file
    // pushed and saved: the board's set differs from the pulled one in those eight only.
    let flash = dir.join("board.flash");
    let fc = format!("board-sim:{}", flash.display());
    let run = |args: &[&str]| {
        let output = sweephold(args);
        assert!(
            output.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        String::from_utf8(output.stdout).unwrap()
    };
    let aircraft = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../aircraft/vehicles/trex700l.toml"
    );
    run(&["fc", "params", "push", aircraft, "--save", "--fc", &fc]);
    let before = dir.join("before.toml");
    run(&[
        "fc",
        "params",
        "pull",
        before.to_str().unwrap(),
        "--fc",
        &fc,
    ]);
    run(&[
        "fc",
        "params",
        "push",
        params.to_str().unwrap(),
        "--save",
        "--fc",
        &fc,
    ]);
    let diff = run(&[
        "fc",
        "params",
        "diff",
        before.to_str().unwrap(),
        "--fc",
        &fc,
    ]);
    let mut names: Vec<&str> = diff.lines().filter_map(|l| l.split(':').next()).collect();
    names.sort_unstable();
    let mut expected_names: Vec<&str> = expected.iter().map(|(name, _)| *name).collect();
    expected_names.sort_unstable();
    assert_eq!(names, expected_names, "{diff}");
    // Each line shows the tuned value on the board.
    for (name, value) in expected {
        assert!(
            diff.contains(&format!("{name}: board {value} file")),
            "{name} {value}: {diff}"
        );
    }
}

#[test]
fn tune_params_refuses_the_model_or_the_json_as_its_file() {
    let model = fixture("trex700l-quick-seed1-model9.json");
    let dir = Scratch::new("tune-params-refused");
    let json = dir.join("tune.json");
    for (params, expected) in [
        (model.to_str().unwrap(), "one of the inputs"),
        (json.to_str().unwrap(), "--params"),
    ] {
        let output = sweephold(&[
            "tune",
            model.to_str().unwrap(),
            "--samples",
            "0",
            "--out",
            json.to_str().unwrap(),
            "--params",
            params,
        ]);
        assert_eq!(output.status.code(), Some(1));
        let stderr = String::from_utf8(output.stderr).unwrap();
        assert!(stderr.starts_with("error: --params"), "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
    assert!(!json.exists());
}
