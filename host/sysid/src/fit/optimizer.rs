//! Levenberg–Marquardt on weighted residuals, and the multi-start search around it.
//!
//! Minimises S(θ) = Σ r_k(θ)² (for the DERIVID cost S = Σ_pairs J = n_pairs·J_ave).
//! Each iteration solves the damped Gauss–Newton system with Marquardt's scaling
//!
//! ```text
//! (JᵀJ + λ D) δ = −Jᵀr,     D = diag(JᵀJ) at the current point
//! ```
//!
//! so the step does not depend on parameter units (Zcol ≈ −120 and Yv ≈ −0.03 move alike).
//! D is Marquardt's own, re-taken every iteration, not Moré's running maximum: a parameter
//! whose sensitivity was once large (a delay near a phase wrap, a coupling on its way
//! through a steep region) would otherwise stay damped by that maximum for the rest of the
//! run and crawl. Measured on the default Bo-105 campaign's 6-DOF fits, seeds 1–10
//! (`docs/decisions/2026-11-24-6dof-marquardt-scaling.md`): the best J_ave of 8 starts
//! is 9.9–14.3 instead of 18.8 and 13.6 on seeds 1 and 2, and some runs that all stopped
//! at the iteration limit converge.
//! Gain ratio ρ = (S(θ) − S(θ+δ)) / (−δᵀJᵀr + λ δᵀDδ) decides acceptance; λ follows
//! Nielsen's rule (λ ← λ·max(1/3, 1 − (2ρ − 1)³) on success, λ ← λ·ν, ν ← 2ν on failure).
//! Bounds are kept by projecting each trial point onto the box, and a parameter that sits
//! on its bound with the gradient pushing it outward is held there for the iteration (the
//! active set: its row and column leave the system, its step is zero). Without that the
//! unconstrained step is computed as if the parameter could move, then clipped, and the
//! other parameters' share of it is wrong; and the stationarity test would see the bound's
//! outward gradient and never stop. Stationarity is tested on the projected gradient.
//!
//! Multi-start (CIFER practice): run from the given start, then from seeded perturbed
//! starts, until the best minimum has been reached twice (same J_ave within a tolerance)
//! or the start budget is spent. The PRNG is SplitMix64, so a seed gives one result.

use nalgebra::{DMatrix, DVector};

use super::error::FitError;
use crate::random::SplitMix64;

/// Stopping rules of one Levenberg–Marquardt run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StoppingRules {
    /// Iteration limit (Jacobian evaluations).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers S by less than this fraction of S.
    pub relative_cost_change: f64,
    /// Stop when the scaled step ‖D^½ δ‖ is below this fraction of ‖D^½ θ‖.
    pub relative_step: f64,
    /// Stop when S falls below this (exact data).
    pub absolute_cost: f64,
    /// Stop when max_i |J_iᵀr| / (‖J_i‖·‖r‖) falls below this (a stationary point).
    pub gradient_orthogonality: f64,
}

impl Default for StoppingRules {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            relative_cost_change: 1e-10,
            relative_step: 1e-10,
            absolute_cost: 1e-24,
            gradient_orthogonality: 1e-10,
        }
    }
}

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The cost change of an accepted step fell below the tolerance.
    CostConverged,
    /// The step length fell below the tolerance.
    StepConverged,
    /// The cost reached the absolute floor (exact fit).
    ExactFit,
    /// The residual is orthogonal to the Jacobian columns (gradient test).
    Stationary,
    /// The iteration limit was reached.
    IterationLimit,
    /// λ grew without an acceptable step (a minimum to working precision).
    NoDescent,
}

/// Result of one run.
#[derive(Clone, Debug)]
pub struct RunOutcome {
    /// Final parameters.
    pub x: DVector<f64>,
    /// Final S = Σ r².
    pub cost: f64,
    /// Iterations used.
    pub iterations: usize,
    /// Why it stopped.
    pub reason: StopReason,
}

/// Box bounds (None = unbounded on that side).
#[derive(Clone, Debug, Default)]
pub struct Bounds {
    /// Lower bound per parameter.
    pub lower: Vec<Option<f64>>,
    /// Upper bound per parameter.
    pub upper: Vec<Option<f64>>,
}

impl Bounds {
    /// Whether parameter `i` of `x` sits on a bound that `gradient` (of S) pushes it
    /// against: a descent step −gradient would leave the box there.
    pub fn holds(&self, x: &DVector<f64>, gradient: &DVector<f64>, i: usize) -> bool {
        let at_lower = matches!(self.lower.get(i), Some(Some(lo)) if x[i] <= *lo);
        let at_upper = matches!(self.upper.get(i), Some(Some(hi)) if x[i] >= *hi);
        (at_lower && gradient[i] > 0.0) || (at_upper && gradient[i] < 0.0)
    }

    /// Clamp `x` into the box.
    pub fn project(&self, x: &mut DVector<f64>) {
        for i in 0..x.len() {
            if let Some(Some(lo)) = self.lower.get(i) {
                x[i] = x[i].max(*lo);
            }
            if let Some(Some(hi)) = self.upper.get(i) {
                x[i] = x[i].min(*hi);
            }
        }
    }
}

/// One Levenberg–Marquardt run. `evaluate(x, with_jacobian)` returns the residuals and,
/// when asked, the Jacobian. A trial point where evaluation fails (e.g. a singular
/// system) counts as a rejected step.
pub fn levenberg_marquardt<E>(
    mut evaluate: E,
    start: DVector<f64>,
    bounds: &Bounds,
    rules: &StoppingRules,
) -> Result<RunOutcome, FitError>
where
    E: FnMut(&DVector<f64>, bool) -> Result<(DVector<f64>, Option<DMatrix<f64>>), FitError>,
{
    let mut x = start;
    bounds.project(&mut x);
    let (mut residual, jacobian) = evaluate(&x, true)?;
    let mut jacobian = jacobian.expect("evaluate returns a Jacobian when asked");
    let mut cost = residual.norm_squared();
    let n = x.len();
    let mut scaling: DVector<f64> = DVector::from_element(n, 0.0);
    let mut lambda = -1.0;
    let mut nu = 2.0;
    let mut iterations = 0;
    let reason = loop {
        if cost <= rules.absolute_cost {
            break StopReason::ExactFit;
        }
        if iterations >= rules.max_iterations {
            break StopReason::IterationLimit;
        }
        iterations += 1;
        let normal = jacobian.tr_mul(&jacobian);
        let gradient = jacobian.tr_mul(&residual);
        let held: Vec<bool> = (0..n).map(|i| bounds.holds(&x, &gradient, i)).collect();
        // The system the steps of this iteration solve: a held parameter decoupled (its
        // row and column zero; its diagonal is set per λ below) with a zero right-hand side.
        let mut system = normal.clone();
        let mut descent = -&gradient;
        for i in (0..n).filter(|&i| held[i]) {
            system.row_mut(i).fill(0.0);
            system.column_mut(i).fill(0.0);
            descent[i] = 0.0;
        }
        // Stationarity (MINPACK's gtol) of the free parameters: the residual is orthogonal
        // to every Jacobian column, max_i |J_iᵀr| / (‖J_i‖·‖r‖) ≤ tolerance.
        let residual_norm = cost.sqrt();
        let orthogonality = (0..n)
            .map(|i| {
                let column_norm = normal[(i, i)].sqrt();
                if column_norm > 0.0 && !held[i] {
                    gradient[i].abs() / (column_norm * residual_norm)
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max);
        if orthogonality <= rules.gradient_orthogonality {
            break StopReason::Stationary;
        }
        for i in 0..n {
            // Marquardt's scaling at this point, floored for unused parameters.
            scaling[i] = normal[(i, i)].max(1e-30);
        }
        if lambda < 0.0 {
            // λ multiplies the scaled diagonal, so it is dimensionless: start mildly damped.
            lambda = 1e-3;
        }
        // Inner loop: raise λ until a step lowers the cost.
        let mut accepted = false;
        let mut step_small = false;
        while lambda < 1e16 {
            let mut damped = system.clone();
            for i in 0..n {
                // A held parameter's pivot is 1 whatever λ: its step is exactly zero.
                damped[(i, i)] = if held[i] {
                    1.0
                } else {
                    damped[(i, i)] + lambda * scaling[i]
                };
            }
            let Some(cholesky) = damped.cholesky() else {
                lambda *= nu;
                nu *= 2.0;
                continue;
            };
            let step = cholesky.solve(&descent);
            let mut trial = &x + &step;
            bounds.project(&mut trial);
            let actual_step = &trial - &x;
            let scaled_step: f64 = (0..n)
                .map(|i| scaling[i] * actual_step[i] * actual_step[i])
                .sum::<f64>()
                .sqrt();
            let scaled_x: f64 = (0..n).map(|i| scaling[i] * x[i] * x[i]).sum::<f64>().sqrt();
            // A tiny step only means convergence when it is close to the Gauss–Newton
            // step (λ ≲ 1); a heavily damped step is tiny because λ is large.
            if lambda <= 1.0
                && scaled_step <= rules.relative_step * (scaled_x + rules.relative_step)
            {
                step_small = true;
                break;
            }
            // Predicted reduction of the linear model: −δᵀg·2 − δᵀ(JᵀJ)δ.
            let predicted =
                -2.0 * actual_step.dot(&gradient) - actual_step.dot(&(&normal * &actual_step));
            match evaluate(&trial, false) {
                Ok((trial_residual, _)) => {
                    let trial_cost = trial_residual.norm_squared();
                    let rho = if predicted > 0.0 {
                        (cost - trial_cost) / predicted
                    } else {
                        -1.0
                    };
                    if trial_cost.is_finite() && trial_cost < cost && rho > 0.0 {
                        let previous = cost;
                        x = trial;
                        let (r, j) = evaluate(&x, true)?;
                        residual = r;
                        jacobian = j.expect("evaluate returns a Jacobian when asked");
                        cost = residual.norm_squared();
                        lambda *= (1.0 / 3.0f64).max(1.0 - (2.0 * rho - 1.0).powi(3));
                        nu = 2.0;
                        accepted = true;
                        if lambda <= 1.0 && previous - cost <= rules.relative_cost_change * previous
                        {
                            step_small = true;
                        }
                        break;
                    }
                }
                Err(FitError::SingularSystem { .. }) => {}
                Err(other) => return Err(other),
            }
            lambda *= nu;
            nu *= 2.0;
        }
        if step_small {
            break if accepted {
                StopReason::CostConverged
            } else {
                StopReason::StepConverged
            };
        }
        if !accepted {
            break StopReason::NoDescent;
        }
    };
    Ok(RunOutcome {
        x,
        cost,
        iterations,
        reason,
    })
}

/// A perturbed start: each value scaled by (1 + spread·U(−1, 1)); zeros get an additive
/// spread·U(−1, 1)·zero_scale. Projected onto the bounds.
pub fn perturbed_start(
    start: &DVector<f64>,
    spread: f64,
    zero_scale: f64,
    bounds: &Bounds,
    random: &mut SplitMix64,
) -> DVector<f64> {
    let mut x = start.map(|value| {
        let u = random.symmetric();
        if value == 0.0 {
            spread * u * zero_scale
        } else {
            value * (1.0 + spread * u)
        }
    });
    bounds.project(&mut x);
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock as residuals: r = [10 (y − x²), 1 − x], minimum at (1, 1).
    fn rosenbrock(
        p: &DVector<f64>,
        with_jacobian: bool,
    ) -> Result<(DVector<f64>, Option<DMatrix<f64>>), FitError> {
        let (x, y) = (p[0], p[1]);
        let r = DVector::from_vec(vec![10.0 * (y - x * x), 1.0 - x]);
        let j = with_jacobian.then(|| DMatrix::from_row_slice(2, 2, &[-20.0 * x, 10.0, -1.0, 0.0]));
        Ok((r, j))
    }

    #[test]
    fn solves_rosenbrock() {
        let outcome = levenberg_marquardt(
            rosenbrock,
            DVector::from_vec(vec![-1.2, 1.0]),
            &Bounds::default(),
            &StoppingRules::default(),
        )
        .unwrap();
        assert!((outcome.x[0] - 1.0).abs() < 1e-8, "{outcome:?}");
        assert!((outcome.x[1] - 1.0).abs() < 1e-8);
        assert!(outcome.iterations < 100);
    }

    #[test]
    fn respects_bounds() {
        // Minimum of (x − 3)² with x ≤ 2 is at the bound.
        let bounds = Bounds {
            lower: vec![None],
            upper: vec![Some(2.0)],
        };
        let outcome = levenberg_marquardt(
            |p: &DVector<f64>, with_jacobian: bool| {
                Ok((
                    DVector::from_vec(vec![p[0] - 3.0]),
                    with_jacobian.then(|| DMatrix::from_element(1, 1, 1.0)),
                ))
            },
            DVector::from_vec(vec![0.0]),
            &bounds,
            &StoppingRules::default(),
        )
        .unwrap();
        assert_eq!(outcome.x[0], 2.0);
        assert!((outcome.cost - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_parameter_held_on_its_bound_leaves_the_others_their_own_minimum() {
        // r = (x₀ − 3, x₁ − x₀ − 1) with x₀ ≤ 2: the minimum is x₀ = 2 on the bound and
        // x₁ = 3. The unconstrained step moves both (x₀ towards 3, x₁ with it); clipped,
        // it leaves x₁ short, and the run crawls (200 iterations, x₁ 3.014). Held on the
        // bound, x₀ drops out and x₁ takes its own minimum in a few steps.
        let bounds = Bounds {
            lower: vec![None, None],
            upper: vec![Some(2.0), None],
        };
        let outcome = levenberg_marquardt(
            |p: &DVector<f64>, with_jacobian: bool| {
                Ok((
                    DVector::from_vec(vec![p[0] - 3.0, p[1] - p[0] - 1.0]),
                    with_jacobian.then(|| DMatrix::from_row_slice(2, 2, &[1.0, 0.0, -1.0, 1.0])),
                ))
            },
            DVector::from_vec(vec![0.0, 0.0]),
            &bounds,
            &StoppingRules::default(),
        )
        .unwrap();
        assert_eq!(outcome.x[0], 2.0);
        assert!((outcome.x[1] - 3.0).abs() < 1e-9, "{:?}", outcome);
        assert!(outcome.iterations <= 5, "{:?}", outcome);
    }

    #[test]
    fn prng_is_deterministic_and_spread() {
        let mut a = SplitMix64::new(7);
        let mut b = SplitMix64::new(7);
        let draws: Vec<f64> = (0..1000).map(|_| a.symmetric()).collect();
        assert!(draws.iter().all(|&u| (-1.0..1.0).contains(&u)));
        assert!(draws
            .iter()
            .zip((0..1000).map(|_| b.symmetric()))
            .all(|(x, y)| *x == y));
        let mean = draws.iter().sum::<f64>() / 1000.0;
        assert!(mean.abs() < 0.1);
        assert!(draws.iter().any(|&u| u > 0.9) && draws.iter().any(|&u| u < -0.9));
    }
}
