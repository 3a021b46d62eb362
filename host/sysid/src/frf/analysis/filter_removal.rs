//! Dividing a known measurement filter out of a group's responses.
//!
//! When the flight controller filtered some outputs before logging them
//! ([`MeasurementFilter`]: a board's IMU filter bank), every response to those outputs
//! is the aircraft's times the filter's, `H_meas(ω) = H(ω)·F(ω)`, for the MISO-conditioned
//! and the SISO estimate alike (both are linear in the output). So
//!
//! ```text
//! |H| dB = |H_meas| dB − 20·log10|F(ω)|,     ∠H = ∠H_meas − ∠F(ω)
//! ```
//!
//! with ∠F unwrapped from 0 ([`MeasurementFilter::phase_rad`]). Coherence and random
//! error are ratios of the same spectra and do not change. Where the filter takes more
//! than half the signal away (|F| < 0.5, near a notch) the division would mostly amplify
//! noise: a pair's valid range ends below the first such frequency.

use crate::document::PairResponse;
use crate::records::MeasurementFilter;

use super::responses::anchor_phase_branch;

/// Below this |F| the responses are not trusted after the division.
pub(super) const MIN_FILTER_GAIN: f64 = 0.5;

/// Divide `filter` out of every pair of `pairs` whose output went through it; notes
/// what was done in `notes` (once per group).
pub(super) fn remove_measurement_filter(
    pairs: &mut [PairResponse],
    filter: &MeasurementFilter,
    axis: &str,
    notes: &mut Vec<String>,
) {
    let mut corrected = Vec::new();
    let mut clipped = Vec::new();
    for pair in pairs.iter_mut().filter(|p| filter.acts_on(&p.output)) {
        for (k, &omega) in pair.omega.iter().enumerate() {
            let gain = filter.response(omega).norm();
            pair.mag_db[k] -= 20.0 * gain.log10();
            pair.phase_deg[k] -= filter.phase_rad(omega).to_degrees();
        }
        if let (Some([lo, hi]), Some(&limit)) = (
            pair.valid_range,
            pair.omega
                .iter()
                .find(|&&w| filter.response(w).norm() < MIN_FILTER_GAIN),
        ) {
            if hi >= limit {
                let below = pair.omega.iter().rev().find(|&&w| w < limit && w >= lo);
                pair.valid_range = below.map(|&top| [lo, top]);
                clipped.push(format!("{}→{}", pair.input, pair.output));
            }
        }
        anchor_phase_branch(pair);
        if !corrected.contains(&pair.output) {
            corrected.push(pair.output.clone());
        }
    }
    if corrected.is_empty() {
        return;
    }
    let at = |hz: f64| {
        let omega = 2.0 * std::f64::consts::PI * hz;
        let response = filter.response(omega);
        format!(
            "{hz} Hz {:+.2} dB {:+.1}°",
            20.0 * response.norm().log10(),
            filter.phase_rad(omega).to_degrees()
        )
    };
    notes.push(format!(
        "{axis} records: the flight controller's measurement filter ({} sections at {} Hz; {}, {}, {}) divided out of the responses of {}",
        filter.sections.len(),
        filter.sample_rate_hz,
        at(1.0),
        at(5.0),
        at(10.0),
        corrected.join(" ")
    ));
    if !clipped.is_empty() {
        notes.push(format!(
            "{axis} records: valid ranges end below the measurement filter's first frequency with a gain under {MIN_FILTER_GAIN} for {}",
            clipped.join(" ")
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::records::measurement_filter::IMU_OUTPUTS;

    fn pair(output: &str, omega: Vec<f64>) -> PairResponse {
        let n = omega.len();
        PairResponse {
            input: "lat".into(),
            output: output.into(),
            mag_db: vec![0.0; n],
            phase_deg: vec![0.0; n],
            coherence: vec![0.9; n],
            random_error: vec![0.05; n],
            valid_range: Some([omega[0], omega[n - 1]]),
            omega,
            group: None,
            multiple_coherence: Vec::new(),
        }
    }

    /// A notch at 10 Hz (Q 3) at 1 kHz, the cookbook design, on the IMU outputs.
    fn notch_10hz() -> MeasurementFilter {
        let w0 = 2.0 * std::f64::consts::PI * 10.0 / 1000.0;
        let alpha = w0.sin() / 6.0;
        let a0 = 1.0 + alpha;
        MeasurementFilter {
            sample_rate_hz: 1000.0,
            sections: vec![[
                1.0 / a0,
                -2.0 * w0.cos() / a0,
                1.0 / a0,
                -2.0 * w0.cos() / a0,
                (1.0 - alpha) / a0,
            ]],
            outputs: IMU_OUTPUTS.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn divides_the_filter_out_of_filtered_outputs_only() {
        let filter = notch_10hz();
        let omega = vec![5.0, 20.0, 40.0];
        let mut pairs = vec![pair("p", omega.clone()), pair("u", omega.clone())];
        let mut notes = Vec::new();
        remove_measurement_filter(&mut pairs, &filter, "lat", &mut notes);
        for (k, &w) in omega.iter().enumerate() {
            let f = filter.response(w);
            assert!((pairs[0].mag_db[k] + 20.0 * f.norm().log10()).abs() < 1e-12);
            assert!((pairs[0].phase_deg[k] + f.arg().to_degrees()).abs() < 1e-9);
        }
        assert!(pairs[1].mag_db.iter().all(|&m| m == 0.0));
        assert!(pairs[1].phase_deg.iter().all(|&p| p == 0.0));
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("divided out of the responses of p"),
            "{notes:?}"
        );
    }

    #[test]
    fn valid_range_ends_below_a_notch() {
        // The 10 Hz notch (62.8 rad/s) lies inside a response measured to 80 rad/s.
        let filter = notch_10hz();
        let omega: Vec<f64> = (1..=80).map(f64::from).collect();
        let mut pairs = vec![pair("q", omega)];
        let mut notes = Vec::new();
        remove_measurement_filter(&mut pairs, &filter, "lon", &mut notes);
        let [lo, hi] = pairs[0].valid_range.unwrap();
        assert_eq!(lo, 1.0);
        assert!(filter.response(hi).norm() >= MIN_FILTER_GAIN, "top {hi}");
        assert!(
            filter.response(hi + 1.0).norm() < MIN_FILTER_GAIN,
            "top {hi}"
        );
        assert_eq!(notes.len(), 2, "{notes:?}");
    }
}
