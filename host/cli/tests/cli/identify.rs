//! From a board's logs to a model: `verify` on every test of a logger's file, and
//! `sweephold identify` (frequency responses, fits and verification with no simulator)
//! on the records `fly --fc board-sim` writes, joined as a logger's file per power-up.

use crate::support::sweephold;
use std::path::{Path, PathBuf};

fn ok(args: &[&str]) -> (String, String) {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert!(output.status.success(), "{args:?}: {stderr}");
    (String::from_utf8_lossy(&output.stdout).to_string(), stderr)
}

/// The one-line error of a run that must fail with exit status 1.
fn one_line_error(args: &[&str]) -> String {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    stderr
}

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("sweephold-identify-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `fly --fc board-sim -q --out DIR` plus `args`.
fn fly(dir: &Path, args: &[&str]) {
    let mut all = vec!["fly", "--fc", "board-sim", "-q", "--out"];
    all.push(dir.to_str().unwrap());
    all.extend_from_slice(args);
    ok(&all);
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A logger's file: the records `parts` one after the other.
fn concatenate(out: &Path, parts: &[PathBuf]) {
    let bytes: Vec<u8> = parts
        .iter()
        .flat_map(|p| std::fs::read(p).unwrap())
        .collect();
    std::fs::write(out, bytes).unwrap();
}

/// A first-order lag from each cyclic stick to its rate: a model `verify` can replay on
/// any record of the board.
const LAG_MODEL: &str = r#"{"version": 1, "structure": "lag", "description": "",
 "states": ["p", "q"], "controls": ["lat", "lon"], "outputs": ["p", "q"],
 "matrices": {"M": {"rows": 2, "cols": 2, "data": [1.0, 0.0, 0.0, 1.0]},
  "F": {"rows": 2, "cols": 2, "data": [-2.0, 0.0, 0.0, -2.0]},
  "G": {"rows": 2, "cols": 2, "data": [3.0, 0.0, 0.0, 3.0]},
  "H0": {"rows": 2, "cols": 2, "data": [1.0, 0.0, 0.0, 1.0]},
  "H1": {"rows": 2, "cols": 2, "data": [0.0, 0.0, 0.0, 0.0]}},
 "delays": [0.0, 0.0], "parameters": [], "pairs": [], "average_cost": 0.0,
 "correlation": null, "starts": [], "minimum_confirmed": true, "reduction": []}"#;

/// The score tables of a `verify` report, one per record: its heading line and its rows.
fn tables(report: &str) -> Vec<(String, Vec<String>)> {
    let mut found = Vec::new();
    for block in report.split("\n\n").skip(1) {
        let mut lines = block.lines();
        let Some(heading) = lines.next() else {
            continue;
        };
        if !heading.contains(" samples at ") {
            continue;
        }
        let rows = lines
            .skip_while(|l| !l.starts_with("output"))
            .skip(1)
            .map(str::to_string)
            .collect();
        found.push((heading.to_string(), rows));
    }
    found
}

#[test]
fn verify_replays_every_test_of_a_log_and_leaves_out_aborted_ones() {
    let dir = scratch("verify");
    let doublets = dir.join("doublets");
    fly(
        &doublets,
        &["--seed", "2", "--axes", "lat,lon", "--input", "doublet"],
    );
    let aborted = dir.join("aborted");
    fly(
        &aborted,
        &[
            "--seed",
            "1",
            "--axes",
            "ped",
            "--t-rec",
            "30",
            "--rc-loss",
            "15",
        ],
    );
    let model = dir.join("lag.json");
    std::fs::write(&model, LAG_MODEL).unwrap();
    let (lat, lon) = (doublets.join("lat-1.bin"), doublets.join("lon-1.bin"));
    let log = dir.join("log.bin");
    concatenate(&log, &[lat.clone(), aborted.join("ped-1.bin"), lon.clone()]);

    let (report, listing) = ok(&["verify", "--model", s(&model), s(&log)]);
    let (separate, _) = ok(&["verify", "--model", s(&model), s(&lat), s(&lon)]);
    // Each test is listed with what became of it: the aborted sweep left out.
    for (number, what, verdict) in [
        (1, "lat Doublet", "completed: used"),
        (
            2,
            "ped Sweep",
            "aborted: left out (--include-aborted uses it)",
        ),
        (3, "lon Doublet", "completed: used"),
    ] {
        let line = format!("log.bin: test {number}: {what}, ");
        let found = listing.lines().find(|l| l.contains(&line));
        assert!(
            found.is_some_and(|l| l.ends_with(verdict)),
            "{line}\n{listing}"
        );
    }
    // The tests of the file score as the files they came from.
    let (joined, apart) = (tables(&report), tables(&separate));
    assert_eq!(joined.len(), 2, "{report}");
    assert!(
        joined[0].0.starts_with(&format!("{} test 1: ", s(&log))),
        "{report}"
    );
    assert!(
        joined[1].0.starts_with(&format!("{} test 3: ", s(&log))),
        "{report}"
    );
    assert_eq!(
        joined.iter().map(|t| &t.1).collect::<Vec<_>>(),
        apart.iter().map(|t| &t.1).collect::<Vec<_>>()
    );
    let mean = |text: &str| {
        text.lines()
            .last()
            .unwrap()
            .rsplit(' ')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(mean(&report), mean(&separate));

    // --include-aborted replays the aborted test too.
    let (all, _) = ok(&["verify", "--model", s(&model), s(&log), "--include-aborted"]);
    let replayed = tables(&all);
    assert_eq!(replayed.len(), 3, "{all}");
    assert!(replayed[1].0.contains("test 2: "), "{all}");

    // A file of aborted tests only is a one-line error.
    let error = one_line_error(&[
        "verify",
        "--model",
        s(&model),
        s(&aborted.join("ped-1.bin")),
    ]);
    assert!(error.contains("test 1 aborted: left out"), "{error}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A board's power-up as its logger writes it: the TREX 700L's sweeps of every axis
/// (30 s, two each), its doublets (another seed) and a sweep the receiver loss aborted,
/// in one file. The flights' folders stay in `dir`.
fn board_log(dir: &Path) -> PathBuf {
    let sweeps = dir.join("sweeps");
    fly(
        &sweeps,
        &["--vehicle", "trex700l", "--seed", "1", "--t-rec", "30"],
    );
    let doublets = dir.join("doublets");
    let trex_doublets = ["--vehicle", "trex700l", "--seed", "2", "--input", "doublet"];
    fly(&doublets, &trex_doublets);
    let aborted = dir.join("aborted");
    let lost = [
        "--vehicle",
        "trex700l",
        "--axes",
        "lat",
        "--t-rec",
        "30",
        "--rc-loss",
        "15",
    ];
    fly(&aborted, &lost);
    let mut parts: Vec<PathBuf> = Vec::new();
    for n in 1..=2 {
        for axis in ["lat", "lon", "ped", "col"] {
            parts.push(sweeps.join(format!("{axis}-{n}.bin")));
        }
    }
    parts.push(aborted.join("lat-1.bin"));
    for axis in ["lat", "lon", "ped", "col"] {
        parts.push(doublets.join(format!("{axis}-1.bin")));
    }
    let log = dir.join("log.bin");
    concatenate(&log, &parts);
    log
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

fn strings(value: &serde_json::Value) -> Vec<String> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn identify_fits_and_verifies_a_board_log_with_every_test_listed_and_no_truth() {
    let dir = scratch("board");
    let log = board_log(&dir);
    let out = dir.join("identified");
    let (stdout, stderr) = ok(&[
        "identify",
        s(&log),
        "--vehicle",
        "trex700l",
        "--out",
        s(&out),
    ]);
    assert_eq!(stdout, format!("model: {}\n", s(&out.join("model9.json"))));
    for file in [
        "frf.json",
        "model6.json",
        "model9.json",
        "verify.json",
        "margins.json",
        "margins-loops.json",
        "summary.json",
        "report.html",
    ] {
        assert!(out.join(file).is_file(), "{file}\n{stderr}");
    }
    // No loop test in the logs: the predicted margins alone.
    assert!(json(&out.join("margins.json")).get("measured").is_none());
    // No truth: no truth model, no truth section in the model, none in the summary.
    assert!(!out.join("truth-model9.json").exists());
    assert!(json(&out.join("model9.json"))
        .get("truth")
        .is_none_or(|t| t.is_null()));
    let summary = json(&out.join("summary.json"));
    let fit = &summary["fit"];
    assert!(fit["truth_cost_ave"].is_null());
    assert!(fit["truth_modes"].as_array().unwrap().is_empty());
    let params = fit["params"].as_array().unwrap();
    assert!(params.iter().any(|p| p["name"] == "Lb1s"), "{fit}");
    assert!(params
        .iter()
        .all(|p| p["truth"].is_null() && p["error_percent"].is_null()));
    assert_eq!(fit["structure"], "trex700l-9dof-hybrid");
    // Every prior: the servo's ω_n estimated under the aircraft file's 60 rad/s (σ the
    // default 20 %), the other constants held at the file's values.
    let priors = fit["priors"].as_array().unwrap();
    let prior = |name: &str| priors.iter().find(|p| p["name"] == name).unwrap();
    let servo = prior("servo_omega");
    assert_eq!(servo["estimated"], true, "{servo}");
    assert_eq!(servo["constant"], "servo_natural_frequency");
    assert_eq!(
        (servo["file_value"].as_f64(), servo["sigma"].as_f64()),
        (Some(60.0), Some(12.0))
    );
    let (estimate, moved) = (
        servo["estimate"].as_f64().unwrap(),
        servo["moved_sigma"].as_f64().unwrap(),
    );
    assert!((moved - (estimate - 60.0) / 12.0).abs() < 1e-9, "{servo}");
    assert_eq!(servo["warning"], moved.abs() > 3.0);
    let hub = prior("hub_height");
    assert_eq!(hub["estimated"], false);
    assert_eq!(hub["estimate"], hub["file_value"]);
    assert!(
        priors
            .iter()
            .all(|p| p["name"] != "servo_natural_frequency"),
        "listed once"
    );

    // Every test of the file is listed with what became of it; the sweeps give the
    // responses (lat, lon, ped, col), the doublets the verification, the aborted sweep
    // nothing.
    let tests = summary["tests"].as_array().unwrap();
    assert_eq!(tests.len(), 13, "{summary}");
    for (index, test) in tests.iter().enumerate() {
        let line = format!(
            "{}: {}: {}",
            s(&log),
            test["test"].as_str().unwrap(),
            test["verdict"].as_str().unwrap()
        );
        assert!(stderr.contains(&line), "{line}\n{stderr}");
        let aborted = index == 8;
        assert_eq!(test["verdict"] == "used", !aborted, "{test}");
        assert!(test["test"]
            .as_str()
            .unwrap()
            .starts_with(&format!("test {}: ", index + 1)));
    }
    assert!(
        tests[8]["test"].as_str().unwrap().ends_with("aborted"),
        "{}",
        tests[8]
    );
    let name = |n: usize| format!("{} test {n}", s(&log));
    assert_eq!(
        strings(&summary["sweeps"]),
        [1, 5, 2, 6, 3, 7, 4, 8].map(name).to_vec()
    );
    assert_eq!(
        strings(&summary["held_out"]),
        [10, 11, 12, 13].map(name).to_vec()
    );
    assert!(summary["trim_points"].is_null());
    assert!(
        summary["notes"].to_string().contains("no trim points"),
        "{summary}"
    );
    assert!(summary["captured_trim_rad"].is_array(), "{summary}");
    // The board measures no air data: neither responses nor scores of u, v, w.
    let tic = summary["verify"]["tic"].as_object().unwrap();
    let scored: Vec<&str> = tic.keys().map(String::as_str).collect();
    assert_eq!(scored, ["ax", "ay", "az", "p", "q", "r"], "{tic:?}");
    assert!(fit["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| !["u", "v", "w"].contains(&p["output"].as_str().unwrap())));

    // Loop tests in a logger's file of their own (two tests): measured in the margins
    // stage beside the model's predicted loops, as `margins --measured` measures them.
    let loops = dir.join("loops");
    fly(
        &loops,
        &[
            "--vehicle",
            "trex700l",
            "--seed",
            "2",
            "--input",
            "loop",
            "--axes",
            "lat,ped",
            "--t-rec",
            "40",
        ],
    );
    let loop_log = dir.join("loops.bin");
    concatenate(
        &loop_log,
        &[loops.join("lat-1.bin"), loops.join("ped-1.bin")],
    );
    let with_loops = dir.join("with-loops");
    let (_, stderr) = ok(&[
        "identify",
        s(&log),
        s(&loop_log),
        "--vehicle",
        "trex700l",
        "--out",
        s(&with_loops),
    ]);
    assert!(stderr.contains("2 loop tests measured"), "{stderr}");
    let listed = json(&with_loops.join("summary.json"))["tests"].to_string();
    assert!(listed.contains("lat LoopSweep"), "{listed}");
    let document = json(&with_loops.join("margins.json"));
    let measured = document["measured"].as_array().unwrap();
    let named: Vec<(&str, &str)> = measured
        .iter()
        .map(|m| (m["name"].as_str().unwrap(), m["source"].as_str().unwrap()))
        .collect();
    assert_eq!(
        named,
        [
            ("roll_attitude", "loops.bin test 1"),
            ("heading", "loops.bin test 2")
        ]
    );
    for loop_ in measured {
        let gm = loop_["gain_margin_difference_db"].as_f64().unwrap();
        let pm = loop_["phase_margin_difference_deg"].as_f64().unwrap();
        assert!(gm.abs() < 1.5 && pm.abs() < 10.0, "{loop_}");
    }
    // The verb on the same model and loop tests writes the same document.
    let verb = dir.join("verb-margins.json");
    ok(&[
        "margins",
        s(&with_loops.join("model9.json")),
        "--vehicle",
        "trex700l",
        "--samples",
        "60",
        "--measured",
        s(&loop_log),
        "--out",
        s(&verb),
    ]);
    assert_eq!(
        std::fs::read(&verb).unwrap(),
        std::fs::read(with_loops.join("margins.json")).unwrap()
    );
    let report = std::fs::read_to_string(with_loops.join("report.html")).unwrap();
    assert!(report.contains("Measured in the loop tests"));
    assert!(report.contains("loops.bin test 2"));
    // Each measured loop is drawn over its predicted Bode plot, and says so.
    assert!(report.contains("black: measured in the loop test loops.bin test 2"));
    assert!(report.contains("black: measured in the loop test loops.bin test 1"));

    // The same log twice gives the same model, byte for byte.
    let again = dir.join("again");
    ok(&[
        "identify",
        s(&log),
        "--vehicle",
        "trex700l",
        "--out",
        s(&again),
        "-q",
    ]);
    for file in ["frf.json", "model6.json", "model9.json", "verify.json"] {
        assert_eq!(
            std::fs::read(out.join(file)).unwrap(),
            std::fs::read(again.join(file)).unwrap(),
            "{file}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn identify_refuses_bad_inputs_in_one_line_and_keeps_the_previous_results() {
    let dir = scratch("bad");
    let sweeps = dir.join("sweeps");
    fly(
        &sweeps,
        &["--vehicle", "trex700l", "--seed", "3", "--t-rec", "20"],
    );
    let doublets = dir.join("doublets");
    fly(
        &doublets,
        &[
            "--vehicle",
            "trex700l",
            "--axes",
            "lat",
            "--input",
            "doublet",
        ],
    );
    let out = dir.join("out");
    let identify = |inputs: &[&Path], extra: &[&str]| -> Vec<String> {
        let mut args: Vec<String> = vec!["identify".into()];
        args.extend(inputs.iter().map(|p| s(p).to_string()));
        args.extend(["--vehicle", "trex700l", "-q", "--out", s(&out)].map(String::from));
        args.extend(extra.iter().map(|a| a.to_string()));
        args
    };
    let run = |args: Vec<String>| sweephold(&args.iter().map(String::as_str).collect::<Vec<_>>());
    // A folder of dumps: every test of each.
    let done = run(identify(&[&sweeps], &[]));
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let model = std::fs::read(out.join("model9.json")).unwrap();
    let summary = std::fs::read(out.join("summary.json")).unwrap();
    let no_doublet = json(&out.join("summary.json"));
    assert!(no_doublet["verify"].is_null());
    assert!(
        no_doublet["notes"].to_string().contains("not verified"),
        "{no_doublet}"
    );

    let missing = dir.join("missing.bin");
    let garbage = dir.join("garbage.bin");
    std::fs::write(&garbage, [1u8, 2, 3, 0, 7, 7, 0]).unwrap();
    let empty_folder = dir.join("empty");
    std::fs::create_dir_all(&empty_folder).unwrap();
    let bad_points = dir.join("points.csv");
    std::fs::write(&bad_points, "not,trim\npoints\n").unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (identify(&[&missing], &[]), "missing.bin"),
        (identify(&[&garbage], &[]), "garbage.bin"),
        (identify(&[&empty_folder], &[]), "no telemetry dump"),
        // Doublets alone: no sweep to identify from.
        (identify(&[&doublets], &[]), "no completed sweep test"),
        (
            identify(&[&sweeps], &["--trim-points", s(&bad_points)]),
            "points.csv",
        ),
        // Only the pedal's sweeps: the fit has no pair of the cyclic controls, and fails
        // in its stage, after the folder was begun.
        (identify(&[&sweeps.join("ped-1.bin")], &[]), "fit-6dof: "),
    ];
    for (args, expected) in cases {
        let error = one_line_error(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(error.contains(expected), "{args:?}: {error}");
        // The previous results stay as they were.
        assert_eq!(
            std::fs::read(out.join("model9.json")).unwrap(),
            model,
            "{args:?}"
        );
        assert_eq!(
            std::fs::read(out.join("summary.json")).unwrap(),
            summary,
            "{args:?}"
        );
    }
    // The failed stage's files are kept beside, its summary naming the error.
    let failed = json(&dir.join("out.failed").join("summary.json"));
    assert_eq!(failed["error"]["stage"], "fit-6dof", "{failed}");
    // An unknown vehicle is a usage error (exit status 2), in one line.
    let output = sweephold(&[
        "identify",
        s(&sweeps),
        "--vehicle",
        "nope",
        "--out",
        s(&out),
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("nope"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The text of the report's section `id` (from its tag to the next section's).
fn report_section<'a>(report: &'a str, id: &str) -> &'a str {
    let start = report
        .find(&format!("<section id=\"{id}\">"))
        .unwrap_or_else(|| panic!("no section {id}"));
    let end = report[start..]
        .find("</section>")
        .map_or(report.len(), |e| start + e);
    &report[start..end]
}

#[test]
fn identify_writes_a_report_without_truth_that_report_redraws_byte_for_byte() {
    let dir = scratch("report");
    let sweeps = dir.join("sweeps");
    fly(
        &sweeps,
        &["--vehicle", "trex700l", "--seed", "3", "--t-rec", "20"],
    );
    let doublets = dir.join("doublets");
    fly(
        &doublets,
        &[
            "--vehicle",
            "trex700l",
            "--seed",
            "4",
            "--axes",
            "lat,lon",
            "--input",
            "doublet",
        ],
    );
    let out = dir.join("identified");
    let (stdout, _) = ok(&[
        "identify",
        s(&sweeps),
        s(&doublets),
        "--vehicle",
        "trex700l",
        "--out",
        s(&out),
        "-q",
    ]);
    assert_eq!(stdout, format!("model: {}\n", s(&out.join("model9.json"))));
    let written = std::fs::read(out.join("report.html")).unwrap();
    let report = String::from_utf8(written.clone()).unwrap();
    assert!(
        !report.to_lowercase().contains("truth"),
        "the report of an identify folder names a truth"
    );
    assert!(!report.contains("sweephold campaign"));
    // Every test read, with its verdict.
    let summary = report_section(&report, "identify-summary");
    for test in ["lat-1.bin", "col-2.bin"] {
        assert!(
            summary.contains(&s(&sweeps.join(test)).to_string()),
            "{test}"
        );
    }
    assert!(summary.contains(s(&doublets.join("lon-1.bin"))));
    // The parameter table: the key parameters with their Cramér–Rao bounds, and the
    // priors.
    let fitted = json(&out.join("summary.json"));
    let parameters = report_section(&report, "parameters");
    assert!(
        parameters.contains("<th>CR %</th>") && parameters.contains("<th>flags</th>"),
        "{parameters}"
    );
    for name in ["Lb1s", "Mb1c", "tau_f", "servo_omega"] {
        let row = format!("<td class=\"name\">{name}</td>");
        assert!(parameters.contains(&row), "{name}: {parameters}");
    }
    let lb1s = fitted["fit"]["params"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "Lb1s")
        .unwrap();
    let value = format!("<td>{:.5}</td>", lb1s["value"].as_f64().unwrap());
    let cr = format!("<td>{:.2}</td>", lb1s["cr_percent"].as_f64().unwrap());
    assert!(
        parameters.contains(&value) && parameters.contains(&cr),
        "{lb1s}"
    );
    assert!(parameters.contains("<th>moved σ</th>"), "the priors table");
    // A Bode plot of every fitted pair, data and model.
    let bode = report_section(&report, "bode");
    let pairs = fitted["fit"]["pairs"].as_array().unwrap();
    assert!(!pairs.is_empty());
    assert_eq!(
        bode.matches("<svg").count(),
        pairs.len(),
        "one plot per pair"
    );
    assert!(bode.contains("p/lat Bode plot") || bode.contains("p/lat magnitude"));
    // The verification on the held-out doublets: their TIC and time histories.
    let verification = report_section(&report, "verification");
    let records = json(&out.join("verify.json"))["records"]
        .as_array()
        .unwrap()
        .len();
    assert_eq!(records, 2);
    assert_eq!(verification.matches("<svg").count(), records);
    assert!(verification.contains("TIC"), "{verification}");
    // The model's loops (identify's margins stage), with no loop test to measure here.
    let loops = report_section(&report, "loops");
    assert!(loops.contains("Bode"), "{loops}");
    assert!(!loops.contains("Measured in the loop tests"));
    // No campaign section: no flights.
    for campaign_only in ["sweep-input", "cross-coherence", "campaign-summary"] {
        assert!(!report.contains(&format!("<section id=\"{campaign_only}\">")));
    }

    // `report DIR` redraws the same page from the folder alone, and changes nothing else.
    let summary_bytes = std::fs::read(out.join("summary.json")).unwrap();
    std::fs::remove_file(out.join("report.html")).unwrap();
    let (stdout, _) = ok(&["report", s(&out)]);
    assert_eq!(stdout, format!("report: {}\n", s(&out.join("report.html"))));
    assert!(
        std::fs::read(out.join("report.html")).unwrap() == written,
        "report DIR drew another page"
    );
    assert_eq!(
        std::fs::read(out.join("summary.json")).unwrap(),
        summary_bytes
    );
    // An identify summary that does not parse is an error in one line, naming it.
    let broken = dir.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    std::fs::write(broken.join("summary.json"), r#"{"tests": 3}"#).unwrap();
    let error = one_line_error(&["report", s(&broken)]);
    assert!(error.contains("summary.json is corrupt"), "{error}");
    std::fs::remove_dir_all(&dir).ok();
}
