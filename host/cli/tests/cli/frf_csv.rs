//! `sweephold frf` on a real logger's CSV as it is: `host/sysid/tests/data/x8roll.csv` (a
//! multirotor's roll chirp, 100 Hz, no header, gyro in deg/s; source in the README there),
//! with its columns and units named on the command line, against an independent scipy
//! estimate (`x8roll_scipy_h1.json`, written by `x8roll_scipy_h1.py` there); and the
//! one-line answers to a file read without them.

use std::path::PathBuf;
use std::process::Output;

use sysid::document::{FrfDocument, PairResponse};

use crate::support::{sweephold, Scratch};

const X8ROLL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../sysid/tests/data/x8roll.csv"
);
const SCIPY_H1: &str = include_str!("../../../sysid/tests/data/x8roll_scipy_h1.json");

/// The documented way to read x8roll.csv: columns by position (with [`DEG_PER_S`], the
/// gyro's unit).
const X8_OPTIONS: [&str; 10] = [
    "--time",
    "1",
    "--inputs",
    "rout=2",
    "--outputs",
    "gx=3",
    "--swept",
    "rout",
    "--band",
    "0.6,60",
];

const DEG_PER_S: [&str; 2] = ["--units", "gx=deg/s"];

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("frfcsv-{name}")))
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

/// `frf FILE X8_OPTIONS extra --out DIR/frf.json`: the run and the document (if written).
fn frf(dir: &TempDir, file: &str, extra: &[&str]) -> (Output, Option<FrfDocument>) {
    let out = dir.path("frf.json");
    let mut args = vec!["frf", file];
    args.extend_from_slice(&X8_OPTIONS);
    args.extend_from_slice(extra);
    args.extend_from_slice(&["--out", out.to_str().unwrap()]);
    let run = sweephold(&args);
    let document = std::fs::read_to_string(&out)
        .ok()
        .map(|text| FrfDocument::from_json(&text).unwrap());
    (run, document)
}

/// The scipy estimate at ω (linear interpolation in the complex plane) as magnitude [dB]
/// and phase [deg], and its coherence.
fn scipy_h1(omega: f64) -> (f64, f64, f64) {
    let json: serde_json::Value = serde_json::from_str(SCIPY_H1).unwrap();
    let column = |key: &str| -> Vec<f64> {
        json[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (w, db, deg, coh) = (
        column("omega"),
        column("mag_db"),
        column("phase_deg"),
        column("coherence"),
    );
    let k = w.partition_point(|&x| x <= omega).clamp(1, w.len() - 1) - 1;
    let a = ((omega - w[k]) / (w[k + 1] - w[k])).clamp(0.0, 1.0);
    let h = |i: usize| {
        let (m, p) = (10f64.powf(db[i] / 20.0), deg[i].to_radians());
        (m * p.cos(), m * p.sin())
    };
    let ((r0, i0), (r1, i1)) = (h(k), h(k + 1));
    let (re, im) = (r0 + a * (r1 - r0), i0 + a * (i1 - i0));
    (
        10.0 * (re * re + im * im).log10(),
        im.atan2(re).to_degrees(),
        coh[k] * (1.0 - a) + coh[k + 1] * a,
    )
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let mid = values.len() / 2;
    if values.len() % 2 == 1 {
        values[mid]
    } else {
        0.5 * (values[mid - 1] + values[mid])
    }
}

/// Median |difference| from scipy in dB and degrees over the pair's valid range where
/// scipy's coherence is at least 0.6, and how many points.
fn against_scipy(pair: &PairResponse) -> (f64, f64, usize) {
    let [lo, hi] = pair.valid_range.expect("a valid range");
    let (mut db, mut deg) = (Vec::new(), Vec::new());
    for k in 0..pair.omega.len() {
        let (mag_db, phase_deg, coherence) = scipy_h1(pair.omega[k]);
        if !(lo..=hi).contains(&pair.omega[k]) || coherence < 0.6 {
            continue;
        }
        db.push((pair.mag_db[k] - mag_db).abs());
        let d = pair.phase_deg[k] - phase_deg;
        deg.push((d - 360.0 * (d / 360.0).round()).abs());
    }
    let count = db.len();
    (median(db), median(deg), count)
}

#[test]
fn x8roll_read_as_it_is_matches_scipy() {
    let dir = TempDir::new("x8");
    let (run, document) = frf(&dir, X8ROLL, &DEG_PER_S);
    assert!(run.status.success(), "{}", stderr(&run));
    // Uniform, units given, swept input named: nothing to note about the file.
    assert!(!stderr(&run).contains("x8roll.csv"), "{}", stderr(&run));
    let pair = document.unwrap().pair("rout", "gx").unwrap().clone();
    let (db, deg, count) = against_scipy(&pair);
    eprintln!("frf x8roll.csv: {count} points, median {db:.3} dB, {deg:.2}° from scipy");
    assert!(
        count >= 150 && db <= 0.3 && deg <= 2.0,
        "{count} {db} {deg}"
    );
}

#[test]
fn the_gyro_without_its_unit_gets_a_note_and_reads_35_db_high() {
    let dir = TempDir::new("deg");
    let (run, document) = frf(&dir, X8ROLL, &["--units", "time=s"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = stderr(&run);
    assert!(
        text.contains("`gx` peaks at 85.1, above 15 rad/s: it looks like deg/s")
            && text.contains("--units gx=deg/s"),
        "{text}"
    );
    let pair = document.unwrap().pair("rout", "gx").unwrap().clone();
    let (db, _, _) = against_scipy(&pair);
    assert!((db - 35.16).abs() < 0.5, "{db} dB");
}

#[test]
fn time_in_ms_window_and_sweep_reference() {
    let dir = TempDir::new("ms");
    // The time column in ms: told by its step, with a note; the response is unchanged.
    let ms: String = std::fs::read_to_string(X8ROLL)
        .unwrap()
        .lines()
        .map(|l| {
            let (t, rest) = l.split_once(',').unwrap();
            let t: f64 = t.parse().unwrap();
            format!("{},{rest}\n", (t * 1e7).round() / 1e4)
        })
        .collect();
    let ms_file = dir.path("x8roll_ms.csv");
    std::fs::write(&ms_file, ms).unwrap();
    let (run, seconds) = frf(&dir, X8ROLL, &DEG_PER_S);
    assert!(run.status.success());
    let (run, in_ms) = frf(&dir, ms_file.to_str().unwrap(), &DEG_PER_S);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stderr(&run).contains("read in ms"), "{}", stderr(&run));
    let (a, b) = (
        seconds.unwrap().pairs[0].clone(),
        in_ms.unwrap().pairs[0].clone(),
    );
    for (x, y) in a.mag_db.iter().zip(&b.mag_db) {
        assert!((x - y).abs() < 1e-6);
    }
    // A window on the file's time axis, in seconds.
    let (run, windowed) = frf(
        &dir,
        ms_file.to_str().unwrap(),
        &[
            "--units", "gx=deg/s", "--units", "time=ms", "--window", "5,75",
        ],
    );
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(!stderr(&run).contains("read in ms"));
    assert!(stderr(&run).contains("70.0 s"), "{}", stderr(&run));
    assert!(windowed.is_some());
    // The sweep reference from a column: here the input itself, so the reference
    // estimate is the cross-spectral one.
    let (run, reference) = frf(
        &dir,
        X8ROLL,
        &[
            "--units",
            "gx=deg/s",
            "--estimator",
            "sweep-reference",
            "--reference",
            "rout=2",
        ],
    );
    assert!(run.status.success(), "{}", stderr(&run));
    let r = reference.unwrap().pairs[0].clone();
    for (x, y) in a.mag_db.iter().zip(&r.mag_db) {
        assert!((x - y).abs() < 1e-6, "{x} {y}");
    }
    let (run, _) = frf(&dir, X8ROLL, &["--estimator", "sweep-reference"]);
    assert!(!run.status.success());
    assert!(
        stderr(&run).contains("frf --reference rout=COLUMN"),
        "{}",
        stderr(&run)
    );
}

#[test]
fn one_line_errors_that_say_what_to_do() {
    let dir = TempDir::new("err");
    let out = dir.path("frf.json");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (
            &["frf", X8ROLL, "--band", "0.6,60", "--out", out],
            "no column `time_s`: the file has no header row (its first row is all numbers); give columns by position, 1–3 (e.g. --time 1 --inputs NAME=2 --outputs NAME=3)",
        ),
        (
            &["frf", X8ROLL, "--time", "1", "--inputs", "rout=2", "--outputs", "gx=3", "--units", "gx=m/s", "--out", out],
            "error: --units `gx=m/s`: a unit is rad/s, deg/s, rad or deg (time: s, ms, us)",
        ),
        (
            &["frf", X8ROLL, "--time", "1", "--inputs", "rout=2", "--outputs", "gx=3", "--units", "p=deg/s", "--band", "0.6,60", "--out", out],
            "unit given for `p`, which is neither an input (rout) nor an output (gx)",
        ),
        (
            &["frf", X8ROLL, "--time", "1", "--inputs", "rout=2", "--outputs", "gx=3", "--window", "200,300", "--band", "0.6,60", "--out", out],
            "window 200–300 s keeps 0 row(s): the time column runs 0.0025–106.5086 s",
        ),
        (
            &["frf", X8ROLL, "--time", "1", "--inputs", "rout=2", "--outputs", "gx=3", "--reference", "lat=2", "--out", out],
            "error: --reference `lat`: not one of the --inputs names (rout)",
        ),
    ];
    for (args, expected) in cases {
        let run = sweephold(args);
        let text = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{text}");
        assert!(text.contains(expected), "{text}");
        assert_eq!(text.trim_end().lines().count(), 1, "{text}");
    }
    assert!(!dir.path("frf.json").exists());
}
