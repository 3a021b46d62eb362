//! Acceptance of the responses to every excited input (MISO, CIFER's MISOSA) against an
//! outside simulator: `tests/data/two_input.csv`, written by scipy
//! (`tests/data/make_two_input_csv.py`), holds two correlated inputs `lat` and `lon`
//! driving the roll rate `p` through known transfer functions. Both conditioned
//! responses must match the exact ones within 1 dB and 5° over 0.5–20 rad/s wherever
//! their partial coherence is at least 0.6.

use num_complex::Complex64;
use sysid::document::{FrfDocument, PairResponse};
use sysid::frf::{analyse, group_by_primary, FrfOptions};
use sysid::records::{load_csv, CsvColumns};

const CSV: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/two_input.csv");
const BAND: [f64; 2] = [0.5, 20.0];
const MIN_COHERENCE: f64 = 0.6;
const MAX_DB: f64 = 1.0;
const MAX_DEG: f64 = 5.0;

/// H_lat(s) = (12 s + 60)/(s² + 6 s + 60)·e^(−0.04 s), as in make_two_input_csv.py.
fn lat_to_p(omega: f64) -> Complex64 {
    let s = Complex64::new(0.0, omega);
    (12.0 * s + 60.0) / (s * s + 6.0 * s + 60.0) * (-0.04 * s).exp()
}

/// H_lon(s) = −(2 s + 2)/(s + 4), as in make_two_input_csv.py.
fn lon_to_p(omega: f64) -> Complex64 {
    let s = Complex64::new(0.0, omega);
    -(2.0 * s + 2.0) / (s + 4.0)
}

/// Largest |error| in dB and degrees (phase difference wrapped to ±180°) against `exact`
/// over the pair's points in `BAND` with coherence ≥ `MIN_COHERENCE`, and how many.
fn errors(pair: &PairResponse, exact: fn(f64) -> Complex64) -> (f64, f64, usize) {
    let (mut db, mut deg, mut count) = (0.0f64, 0.0f64, 0);
    for k in 0..pair.omega.len() {
        let omega = pair.omega[k];
        if !(BAND[0]..=BAND[1]).contains(&omega) || pair.coherence[k] < MIN_COHERENCE {
            continue;
        }
        let h = exact(omega);
        db = db.max((pair.mag_db[k] - 20.0 * h.norm().log10()).abs());
        let mut d = pair.phase_deg[k] - h.arg().to_degrees();
        d -= 360.0 * (d / 360.0).round();
        deg = deg.max(d.abs());
        count += 1;
    }
    (db, deg, count)
}

fn document() -> FrfDocument {
    let columns = CsvColumns {
        time: "t".into(),
        inputs: vec![("lat".into(), "lat".into()), ("lon".into(), "lon".into())],
        outputs: vec![("p".into(), "p".into())],
        ..CsvColumns::default()
    };
    let record = load_csv(CSV, &columns).expect("two_input.csv reads");
    // No primary column, nothing named: the most active input, `lat`, is taken as the
    // swept one, and the record is treated as exciting several inputs.
    assert_eq!(record.primary, "lat");
    assert!(record.primary_guessed);
    let options = FrfOptions {
        band: Some(BAND),
        ..FrfOptions::default()
    };
    analyse(&group_by_primary(vec![record]).unwrap(), &options)
        .expect("frf")
        .document
}

#[test]
fn both_conditioned_responses_match_the_exact_transfer_functions() {
    let document = document();
    let grid = FrfOptions::default().points; // log-spaced over BAND
    for (input, exact) in [("lat", lat_to_p as fn(f64) -> Complex64), ("lon", lon_to_p)] {
        let pair = document.pair(input, "p").expect("pair");
        let (db, deg, count) = errors(pair, exact);
        eprintln!(
            "{input} → p (MISO): {count}/{grid} points compared, worst {db:.3} dB, {deg:.2}°"
        );
        assert!(
            count * 10 >= grid * 8,
            "{input}: only {count} points compared"
        );
        assert!(db <= MAX_DB, "{input} → p: {db:.3} dB off");
        assert!(deg <= MAX_DEG, "{input} → p: {deg:.2}° off");
        // Each pair names its record group and carries the output's multiple coherence,
        // which is never below the pair's partial coherence (the inputs together explain
        // at least what one of them explains with the other removed).
        assert_eq!(pair.group.as_deref(), Some("lat"));
        assert_eq!(pair.multiple_coherence.len(), pair.omega.len());
        for (partial, multiple) in pair.coherence.iter().zip(&pair.multiple_coherence) {
            assert!(partial <= &(multiple + 1e-9), "{partial} > {multiple}");
        }
    }
    // The check can fail: the single-input estimate of lat → p, which ignores that lon
    // moves with lat, misses the exact response by far more (measured: 4.1 dB, 32°).
    let siso = document
        .siso
        .iter()
        .find(|p| p.input == "lat" && p.output == "p")
        .unwrap();
    let (db, deg, count) = errors(siso, lat_to_p);
    eprintln!("lat → p (SISO): {count} points compared, worst {db:.3} dB, {deg:.2}°");
    assert!(db > 2.0 * MAX_DB && deg > 2.0 * MAX_DEG, "{db} dB {deg}°");
}
