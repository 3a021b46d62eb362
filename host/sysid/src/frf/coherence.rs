//! Coherence-derived quantities: random error, the valid frequency range of a pair, and
//! the estimation bias of a coherence. The cross-control coherence of a sweep, which
//! uses them, is computed in [`analysis`](super::analysis).

/// Smallest coherence used in [`random_error`], so that the error stays finite.
const MIN_COHERENCE: f64 = 1e-12;

/// Normalised random error of a response estimate (Bendat & Piersol; Tischler):
///
/// ```text
///     εr = √(1 − γ²) / (|γ| · √(2·n_d))
/// ```
///
/// with γ² the (partial) coherence and n_d the number of independent windows. γ² is
/// clamped to [1e-12, 1] so the result is always finite.
pub fn random_error(coherence: f64, independent_windows: f64) -> f64 {
    let g2 = if coherence.is_finite() {
        coherence.clamp(MIN_COHERENCE, 1.0)
    } else {
        MIN_COHERENCE
    };
    ((1.0 - g2) / g2).sqrt() / (2.0 * independent_windows.max(1e-12)).sqrt()
}

/// Magnitude-squared coherence corrected for its estimation bias. An estimate from n_d
/// independent averages is biased upward, to first order (Carter, Knapp & Nuttall 1973;
/// Bendat & Piersol §9.2.3)
///
/// ```text
/// E[γ̂²] ≈ γ² + (1 − γ²)² / n_d
/// ```
///
/// so two unrelated signals read about 1/n_d (0.4 from a window half the record long).
/// Clipping at 0 leaves a floor of about 0.4/n_d on average for unrelated signals.
/// Solving that quadratic for γ² gives the estimate returned here: 0 when γ̂² ≤ 1/n_d,
/// nearly γ̂² when γ̂² is near 1 or n_d is large. Needs n_d > 2 (where the bias curve is
/// monotonic); returns `None` otherwise.
pub fn debiased_coherence(estimate: f64, independent_averages: f64) -> Option<f64> {
    let n = independent_averages;
    if n.is_nan() || n <= 2.0 || !estimate.is_finite() {
        return None;
    }
    let c = estimate.clamp(0.0, 1.0);
    let a = 1.0 / n;
    if c <= a {
        return Some(0.0);
    }
    // a·x² + (1 − 2a)·x + (a − c) = 0, the root in [0, 1].
    let b = 1.0 - 2.0 * a;
    let discriminant = (b * b - 4.0 * a * (a - c)).max(0.0);
    Some(((-b + discriminant.sqrt()) / (2.0 * a)).clamp(0.0, 1.0))
}

/// The valid range of a response: the band where `coherence ≥ threshold`.
///
/// Coherence usually dips here and there (a lightly damped zero, the sweep's ends), so
/// there may be several runs of valid points. One contiguous band is reported — the run
/// spanning the most octaves (largest ω_hi/ω_lo), the earlier one on a tie — because a
/// fit over a band with holes in it would weight points the data do not support. A run
/// needs at least two points. `omega` must be ascending; returns `[ω_lo, ω_hi]`.
pub fn valid_range(omega: &[f64], coherence: &[f64], threshold: f64) -> Option<[f64; 2]> {
    widest_run(omega, coherence.iter().map(|&c| c >= threshold))
}

/// [`valid_range`] with a second condition per point: the random error `ε_r` (see
/// [`random_error`]) at most `max_random_error` as well as `coherence ≥ threshold`.
/// `None` for `max_random_error` gives [`valid_range`].
pub fn accurate_range(
    omega: &[f64],
    coherence: &[f64],
    random_error: &[f64],
    threshold: f64,
    max_random_error: Option<f64>,
) -> Option<[f64; 2]> {
    let max = max_random_error.unwrap_or(f64::INFINITY);
    widest_run(
        omega,
        coherence
            .iter()
            .zip(random_error)
            .map(|(&c, &e)| c >= threshold && e <= max),
    )
}

/// The run of consecutive `true` flags spanning the most octaves (two points at least, the
/// earlier run on a tie), as `[ω_lo, ω_hi]`.
fn widest_run(omega: &[f64], flags: impl Iterator<Item = bool>) -> Option<[f64; 2]> {
    let mut best: Option<(f64, [f64; 2])> = None;
    let mut run_start: Option<usize> = None;
    // One step past the end closes a run that reaches the last point.
    let flags = flags.take(omega.len()).chain([false]);
    for (k, valid) in flags.enumerate() {
        match (valid, run_start) {
            (true, None) => run_start = Some(k),
            (false, Some(start)) => {
                run_start = None;
                let end = k - 1;
                if end > start {
                    let span = (omega[end] / omega[start]).ln();
                    if best.is_none_or(|(s, _)| span > s) {
                        best = Some((span, [omega[start], omega[end]]));
                    }
                }
            }
            _ => {}
        }
    }
    best.map(|(_, band)| band)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frf::spectra::welch_independent_averages;

    #[test]
    fn random_error_follows_the_formula() {
        // γ² = 0.8, n_d = 4: √0.2/(√0.8·√8) = 0.5/√8
        assert!((random_error(0.8, 4.0) - 0.5 / 8f64.sqrt()).abs() < 1e-12);
        assert_eq!(random_error(1.0, 3.0), 0.0);
        assert!(random_error(0.0, 3.0).is_finite());
        assert!(random_error(f64::NAN, 3.0).is_finite());
    }

    #[test]
    fn valid_range_picks_the_widest_run() {
        let omega = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 16.0];
        let coherence = [0.9, 0.9, 0.9, 0.2, 0.7, 0.7, 0.1, 0.9];
        // Runs: 1..3 (ln 3) and 5..6 (ln 1.2); a single point does not count.
        assert_eq!(valid_range(&omega, &coherence, 0.6), Some([1.0, 3.0]));
        assert_eq!(valid_range(&omega, &coherence, 0.95), None);
        assert_eq!(valid_range(&omega, &[0.7; 8], 0.6), Some([1.0, 16.0]));
    }

    #[test]
    fn accurate_range_also_bounds_the_random_error() {
        let omega = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 16.0];
        let coherence = [0.7; 8];
        let error = [0.3, 0.3, 0.1, 0.1, 0.1, 0.25, 0.1, 0.1];
        // Runs with ε_r ≤ 0.2: 3..5 (ln 5/3) and 8..16 (ln 2), the second is wider.
        assert_eq!(
            accurate_range(&omega, &coherence, &error, 0.6, Some(0.2)),
            Some([8.0, 16.0])
        );
        assert_eq!(
            accurate_range(&omega, &coherence, &error, 0.6, Some(0.3)),
            Some([1.0, 16.0])
        );
        assert_eq!(
            accurate_range(&omega, &coherence, &error, 0.6, Some(0.05)),
            None
        );
        // No bound: the coherence alone, as `valid_range`.
        assert_eq!(
            accurate_range(&omega, &coherence, &error, 0.6, None),
            valid_range(&omega, &coherence, 0.6)
        );
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
        /// The valid range is a run of valid points: every point inside it passes the
        /// threshold and it cannot be extended by a valid neighbour.
        #[test]
        fn valid_range_is_a_maximal_valid_run(
            coherence in proptest::collection::vec(0.0f64..1.0, 2..60),
            threshold in 0.1f64..0.9,
        ) {
            let omega: Vec<f64> = (0..coherence.len()).map(|k| 1.1f64.powi(k as i32)).collect();
            if let Some([lo, hi]) = valid_range(&omega, &coherence, threshold) {
                let first = omega.iter().position(|&w| w == lo).unwrap();
                let last = omega.iter().position(|&w| w == hi).unwrap();
                proptest::prop_assert!(last > first);
                proptest::prop_assert!(coherence[first..=last].iter().all(|&c| c >= threshold));
                proptest::prop_assert!(first == 0 || coherence[first - 1] < threshold);
                proptest::prop_assert!(last + 1 == omega.len() || coherence[last + 1] < threshold);
            } else {
                // No two neighbouring valid points anywhere.
                proptest::prop_assert!(coherence
                    .windows(2)
                    .all(|w| w[0] < threshold || w[1] < threshold));
            }
        }
    }

    #[test]
    fn debiasing_inverts_the_bias_model() {
        for n in [2.5, 5.0, 20.0, 100.0] {
            for truth in [0.0, 0.1, 0.3, 0.5, 0.8, 0.95, 1.0] {
                let biased = truth + (1.0f64 - truth).powi(2) / n;
                let back = debiased_coherence(biased, n).unwrap();
                assert!((back - truth).abs() < 1e-9, "n {n}, truth {truth}: {back}");
            }
            assert_eq!(debiased_coherence(0.5 / n, n), Some(0.0));
        }
        assert_eq!(debiased_coherence(0.5, 1.5), None);
        assert_eq!(debiased_coherence(f64::NAN, 10.0), None);
    }

    /// Two independent white noises: the raw coherence of a few-average estimate reads
    /// about 1/n_d; the debiased one about 0.
    #[test]
    fn debiasing_removes_the_floor_of_unrelated_signals() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut noise = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let a: Vec<f64> = (0..40_000).map(|_| noise()).collect();
        let b: Vec<f64> = (0..40_000).map(|_| noise()).collect();
        let n = 4000;
        let w: Vec<f64> = (0..n)
            .map(|i| {
                (std::f64::consts::PI * (i as f64 + 0.5) / n as f64)
                    .sin()
                    .powi(2)
            })
            .collect();
        let hop = n / 5;
        let (mut gaa, mut gbb, mut gab) = (
            vec![0.0; 200],
            vec![0.0; 200],
            vec![num_complex::Complex64::new(0.0, 0.0); 200],
        );
        let mut segments = 0;
        let mut start = 0;
        while start + n <= a.len() {
            for (bin, ((pa, pb), pab)) in gaa
                .iter_mut()
                .zip(gbb.iter_mut())
                .zip(gab.iter_mut())
                .enumerate()
            {
                let omega = std::f64::consts::TAU * (bin + 10) as f64 / n as f64;
                let dft = |x: &[f64]| {
                    x.iter().zip(&w).enumerate().fold(
                        num_complex::Complex64::new(0.0, 0.0),
                        |acc, (i, (v, wi))| {
                            acc + num_complex::Complex64::from_polar(v * wi, -omega * i as f64)
                        },
                    )
                };
                let (xa, xb) = (dft(&a[start..start + n]), dft(&b[start..start + n]));
                *pa += xa.norm_sqr();
                *pb += xb.norm_sqr();
                *pab += xa.conj() * xb;
            }
            segments += 1;
            start += hop;
        }
        let n_eq = welch_independent_averages(&w, hop, segments);
        let raw: f64 = (0..200)
            .map(|k| gab[k].norm_sqr() / (gaa[k] * gbb[k]))
            .sum::<f64>()
            / 200.0;
        let fixed: f64 = (0..200)
            .map(|k| debiased_coherence(gab[k].norm_sqr() / (gaa[k] * gbb[k]), n_eq).unwrap())
            .sum::<f64>()
            / 200.0;
        assert!(
            (raw - 1.0 / n_eq).abs() < 0.5 / n_eq,
            "raw {raw} vs 1/n_eq {}",
            1.0 / n_eq
        );
        // Estimates above 1/n_d stay positive after the correction: the mean keeps a
        // floor of about 0.4/n_eq instead of 1/n_eq.
        assert!(
            fixed < 0.5 * raw && fixed < 0.6 / n_eq,
            "debiased {fixed} vs raw {raw}"
        );
    }
}
