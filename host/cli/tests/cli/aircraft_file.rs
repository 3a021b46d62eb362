//! An aircraft that exists only as a file, never in the sources: a TREX 700L-class variant
//! (12 % heavier, 20 % more inertia, 7 % lower head speed, a 5 % longer tail, blades 10 %
//! heavier, servos 15 % slower) written into a temporary folder under a name made at run
//! time, trimmed by `sim` and flown and identified by `campaign --quick` through
//! `--vehicle FILE`. What reaches the simulator, the flight controller's Header and the
//! fit's priors is the file's.

use serde_json::Value;

use crate::support::{sweephold, Scratch};

fn scratch() -> Scratch {
    Scratch::new("aircraft")
}

fn json(path: &std::path::Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// The variant's file text: the shipped TREX 700L's with every changed line replaced.
fn variant(name: &str) -> String {
    let mut text = aircraft::SHIPPED[1].1.to_string();
    for (from, to) in [
        (
            "name = \"trex700l\"".to_string(),
            format!("name = \"{name}\""),
        ),
        (
            "mass = \"5.0 kg\"".into(),
            "mass = \"5.6 ± 0.05 kg\"".into(),
        ),
        (
            "ixx = \"0.12 kg*m^2\"".into(),
            "ixx = \"0.144 kg*m^2\"".into(),
        ),
        (
            "iyy = \"0.40 kg*m^2\"".into(),
            "iyy = \"0.48 kg*m^2\"".into(),
        ),
        (
            "izz = \"0.35 kg*m^2\"".into(),
            "izz = \"0.42 kg*m^2\"".into(),
        ),
        (
            "head_speed = \"1900 rpm\"".into(),
            "head_speed = \"1767 rpm\"".into(),
        ),
        ("speed = \"8930 rpm\"".into(), "gear_ratio = 4.7".into()),
        (
            "flap_inertia = \"0.046 kg*m^2\"".into(),
            "flap_inertia = \"0.0511 kg*m^2\"".into(),
        ),
        ("hub = [\"-0.95 m\"".into(), "hub = [\"-0.9975 m\"".into()),
        (
            "natural_frequency = \"60 rad/s\"".into(),
            "natural_frequency = \"51 rad/s\"".into(),
        ),
    ] {
        assert!(text.contains(&from), "{from}");
        text = text.replacen(&from, &to, 1);
    }
    text
}

#[test]
fn an_aircraft_file_is_simulated_flown_and_identified_with_its_own_numbers() {
    let dir = scratch();
    let name = format!("heli{}", std::process::id());
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, variant(&name)).unwrap();
    let file_arg = file.to_str().unwrap();

    // The simulator trims the file's aircraft, not the preset it came from.
    let trim = |vehicle: &str| {
        let output = sweephold(&["sim", "trim", "--vehicle", vehicle, "--json"]);
        assert!(output.status.success(), "{output:?}");
        serde_json::from_slice::<Value>(&output.stdout).unwrap()
    };
    let (own, trex) = (trim(file_arg), trim("trex700l"));
    assert_eq!(own["vehicle"], name.as_str());
    let collective = |doc: &Value| doc["controls"]["col"].as_f64().unwrap();
    assert!(
        collective(&own) > collective(&trex) + 0.01,
        "heavier and slower: more collective ({} vs {})",
        collective(&own),
        collective(&trex)
    );

    let out = dir.join("campaign");
    let output = sweephold(&[
        "campaign",
        "--quick",
        "--quiet",
        "--vehicle",
        file_arg,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["vehicle"], name.as_str());
    assert_eq!(
        json(&out.join("truth-model9.json"))["vehicle"],
        name.as_str()
    );
    // The fit's servo prior is the file's 51 rad/s (σ the default 20 %), not the preset's
    // 60; the servo the model carries is its estimate under that prior.
    let model = json(&out.join("model9.json"));
    let parameters = model["parameters"].as_array().unwrap();
    let omega = parameters
        .iter()
        .find(|p| p["name"] == "servo_omega")
        .expect("the TREX hybrid's servo ω_n");
    assert_eq!(omega["prior"]["value"], 51.0, "{omega}");
    assert!((omega["prior"]["sigma"].as_f64().unwrap() - 10.2).abs() < 1e-12);
    let actuators = model["actuators"]
        .as_array()
        .expect("the TREX hybrid's servos");
    let servo = actuators.iter().find(|a| !a.is_null()).expect("a servo");
    assert_eq!(servo["natural_frequency_rad_s"], omega["value"], "{servo}");
    // The file's σ reaches the constants it enters: the mass, written 5.6 ± 0.05 kg, makes
    // M/I_yy = 5.6/0.48 uncertain by 0.05/0.48; the hub height has no σ in the file.
    let constants = model["aircraft_constants"]
        .as_array()
        .expect("aircraft_constants: the file gives a σ");
    let constant = |name: &str| {
        constants
            .iter()
            .find(|c| c["name"] == name)
            .unwrap_or_else(|| panic!("{name} in {constants:?}"))
    };
    let ratio = constant("mass_over_iyy");
    assert!((ratio["value"].as_f64().unwrap() - 5.6 / 0.48).abs() < 1e-12);
    assert!((ratio["sigma"].as_f64().unwrap() - 0.05 / 0.48).abs() < 1e-12);
    assert_eq!(constant("hub_height").get("sigma"), None);
    // The flight controller flew the firmware preset the file names (the Header's vehicle).
    let jsonl = dir.join("lat-1.jsonl");
    let decode = sweephold(&[
        "decode",
        "--format",
        "jsonl",
        "--quiet",
        out.join("fly-cah/lat-1.bin").to_str().unwrap(),
        "-o",
        jsonl.to_str().unwrap(),
    ]);
    assert!(decode.status.success(), "{decode:?}");
    let text = std::fs::read_to_string(&jsonl).unwrap();
    let header = text
        .lines()
        .find(|l| l.contains("\"type\":\"header\""))
        .expect("a Header");
    assert!(header.contains("\"vehicle\":\"trex700l\""), "{header}");

    // A file that does not read is one line naming its field, exit status 2.
    let broken = dir.join("broken.toml");
    std::fs::write(
        &broken,
        variant(&name).replace("mass = \"5.6 ± 0.05 kg\"", "mass = \"5.6\""),
    )
    .unwrap();
    let output = sweephold(&["campaign", "--quick", "--vehicle", broken.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("airframe.mass"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
