//! Multi-input conditioning at one frequency (CIFER MISOSA).
//!
//! With inputs u (spectral matrix G_uu, n×n Hermitian) and one output y, the conditioned
//! responses solve
//!
//! ```text
//!     G_uu · H = G_uy                          (H_i: y per u_i, the others held)
//! ```
//!
//! by a Cholesky factorisation of the *normalised* matrix
//! `A = D^{-1/2} G_uu D^{-1/2}` (D = diag G_uu, so A has a unit diagonal), never an
//! explicit inverse. The squared Cholesky pivots of A are `1 − γ²` of each input with
//! the inputs before it, so a tiny pivot means nearly collinear inputs: the solve is
//! then refused ([`IllConditioned`]) instead of returning amplified noise.
//!
//! The primary (swept) input is ordered **last**. Its last pivot `d_n` then gives its
//! autospectrum conditioned on all other inputs, `G_pp·r = G_pp·d_n`, and
//!
//! ```text
//!     multiple coherence   γ²_y:u = Re(G_uy^H · H) / G_yy
//!     residual             G_yy·u = G_yy (1 − γ²_y:u)
//!     partial coherence    γ²_py·r = |H_p|² G_pp·r / (G_yy·u + |H_p|² G_pp·r)
//! ```
//!
//! (the last because `G_py·r = H_p G_pp·r` and `G_yy·r = G_yy·u + |G_py·r|²/G_pp·r`).

use num_complex::Complex64;

/// Most inputs a conditioning handles (the four controls).
pub const MAX_INPUTS: usize = 4;

/// The input spectral matrix was too close to singular.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IllConditioned {
    /// The offending normalised pivot (1 − γ² of one input with the others).
    pub pivot: f64,
}

/// Cholesky factor of the normalised input matrix at one frequency.
#[derive(Clone, Copy, Debug)]
pub struct InputFactor {
    n: usize,
    /// √G_ii.
    scale: [f64; MAX_INPUTS],
    /// Lower-triangular L with A = L·L^H.
    lower: [[Complex64; MAX_INPUTS]; MAX_INPUTS],
    /// G_pp·r: autospectrum of the last input conditioned on the others.
    last_conditioned: f64,
}

/// One conditioned estimate of the last (primary) input's response.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conditioned {
    /// H_p, the response to the primary input with the other inputs accounted for.
    pub response: Complex64,
    /// Partial coherence γ²_py·r.
    pub partial_coherence: f64,
    /// Multiple coherence γ²_y:u.
    pub multiple_coherence: f64,
}

impl InputFactor {
    /// Factor the n×n row-major Hermitian matrix `guu` (1 ≤ n ≤ [`MAX_INPUTS`]); refuse
    /// a normalised pivot below `min_pivot` (and a malformed matrix, as pivot 0).
    pub fn new(guu: &[Complex64], n: usize, min_pivot: f64) -> Result<InputFactor, IllConditioned> {
        if !(1..=MAX_INPUTS).contains(&n) || guu.len() < n * n {
            return Err(IllConditioned { pivot: 0.0 });
        }
        let mut scale = [0.0; MAX_INPUTS];
        for i in 0..n {
            let d = guu[i * n + i].re;
            if !(d > 0.0 && d.is_finite()) {
                return Err(IllConditioned { pivot: 0.0 });
            }
            scale[i] = d.sqrt();
        }
        let zero = Complex64::new(0.0, 0.0);
        let mut lower = [[zero; MAX_INPUTS]; MAX_INPUTS];
        let mut last_pivot = 1.0;
        for j in 0..n {
            // d_j = A_jj − Σ_{k<j} |L_jk|²  (A_jj = 1)
            let pivot = 1.0 - (0..j).map(|k| lower[j][k].norm_sqr()).sum::<f64>();
            if pivot.is_nan() || pivot < min_pivot {
                return Err(IllConditioned { pivot });
            }
            let diagonal = pivot.sqrt();
            lower[j][j] = Complex64::new(diagonal, 0.0);
            for i in j + 1..n {
                // L_ij = (A_ij − Σ_{k<j} L_ik·conj(L_jk)) / L_jj
                let a = guu[i * n + j] / (scale[i] * scale[j]);
                let sum: Complex64 = (0..j).map(|k| lower[i][k] * lower[j][k].conj()).sum();
                lower[i][j] = (a - sum) / diagonal;
            }
            last_pivot = pivot;
        }
        Ok(InputFactor {
            n,
            scale,
            lower,
            last_conditioned: last_pivot * scale[n - 1] * scale[n - 1],
        })
    }

    /// G_pp·r: the last (primary) input's autospectrum conditioned on the others,
    /// 1/[G_uu⁻¹]_pp.
    pub fn conditioned_primary(&self) -> f64 {
        self.last_conditioned
    }

    /// Solve G_uu·H = g for H (length n).
    // Triangular solves read best with the matrix indices written out.
    #[allow(clippy::needless_range_loop)]
    pub fn solve(&self, g: &[Complex64]) -> [Complex64; MAX_INPUTS] {
        let n = self.n;
        let zero = Complex64::new(0.0, 0.0);
        // A·z = D^{-1/2}·g, then H = D^{-1/2}·z.
        let mut z = [zero; MAX_INPUTS];
        for i in 0..n {
            let mut v = g[i] / self.scale[i];
            for k in 0..i {
                v -= self.lower[i][k] * z[k];
            }
            z[i] = v / self.lower[i][i].re;
        }
        for i in (0..n).rev() {
            let mut v = z[i];
            for k in i + 1..n {
                v -= self.lower[k][i].conj() * z[k];
            }
            z[i] = v / self.lower[i][i].re;
        }
        for i in 0..n {
            z[i] /= self.scale[i];
        }
        z
    }

    /// Condition one output: `guy` = G_{u_i y} (length n), `gyy` = G_yy > 0.
    pub fn condition(&self, guy: &[Complex64], gyy: f64) -> Conditioned {
        let h = self.solve(guy);
        let explained: f64 = (0..self.n).map(|i| (guy[i].conj() * h[i]).re).sum();
        let multiple = (explained / gyy).clamp(0.0, 1.0);
        let residual = gyy * (1.0 - multiple);
        let response = h[self.n - 1];
        let primary_part = response.norm_sqr() * self.last_conditioned;
        let partial = if primary_part + residual > 0.0 {
            (primary_part / (primary_part + residual)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Conditioned {
            response,
            partial_coherence: partial,
            multiple_coherence: multiple,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    /// G_uu = Σ_windows u*·uᵀ from explicit "window" vectors: always Hermitian PSD.
    fn spectral_matrix(windows: &[Vec<Complex64>]) -> Vec<Complex64> {
        let n = windows[0].len();
        let mut g = vec![c(0.0, 0.0); n * n];
        for w in windows {
            for i in 0..n {
                for j in 0..n {
                    g[i * n + j] += w[i].conj() * w[j];
                }
            }
        }
        g
    }

    #[test]
    fn exact_linear_relation_is_recovered_with_unit_coherence() {
        // y = Σ H_i u_i exactly in every window.
        let h_true = [c(1.0, -0.5), c(-0.3, 0.2), c(2.0, 1.0)];
        let windows: Vec<Vec<Complex64>> = (0..6)
            .map(|k| {
                let k = k as f64;
                vec![
                    c(k.sin() + 1.0, k.cos()),
                    c(0.5 * k, -1.0),
                    c((2.0 * k).cos(), 0.3 * k),
                ]
            })
            .collect();
        let guu = spectral_matrix(&windows);
        let ys: Vec<Complex64> = windows
            .iter()
            .map(|u| u.iter().zip(&h_true).map(|(u, h)| u * h).sum())
            .collect();
        let guy: Vec<Complex64> = (0..3)
            .map(|i| windows.iter().zip(&ys).map(|(u, y)| u[i].conj() * y).sum())
            .collect();
        let gyy: f64 = ys.iter().map(|y| y.norm_sqr()).sum();
        let factor = InputFactor::new(&guu, 3, 1e-6).unwrap();
        let h = factor.solve(&guy);
        for i in 0..3 {
            assert!(
                (h[i] - h_true[i]).norm() < 1e-10,
                "{i}: {} vs {}",
                h[i],
                h_true[i]
            );
        }
        let conditioned = factor.condition(&guy, gyy);
        assert!((conditioned.multiple_coherence - 1.0).abs() < 1e-9);
        assert!((conditioned.partial_coherence - 1.0).abs() < 1e-9);
    }

    #[test]
    fn collinear_inputs_are_refused() {
        let windows: Vec<Vec<Complex64>> = (0..5)
            .map(|k| {
                let u = c(k as f64 + 1.0, 0.5);
                vec![u, u * c(2.0, 0.0)]
            })
            .collect();
        let guu = spectral_matrix(&windows);
        assert!(InputFactor::new(&guu, 2, 1e-3).is_err());
        let zero_input = vec![c(1.0, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(0.0, 0.0)];
        assert!(InputFactor::new(&zero_input, 2, 1e-3).is_err());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// With one input the conditioning is the SISO H1 estimate and coherence.
        #[test]
        fn single_input_reduces_to_h1(
            gxx in 0.01f64..100.0,
            re in -10.0f64..10.0,
            im in -10.0f64..10.0,
            extra in 0.0f64..100.0,
        ) {
            let gxy = c(re, im);
            // Cauchy–Schwarz: G_yy ≥ |G_xy|²/G_xx.
            let gyy = gxy.norm_sqr() / gxx + extra + 1e-9;
            let factor = InputFactor::new(&[c(gxx, 0.0)], 1, 1e-3).unwrap();
            let out = factor.condition(&[gxy], gyy);
            prop_assert!((out.response - gxy / gxx).norm() <= 1e-12 * (1.0 + (gxy / gxx).norm()));
            let coherence = gxy.norm_sqr() / (gxx * gyy);
            prop_assert!((out.partial_coherence - coherence).abs() < 1e-9);
            prop_assert!((out.multiple_coherence - coherence).abs() < 1e-9);
        }
    }
}
