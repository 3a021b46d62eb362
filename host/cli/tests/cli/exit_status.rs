//! Every verb's numeric (and named-value) options out of range: exit status 2 (the
//! command line is wrong), one line naming the option and the expected range, and that
//! range written in the verb's `--help`. One row per case; each is refused while the
//! command line is read, before any input is opened (the inputs named here need not exist).

use std::process::{Command, Output};

fn sweephold(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(std::env::temp_dir())
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The command line before the option, per verb (inputs that do not exist: a check of
/// the option must come first).
const FRF: &[&str] = &["frf", "missing.bin", "--out", "missing.json"];
const FIT: &[&str] = &["fit", "--frf", "missing.json", "--model", "bo105-6dof"];
const FLY: &[&str] = &["fly", "--out", "never-written"];
const VERIFY: &[&str] = &["verify", "--model", "missing.json", "missing.bin"];
const CAMPAIGN: &[&str] = &["campaign", "--out", "never-written"];
const TRIM: &[&str] = &["sim", "trim"];
const LINEARIZE: &[&str] = &["sim", "linearize"];
const TRIM_POINTS: &[&str] = &["sim", "trim-points"];

/// (verb, option, bad values, message fragment, range as `--help` writes it).
type Case = (
    &'static [&'static str],
    &'static str,
    &'static [&'static str],
    &'static str,
    Option<&'static str>,
);

const CASES: &[Case] = &[
    (
        TRIM,
        "--speed",
        &["nan", "-5", "200", "inf", "fast", "", "120.5", "1e3"],
        "expected a speed from 0 to 120 kt",
        Some("0 (hover) to 120"),
    ),
    (
        LINEARIZE,
        "--speed",
        &["nan", "-0.1", "121", "-inf"],
        "expected a speed from 0 to 120 kt",
        Some("0 (hover) to 120"),
    ),
    (
        TRIM,
        "--vehicle",
        &["ec135", "", "bo106"],
        "unknown vehicle",
        Some("shipped aircraft (bo105, trex700l, fbl700) or the path of an aircraft file"),
    ),
    (
        LINEARIZE,
        "--vehicle",
        &["ec135"],
        "unknown vehicle",
        Some("shipped aircraft (bo105, trex700l, fbl700) or the path of an aircraft file"),
    ),
    (
        TRIM_POINTS,
        "--vehicle",
        &["ec135"],
        "unknown vehicle",
        Some("shipped aircraft (bo105, trex700l, fbl700) or the path of an aircraft file"),
    ),
    (
        FRF,
        "--points",
        &["1", "100001", "0", "-3", "x", "2.5"],
        "expected a whole number from 2 to 100000",
        Some("2–100000"),
    ),
    (
        FRF,
        "--windows",
        &["0", "21", "-1", "nan"],
        "expected a whole number from 1 to 20",
        Some("1–20"),
    ),
    (
        FRF,
        "--overlap",
        &["0.96", "nan", "-0.1", "1", "inf", "x"],
        "expected a fraction from 0 to 0.95",
        Some("0–0.95"),
    ),
    (
        FRF,
        "--coherence-threshold",
        &["1.5", "-0.1", "nan", "inf", ""],
        "expected a number from 0 to 1",
        Some("0–1"),
    ),
    (
        FRF,
        "--band",
        &["5,1", "0,10", "-1,10", "nan,10", "1", "1,2,3", "1,inf"],
        "WMIN",
        Some("WMIN,WMAX"),
    ),
    (
        FRF,
        "--max-random-error",
        &["0", "-0.1", "nan", "inf", "some"],
        "expected a random error > 0",
        Some("`none`"),
    ),
    (
        FIT,
        "--max-starts",
        &["0", "65", "-1", "x"],
        "expected a whole number from 1 to 64",
        Some("1–64"),
    ),
    (
        FIT,
        "--points",
        &["1", "201", "nan"],
        "expected a whole number from 2 to 200",
        Some("2–200"),
    ),
    (
        FIT,
        "--seed",
        &["-1", "1.5", "18446744073709551616", "x"],
        "expected a whole number from 0 to",
        None,
    ),
    (FIT, "--truth", &["ec135"], "unknown vehicle", None),
    (
        FIT,
        "--constant",
        &["x", "x=nan", "x=inf", "=1", "x=fast"],
        "",
        Some("NAME=VALUE"),
    ),
    (
        FLY,
        "--pilot-noise",
        &["0.5", "-0.1", "nan", "1", "inf"],
        "expected a fraction from 0 to below 0.5",
        Some("0 to < 0.5"),
    ),
    (
        FLY,
        "--t-rec",
        &["0", "4.9", "1001", "nan", "inf", "-90"],
        "expected a record length from 5 to 1000 s",
        Some("5–1000"),
    ),
    (
        FLY,
        "--rate",
        &["49", "1001", "0", "-200", "x"],
        "",
        Some("50–1000"),
    ),
    (
        FLY,
        "--gust",
        &["-1", "nan", "inf"],
        "expected a finite number >= 0",
        Some(">= 0"),
    ),
    (
        FLY,
        "--sensor-dropout",
        &["1.01", "-0.1", "nan"],
        "expected a probability from 0 to 1",
        Some("0–1"),
    ),
    (
        FLY,
        "--sensor-spike",
        &["2", "-1", "nan"],
        "expected a probability from 0 to 1",
        Some("0–1"),
    ),
    (
        FLY,
        "--pilot-override",
        &["-1", "nan", "inf"],
        "expected a finite number >= 0",
        Some(">= 0"),
    ),
    (
        FLY,
        "--rc-loss",
        &["-0.5", "nan", "inf"],
        "expected a finite number >= 0",
        Some(">= 0"),
    ),
    (
        FLY,
        "--fly-on",
        &["-1", "601", "nan"],
        "expected seconds from 0 to 600",
        Some("0–600"),
    ),
    (
        FLY,
        "--imu-fault",
        &["stuck@-1", "stuck@nan", "melted", "stuck@", "saturate@inf"],
        "",
        Some("stuck@AT_S"),
    ),
    (
        FLY,
        "--axes",
        &["yaw", "lat,yaw", ""],
        "",
        Some("lat,lon,ped,col"),
    ),
    (
        FLY,
        "--seed",
        &["-1", "x"],
        "expected a whole number from 0 to",
        None,
    ),
    (
        FLY,
        "--fc",
        &["qemu2", "serial:", ""],
        "",
        Some("in-process"),
    ),
    (
        VERIFY,
        "--segment",
        &["0", "-1", "nan", "inf", "x"],
        "expected a number of seconds > 0",
        Some("SECONDS (> 0)"),
    ),
    (VERIFY, "--bias", &["mean"], "", Some("trim")),
    (
        CAMPAIGN,
        "--seed",
        &["-1", "1e3", "x"],
        "expected a whole number from 0 to",
        None,
    ),
    (CAMPAIGN, "--vehicle", &["ec135"], "", Some("bo105")),
];

#[test]
fn out_of_range_options_exit_2_naming_the_option_and_its_range() {
    let mut checked = 0;
    for (verb, option, values, fragment, help) in CASES {
        for value in *values {
            let mut args = verb.to_vec();
            args.extend([*option, value]);
            let output = sweephold(&args);
            let stderr = String::from_utf8_lossy(&output.stderr).trim().to_string();
            let case = format!("{} {option} {value:?}", verb.join(" "));
            assert_eq!(output.status.code(), Some(2), "{case}: {stderr}");
            assert_eq!(stderr.lines().count(), 1, "{case}: {stderr}");
            assert!(stderr.starts_with("error: "), "{case}: {stderr}");
            assert!(stderr.contains(option), "{case}: {stderr} names {option}");
            assert!(
                stderr.contains(fragment),
                "{case}: {stderr} says {fragment}"
            );
            assert!(output.stdout.is_empty(), "{case}");
            checked += 1;
        }
        if let Some(help) = help {
            let mut args = verb.to_vec();
            args.push("--help");
            let text = String::from_utf8_lossy(&sweephold(&args).stdout).to_string();
            let at = text
                .find(&format!("{option} "))
                .unwrap_or_else(|| panic!("{} --help lists {option}", verb.join(" ")));
            // The option's own paragraph (up to the next option).
            let paragraph = text[at..].split("\n  -").next().unwrap_or_default();
            assert!(
                paragraph.contains(help),
                "{} --help: {option} documents {help}: {paragraph}",
                verb.join(" ")
            );
        }
    }
    assert!(checked >= 120, "{checked} cases");
}
