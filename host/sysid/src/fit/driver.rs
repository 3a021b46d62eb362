//! The fit as a whole: the pairs the data support, their fit grids, the multi-start search
//! ([`super::search`]), the trim-derived parameters and the optional reduction.

use super::cost::{self, PairGrid};
use super::error::FitError;
use super::search::{finish_fit, fit_on_grids, search_minima, StartSearch};
use super::structure::{self, ModelStructure, ParameterKind};
use super::{reduce, trim, FitOptions, FitResult, SkippedPair, StartSetOutcome};
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
    let mut result = fit_on_grids(&usable, &grids, options)?;
    result = settle_trim(result, &grids, options)?;
    if options.reduce {
        result = reduce::reduce(result, &grids, options)?;
        result = settle_trim(result, &grids, options)?;
    }
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
/// first set's error).
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
    // The restart budget is shared: each set gets its part of `max_starts` (at least two,
    // so that each can still confirm its minimum). The set that reaches the lowest J_ave
    // gets the whole budget afterwards if its minimum was not found twice.
    let per_set = FitOptions {
        max_starts: (options.max_starts / starts.len()).max(2),
        ..options.clone()
    };
    // The best set so far: its index, result, search state and usable structure.
    let mut best: Option<(usize, FitResult, StartSearch, ModelStructure)> = None;
    let mut first_error = None;
    let mut outcomes = Vec::with_capacity(starts.len());
    for (set, (label, structure)) in starts.iter().enumerate() {
        let (usable, _) = usable_pairs(structure, data, options.min_auto_range_ratio);
        let mut search = StartSearch::new(per_set.seed);
        let fitted = search_minima(&usable, &grids, &per_set, per_set.max_starts, &mut search)
            .and_then(|()| finish_fit(&usable, &grids, &per_set, search.clone()));
        match fitted {
            Ok(result) => {
                outcomes.push(StartSetOutcome {
                    label: label.clone(),
                    average_cost: Ok(result.average_cost),
                });
                if best
                    .as_ref()
                    .is_none_or(|(_, b, _, _)| result.average_cost < b.average_cost)
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
        search_minima(&usable, &grids, options, options.max_starts, &mut search)?;
        result = finish_fit(&usable, &grids, options, search)?;
        if let Some(outcome) = outcomes.get_mut(best_set) {
            outcome.average_cost = Ok(result.average_cost);
        }
    }
    result = settle_trim(result, &grids, options)?;
    if options.reduce {
        result = reduce::reduce(result, &grids, options)?;
        result = settle_trim(result, &grids, options)?;
    }
    result.skipped_pairs = skipped;
    Ok((result, outcomes))
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
