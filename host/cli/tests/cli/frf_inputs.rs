//! `sweephold frf` as a user runs it on CSV logs: which input was swept, the responses to
//! every excited input of a two-input log made by an outside simulator
//! (`host/sysid/tests/data/two_input.csv`, written by scipy: see
//! `make_two_input_csv.py` there), and readers refusing a damaged `frf.json`.

use std::path::{Path, PathBuf};
use std::process::Output;

use sysid::document::{FrfDocument, PairResponse};

use crate::support::{sweephold, Scratch};

const TWO_INPUT_CSV: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../sysid/tests/data/two_input.csv"
);

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("frf-{name}")))
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

/// `frf` on the two-input CSV with `extra` arguments; the document it wrote.
fn frf_two_input(dir: &TempDir, extra: &[&str]) -> FrfDocument {
    let out = dir.path("frf.json");
    let mut args = vec![
        "frf",
        TWO_INPUT_CSV,
        "--time",
        "t",
        "--inputs",
        "lat,lon",
        "--outputs",
        "p",
        "--band",
        "0.5,20",
        "--out",
        out.to_str().unwrap(),
        "-q",
    ];
    args.extend_from_slice(extra);
    let run = sweephold(&args);
    assert!(run.status.success(), "{}", stderr(&run));
    read_document(&out)
}

fn read_document(path: &Path) -> FrfDocument {
    FrfDocument::from_json(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn pairs(document: &FrfDocument) -> Vec<String> {
    document
        .pairs
        .iter()
        .map(|p| format!("{}→{}", p.input, p.output))
        .collect()
}

/// The transfer functions of make_two_input_csv.py at ω: (re, im).
fn exact(input: &str, omega: f64) -> (f64, f64) {
    // Complex arithmetic by hand: the CLI crate does not depend on num-complex.
    let div = |(a, b): (f64, f64), (c, d): (f64, f64)| {
        let n = c * c + d * d;
        ((a * c + b * d) / n, (b * c - a * d) / n)
    };
    match input {
        // (12 s + 60)/(s² + 6 s + 60)·e^(−0.04 s)
        "lat" => {
            let (re, im) = div((60.0, 12.0 * omega), (60.0 - omega * omega, 6.0 * omega));
            let (c, s) = ((0.04 * omega).cos(), (-0.04 * omega).sin());
            (re * c - im * s, re * s + im * c)
        }
        // −(2 s + 2)/(s + 4)
        "lon" => div((-2.0, -2.0 * omega), (4.0, omega)),
        _ => unreachable!(),
    }
}

/// Worst |dB| and |deg| errors over 0.5–20 rad/s where γ² ≥ 0.6, and the point count.
fn errors(pair: &PairResponse) -> (f64, f64, usize) {
    let (mut db, mut deg, mut count) = (0.0f64, 0.0f64, 0);
    for k in 0..pair.omega.len() {
        let omega = pair.omega[k];
        if !(0.5..=20.0).contains(&omega) || pair.coherence[k] < 0.6 {
            continue;
        }
        let (re, im) = exact(&pair.input, omega);
        db = db.max((pair.mag_db[k] - 10.0 * (re * re + im * im).log10()).abs());
        let mut d = pair.phase_deg[k] - im.atan2(re).to_degrees();
        d -= 360.0 * (d / 360.0).round();
        deg = deg.max(d.abs());
        count += 1;
    }
    (db, deg, count)
}

#[test]
fn a_two_input_log_gives_both_conditioned_responses_within_1_db_and_5_degrees() {
    let dir = TempDir::new("two-input");
    let document = frf_two_input(&dir, &[]);
    assert_eq!(pairs(&document), ["lat→p", "lon→p"]);
    for pair in &document.pairs {
        let (db, deg, count) = errors(pair);
        eprintln!(
            "{}→p: {count}/{} points, worst {db:.3} dB {deg:.2}°",
            pair.input,
            pair.omega.len()
        );
        assert!(count * 10 >= 200 * 8, "{}: {count} points", pair.input);
        assert!(db <= 1.0 && deg <= 5.0, "{}: {db} dB {deg}°", pair.input);
        assert_eq!(pair.group.as_deref(), Some("lat"));
        assert_eq!(pair.multiple_coherence.len(), pair.omega.len());
    }
    // Ignoring lon, the plain lat → p estimate is off by more than the bounds.
    let (db, deg, _) = errors(&document.siso[0]);
    assert!(db > 1.0 && deg > 5.0, "SISO lat→p only {db} dB {deg}°");

    // Same bytes from the same input.
    let first = std::fs::read(dir.path("frf.json")).unwrap();
    frf_two_input(&dir, &[]);
    assert_eq!(first, std::fs::read(dir.path("frf.json")).unwrap());
}

#[test]
fn the_excited_inputs_and_the_swept_one_can_be_named() {
    let dir = TempDir::new("named");
    // Only the swept input: the lat → p pair alone, without the multi-input fields.
    let swept_only = frf_two_input(&dir, &["--excited", "swept"]);
    assert_eq!(pairs(&swept_only), ["lat→p"]);
    assert!(swept_only.pairs[0].group.is_none());
    assert!(swept_only.pairs[0].multiple_coherence.is_empty());
    // Conditioned on the same inputs, it is the same response as with --excited all.
    let all = frf_two_input(&dir, &["--excited", "all"]);
    assert_eq!(all.pairs[0].mag_db, swept_only.pairs[0].mag_db);
    // Naming the swept input says which one was swept: responses to it only.
    let lon = frf_two_input(&dir, &["--swept", "lon"]);
    assert_eq!(pairs(&lon), ["lon→p"]);
    // ...unless every excited input is asked for; lat → p then comes from the lon group.
    let lon_all = frf_two_input(&dir, &["--swept", "lon", "--excited", "all"]);
    assert_eq!(pairs(&lon_all), ["lon→p", "lat→p"]);
    assert_eq!(lon_all.pairs[1].group.as_deref(), Some("lon"));

    let out = dir.path("unused.json");
    let run = sweephold(&[
        "frf",
        TWO_INPUT_CSV,
        "--time",
        "t",
        "--inputs",
        "lat,lon",
        "--outputs",
        "p",
        "--band",
        "0.5,20",
        "--swept",
        "ped",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(1));
    let message = stderr(&run);
    assert!(
        message.contains("--swept `ped`: not one of the --inputs names (lat, lon)"),
        "{message}"
    );
    assert_eq!(message.trim_end().lines().count(), 1, "{message}");
    assert!(!out.exists());
}

#[test]
fn fit_refuses_a_damaged_frf_json_in_one_line() {
    let dir = TempDir::new("damaged");
    let mut document = frf_two_input(&dir, &[]);
    document.pairs[0].mag_db.pop();
    let damaged = dir.path("damaged.json");
    std::fs::write(&damaged, serde_json::to_string(&document).unwrap()).unwrap();
    let run = sweephold(&[
        "fit",
        "--frf",
        damaged.to_str().unwrap(),
        "--model",
        "no-such-structure.toml",
    ]);
    assert_eq!(run.status.code(), Some(1));
    let message = stderr(&run);
    assert!(
        message.contains("frf.json: pair lat→p: mag_db has 199 values, omega 200"),
        "{message}"
    );
    assert_eq!(message.trim_end().lines().count(), 1, "{message}");
}
