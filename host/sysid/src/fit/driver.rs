//! The fit as a whole: the pairs the data support, their fit grids, the multi-start search
//! ([`super::search`]), the trim-derived parameters and the optional reduction.

use super::cost::{self, PairGrid};
use super::error::FitError;
use super::options::FitOptions;
use super::result::{FitResult, SkippedPair, StartSetOutcome};
use super::search::{finish_fit, fit_on_grids, search_minima, StartSearch};
use super::structure::{self, ModelStructure, ParameterKind};
use super::{degenerate, plausible, reduce, trim};
use crate::document::FrfDocument;

/// Fit `structure` to the responses in `data`.
pub fn fit(
    structure: &ModelStructure,
    data: &FrfDocument,
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    let (usable, skipped) = usable_pairs(structure, data, options.min_auto_range_ratio);
    if usable.pairs.is_empty() && !structure.pairs.is_empty() {
        return Err(FitError::NoUsablePairs {
            skipped: skipped.len(),
        });
    }
    let grids = cost::build_pair_grids(&usable, data, options.points_per_pair)?;
    let run = |held: &[String], options: &FitOptions| {
        let structure = held_at_a_priori(&usable, held, &usable);
        let result = fit_on_grids(&structure, &grids, &without_balances(options))?;
        if degenerate_before_trim(&result, &structure, options)? {
            return Ok((result, ()));
        }
        Ok((settle_and_release(result, &structure, &grids, options)?, ()))
    };
    let (mut result, ()) = restart_then_recover(&usable, options, run)?;
    result.skipped_pairs = skipped;
    Ok(result)
}

/// Fit the same structure from several sets of start values (each a copy of the structure
/// with its own values, e.g. from a 6-DOF fit and from the file), keep the lowest J_ave,
/// and only then reduce it. A 6-DOF fit can land in a degenerate minimum (its roll
/// damping and control power both huge, their ratio right) whose Eq. 26–27 starts are
/// useless; the file's generic starts are the fallback. Each set gets its share of the
/// perturbed restarts; the set with the lowest J_ave gets the whole `max_starts` when its
/// minimum was not found twice within its share. Errors only when every set fails (the
/// first set's error). The last set is the a-priori one (the structure file's own
/// values): parameters the responses leave undetermined are held at its values in every
/// set.
pub fn fit_from_alternative_starts(
    starts: &[(String, ModelStructure)],
    data: &FrfDocument,
    options: &FitOptions,
) -> Result<(FitResult, Vec<StartSetOutcome>), FitError> {
    let Some((_, first)) = starts.first() else {
        return Err(FitError::StartValues(
            "no set of start values to fit from".into(),
        ));
    };
    let (usable, skipped) = usable_pairs(first, data, options.min_auto_range_ratio);
    if usable.pairs.is_empty() && !first.pairs.is_empty() {
        return Err(FitError::NoUsablePairs {
            skipped: skipped.len(),
        });
    }
    let grids = cost::build_pair_grids(&usable, data, options.points_per_pair)?;
    // The a-priori values: the last set's (the structure file's own).
    let a_priori = starts.last().map_or(first, |(_, structure)| structure);
    let run = |held: &[String], options: &FitOptions| {
        let starts: Vec<(String, ModelStructure)> = starts
            .iter()
            .map(|(label, structure)| (label.clone(), held_at_a_priori(structure, held, a_priori)))
            .collect();
        let (result, (outcomes, usable)) = best_of_start_sets(&starts, data, &grids, options)?;
        if degenerate_before_trim(&result, &usable, options)? {
            return Ok((result, outcomes));
        }
        Ok((
            settle_and_release(result, &usable, &grids, options)?,
            outcomes,
        ))
    };
    let (mut result, outcomes) = restart_then_recover(first, options, run)?;
    result.skipped_pairs = skipped;
    Ok((result, outcomes))
}

/// Most searches run again from other starts when the fit's model is degenerate
/// (`restart_then_recover`).
pub const DEGENERATE_RESTARTS: usize = 3;

/// The seed of the `round`-th search run again elsewhere (1, 2, …): a SplitMix64 step
/// from the fit's seed, so that the same seed gives the same restarts and no restart
/// repeats the fit's own perturbations.
pub fn restart_seed(seed: u64, round: usize) -> u64 {
    let mut random = crate::random::SplitMix64::new(seed);
    let mut next = seed;
    for _ in 0..round {
        next = random.next_u64();
    }
    next
}

/// The whole fit `run(held, options)` with the fit's options; when its model is
/// degenerate ([`degenerate`]: a parameter outside its physical range or a free one on a
/// range bound of the structure file), run again from other starts: the same search
/// with another seed ([`restart_seed`]: other perturbations, other box draws), up to
/// [`DEGENERATE_RESTARTS`] times, keeping the first model that is not degenerate. Only
/// when none is, the parameters outside their range are held ([`recover_plausible`])
/// from the original run. The result records the restarts' seeds and, when it is still
/// degenerate, why ([`FitResult::degenerate`]). A restart that fails is skipped. A fit
/// whose model is not degenerate runs exactly as before; without
/// [`FitOptions::recover_implausible`] its model is taken as it is, unjudged.
fn restart_then_recover<X>(
    structure: &ModelStructure,
    options: &FitOptions,
    mut run: impl FnMut(&[String], &FitOptions) -> Result<(FitResult, X), FitError>,
) -> Result<(FitResult, X), FitError> {
    let judge =
        |result: &FitResult| degenerate::degenerate_reasons(&result.structure, &result.values);
    let first = run(&[], options)?;
    if !options.recover_implausible {
        return Ok(first);
    }
    let mut reasons = judge(&first.0);
    if reasons.is_empty() {
        return Ok(first);
    }
    let mut seeds = Vec::new();
    for round in 1..=DEGENERATE_RESTARTS {
        let seed = restart_seed(options.seed, round);
        seeds.push(seed);
        let elsewhere = FitOptions {
            seed,
            ..options.clone()
        };
        let Ok(mut next) = run(&[], &elsewhere) else {
            continue;
        };
        if judge(&next.0).is_empty() {
            next.0.degenerate_restarts = seeds;
            return Ok(next);
        }
    }
    let mut result = recover_plausible(structure, first, |held| run(held, options));
    reasons = if result.0.implausible_held.is_empty() {
        reasons
    } else {
        judge(&result.0)
    };
    result.0.degenerate = reasons;
    result.0.degenerate_restarts = seeds;
    Ok(result)
}

/// The search of [`fit_from_alternative_starts`] over its start sets, before the trim
/// points: the best result, what each set reached, and the best set's usable structure.
#[allow(clippy::type_complexity)]
fn best_of_start_sets(
    starts: &[(String, ModelStructure)],
    data: &FrfDocument,
    grids: &[PairGrid],
    options: &FitOptions,
) -> Result<(FitResult, (Vec<StartSetOutcome>, ModelStructure)), FitError> {
    // The restart budget is shared: each set gets its part of `max_starts` (at least two,
    // so that each can still confirm its minimum). The set that reaches the lowest J_ave
    // gets the whole budget afterwards if its minimum was not found twice.
    let per_set = FitOptions {
        max_starts: (options.max_starts / starts.len()).max(2),
        ..without_balances(options)
    };
    // The best set so far: its index, result, search state and usable structure.
    let mut best: Option<(usize, FitResult, StartSearch, ModelStructure)> = None;
    let mut first_error = None;
    let mut outcomes = Vec::with_capacity(starts.len());
    for (set, (label, structure)) in starts.iter().enumerate() {
        let (usable, _) = usable_pairs(structure, data, options.min_auto_range_ratio);
        let mut search = StartSearch::new(per_set.seed);
        let fitted = search_minima(&usable, grids, &per_set, per_set.max_starts, &mut search)
            .and_then(|()| finish_fit(&usable, grids, &per_set, search.clone()));
        match fitted {
            Ok(result) => {
                outcomes.push(StartSetOutcome {
                    label: label.clone(),
                    average_cost: Ok(result.average_cost),
                });
                if best
                    .as_ref()
                    .is_none_or(|(_, b, _, _)| result.objective() < b.objective())
                {
                    best = Some((set, result, search, usable));
                }
            }
            Err(error) => {
                outcomes.push(StartSetOutcome {
                    label: label.clone(),
                    average_cost: Err(error.to_string()),
                });
                first_error.get_or_insert(error);
            }
        }
    }
    let Some((best_set, mut result, mut search, usable)) = best else {
        return Err(first_error.unwrap_or(FitError::StartValues(
            "no set of start values to fit from".into(),
        )));
    };
    // The lowest minimum is only taken once found twice (CIFER's rule). Seed 8 of the
    // 20-seed campaign: both sets stopped unconfirmed after four starts each (J_ave 280
    // and 190); the file's set, given all eight, found J_ave 25 twice. Its search goes on
    // where it stopped, so it keeps the minima it has and reaches at least the same one.
    if !result.minimum_confirmed && per_set.max_starts < options.max_starts {
        let options = without_balances(options);
        search_minima(&usable, grids, &options, options.max_starts, &mut search)?;
        result = finish_fit(&usable, grids, &options, search)?;
        if let Some(outcome) = outcomes.get_mut(best_set) {
            outcome.average_cost = Ok(result.average_cost);
        }
    }
    Ok((result, (outcomes, usable)))
}

/// Most rounds of [`recover_plausible`]: each holds the parameters the last run put
/// outside their range.
const RECOVERY_ROUNDS: usize = 4;

/// A recovered fit is kept when its J_ave is at most this (the guideline's "acceptable")
/// or at most the degenerate fit's.
const RECOVERED_ACCEPTABLE_COST: f64 = 100.0;

/// A fit with parameters outside their physical range ([`plausible`]) sits in a
/// degenerate minimum: the responses do not determine them (a control derivative of 10⁸
/// that a coupling of 10⁻⁸ cancels fits as well as two ordinary values). Hold those
/// parameters at their a-priori values ([`held_at_a_priori`]) and run the fit again from the
/// same start sets (the file's, the equation-error or 6-DOF ones), up to
/// [`RECOVERY_ROUNDS`] times while a run puts others outside. The first plausible result
/// whose J_ave is acceptable ([`RECOVERED_ACCEPTABLE_COST`]) wins, recording what it held
/// ([`FitResult::implausible_held`]); otherwise, or when a run fails, `first` is
/// returned as it is and the caller refuses it. Only parameters `structure` has free and
/// outside M are held (a trim-derived one follows the others; a time constant at zero
/// would make M singular). `run(held)` fits with `held` at their a-priori values.
fn recover_plausible<X>(
    structure: &ModelStructure,
    first: (FitResult, X),
    mut run: impl FnMut(&[String]) -> Result<(FitResult, X), FitError>,
) -> (FitResult, X) {
    let mut found = plausible::implausible_parameters(&first.0.structure, &first.0.values);
    let mut held: Vec<plausible::HeldParameter> = Vec::new();
    let acceptable = first.0.average_cost.max(RECOVERED_ACCEPTABLE_COST);
    for _ in 0..RECOVERY_ROUNDS {
        if found.is_empty() {
            break;
        }
        let before = held.len();
        for parameter in &found {
            if plausible::droppable(structure, &parameter.name)
                && !held.iter().any(|d| d.name == parameter.name)
            {
                held.push(plausible::HeldParameter {
                    name: parameter.name.clone(),
                    value: parameter.value,
                });
            }
        }
        if held.len() == before {
            break;
        }
        let names: Vec<String> = held.iter().map(|d| d.name.clone()).collect();
        let Ok(mut next) = run(&names) else {
            break;
        };
        found = plausible::implausible_parameters(&next.0.structure, &next.0.values);
        if found.is_empty() && next.0.average_cost <= acceptable {
            next.0.implausible_held = held;
            return next;
        }
    }
    first
}

/// Whether the search's minimum already lies outside the physical ranges and the
/// recovery is on: then the trim rounds are not run on it (the balance would scale its
/// undetermined control derivatives into speed derivatives of 10¹⁵ and drive the refits
/// further out); the recovery holds those parameters and runs again. The points are
/// still checked, at `structure`'s start values, so that points that cannot inform the
/// derived parameters (collinear, no climb) are named as such rather than as a
/// degenerate fit.
fn degenerate_before_trim(
    result: &FitResult,
    structure: &ModelStructure,
    options: &FitOptions,
) -> Result<bool, FitError> {
    let Some(points) = &options.trim_points else {
        return Ok(false);
    };
    if !options.recover_implausible
        || plausible::implausible_parameters(&result.structure, &result.values).is_empty()
    {
        return Ok(false);
    }
    if !structure.trim_derived.is_empty() {
        trim::derive(
            structure,
            &structure.values(),
            points,
            &structure.trim_derived,
        )
        .map_err(|e| FitError::TrimPoints(e.to_string()))?;
    }
    Ok(true)
}

/// `structure` with the parameters `names` fixed at their a-priori values (`a_priori`'s:
/// the structure file's own start values), or at zero where that value lies outside the
/// physical range. Held because the responses left them undetermined, they are held at
/// the same value in every start set: a start set computed from another fit (the 6-DOF's)
/// carries that fit's value of them, which the data did not determine either (fbl700,
/// board-sim, seed 4: the 6-DOF's N_col of 202 against a truth of 18.6, held, and the
/// trim balance took N_ped to +66 % with it; decision 2026-11-27-held-at-a-priori).
fn held_at_a_priori(
    structure: &ModelStructure,
    names: &[String],
    a_priori: &ModelStructure,
) -> ModelStructure {
    let mut held = structure.clone();
    let values = a_priori.values();
    let outside: Vec<String> = plausible::implausible_parameters(a_priori, &values)
        .into_iter()
        .map(|p| p.name)
        .collect();
    for name in names {
        let (Some(index), Some(prior)) =
            (held.parameter_index(name), a_priori.parameter_index(name))
        else {
            continue;
        };
        let parameter = &mut held.parameters[index];
        parameter.kind = ParameterKind::Fixed;
        parameter.value = if outside.contains(name) {
            0.0
        } else {
            values[prior]
        };
    }
    held
}

/// `options` with the trim balances out of the cost (the search before the trim points
/// come in).
fn without_balances(options: &FitOptions) -> FitOptions {
    FitOptions {
        trim_balance: trim::TrimBalance::Hold,
        ..options.clone()
    }
}

/// After the search: hold the trim-derived parameters until they settle
/// ([`settle_trim`]); with [`trim::TrimBalance::Joint`] release them into the joint cost
/// ([`release_trim`]); then the reduction, if asked for, and the trim step again.
fn settle_and_release(
    result: FitResult,
    original: &ModelStructure,
    grids: &[PairGrid],
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    let hold = without_balances(options);
    let mut result = settle_trim(result, grids, &hold)?;
    result = release_trim(result, original, grids, options)?;
    if options.reduce {
        let outcome = result.trim.clone();
        result = reduce::reduce(result, grids, options)?;
        if matches!(options.trim_balance, trim::TrimBalance::Joint { .. }) {
            // The reduction refitted under the joint cost: report where it left them.
            result.trim = outcome;
            report_trim_values(&mut result);
        } else {
            result = settle_trim(result, grids, &hold)?;
        }
    }
    Ok(result)
}

/// The trim outcome's parameters at the values of `result`.
fn report_trim_values(result: &mut FitResult) {
    let values: Vec<Option<f64>> = result
        .trim
        .iter()
        .flat_map(|outcome| &outcome.parameters)
        .map(|d| result.parameter(&d.name))
        .collect();
    if let Some(outcome) = &mut result.trim {
        for (d, value) in outcome.parameters.iter_mut().zip(values) {
            if let Some(value) = value {
                d.value = value;
            }
        }
    }
}

/// With [`trim::TrimBalance::Joint`] and trim points: the held trim-derived parameters
/// of `current` (status `trim`) free again, within `original`'s bounds, and refitted with
/// the others under the joint cost ([`trim::joint`]), from `current`'s values (one start
/// and one perturbed restart, as in the reduction). The trim outcome then reports the
/// values the joint fit gave them. Otherwise `current` as it is.
fn release_trim(
    current: FitResult,
    original: &ModelStructure,
    grids: &[PairGrid],
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    let (Some(_), trim::TrimBalance::Joint { .. }) = (&options.trim_points, options.trim_balance)
    else {
        return Ok(current);
    };
    let names = current.structure.trim_derived.clone();
    let mut structure = current.structure.clone();
    let mut released = false;
    for name in &names {
        let (Some(index), Some(source)) = (
            structure.parameter_index(name),
            original.parameter_index(name),
        ) else {
            continue;
        };
        let parameter = &mut structure.parameters[index];
        if parameter.kind != ParameterKind::Trim {
            continue;
        }
        let bounds = &original.parameters[source];
        parameter.kind = ParameterKind::Free;
        parameter.lower = bounds.lower;
        parameter.upper = bounds.upper;
        if let Some(lower) = bounds.lower {
            parameter.value = parameter.value.max(lower);
        }
        if let Some(upper) = bounds.upper {
            parameter.value = parameter.value.min(upper);
        }
        released = true;
    }
    if !released {
        return Ok(current);
    }
    let refit_options = FitOptions {
        max_starts: options.max_starts.min(2),
        ..options.clone()
    };
    let mut refit = fit_on_grids(&structure, grids, &refit_options)?;
    refit.reduction = current.reduction;
    reduce::flag_needed(&mut refit);
    refit.trim = current.trim;
    report_trim_values(&mut refit);
    Ok(refit)
}

/// Derive the structure's `trim_derived` parameters from the trim points, hold them
/// (status `trim`) and refit from the current values; repeat until they settle
/// ([`trim`]). Without trim points, or without `trim_derived`, `result` is returned as it
/// is. Each refit is one start from the current minimum and one perturbed restart, as in
/// the reduction.
fn settle_trim(
    mut current: FitResult,
    grids: &[PairGrid],
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    let Some(points) = &options.trim_points else {
        return Ok(current);
    };
    let names = current.structure.trim_derived.clone();
    if names.is_empty() {
        return Ok(current);
    }
    let refit_options = FitOptions {
        max_starts: options.max_starts.min(2),
        ..options.clone()
    };
    let mut rounds = 0;
    let mut settled = false;
    let mut derived = Vec::new();
    while rounds < trim::MAX_ROUNDS {
        derived = trim::derive(&current.structure, &current.values, points, &names)
            .map_err(|e| FitError::TrimPoints(e.to_string()))?;
        let mut structure = current.structure.clone();
        let mut change: f64 = 0.0;
        let mut newly_held = false;
        for d in &derived {
            let Some(index) = structure.parameter_index(&d.name) else {
                continue;
            };
            let parameter = &mut structure.parameters[index];
            newly_held |= parameter.kind != ParameterKind::Trim;
            change = change.max((d.value - parameter.value).abs() / d.value.abs().max(1e-12));
            parameter.value = d.value;
            parameter.kind = ParameterKind::Trim;
            parameter.lower = None;
            parameter.upper = None;
        }
        if !newly_held && change <= trim::SETTLED_RELATIVE_CHANGE {
            settled = true;
            break;
        }
        rounds += 1;
        // Holding the derived parameters for the first time changes the cost surface
        // (they were free): that refit gets the whole restart budget; later rounds only
        // nudge them and restart from the minimum.
        let round_options = if newly_held { options } else { &refit_options };
        let reduction = std::mem::take(&mut current.reduction);
        current = fit_on_grids(&structure, grids, round_options)?;
        current.reduction = reduction;
        reduce::flag_needed(&mut current);
    }
    current.trim = Some(trim::TrimOutcome {
        points: points.points.len(),
        rounds,
        settled,
        parameters: derived,
    });
    Ok(current)
}

/// The structure with its `auto` pairs whose data support no usable range removed: no
/// valid range at all, or one (after `auto_range_limit`) narrower than `min_ratio`.
/// Pairs missing from the data are kept, so that the fit reports them as errors.
pub fn usable_pairs(
    structure: &ModelStructure,
    data: &FrfDocument,
    min_ratio: f64,
) -> (ModelStructure, Vec<SkippedPair>) {
    let mut usable = structure.clone();
    let mut skipped = Vec::new();
    usable.pairs.retain(|spec| {
        if spec.range != structure::PairRange::Auto {
            return true;
        }
        let Some(pair) = data.pair(&spec.input, &spec.output) else {
            return true;
        };
        let reason = match pair.valid_range {
            None => Some("coherence never reaches the threshold".to_string()),
            Some(band) => {
                let [lo, hi] = match structure.auto_range_limit {
                    Some([lo, hi]) => [band[0].max(lo), band[1].min(hi)],
                    None => band,
                };
                (hi < min_ratio * lo).then(|| {
                    format!(
                        "valid range {:.3}-{:.3} rad/s{} spans less than a factor {min_ratio}",
                        band[0],
                        band[1],
                        if structure.auto_range_limit.is_some() {
                            " (clipped)"
                        } else {
                            ""
                        }
                    )
                })
            }
        };
        match reason {
            Some(reason) => {
                skipped.push(SkippedPair {
                    input: spec.input.clone(),
                    output: spec.output.clone(),
                    line: spec.line,
                    reason,
                });
                false
            }
            None => true,
        }
    });
    (usable, skipped)
}

#[cfg(test)]
mod tests;
