//! The settings of a fit ([`FitOptions`]): its starts, iteration limits, reduction and
//! accuracy limits, and how trim points enter it.

use super::cost;
use super::trim;

/// Settings of a fit. `Default` gives CIFER-like values.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// Fit frequencies per pair, log-spaced over its range (n_ω, usually 20).
    pub points_per_pair: usize,
    /// Levenberg–Marquardt iteration limit per start.
    pub max_iterations: usize,
    /// Most starts (the first from the structure's start values, exact zeros nudged to
    /// 1e−3; the rest perturbed).
    pub max_starts: usize,
    /// Perturbation of the exploring restarts: each free value × (1 + spread·U(−1, 1)).
    pub start_spread: f64,
    /// Starts that explore: the structure's start values and perturbations of them by
    /// `start_spread`. Every later start perturbs the best minimum found so far by
    /// `polish_spread` instead, so that a minimum in a long, flat valley (the 6-DOF's,
    /// where runs stop at the iteration limit) is reached again rather than each start
    /// ending somewhere else along it.
    pub explore_starts: usize,
    /// Perturbation of the starts after `explore_starts`, about the best minimum so far.
    pub polish_spread: f64,
    /// Spend every one of `max_starts` (a budget, not a limit): after the structure's
    /// values, half of the starts are drawn across the parameter box
    /// (`box_decades` either side of each start value, log-uniform, sign kept) and the
    /// rest perturb the best minimum by `polish_spread`, doubled after every four of them
    /// in a row that find nothing lower (up to ±80 %); the minimum counts as confirmed
    /// only when two independent starts (the structure's values or box draws) reach it
    /// (the `search` module). Off by default: the shipped structures' campaigns keep
    /// the local search; `sweephold fit --search global` turns it on.
    pub global_search: bool,
    /// Half-width of the global phase's box in decades (default 1: a tenth to ten times
    /// each start value).
    pub box_decades: f64,
    /// Seed of the restart perturbations.
    pub seed: u64,
    /// Two starts found the same minimum when their J_ave differ by at most
    /// `same_minimum_tolerance · max(1, J_ave)`.
    pub same_minimum_tolerance: f64,
    /// Run the parameter reduction after the fit ([`reduce`](super::reduce)).
    pub reduce: bool,
    /// Reduction keeps dropping parameters while J_ave rises by less than this per step.
    pub reduce_max_cost_rise: f64,
    /// A reduction step is also undone when its refit moves another free parameter by more
    /// than this many of that parameter's Cramér–Rao bounds (default 10, the most a drop can
    /// move it near a minimum with the guideline limits): the model then slid into another
    /// minimum rather than losing a term the data do not determine ([`reduce`](super::reduce)).
    pub reduce_max_shift_cramer_rao: f64,
    /// A reduction step is also undone when its refit moves a hover mode (|λ| < 3 rad/s)
    /// of the model before it by more than this percentage of |λ|, or adds a pole at the
    /// origin (default 10 %: well inside the 25 % a hover mode may be off the truth)
    /// ([`reduce`](super::reduce)).
    pub reduce_max_hover_mode_shift_percent: f64,
    /// A reduction step is also undone when its refit moves a remaining free parameter
    /// that the refit identifies within `cramer_rao_limit_percent` by more than this
    /// percentage of its value before the step (default 50 %: the data determine that
    /// parameter within a fifth of its value, and it moved by more than twice that to
    /// stand in for the dropped one; the R-50's yaw damping N_r dropped at CR 31 % moved
    /// its damper gain K_r +104 %, identified at CR 6 % after the step)
    /// ([`reduce`](super::reduce)).
    pub reduce_max_shift_percent: f64,
    /// Flag a Cramér–Rao bound above this percentage of the value.
    pub cramer_rao_limit_percent: f64,
    /// Flag an insensitivity above this percentage of the value.
    pub insensitivity_limit_percent: f64,
    /// Flag a parameter pair correlated beyond this |ρ|.
    pub correlation_limit: f64,
    /// An `auto` pair is fitted only when its valid range (after the structure's
    /// `auto_range_limit`) spans at least this ratio ω_hi/ω_lo; narrower ones — usually a
    /// sliver where noise crossed the coherence threshold — are skipped and reported.
    pub min_auto_range_ratio: f64,
    /// Trim points: with them the structure's `trim_derived` parameters are derived from
    /// the steady-state balance at the points and held (status `trim`), re-derived as the
    /// fit moves the others ([`trim`](super::trim)), then, with [`trim::TrimBalance::Joint`], fitted
    /// with the others under the balances ([`trim::joint`](super::trim::joint)). Without them those parameters
    /// are fitted like the rest.
    pub trim_points: Option<trim::TrimPoints>,
    /// How the trim points enter the fit ([`trim::TrimBalance`]; default: held, status
    /// `trim`, as the paper fixes its speed derivatives).
    pub trim_balance: trim::TrimBalance,
    /// Whether a fit whose model is degenerate ([`degenerate`](super::degenerate)) is run
    /// again elsewhere (other seeds) and, failing that, with the parameters outside their
    /// physical range held at the structure file's values ([`plausible`](super::plausible); the
    /// driver's recovery), the reasons it is still degenerate recorded. Off only where the
    /// fit gives start values and nothing else (the campaign's 6-DOF stage): its minimum
    /// is then taken as it is.
    pub recover_implausible: bool,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            points_per_pair: cost::DEFAULT_POINTS_PER_PAIR,
            max_iterations: 200,
            max_starts: 8,
            start_spread: 0.3,
            explore_starts: 3,
            polish_spread: 0.1,
            global_search: false,
            box_decades: 0.5,
            seed: 1,
            same_minimum_tolerance: 1e-4,
            reduce: false,
            reduce_max_cost_rise: 2.0,
            reduce_max_shift_cramer_rao: 10.0,
            reduce_max_hover_mode_shift_percent: 10.0,
            reduce_max_shift_percent: 50.0,
            cramer_rao_limit_percent: 20.0,
            insensitivity_limit_percent: 10.0,
            correlation_limit: 0.9,
            min_auto_range_ratio: 3.0,
            trim_points: None,
            trim_balance: trim::TrimBalance::Hold,
            recover_implausible: true,
        }
    }
}
