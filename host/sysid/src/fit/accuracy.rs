//! Parameter accuracy at the converged fit: Cramér–Rao bounds, insensitivities and the
//! correlation matrix, from the Gauss–Newton Hessian of the cost.
//!
//! With r the weighted residuals of [`super::cost`] stacked over all pairs (so that
//! Σ r² = Σ_pairs J, the total cost, not J_ave) and J_r = ∂r/∂θ over the free parameters:
//!
//! ```text
//! H    = J_rᵀ J_r                       (Gauss–Newton Hessian, as CIFER forms it)
//! CR_i = √((H⁻¹)_ii)                     Cramér–Rao bound, in units of θ_i
//! I_i  = 1/√(H_ii)                       insensitivity: the change of θ_i alone that
//!                                        raises the total cost by one unit
//! ρ_ij = (H⁻¹)_ij / √((H⁻¹)_ii (H⁻¹)_jj) correlation
//! ```
//!
//! Reported in percent of |θ_i|: CR% = 100·CR_i/|θ_i|, I% = 100·I_i/|θ_i|. The weights
//! W_g = 1 dB⁻², W_p = 0.01745 deg⁻² play the role of inverse error variances (1 dB and
//! 7.57° count the same), and no further rescaling by the residual variance is applied,
//! so the guidelines CR ≤ 20 %, I ≤ 10 % read as in the paper and in Tischler & Remple.
//! Always I_i ≤ CR_i; CR_i ≫ I_i means θ_i is correlated with other parameters.

use nalgebra::DMatrix;

/// Accuracy of one free parameter, in the parameter's own units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterAccuracy {
    /// Cramér–Rao bound √((H⁻¹)_ii) (infinite when H is singular).
    pub cramer_rao: f64,
    /// Insensitivity 1/√(H_ii) (infinite when the cost does not depend on θ_i).
    pub insensitivity: f64,
}

/// The accuracy analysis of all free parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct AccuracyAnalysis {
    /// H = J_rᵀJ_r over the free parameters.
    pub hessian: DMatrix<f64>,
    /// Per free parameter, in the order of the Jacobian columns.
    pub parameters: Vec<ParameterAccuracy>,
    /// Correlation matrix (NaN everywhere when H is singular).
    pub correlation: DMatrix<f64>,
    /// True when H could not be inverted (some parameter combination does not affect
    /// the cost): CR bounds are infinite.
    pub singular: bool,
}

/// Analyse the Jacobian of the weighted residuals at the minimum.
pub fn analyse(jacobian: &DMatrix<f64>) -> AccuracyAnalysis {
    let hessian = jacobian.tr_mul(jacobian);
    let n = hessian.nrows();
    let insensitivity: Vec<f64> = (0..n)
        .map(|i| {
            let h = hessian[(i, i)];
            if h > 0.0 {
                1.0 / h.sqrt()
            } else {
                f64::INFINITY
            }
        })
        .collect();
    // Invert through the correlation form D⁻½ H D⁻½ (unit diagonal) so that parameters of
    // very different size do not spoil the Cholesky factorisation.
    let scale: Vec<f64> = (0..n).map(|i| hessian[(i, i)].sqrt()).collect();
    let normalized_ok = scale.iter().all(|&s| s > 0.0 && s.is_finite());
    let covariance = normalized_ok
        .then(|| {
            let normalized = DMatrix::from_fn(n, n, |i, j| hessian[(i, j)] / (scale[i] * scale[j]));
            normalized.cholesky().and_then(|c| {
                // A pivot² below 1e−13 of the unit diagonal means a combination of
                // parameters the cost cannot see (numerically singular).
                let smallest_pivot = c
                    .l_dirty()
                    .diagonal()
                    .iter()
                    .fold(f64::INFINITY, |a, &b| a.min(b));
                (smallest_pivot * smallest_pivot > 1e-13).then(|| {
                    let inverse = c.inverse();
                    DMatrix::from_fn(n, n, |i, j| inverse[(i, j)] / (scale[i] * scale[j]))
                })
            })
        })
        .flatten()
        .filter(|c| (0..n).all(|i| c[(i, i)] > 0.0 && c[(i, i)].is_finite()));
    match covariance {
        Some(covariance) => {
            let parameters = (0..n)
                .map(|i| ParameterAccuracy {
                    cramer_rao: covariance[(i, i)].sqrt(),
                    insensitivity: insensitivity[i],
                })
                .collect();
            let correlation = DMatrix::from_fn(n, n, |i, j| {
                covariance[(i, j)] / (covariance[(i, i)] * covariance[(j, j)]).sqrt()
            });
            AccuracyAnalysis {
                hessian,
                parameters,
                correlation,
                singular: false,
            }
        }
        None => AccuracyAnalysis {
            parameters: insensitivity
                .iter()
                .map(|&insensitivity| ParameterAccuracy {
                    cramer_rao: f64::INFINITY,
                    insensitivity,
                })
                .collect(),
            correlation: DMatrix::from_element(n, n, f64::NAN),
            hessian,
            singular: true,
        },
    }
}

/// A bound in percent of |value| (infinite for a zero value).
pub fn percent_of(bound: f64, value: f64) -> f64 {
    if value == 0.0 {
        f64::INFINITY
    } else {
        100.0 * bound / value.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::cost::{build_pair_grids, coherence_weight, residuals_and_jacobian};
    use crate::fit::structure::ModelStructure;
    use crate::fit::test_support::synthetic_document;

    #[test]
    fn one_parameter_gain_has_the_analytic_bound() {
        // ẋ = −x + b u, y = x: T = b/(s + 1). Only |T|_dB depends on b, with
        // ∂|T|_dB/∂b = 20/(ln10·b); the phase does not. Over n points at coherence 1:
        // H = Σ (20/n)·W_γ·W_g·(20/(ln10·b))² = 20·W_γ·(20/(ln10·b))², so
        // CR = I = 1/√H = ln10·b / (20·√(20·W_γ)), i.e. CR% = 100·ln10/(20·√(20·W_γ)).
        let text = r#"
name = "gain"
states = ["x"]
controls = ["u"]
outputs = ["x"]
pairs = [{ output = "x", input = "u", range = [0.2, 20.0] }]
[parameters]
b = 2.5
[F.x]
x = -1.0
[G.x]
u = "b"
"#;
        let structure = ModelStructure::parse(text, "gain.toml").unwrap();
        let truth = structure.model(&structure.values()).unwrap();
        let document = synthetic_document(&truth, &structure, 50);
        let grids = build_pair_grids(&structure, &document, 20).unwrap();
        let (_, jacobian) =
            residuals_and_jacobian(&structure, &structure.values(), &[0], &grids).unwrap();
        let analysis = analyse(&jacobian);
        let b = 2.5;
        let expected = std::f64::consts::LN_10 * b / (20.0 * (20.0 * coherence_weight(1.0)).sqrt());
        let accuracy = analysis.parameters[0];
        assert!(
            (accuracy.cramer_rao - expected).abs() < 1e-9 * expected,
            "{accuracy:?} vs {expected}"
        );
        assert!((accuracy.insensitivity - expected).abs() < 1e-9 * expected);
        let percent = percent_of(accuracy.cramer_rao, b);
        let expected_percent =
            100.0 * std::f64::consts::LN_10 / (20.0 * (20.0 * coherence_weight(1.0)).sqrt());
        assert!((percent - expected_percent).abs() < 1e-9);
        assert_eq!(analysis.correlation[(0, 0)], 1.0);
    }

    #[test]
    fn two_correlated_parameters() {
        // r = [θ1 + θ2, θ1 + 1.1 θ2]: H = [[2, 2.1], [2.1, 2.21]], strongly correlated.
        let jacobian = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.1]);
        let analysis = analyse(&jacobian);
        let h: DMatrix<f64> = DMatrix::from_row_slice(2, 2, &[2.0, 2.1, 2.1, 2.21]);
        let inverse = h.clone().try_inverse().unwrap();
        for i in 0..2 {
            assert!((analysis.parameters[i].cramer_rao - inverse[(i, i)].sqrt()).abs() < 1e-9);
            assert!((analysis.parameters[i].insensitivity - 1.0 / h[(i, i)].sqrt()).abs() < 1e-12);
            assert!(analysis.parameters[i].insensitivity < analysis.parameters[i].cramer_rao);
        }
        let rho = inverse[(0, 1)] / (inverse[(0, 0)] * inverse[(1, 1)]).sqrt();
        assert!((analysis.correlation[(0, 1)] - rho).abs() < 1e-9);
        assert!(analysis.correlation[(0, 1)] < -0.9);
        assert!(!analysis.singular);
    }

    #[test]
    fn singular_hessian_is_reported() {
        let jacobian = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        let analysis = analyse(&jacobian);
        assert!(analysis.singular);
        assert!(analysis.parameters[0].cramer_rao.is_infinite());
        let unused = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 1.0, 0.0]);
        let analysis = analyse(&unused);
        assert!(analysis.singular);
        assert!(analysis.parameters[1].insensitivity.is_infinite());
    }
}
