//! Reference (instrumental-variable) estimate of the conditioned responses at one
//! frequency, for records flown with a feedback controller in the loop.
//!
//! With the conditional attitude hold engaged, the swept control u_p carries the hold
//! controller's answer to everything the aircraft does, including the part v of the
//! measured output that is not a linear response to the controls (sensor noise, gusts,
//! nonlinearity). Then u_p and v are correlated and the cross-spectral estimate
//! `G_uu·H = G_uy` ([`miso`]) is pulled towards the inverse of the controller. The flight
//! controller also records the excitation it injected into u_p (the sweep, not the
//! hold's share), which is independent of v. With instruments z — that recorded
//! excitation for the swept control, each other control for itself — cross-spectra with
//! z instead of u give
//!
//! ```text
//!     G_zy = G_zu · H        G_zu[i][j] = G_{z_i u_j},  G_zy[i] = G_{z_i y}
//! ```
//!
//! (y = Σ_j H_j u_j + v, multiplied by conj(z_i) and averaged; for the swept control's
//! row the v term averages out). The other controls are their own instruments because
//! their recorded excitation, the off-axis noise, is weak next to their holds' output:
//! as instruments they multiply the scatter (measured over 20 seeded campaigns,
//! docs/decisions/2026-11-21-sweep-reference-estimator.md).
//! G_zu is not Hermitian, so it is solved by LU with partial pivoting, on the normalised
//! matrix `Â = D_z^{-1/2} G_zu D_u^{-1/2}` whose entries satisfy |Â_ij|² = coherence of z_i
//! with u_j ≤ 1. A pivot with |p|² below `min_pivot` means the instruments do not drive
//! the controls independently at this frequency (e.g. the hold was engaged through the
//! whole window): the solve is refused.
//!
//! Variance: the error of the estimate is δH = G_zu⁻¹·G_zv, whose covariance is
//! `G_zu⁻¹ G_zz G_zu⁻ᴴ · G_vv` (per averaged window), against `G_uu⁻¹ · G_vv` for the
//! cross-spectral estimate. For the primary (last) input, with b the last row of
//! G_zu⁻¹, the variance ratio is
//!
//! ```text
//!     var(H_z) / var(H₁) = (b · G_zz · bᴴ) · G_pp·u     (≥ 1)
//! ```
//!
//! (G_pp·u = 1/[G_uu⁻¹]_pp, the primary's autospectrum conditioned on the other inputs,
//! [`InputFactor::conditioned_primary`](super::miso::InputFactor::conditioned_primary)).
//! With one input this is 1/γ²_zu, the textbook efficiency loss of an instrumental
//! variable. The random error of the reference estimate is εr(H₁)·√ratio
//! ([`ReferenceSolve::variance_ratio`]), so the composite leans on the windows where the
//! sweep drives the control.
//!
//! [`miso`]: super::miso

use num_complex::Complex64;

use super::miso::{IllConditioned, MAX_INPUTS};

/// LU factors of the normalised instrument–input matrix at one frequency.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceSolve {
    n: usize,
    /// √G_{z_i z_i}.
    instrument_scale: [f64; MAX_INPUTS],
    /// √G_{u_j u_j}.
    input_scale: [f64; MAX_INPUTS],
    /// Combined L (unit diagonal, below) and U (on and above) of P·Â.
    lu: [[Complex64; MAX_INPUTS]; MAX_INPUTS],
    /// Row order: row i of P·Â is row `rows[i]` of Â.
    rows: [usize; MAX_INPUTS],
    /// b·G_zz·bᴴ with b the last row of G_zu⁻¹ (module docs).
    primary_variance: f64,
}

impl ReferenceSolve {
    /// Factor from `gzu` (n×n row-major, `gzu[i·n + j]` = G_{z_i u_j}), the instruments'
    /// spectral matrix `gzz` (n×n row-major, G_{z_i z_j}) and the input autospectra
    /// `guu` (length n).
    // LU reads best with the matrix indices written out.
    #[allow(clippy::needless_range_loop)]
    pub fn new(
        gzu: &[Complex64],
        gzz: &[Complex64],
        guu: &[f64],
        n: usize,
        min_pivot: f64,
    ) -> Result<ReferenceSolve, IllConditioned> {
        if !(1..=MAX_INPUTS).contains(&n) || gzu.len() < n * n || gzz.len() < n * n || guu.len() < n
        {
            return Err(IllConditioned { pivot: 0.0 });
        }
        let mut instrument_scale = [0.0; MAX_INPUTS];
        let mut input_scale = [0.0; MAX_INPUTS];
        for i in 0..n {
            let r = gzz[i * n + i].re;
            if !(r > 0.0 && r.is_finite() && guu[i] > 0.0 && guu[i].is_finite()) {
                return Err(IllConditioned { pivot: 0.0 });
            }
            instrument_scale[i] = r.sqrt();
            input_scale[i] = guu[i].sqrt();
        }
        let zero = Complex64::new(0.0, 0.0);
        let mut lu = [[zero; MAX_INPUTS]; MAX_INPUTS];
        for i in 0..n {
            for j in 0..n {
                lu[i][j] = gzu[i * n + j] / (instrument_scale[i] * input_scale[j]);
            }
        }
        let mut rows = [0, 1, 2, 3];
        for col in 0..n {
            let best = (col..n)
                .max_by(|&a, &b| lu[a][col].norm_sqr().total_cmp(&lu[b][col].norm_sqr()))
                .unwrap_or(col);
            let pivot = lu[best][col].norm_sqr();
            if pivot.is_nan() || pivot < min_pivot {
                return Err(IllConditioned { pivot });
            }
            lu.swap(col, best);
            rows.swap(col, best);
            for i in col + 1..n {
                let factor = lu[i][col] / lu[col][col];
                lu[i][col] = factor;
                for j in col + 1..n {
                    let above = lu[col][j];
                    lu[i][j] -= factor * above;
                }
            }
        }
        let mut solve = ReferenceSolve {
            n,
            instrument_scale,
            input_scale,
            lu,
            rows,
            primary_variance: 0.0,
        };
        // b = last row of G_zu⁻¹: b_j = (G_zu⁻¹·e_j)_last.
        let mut b = [zero; MAX_INPUTS];
        let mut unit = [zero; MAX_INPUTS];
        for j in 0..n {
            unit[j] = Complex64::new(1.0, 0.0);
            b[j] = solve.solve(&unit)[n - 1];
            unit[j] = zero;
        }
        let mut variance = 0.0;
        for i in 0..n {
            for j in 0..n {
                variance += (b[i] * gzz[i * n + j] * b[j].conj()).re;
            }
        }
        if !(variance.is_finite() && variance > 0.0) {
            return Err(IllConditioned { pivot: 0.0 });
        }
        solve.primary_variance = variance;
        Ok(solve)
    }

    /// Solve G_zu·H = `gzy` (G_{z_i y}, length n) for H.
    #[allow(clippy::needless_range_loop)]
    pub fn solve(&self, gzy: &[Complex64]) -> [Complex64; MAX_INPUTS] {
        let n = self.n;
        let zero = Complex64::new(0.0, 0.0);
        // Â·x = D_z^{-1/2}·g with x = D_u^{1/2}·H; rows permuted as in the factors.
        let mut z = [zero; MAX_INPUTS];
        for i in 0..n {
            let row = self.rows[i];
            let mut v = gzy[row] / self.instrument_scale[row];
            for k in 0..i {
                v -= self.lu[i][k] * z[k];
            }
            z[i] = v;
        }
        for i in (0..n).rev() {
            let mut v = z[i];
            for k in i + 1..n {
                v -= self.lu[i][k] * z[k];
            }
            z[i] = v / self.lu[i][i];
        }
        for j in 0..n {
            z[j] /= self.input_scale[j];
        }
        z
    }

    /// var(H_z)/var(H₁) of the primary response, given G_pp·u (the primary's
    /// autospectrum conditioned on the other inputs); at least 1 (module docs).
    pub fn variance_ratio(&self, conditioned_primary: f64) -> f64 {
        (self.primary_variance * conditioned_primary).max(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    /// Cross-spectra Σ conj(a)·b over explicit "windows".
    fn cross(a: &[Complex64], b: &[Complex64]) -> Complex64 {
        a.iter().zip(b).map(|(a, b)| a.conj() * b).sum()
    }

    /// A closed loop in the frequency domain, window by window: u = r − K·y_measured,
    /// y = H·u + v (v: noise the controller sees). The cross-spectral estimate G_uy/G_uu
    /// is biased towards −1/K; the reference estimate recovers H.
    #[test]
    fn closed_loop_response_is_recovered_where_the_cross_spectral_estimate_is_biased() {
        let h = c(0.8, -0.6);
        let k = c(1.5, 0.2);
        let windows = 4000;
        // Deterministic pseudo-random phases for r and v.
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut r = Vec::new();
        let mut u = Vec::new();
        let mut y = Vec::new();
        for _ in 0..windows {
            let ri = Complex64::from_polar(1.0, std::f64::consts::TAU * next());
            let vi = Complex64::from_polar(0.7, std::f64::consts::TAU * next());
            // u = r − K(Hu + v)  ⇒  u = (r − K v)/(1 + K H)
            let ui = (ri - k * vi) / (c(1.0, 0.0) + k * h);
            r.push(ri);
            u.push(ui);
            y.push(h * ui + vi);
        }
        let h1 = cross(&u, &y) / cross(&u, &u).re;
        assert!((h1 - h).norm() > 0.2, "the test needs a biased H1: {h1}");
        let (gru, grr, guu) = (cross(&r, &u), cross(&r, &r), cross(&u, &u).re);
        let solve = ReferenceSolve::new(&[gru], &[grr], &[guu], 1, 1e-3).unwrap();
        let estimate = solve.solve(&[cross(&r, &y)])[0];
        assert!((estimate - h).norm() < 0.05, "{estimate} vs {h}");
        // One input: the variance ratio is 1/γ²_ru.
        let coherence = gru.norm_sqr() / (grr.re * guu);
        let ratio = solve.variance_ratio(guu);
        assert!(
            (ratio * coherence - 1.0).abs() < 1e-9,
            "{ratio} vs 1/{coherence}"
        );
    }

    #[test]
    fn exact_multi_input_relation_is_recovered() {
        // u = M·r (mixing, not Hermitian), y = Σ H_j u_j exactly.
        let h_true = [c(1.0, -0.5), c(-0.3, 0.2), c(2.0, 1.0)];
        let mix = [
            [c(1.0, 0.0), c(0.4, 0.1), c(0.0, 0.0)],
            [c(0.2, -0.3), c(1.0, 0.0), c(0.5, 0.0)],
            [c(0.0, 0.0), c(0.6, 0.2), c(0.1, 0.0)], // primary mostly driven by r_1
        ];
        let windows: Vec<[Complex64; 3]> = (0..8)
            .map(|k| {
                let k = k as f64;
                [
                    c(k.sin() + 1.0, k.cos()),
                    c(0.5 * k, -1.0),
                    c((2.0 * k).cos(), 0.3 * k),
                ]
            })
            .collect();
        let (mut gru, mut grr, mut guu, mut gry) = (
            vec![c(0.0, 0.0); 9],
            vec![c(0.0, 0.0); 9],
            [0.0; 3],
            [c(0.0, 0.0); 3],
        );
        for r in &windows {
            let u: Vec<Complex64> = (0..3)
                .map(|j| (0..3).map(|i| mix[j][i] * r[i]).sum())
                .collect();
            let y: Complex64 = (0..3).map(|j| h_true[j] * u[j]).sum();
            for i in 0..3 {
                guu[i] += u[i].norm_sqr();
                gry[i] += r[i].conj() * y;
                for j in 0..3 {
                    gru[i * 3 + j] += r[i].conj() * u[j];
                    grr[i * 3 + j] += r[i].conj() * r[j];
                }
            }
        }
        let solve = ReferenceSolve::new(&gru, &grr, &guu, 3, 1e-6).unwrap();
        let h = solve.solve(&gry);
        for j in 0..3 {
            assert!(
                (h[j] - h_true[j]).norm() < 1e-9,
                "{j}: {} vs {}",
                h[j],
                h_true[j]
            );
        }
        // The controls are exactly the mixed references (u = M·r), so the reference
        // estimate is as good as the cross-spectral one: the variance ratio is 1.
        let conditioned_primary = {
            let g: Vec<Complex64> = (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|(i, j)| {
                    windows
                        .iter()
                        .map(|r| {
                            let u: Vec<Complex64> = (0..3)
                                .map(|k| (0..3).map(|m| mix[k][m] * r[m]).sum())
                                .collect();
                            u[i].conj() * u[j]
                        })
                        .sum()
                })
                .collect();
            crate::frf::miso::InputFactor::new(&g, 3, 1e-9)
                .unwrap()
                .conditioned_primary()
        };
        let ratio = solve.variance_ratio(conditioned_primary);
        assert!((ratio - 1.0).abs() < 1e-6, "{ratio}");
    }

    #[test]
    fn a_reference_that_does_not_drive_its_control_is_refused() {
        // r never reaches u (the hold drove the control throughout).
        let gru = [c(1e-6, 0.0)];
        assert!(ReferenceSolve::new(&gru, &[c(1.0, 0.0)], &[1.0], 1, 1e-3).is_err());
        assert!(ReferenceSolve::new(&[c(1.0, 0.0)], &[c(0.0, 0.0)], &[1.0], 1, 1e-3).is_err());
    }
}
