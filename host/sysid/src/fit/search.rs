//! The multi-start search: Levenberg–Marquardt from the structure's start values, then
//! from perturbed ones, until the same minimum is found twice ([`super::optimizer`]);
//! then the accuracy analysis and the report at the best minimum.
//!
//! With [`FitOptions::global_search`] the starts are a budget, all spent: after the
//! structure's values, half of them are drawn across the parameter box
//! ([`super::start_box`]) and the rest perturb the best minimum so far, by a spread that
//! widens while they find nothing lower ([`polish_spread`]); the minimum is
//! confirmed only when two independent starts (the structure's values or box draws, not
//! the perturbations of the best) reach it.

use nalgebra::{DMatrix, DVector};

use super::accuracy;
use super::cost::{self, PairGrid};
use super::error::FitError;
use super::optimizer;
use super::options::FitOptions;
use super::plausible;
use super::prior;
use super::result::parameter_reports;
use super::result::{FitResult, PairFit, StartOutcome};
use super::start_box;
use super::structure::ModelStructure;
use super::trim::{joint::JointBalance, TrimBalance, TrimError};

/// What a free parameter starting at exactly zero starts at instead (the first start;
/// the perturbed ones add spread·U(−1, 1)·0.1 to it).
const ZERO_START_NUDGE: f64 = 1e-3;

/// Base-parameter vector with the free entries replaced by `free_values`.
fn merge(base: &[f64], free: &[usize], free_values: &DVector<f64>) -> Vec<f64> {
    let mut values = base.to_vec();
    for (k, &index) in free.iter().enumerate() {
        values[index] = free_values[k];
    }
    values
}

/// The index of the best of `finals`: the lowest J_ave, and with `prefer_plausible` the
/// lowest among the plausible minima when there is one. A degenerate minimum (the R-50's
/// yaw-damper pole driven to 10¹⁴ /s, its gain with it, J_ave 21.6) can be lower than the
/// physical ones found so far; polishing it wastes the rest of the budget.
fn best_index(
    finals: &[(DVector<f64>, f64)],
    plausible: &[bool],
    prefer_plausible: bool,
) -> Option<usize> {
    let rank = |i: usize| {
        (
            prefer_plausible && !plausible.get(i).copied().unwrap_or(true),
            finals[i].1,
        )
    };
    (0..finals.len())
        .filter(|&i| finals[i].1.is_finite())
        .min_by(|&a, &b| {
            let (ra, rb) = (rank(a), rank(b));
            ra.0.cmp(&rb.0).then(ra.1.total_cmp(&rb.1))
        })
}

/// Decades beyond the box's edge within which a global search's minimum still counts as
/// plausible ([`near_the_box`]).
const BEYOND_THE_BOX_DECADES: f64 = 2.0;

/// Whether every free value of `x` lies within `decades` + [`BEYOND_THE_BOX_DECADES`] of
/// its start value's magnitude (a start of exactly 0 sets no scale). The start values are
/// the structure's orders of magnitude; the physical ranges ([`plausible`]) know only the
/// states they can name (u … r, φ, θ and flapping), and a state such as the R-50's yaw
/// damper r_fb is named by no rule: its pole slid to 10¹⁴ /s without a limit there.
fn near_the_box(x: &DVector<f64>, start: &DVector<f64>, decades: f64) -> bool {
    let limit = 10f64.powf(decades + BEYOND_THE_BOX_DECADES);
    x.iter()
        .zip(start.iter())
        .all(|(value, start)| *start == 0.0 || value.abs() <= limit * start.abs())
}

/// Polishes in a row without a lower best after which the global search's polishing
/// spread doubles ([`polish_spread`]).
const POLISHES_PER_DOUBLING: usize = 4;

/// The largest polishing spread of the global search (a factor 0.2–1.8 on each value:
/// the sign kept).
const MAX_POLISH_SPREAD: f64 = 0.8;

/// The spread of the global search's next polish: `base` (±10 % by default) while
/// polishing lowers the best minimum, doubled after every [`POLISHES_PER_DOUBLING`]
/// polishes in a row that did not, up to [`MAX_POLISH_SPREAD`]; back to `base` when one
/// does (the step size of a basin-hopping search, widened while it finds nothing). On the
/// R-50's noise-free records (`docs/published_model`, n_ω 80) fit seed 9's box draws
/// ended at J_ave 19.0 at best and ±10 % about it found only 19.0, 23.6 and 26.7 in its
/// 31 polishes, where seed 1 went 21.9 → 7.0 → 2.8.
fn polish_spread(base: f64, polishes_without_gain: usize) -> f64 {
    let doublings = (polishes_without_gain / POLISHES_PER_DOUBLING).min(16) as i32;
    (base * 2f64.powi(doublings)).min(MAX_POLISH_SPREAD.max(base))
}

/// Multi-start fit on prepared grids, then the accuracy analysis.
pub(crate) fn fit_on_grids(
    structure: &ModelStructure,
    grids: &[PairGrid],
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    let mut search = StartSearch::new(options.seed);
    search_minima(structure, grids, options, options.max_starts, &mut search)?;
    finish_fit(structure, grids, options, search)
}

/// The state of a multi-start search: where its random perturbations stand and what each
/// start reached, so that a search stopped after a share of the starts can go on where
/// it stopped ([`fit_from_alternative_starts`]) instead of repeating them.
#[derive(Clone, Debug)]
pub(super) struct StartSearch {
    random: crate::random::SplitMix64,
    /// Starts made so far (including those that could not be evaluated).
    attempts: usize,
    starts: Vec<StartOutcome>,
    /// Final parameter vector and J_ave of each evaluated start.
    finals: Vec<(DVector<f64>, f64)>,
    /// Whether each of `finals` came from an independent start (the structure's values or
    /// a draw across the box), as opposed to a perturbation of the best minimum so far.
    independent: Vec<bool>,
    /// Whether each of `finals` lies within the physical ranges ([`plausible`]); the
    /// global search ranks plausible minima before implausible ones.
    plausible: Vec<bool>,
    minimum_confirmed: bool,
    last_error: Option<FitError>,
    /// Global search: polishes in a row that did not lower the best J_ave
    /// ([`polish_spread`]).
    polishes_without_gain: usize,
}

impl StartSearch {
    pub(super) fn new(seed: u64) -> Self {
        StartSearch {
            random: crate::random::SplitMix64::new(seed),
            attempts: 0,
            starts: Vec::new(),
            finals: Vec::new(),
            independent: Vec::new(),
            plausible: Vec::new(),
            minimum_confirmed: false,
            last_error: None,
            polishes_without_gain: 0,
        }
    }
}

/// Levenberg–Marquardt from the structure's start values, then from perturbed ones (about
/// the start values for the first `explore_starts`, about the best minimum so far after
/// them), until the best minimum has been reached twice or `max_starts` starts have been
/// made in all.
pub(super) fn search_minima(
    structure: &ModelStructure,
    grids: &[PairGrid],
    options: &FitOptions,
    max_starts: usize,
    search: &mut StartSearch,
) -> Result<(), FitError> {
    let base = structure.values();
    let free = structure.free_indices();
    let n_pairs = grids.len() as f64;
    let bounds = optimizer::Bounds {
        lower: free
            .iter()
            .map(|&i| structure.parameters[i].lower)
            .collect(),
        upper: free
            .iter()
            .map(|&i| structure.parameters[i].upper)
            .collect(),
    };
    let rules = optimizer::StoppingRules {
        max_iterations: options.max_iterations,
        ..optimizer::StoppingRules::default()
    };
    let balance = joint_balance(structure, options)?;
    let evaluate = |x: &DVector<f64>, with_jacobian: bool| {
        let values = merge(&base, &free, x);
        if with_jacobian {
            let (r, j) = residuals_and_jacobian(structure, &values, &free, grids, &balance)?;
            Ok((r, Some(j)))
        } else {
            let model = structure.model(&values)?;
            let r = DVector::from_vec(cost::residuals(&model, grids)?);
            let r = match &balance {
                None => r,
                Some(balance) => {
                    let e = balance
                        .residuals(structure, &values)
                        .map_err(balance_error)?;
                    stack(&r, &e)
                }
            };
            // The priors' residuals last (`prior`), as with the Jacobian.
            let priors = prior::residuals_and_jacobian(structure, &values, &free).0;
            Ok((stack(&r, &priors), None))
        }
    };

    let first_start = DVector::from_iterator(free.len(), free.iter().map(|&i| base[i]));
    let tolerance = |a: f64, b: f64| {
        (a - b).abs() <= options.same_minimum_tolerance * a.abs().max(b.abs()).max(1.0)
    };
    let global = options.global_search;
    // Global search: starts 1 .. box_end are drawn across the box, the rest polish.
    let box_end = 1 + (max_starts.max(1) - 1) / 2;
    while (global || !search.minimum_confirmed) && search.attempts < max_starts.max(1) {
        let start_number = search.attempts;
        search.attempts += 1;
        let independent = start_number == 0 || (global && start_number < box_end);
        let start = if start_number == 0 {
            let mut x = first_start.clone();
            // A free parameter at exactly zero makes the responses it alone carries
            // exactly zero, −600 dB on the magnitude floor: J ~10⁶ and a log-magnitude
            // residual with no usable gradient, so the start goes nowhere (the 6-DOF
            // file's zero couplings: its first start ended at J_ave 1.8·10⁶, now 63).
            for value in x.iter_mut().filter(|value| **value == 0.0) {
                *value = ZERO_START_NUDGE;
            }
            bounds.project(&mut x);
            x
        } else if independent {
            start_box::draw(
                &first_start,
                options.box_decades,
                ZERO_START_NUDGE,
                &bounds,
                &mut search.random,
            )
        } else {
            // Explore about the structure's start values first, then perturb the best
            // minimum so far (`FitOptions::explore_starts`).
            let best_so_far =
                best_index(&search.finals, &search.plausible, global).map(|i| &search.finals[i]);
            let (centre, spread) = match best_so_far {
                Some((x, _)) if global => (
                    x,
                    polish_spread(options.polish_spread, search.polishes_without_gain),
                ),
                Some((x, _)) if start_number >= options.explore_starts => {
                    (x, options.polish_spread)
                }
                _ => (&first_start, options.start_spread),
            };
            optimizer::perturbed_start(centre, spread, 0.1, &bounds, &mut search.random)
        };
        if free.is_empty() {
            search.finals.push((start, f64::NAN));
            search.independent.push(true);
            search.plausible.push(true);
            break;
        }
        let best_before = best_index(&search.finals, &search.plausible, global)
            .map_or(f64::INFINITY, |i| search.finals[i].1);
        match optimizer::levenberg_marquardt(evaluate, start, &bounds, &rules) {
            Ok(outcome) => {
                let average_cost = outcome.cost / n_pairs;
                search.starts.push(StartOutcome {
                    average_cost: Some(average_cost),
                    iterations: outcome.iterations,
                    stop: format!("{:?}", outcome.reason),
                });
                let values = merge(&base, &free, &outcome.x);
                search.plausible.push(
                    plausible::implausible_parameters(structure, &values).is_empty()
                        && near_the_box(&outcome.x, &first_start, options.box_decades),
                );
                search.finals.push((outcome.x, average_cost));
                search.independent.push(independent);
            }
            Err(FitError::SingularSystem { omega }) => {
                search.starts.push(StartOutcome {
                    average_cost: None,
                    iterations: 0,
                    stop: format!("start not evaluable (singular at ω = {omega})"),
                });
                search.last_error = Some(FitError::SingularSystem { omega });
                continue;
            }
            Err(other) => return Err(other),
        }
        let best = best_index(&search.finals, &search.plausible, global)
            .map_or(f64::INFINITY, |i| search.finals[i].1);
        if global && !independent {
            let gained = best < best_before && !tolerance(best, best_before);
            search.polishes_without_gain = if gained {
                0
            } else {
                search.polishes_without_gain + 1
            };
        }
        let hits = search
            .finals
            .iter()
            .zip(&search.independent)
            .filter(|((_, j), &independent)| tolerance(*j, best) && (independent || !global))
            .count();
        search.minimum_confirmed = hits >= 2;
    }
    Ok(())
}

/// The best minimum of a search, with its accuracy analysis and report.
pub(super) fn finish_fit(
    structure: &ModelStructure,
    grids: &[PairGrid],
    options: &FitOptions,
    search: StartSearch,
) -> Result<FitResult, FitError> {
    let base = structure.values();
    let free = structure.free_indices();
    let StartSearch {
        starts,
        finals,
        plausible,
        minimum_confirmed,
        last_error,
        ..
    } = search;
    let best = match best_index(&finals, &plausible, options.global_search) {
        Some(i) => Some(finals[i].0.clone()),
        // No evaluated start (free set empty: its one entry has J NaN).
        None => finals.first().map(|(x, _)| x.clone()),
    };
    let Some(best) = best else {
        return Err(last_error.unwrap_or(FitError::NoPairs));
    };
    let values = merge(&base, &free, &best);
    let balance = joint_balance(structure, options)?;
    let (residual, jacobian) = residuals_and_jacobian(structure, &values, &free, grids, &balance)?;
    // The pairs' residuals come first; the balances' (if any) after them.
    let costs = cost::pair_costs_from_residuals(grids, residual.as_slice());
    let pair_rows: usize = grids.iter().map(|g| 2 * g.omega.len()).sum();
    // The priors' rows are the last ones (`prior::cost` gives their share).
    let prior_rows = prior::count(structure, &free);
    let balance_cost = residual
        .rows(pair_rows, residual.len() - pair_rows - prior_rows)
        .norm_squared();
    let analysis = accuracy::analyse(&jacobian);
    let fitted_structure = structure.with_values(&values)?;
    let model = structure.model(&values)?;
    let parameters = parameter_reports(&fitted_structure, &values, &free, &analysis, options);
    Ok(FitResult {
        pairs: grids
            .iter()
            .zip(&costs)
            .map(|(grid, &cost)| PairFit {
                input: grid.input.clone(),
                output: grid.output.clone(),
                range: grid.range,
                cost,
            })
            .collect(),
        average_cost: cost::average(&costs),
        correlation_names: free
            .iter()
            .map(|&i| structure.parameters[i].name.clone())
            .collect(),
        correlation: analysis.correlation.clone(),
        hessian_singular: analysis.singular,
        structure: fitted_structure,
        values,
        model,
        parameters,
        starts,
        minimum_confirmed,
        reduction: Vec::new(),
        skipped_pairs: Vec::new(),
        trim: None,
        implausible_held: Vec::new(),
        degenerate: Vec::new(),
        degenerate_restarts: Vec::new(),
        balance_cost,
    })
}

/// The trim balances the cost carries ([`trim::joint`]): with trim points, a structure
/// that derives parameters from them, and [`TrimBalance::Joint`].
fn joint_balance(
    structure: &ModelStructure,
    options: &FitOptions,
) -> Result<Option<JointBalance>, FitError> {
    let (Some(points), TrimBalance::Joint { stick_sigma }) =
        (&options.trim_points, options.trim_balance)
    else {
        return Ok(None);
    };
    if structure.trim_derived.is_empty() {
        return Ok(None);
    }
    JointBalance::new(structure, points, &structure.trim_derived, stick_sigma)
        .map(Some)
        .map_err(|e| FitError::TrimPoints(e.to_string()))
}

/// A balance that cannot be evaluated at a trial point (its flapping rows singular) is a
/// rejected step, like a singular frequency response.
fn balance_error(error: TrimError) -> FitError {
    match error {
        TrimError::HiddenStatesSingular | TrimError::Model(_) => {
            FitError::SingularSystem { omega: 0.0 }
        }
        other => FitError::TrimPoints(other.to_string()),
    }
}

/// `a` over `b`.
fn stack(a: &DVector<f64>, b: &DVector<f64>) -> DVector<f64> {
    DVector::from_iterator(a.len() + b.len(), a.iter().chain(b.iter()).copied())
}

/// The pairs' residuals and Jacobian ([`cost::residuals_and_jacobian`]) with the
/// balances' below them when the cost carries them.
fn residuals_and_jacobian(
    structure: &ModelStructure,
    values: &[f64],
    free: &[usize],
    grids: &[PairGrid],
    balance: &Option<JointBalance>,
) -> Result<(DVector<f64>, DMatrix<f64>), FitError> {
    let (r, j) = cost::residuals_and_jacobian(structure, values, free, grids)?;
    let priors = prior::residuals_and_jacobian(structure, values, free);
    let Some(balance) = balance else {
        return Ok(prior::stack((r, j), priors));
    };
    let (e, je) = balance
        .residuals_and_jacobian(structure, values, free)
        .map_err(balance_error)?;
    let mut jacobian = DMatrix::zeros(j.nrows() + je.nrows(), free.len());
    jacobian.rows_mut(0, j.nrows()).copy_from(&j);
    jacobian.rows_mut(j.nrows(), je.nrows()).copy_from(&je);
    Ok(prior::stack((stack(&r, &e), jacobian), priors))
}

#[cfg(test)]
mod tests {
    use super::polish_spread;

    /// ±10 % while polishing gains; doubled after every four polishes without a gain, up
    /// to ±80 %; a base above the cap is kept.
    #[test]
    fn the_polish_widens_while_it_finds_nothing() {
        assert_eq!(polish_spread(0.1, 0), 0.1);
        assert_eq!(polish_spread(0.1, 3), 0.1);
        assert_eq!(polish_spread(0.1, 4), 0.2);
        assert_eq!(polish_spread(0.1, 8), 0.4);
        assert_eq!(polish_spread(0.1, 12), 0.8);
        assert_eq!(polish_spread(0.1, 1000), 0.8);
        assert_eq!(polish_spread(0.9, 40), 0.9);
    }
}
