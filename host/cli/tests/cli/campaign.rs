//! `sweephold campaign --quick` end to end through the binary: summary.json's documented
//! keys and types, one <svg> per plot section of report.html, `sweephold report DIR`
//! regenerating the same structure, and one-line stage errors with a non-zero exit.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;
use sweephold::artifacts::stage::Stage;

use crate::support::{sweephold, Scratch};

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("campaign-{name}"))
}

fn number(value: &Value, what: &str) -> f64 {
    value
        .as_f64()
        .unwrap_or_else(|| panic!("{what} is not a number: {value}"))
}

fn optional_number(value: &Value, what: &str) {
    assert!(
        value.is_null() || value.is_f64() || value.is_i64(),
        "{what}: {value}"
    );
}

fn string<'a>(value: &'a Value, what: &str) -> &'a str {
    value
        .as_str()
        .unwrap_or_else(|| panic!("{what} is not a string: {value}"))
}

/// Each `<section id=…>` of the page with its number of `<svg>` elements.
fn structure(html: &str) -> Vec<(String, usize)> {
    html.split("<section id=\"")
        .skip(1)
        .map(|part| {
            let id = part.split('"').next().unwrap_or_default().to_string();
            let body = part.split("</section>").next().unwrap_or_default();
            (id, body.matches("<svg").count())
        })
        .collect()
}

fn one_line_failure(output: &Output) -> String {
    assert!(!output.status.success(), "expected a failure");
    let stderr = String::from_utf8_lossy(&output.stderr).trim().to_string();
    assert_eq!(stderr.lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    stderr
}

fn check_summary(dir: &Path) -> Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let summary: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(string(&summary["vehicle"], "vehicle"), "bo105");
    assert_eq!(summary["seed"].as_u64(), Some(3));
    assert!(summary["error"].is_null(), "{}", summary["error"]);
    for mode in ["cah", "standard", "noise"] {
        let m = &summary["modes"][mode];
        let coherence = number(&m["cross_coherence_lat_lon"], "cross_coherence_lat_lon");
        assert!((0.0..=1.0).contains(&coherence), "{mode}: {coherence}");
        for angle in ["phi", "theta"] {
            let deg = number(&m["max_abs_deg"][angle], angle);
            assert!(deg > 0.0 && deg < 90.0, "{mode} {angle}: {deg}");
            // Every record captured a trim: the excursion from it is there too.
            let from_trim = number(&m["max_from_trim_deg"][angle], angle);
            assert!(
                from_trim > 0.0 && from_trim < 90.0,
                "{mode} {angle} from trim: {from_trim}"
            );
        }
        assert!(m["aborts"].is_u64(), "{mode} aborts: {}", m["aborts"]);
    }
    // The relation the paper is about, even on short records: the standard hold
    // correlates the controls far more than conditional hold.
    assert!(
        number(
            &summary["modes"]["standard"]["cross_coherence_lat_lon"],
            "standard"
        ) > number(&summary["modes"]["cah"]["cross_coherence_lat_lon"], "cah") + 0.2
    );

    let fit = &summary["fit"];
    assert!(string(&fit["structure"], "structure").contains("9dof"));
    assert!(number(&fit["cost_ave"], "cost_ave") >= 0.0);
    let pairs = fit["pairs"].as_array().expect("pairs");
    assert!(!pairs.is_empty());
    for pair in pairs {
        string(&pair["output"], "output");
        string(&pair["input"], "input");
        assert!(number(&pair["cost"], "cost") >= 0.0);
        let range = pair["range"].as_array().expect("range");
        assert_eq!(range.len(), 2);
        assert!(number(&range[0], "lo") < number(&range[1], "hi"));
    }
    let params = fit["params"].as_array().expect("params");
    assert!(params.iter().any(|p| p["name"] == "tau_f"));
    for param in params {
        string(&param["name"], "name");
        number(&param["value"], "value");
        for key in [
            "cr_percent",
            "insensitivity_percent",
            "truth",
            "error_percent",
        ] {
            assert!(param.get(key).is_some(), "{key} missing");
            optional_number(&param[key], key);
        }
    }
    assert!(
        params.iter().any(|p| p["truth"].is_f64()),
        "no truth values"
    );

    // The identified modes, each paired with a truth mode (the same structure: as many
    // modes on both sides unless a pair split), and the hover-mode score.
    let modes = fit["modes"].as_array().expect("fit.modes");
    assert!(!modes.is_empty());
    for mode in modes {
        string(&mode["name"], "mode name");
        let eigenvalue = mode["eigenvalue"].as_array().expect("eigenvalue");
        assert_eq!(eigenvalue.len(), 2);
        assert!(number(&eigenvalue[1], "Im λ") >= 0.0);
        for key in [
            "omega_n",
            "zeta",
            "time_to_double_s",
            "time_to_half_s",
            "error_percent",
        ] {
            assert!(mode.get(key).is_some(), "mode {key} missing");
            optional_number(&mode[key], key);
        }
        assert!(mode["truth"].is_null() || mode["truth"].as_array().map(Vec::len) == Some(2));
    }
    assert!(
        modes.iter().any(|m| m["truth"].is_array()),
        "no mode paired"
    );
    let truth_modes = fit["truth_modes"].as_array().expect("fit.truth_modes");
    let hover = &fit["hover_modes_matched"];
    // The Bo-105 truth at hover: two oscillations, heave and yaw below 3 rad/s.
    assert_eq!(hover["of"].as_u64(), Some(4), "{hover}");
    assert_eq!(truth_modes.iter().filter(|t| t["hover"] == true).count(), 4);
    assert!(hover["matched"].as_u64().unwrap() <= 4);
    optional_number(&hover["worst_error_percent"], "worst_error_percent");
    assert!(
        fit["poles_at_origin"].is_u64(),
        "{}",
        fit["poles_at_origin"]
    );

    let verify = &summary["verify"];
    assert_eq!(string(&verify["bias"], "bias"), "trim");
    let tic = &verify["tic"];
    // Every output the 9-DOF model predicts is recorded in the dumps and compared.
    let outputs = ["u", "v", "w", "p", "q", "r", "ax", "ay", "az"];
    assert_eq!(tic.as_object().expect("tic").len(), outputs.len(), "{tic}");
    for output in outputs {
        let value = number(&tic[output], output);
        assert!((0.0..=1.0).contains(&value), "TIC {output}: {value}");
    }
    let mean = |names: &[&str]| {
        names.iter().map(|o| number(&tic[*o], o)).sum::<f64>() / names.len() as f64
    };
    let pqr = number(&verify["tic_mean_pqr"], "tic_mean_pqr");
    assert!((pqr - mean(&["p", "q", "r"])).abs() < 1e-12, "{pqr}");
    let all = number(&verify["tic_mean_all"], "tic_mean_all");
    assert!((all - mean(&outputs)).abs() < 1e-12, "{all}");
    assert_eq!(number(&verify["tic_mean"], "tic_mean"), all);
    let verify_json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("verify.json")).unwrap()).unwrap();
    assert_eq!(string(&verify_json["bias"], "verify.json bias"), "trim");
    for record in verify_json["records"].as_array().expect("records") {
        for output in record["outputs"].as_array().expect("outputs") {
            number(&output["bias"], "bias");
        }
    }
    let timings = summary["timings_s"].as_object().expect("timings_s");
    for stage in Stage::ALL
        .map(Stage::name)
        .into_iter()
        // fly_steady: --fc board-sim campaigns only.
        .filter(|s| *s != "setup" && *s != "fly_steady")
        .chain(["total"])
    {
        assert!(number(&timings[stage], stage) >= 0.0);
    }
    summary
}

#[test]
fn quick_campaign_report_and_errors() {
    let dir = scratch("quick");
    let out = dir.join("campaign");
    let output = sweephold(&[
        "campaign",
        "--quick",
        "--quiet",
        "--seed",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("report.html"), "{stdout}");
    let summary = check_summary(&out);

    // `fit --constant`: the shipped structure with another hub height reaches the model
    // (Kpq = hub_height·Lfu); a constant the file does not declare is one line, exit 1.
    let hybrid =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../sysid/models/bo105-9dof-hybrid.toml");
    let frf = out.join("frf.json");
    let refit = dir.join("refit.json");
    let fit_args = |constant: &str| {
        sweephold(&[
            "fit",
            "--frf",
            frf.to_str().unwrap(),
            "--model",
            hybrid.to_str().unwrap(),
            "--max-starts",
            "1",
            "--constant",
            constant,
            "--out",
            refit.to_str().unwrap(),
        ])
    };
    let output = fit_args("hub_height=0.25");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        String::from_utf8_lossy(&output.stdout).contains("modes (eigenvalues of M⁻¹F"),
        "fit prints the modes table"
    );
    let model: Value = serde_json::from_str(&std::fs::read_to_string(&refit).unwrap()).unwrap();
    assert!(!model["modes"].as_array().expect("modes").is_empty());
    let model9: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("model9.json")).unwrap()).unwrap();
    assert_eq!(model9["modes"], summary["fit"]["modes"]);
    assert!(model9["truth"]["modes"].is_array());
    let value = |name: &str| {
        let parameters = model["parameters"].as_array().expect("parameters");
        let parameter = parameters.iter().find(|p| p["name"] == name).expect(name);
        number(&parameter["value"], name)
    };
    assert!((value("Kpq") - 0.25 * value("Lfu")).abs() <= 1e-12 * value("Lfu").abs().max(1e-9));
    let message = one_line_failure(&fit_args("hub_heigth=0.25"));
    assert!(
        message.contains("unknown constant `hub_heigth`"),
        "{message}"
    );

    // One <svg> at least per plot section; one Bode figure per fitted pair.
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        !html.contains("<script"),
        "the shipped report has no script"
    );
    let sections = structure(&html);
    for id in sweephold::report::sections::PLOT_SECTIONS {
        let svgs = sections
            .iter()
            .find(|(s, _)| s == id)
            .map(|(_, n)| *n)
            .unwrap_or_else(|| panic!("no section {id}"));
        assert!(svgs >= 1, "section {id} has no <svg>");
    }
    assert!(
        sections.iter().any(|(s, _)| s == "modes"),
        "no modes section"
    );
    assert!(html.contains("no pole at the origin"), "no hover-mode bar");
    let bode = sections.iter().find(|(s, _)| s == "bode").unwrap().1;
    assert_eq!(bode, summary["fit"]["pairs"].as_array().unwrap().len());

    // `report DIR` regenerates a page of the same structure from the files alone.
    std::fs::remove_file(out.join("report.html")).unwrap();
    let output = sweephold(&["report", out.to_str().unwrap()]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let again = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert_eq!(structure(&again), sections);

    // The loops section: a Bode plot per broken loop and a chart per axis, from
    // margins.json and margins-loops.json. A folder without them (a campaign from before
    // the margins stage) still makes a report, whose section says they are absent.
    assert_eq!(sections.iter().find(|(s, _)| s == "loops").unwrap().1, 9);
    let margins: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("margins.json")).unwrap()).unwrap();
    assert_eq!(margins["loops"].as_array().unwrap().len(), 6);
    assert_eq!(margins["samples"], 40);
    let older = dir.join("older");
    std::fs::create_dir_all(&older).unwrap();
    for file in [
        "summary.json",
        "frf.json",
        "model9.json",
        "truth-model9.json",
        "verify.json",
    ] {
        std::fs::copy(out.join(file), older.join(file)).unwrap();
    }
    let output = sweephold(&["report", older.to_str().unwrap()]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let older_html = std::fs::read_to_string(older.join("report.html")).unwrap();
    let older_sections = structure(&older_html);
    assert_eq!(
        older_sections.iter().find(|(s, _)| s == "loops").unwrap().1,
        0
    );
    assert!(older_html.contains("No margins.json in this folder"));

    // Ctrl-C mid-way: the campaign stops at its next safe point, names the stage, keeps its
    // files with the error in DIR.failed, and leaves the previous campaign as it was.
    let report_before = std::fs::read(out.join("report.html")).unwrap();
    let summary_before = std::fs::read(out.join("summary.json")).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .args(["campaign", "--quick", "--quiet", "--seed", "4", "--out"])
        .arg(&out)
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("the binary runs");
    let flown = dir.join("campaign.partial/fly-cah/summary.json");
    let waited = std::time::Instant::now();
    while !flown.exists() && waited.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(flown.exists(), "the cah records were never written");
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let interrupted = child.wait_with_output().unwrap();
    let message = one_line_failure(&interrupted);
    assert!(
        message.contains("interrupted (Ctrl-C or SIGTERM)"),
        "{message}"
    );
    assert!(message.contains("campaign.failed"), "{message}");
    assert_eq!(
        std::fs::read(out.join("report.html")).unwrap(),
        report_before
    );
    assert_eq!(
        std::fs::read(out.join("summary.json")).unwrap(),
        summary_before
    );
    let stopped: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("campaign.failed/summary.json")).unwrap(),
    )
    .unwrap();
    // Within a flight stage the record in flight names itself before the reason.
    let reason = stopped["error"]["message"].as_str().unwrap();
    assert!(
        reason.ends_with("interrupted (Ctrl-C or SIGTERM)"),
        "{reason}"
    );
    assert_eq!(stopped["seed"], 4);
    assert!(!dir.join("campaign.partial").exists());

    // A corrupt file: one line naming it, non-zero exit.
    std::fs::write(out.join("model9.json"), "{ not json").unwrap();
    let message = one_line_failure(&sweephold(&["report", out.to_str().unwrap()]));
    assert!(message.contains("model9.json"), "{message}");

    // A priors file that does not read: one line, before anything is flown.
    let missing = dir.join("no-such-aircraft.toml");
    let message = one_line_failure(&sweephold(&[
        "campaign",
        "--priors",
        missing.to_str().unwrap(),
        "--out",
        dir.join("never").to_str().unwrap(),
    ]));
    assert!(message.contains("--priors"), "{message}");
    assert!(!dir.join("never").exists());

    // An output folder that cannot be created (its parent is a file).
    let blocker = dir.join("file");
    std::fs::write(&blocker, "x").unwrap();
    let unwritable = blocker.join("campaign");
    let message = one_line_failure(&sweephold(&[
        "campaign",
        "--quick",
        "--quiet",
        "--out",
        unwritable.to_str().unwrap(),
    ]));
    assert!(message.contains("`setup`"), "{message}");

    // A folder holding other files than a campaign's is refused before anything is
    // written, its files untouched.
    let foreign = dir.join("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "mine").unwrap();
    let message = one_line_failure(&sweephold(&[
        "campaign",
        "--quick",
        "--quiet",
        "--out",
        foreign.to_str().unwrap(),
    ]));
    assert!(message.contains("not a sweephold run"), "{message}");
    assert_eq!(
        std::fs::read_to_string(foreign.join("notes.txt")).unwrap(),
        "mine"
    );
    assert_eq!(std::fs::read_dir(&foreign).unwrap().count(), 1);

    std::fs::remove_dir_all(&dir).ok();
}

/// `campaign --fc board-sim`: every record flown by the board application on the emulated
/// IMU and receiver; the summary names the link, nothing aborts, and since the board
/// measures no air data neither the fits nor the verification use u, v or w.
#[test]
fn quick_board_sim_campaign_fits_without_air_data() {
    let dir = scratch("board-sim");
    let out = dir.join("campaign");
    let output = sweephold(&[
        "campaign",
        "--quick",
        "--quiet",
        "--fc",
        "board-sim",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", one_line_failure(&output));
    let read = |file: &str| -> Value {
        serde_json::from_str(&std::fs::read_to_string(out.join(file)).unwrap()).unwrap()
    };
    let summary = read("summary.json");
    assert_eq!(string(&summary["link"], "link"), "board-sim");
    for mode in ["cah", "standard", "noise"] {
        assert_eq!(
            number(&summary["modes"][mode]["aborts"], "aborts"),
            0.0,
            "{mode}"
        );
    }
    let air_data = |name: &str| ["u", "v", "w"].contains(&name);
    for file in ["model6.json", "model9.json"] {
        let pairs = read(file)["pairs"].as_array().unwrap().clone();
        assert!(!pairs.is_empty(), "{file}");
        assert!(
            pairs
                .iter()
                .all(|pair| !air_data(pair["output"].as_str().unwrap())),
            "{file} fits an air-data pair"
        );
    }
    let verify = read("verify.json");
    for record in verify["records"].as_array().unwrap() {
        let names: Vec<&str> = record["outputs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|o| o["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["p", "q", "r", "ax", "ay", "az"]);
    }
    // The fly stages' own summaries say which link flew them.
    let fly = read("fly-cah/summary.json");
    assert_eq!(string(&fly["link"], "fly link"), "board-sim");
    let _ = std::fs::remove_dir_all(&dir);
}
