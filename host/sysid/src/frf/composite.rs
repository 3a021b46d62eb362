//! Composite window (CIFER COMPOSITE): one estimate per frequency from several window
//! lengths.
//!
//! At each frequency the window-length estimates are averaged with weights
//! `w_i = 1/εr_i²` (inverse variance): long windows dominate at low frequency, where
//! they alone resolve the response, short windows at high frequency, where they average
//! many more segments. The complex responses are averaged (not magnitude and phase
//! separately, which would fail near ±180°), and so are the coherences.
//!
//! The composite random error is the smallest εr among the contributing windows, not the
//! inverse-variance combination `1/√Σ(1/εr_i²)`: every window length is computed from
//! the same data, so their errors are strongly correlated and combining them as if
//! independent would overstate the accuracy.

use num_complex::Complex64;

/// One estimate of a response at one frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Response H.
    pub response: Complex64,
    /// Coherence γ² (ordinary or partial).
    pub coherence: f64,
    /// Random error εr.
    pub random_error: f64,
}

/// Smallest random error used for a weight: a noise-free estimate (γ² = 1, εr = 0) gets
/// a large but finite weight.
const MIN_RANDOM_ERROR: f64 = 1e-9;

/// Blend estimates by inverse squared random error; `None` when there are none.
pub fn blend(estimates: impl IntoIterator<Item = Estimate>) -> Option<Estimate> {
    let mut weight_sum = 0.0;
    let mut response = Complex64::new(0.0, 0.0);
    let mut coherence = 0.0;
    let mut best_error = f64::INFINITY;
    for e in estimates {
        let sigma = e.random_error.max(MIN_RANDOM_ERROR);
        let weight = 1.0 / (sigma * sigma);
        weight_sum += weight;
        response += e.response * weight;
        coherence += e.coherence * weight;
        best_error = best_error.min(e.random_error);
    }
    (weight_sum > 0.0 && weight_sum.is_finite()).then(|| Estimate {
        response: response / weight_sum,
        coherence: coherence / weight_sum,
        random_error: best_error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(re: f64, coherence: f64, random_error: f64) -> Estimate {
        Estimate {
            response: Complex64::new(re, 0.0),
            coherence,
            random_error,
        }
    }

    #[test]
    fn weights_follow_inverse_variance() {
        // Errors 0.1 and 0.2: weights 100 and 25.
        let out = blend([estimate(1.0, 0.9, 0.1), estimate(2.0, 0.5, 0.2)]).unwrap();
        assert!((out.response.re - (100.0 + 50.0) / 125.0).abs() < 1e-12);
        assert!((out.coherence - (90.0 + 12.5) / 125.0).abs() < 1e-12);
        assert_eq!(out.random_error, 0.1);
    }

    #[test]
    fn empty_and_perfect_inputs() {
        assert!(blend([]).is_none());
        let out = blend([estimate(3.0, 1.0, 0.0), estimate(0.0, 0.1, 1.0)]).unwrap();
        assert!((out.response.re - 3.0).abs() < 1e-12);
        assert!(out.coherence.is_finite() && out.random_error == 0.0);
    }
}
