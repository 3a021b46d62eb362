//! A real logger's CSV read as it is: `tests/data/x8roll.csv` (a multirotor's roll chirp,
//! 100 Hz, no header, gyro in deg/s; its source in `tests/data/README.md`).
//!
//! - The response `rout → gx` read with positional columns and `gx` in deg/s matches an
//!   independent scipy H1 estimate (`tests/data/x8roll_scipy_h1.py` → `.json`) to a median
//!   0.3 dB and 2° over the points valid in both.
//! - The same file disturbed as loggers disturb it (±1 ms jitter, a 50 ms gap, a `nan`
//!   row, a 0.5 s gap, time in ms or µs, a time window, the gyro left in deg/s) gives the
//!   documented outcome, and where samples are resampled or filled, a response within a
//!   stated tolerance of the undisturbed file's.

use num_complex::Complex64;
use sysid::document::PairResponse;
use sysid::frf::{analyse, group_by_primary, FrfOptions};
use sysid::records::{parse_csv_records, CsvColumns, Record, Unit};

const X8ROLL: &str = include_str!("data/x8roll.csv");
const SCIPY_H1: &str = include_str!("data/x8roll_scipy_h1.json");
const BAND: [f64; 2] = [0.6, 60.0];

/// The columns of x8roll.csv by position; `gx` in deg/s.
fn columns() -> CsvColumns {
    CsvColumns {
        time: "1".into(),
        inputs: vec![("rout".into(), "2".into())],
        outputs: vec![("gx".into(), "3".into())],
        primary: Some("rout".into()),
        units: vec![("gx".into(), Unit::DegPerS)],
        ..CsvColumns::default()
    }
}

fn records(text: &str, columns: &CsvColumns) -> Vec<Record> {
    parse_csv_records(text, "x8roll.csv", columns).expect("x8roll reads")
}

/// `rout → gx` from `records`, over BAND, default options.
fn response(records: Vec<Record>) -> (PairResponse, Vec<String>) {
    let options = FrfOptions {
        band: Some(BAND),
        ..FrfOptions::default()
    };
    let document = analyse(&group_by_primary(records).unwrap(), &options)
        .expect("frf")
        .document;
    let pair = document.pair("rout", "gx").expect("rout → gx").clone();
    (pair, document.notes)
}

/// Median |difference| in dB and degrees (wrapped to ±180°) of `pair` from `reference`
/// (ω ↦ response, coherence) over the pair's valid range where the reference's coherence
/// is at least 0.6, and the number of points compared.
fn median_difference(
    pair: &PairResponse,
    reference: impl Fn(f64) -> (Complex64, f64),
) -> (f64, f64, usize) {
    let [lo, hi] = pair.valid_range.expect("a valid range");
    let (mut db, mut deg) = (Vec::new(), Vec::new());
    for k in 0..pair.omega.len() {
        let omega = pair.omega[k];
        let (h, coherence) = reference(omega);
        if !(lo..=hi).contains(&omega) || coherence < 0.6 {
            continue;
        }
        db.push((pair.mag_db[k] - 20.0 * h.norm().log10()).abs());
        let d = pair.phase_deg[k] - h.arg().to_degrees();
        deg.push((d - 360.0 * (d / 360.0).round()).abs());
    }
    let count = db.len();
    (median(db), median(deg), count)
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

/// The scipy estimate, linearly interpolated (in the complex plane) onto ω.
fn scipy_h1(omega: f64) -> (Complex64, f64) {
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
    let h = |i: usize| Complex64::from_polar(10f64.powf(db[i] / 20.0), deg[i].to_radians());
    (
        h(k) * (1.0 - a) + h(k + 1) * a,
        coh[k] * (1.0 - a) + coh[k + 1] * a,
    )
}

/// `pair` as a reference function for [`median_difference`] (its own coherence).
fn as_reference(pair: &PairResponse) -> impl Fn(f64) -> (Complex64, f64) + '_ {
    move |omega| {
        let k = pair.omega.iter().position(|&w| w == omega).unwrap();
        let h = Complex64::from_polar(
            10f64.powf(pair.mag_db[k] / 20.0),
            pair.phase_deg[k].to_radians(),
        );
        (h, pair.coherence[k])
    }
}

/// The file's rows as (t, rout, gx).
fn rows() -> Vec<[f64; 3]> {
    X8ROLL
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|f| f.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

fn text(rows: &[[f64; 3]]) -> String {
    rows.iter()
        .map(|[t, a, b]| format!("{t},{a},{b}\n"))
        .collect()
}

fn records_of(text: &str) -> Vec<Record> {
    records(text, &columns())
}

fn undisturbed() -> PairResponse {
    response(records(X8ROLL, &columns())).0
}

/// `disturbed` against the undisturbed file's response: median dB and degrees.
fn against_undisturbed(disturbed: &PairResponse, label: &str) -> (f64, f64) {
    let reference = undisturbed();
    let (db, deg, count) = median_difference(disturbed, as_reference(&reference));
    eprintln!(
        "{label}: median {db:.4} dB, {deg:.3}° from the undisturbed file over {count} points"
    );
    assert!(count >= 150, "{label}: only {count} points compared");
    (db, deg)
}

#[test]
fn x8roll_as_it_is_matches_an_independent_scipy_estimate() {
    let records = records(X8ROLL, &columns());
    assert_eq!(records.len(), 1);
    assert_eq!(records[0].len(), 10649);
    assert!((records[0].sample_rate_hz - 99.976).abs() < 0.001);
    let (pair, notes) = response(records);
    // Nothing to say about this file: uniform, units given, swept input named.
    assert!(notes.iter().all(|n| !n.contains("x8roll.csv")), "{notes:?}");
    let (db, deg, count) = median_difference(&pair, scipy_h1);
    eprintln!(
        "x8roll rout → gx: valid {:?} rad/s; against scipy H1 over {count} points: median {db:.3} dB, {deg:.2}°",
        pair.valid_range
    );
    assert!(count >= 150, "only {count} points compared");
    assert!(db <= 0.3, "median {db:.3} dB");
    assert!(deg <= 2.0, "median {deg:.2}°");
}

#[test]
fn a_gyro_left_in_deg_per_s_gets_a_note_and_reads_35_db_high() {
    let no_unit = CsvColumns {
        units: Vec::new(),
        ..columns()
    };
    let (pair, notes) = response(records(X8ROLL, &no_unit));
    assert!(
        notes
            .iter()
            .any(|n| n.contains("`gx` peaks at 85.1") && n.contains("--units gx=deg/s")),
        "{notes:?}"
    );
    let reference = undisturbed();
    let offset = 20.0 * (180.0 / std::f64::consts::PI).log10(); // 35.16 dB
    for (a, b) in pair.mag_db.iter().zip(&reference.mag_db) {
        assert!((a - b - offset).abs() < 1e-6, "{a} − {b}");
    }
}

/// `column` of `rows` (uniform, step `step`) at time `t`, by Lanczos interpolation (8
/// lobes): the band-limited signal between the samples, as a logger sampling at `t` would
/// have read it.
fn lanczos(rows: &[[f64; 3]], column: usize, step: f64, t: f64) -> f64 {
    const LOBES: isize = 8;
    let x = (t - rows[0][0]) / step;
    let centre = x.floor() as isize;
    let sinc = |v: f64| {
        if v.abs() < 1e-12 {
            1.0
        } else {
            let a = std::f64::consts::PI * v;
            a.sin() / a
        }
    };
    (centre - LOBES + 1..=centre + LOBES)
        .map(|j| {
            let d = x - j as f64;
            let sample = rows[j.clamp(0, rows.len() as isize - 1) as usize][column];
            sample * sinc(d) * sinc(d / LOBES as f64)
        })
        .sum()
}

/// ±1 ms of jitter on every timestamp (uniform, seeded), the values those a logger would
/// have read at the jittered times.
#[test]
fn jittered_timestamps_are_resampled() {
    let rows = rows();
    let step = (rows[rows.len() - 1][0] - rows[0][0]) / (rows.len() - 1) as f64;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut jitter = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 0.002 - 0.001
    };
    let jittered: Vec<[f64; 3]> = (0..rows.len())
        .map(|k| {
            let t = rows[k][0] + jitter();
            let t = (t * 1e5).round() / 1e5;
            [t, lanczos(&rows, 1, step, t), lanczos(&rows, 2, step, t)]
        })
        .collect();
    let records = records(&text(&jittered), &columns());
    assert_eq!(records.len(), 1);
    assert!((records[0].sample_rate_hz - 99.976).abs() < 0.001);
    let notes = records[0].notes.join("\n");
    assert!(
        notes.contains("timestamps jitter") && notes.contains("resampled"),
        "{notes}"
    );
    let (db, deg) = against_undisturbed(&response(records).0, "±1 ms jitter");
    assert!(db <= 0.2 && deg <= 1.0, "{db} dB, {deg}°");
    // The same values taken as if they were on the uniform grid stray further.
    let as_uniform: Vec<[f64; 3]> = jittered
        .iter()
        .zip(&rows)
        .map(|(j, r)| [r[0], j[1], j[2]])
        .collect();
    let (db_u, deg_u) = against_undisturbed(
        &response(records_of(&text(&as_uniform))).0,
        "±1 ms jitter, not resampled",
    );
    assert!(db_u > db && deg_u > deg, "{db_u} dB, {deg_u}°");
}

#[test]
fn a_50_ms_gap_is_filled() {
    let mut rows = rows();
    rows.drain(4000..4005); // 5 samples: no sample for 50 ms after 39.99 s
    let records = records(&text(&rows), &columns());
    assert_eq!(records.len(), 1);
    assert_eq!(records[0].len(), 10649);
    let notes = records[0].notes.join("\n");
    assert!(
        notes.contains("1 gap(s) of up to 5 missing samples filled"),
        "{notes}"
    );
    let (db, deg) = against_undisturbed(&response(records).0, "50 ms gap");
    assert!(db <= 0.1 && deg <= 1.0, "{db} dB, {deg}°");
}

#[test]
fn a_nan_row_is_a_filled_sample() {
    let disturbed: String = X8ROLL
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == 3000 {
                let t = l.split(',').next().unwrap();
                format!("{t},nan,nan\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let records = records(&disturbed, &columns());
    assert_eq!(records.len(), 1);
    assert_eq!(records[0].len(), 10649);
    let notes = records[0].notes.join("\n");
    assert!(
        notes.contains(
            "1 row(s) with an empty or non-finite field left out as missing samples (line(s) 3001)"
        ) && notes.contains("1 gap(s) of up to 1 missing samples filled"),
        "{notes}"
    );
    let (db, deg) = against_undisturbed(&response(records).0, "nan row");
    assert!(db <= 0.05 && deg <= 0.5, "{db} dB, {deg}°");
}

#[test]
fn a_gap_longer_than_5_samples_splits_the_record() {
    let mut rows = rows();
    rows.drain(4000..4050); // 0.5 s
    let records = records(&text(&rows), &columns());
    assert_eq!(records.len(), 2);
    // On the grid of the file's mean step (10.0025 ms), the 4000 rows before the gap
    // (39.988 s) make 3998 samples.
    assert_eq!((records[0].len(), records[1].len()), (3998, 6600));
    let notes = records[0].notes.join("\n");
    assert!(notes.contains("split the file into 2 records"), "{notes}");
    let (db, deg) = against_undisturbed(&response(records).0, "0.5 s gap, split");
    assert!(db <= 0.3 && deg <= 2.0, "{db} dB, {deg}°");
}

#[test]
fn time_in_ms_or_us_is_detected_and_reads_as_in_seconds() {
    let reference = undisturbed();
    for (scale, unit) in [(1e3, "ms"), (1e6, "µs")] {
        let rows: Vec<[f64; 3]> = rows()
            .into_iter()
            .map(|[t, a, b]| [(t * scale * 1e4).round() / 1e4, a, b])
            .collect();
        let records = records(&text(&rows), &columns());
        let notes = records[0].notes.join("\n");
        assert!(notes.contains(&format!("read in {unit}")), "{notes}");
        assert!((records[0].sample_rate_hz - 99.976).abs() < 0.001);
        let pair = response(records).0;
        assert_eq!(pair.valid_range, reference.valid_range, "{unit}");
        for (a, b) in pair.mag_db.iter().zip(&reference.mag_db) {
            assert!((a - b).abs() < 1e-6, "{unit}: {a} dB, {b} dB");
        }
    }
}

#[test]
fn a_window_keeps_the_sweep() {
    let window = CsvColumns {
        window_s: Some([5.0, 75.0]),
        ..columns()
    };
    let records = records(X8ROLL, &window);
    let inside = rows()
        .iter()
        .filter(|r| (5.0..=75.0).contains(&r[0]))
        .count();
    assert_eq!(records[0].len(), inside);
    let (db, deg) = against_undisturbed(&response(records).0, "window 5–75 s");
    assert!(db <= 0.5 && deg <= 3.0, "{db} dB, {deg}°");
}
