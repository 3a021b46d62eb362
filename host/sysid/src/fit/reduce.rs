//! Model structure reduction (CIFER practice, Tischler & Remple): drop the worst
//! identified parameter — the most insensitive one while any insensitivity exceeds its
//! limit, else the one with the largest Cramér–Rao bound while any exceeds its limit —
//! by fixing it at zero, refit, and keep the smaller model while J_ave rises by less than
//! a set amount per step. A step that costs more is undone: that parameter is needed (the
//! paper keeps Lf_lat for that reason) and stays in, flagged if it is, and the reduction
//! goes on with the worst of the others — a needed parameter early in the order (say a
//! heave damping) must not shield the unidentifiable ones behind it. When only needed
//! parameters are left to drop, those found needed before a later drop was accepted are
//! tried once more: the smaller model may not need them any longer (a speed derivative
//! that carried a correlated one, dropped since, can then be flagged at CR 170 % and
//! cost nothing to remove). A parameter whose zero would make the mass matrix M singular
//! (the flapping time constant τ_f) is never dropped: the result would not be a
//! state-space model.
//!
//! **The physics guard.** J_ave weighs the fitted band, where the hover modes (below
//! 3 rad/s) leave little trace, so a drop can pass the cost test and still change the
//! aircraft: a heave damping at zero turns the heave mode into a pole at the origin, and
//! a flap-back term at zero takes the hover oscillations with it. A step is therefore also
//! undone when the refit moves any hover mode of the model before it by more than
//! [`FitOptions::reduce_max_hover_mode_shift_percent`] (`|λ_after − λ_before| / |λ_before|`,
//! modes paired one to one as in [`super::modes::pair_modes`]) or adds a pole at the
//! origin.
//!
//! **The compensation guard.** Nor may another parameter make up for the dropped one: a
//! step is undone when its refit moves a remaining free parameter that the refit
//! identifies within the Cramér–Rao guideline by more than
//! [`FitOptions::reduce_max_shift_percent`] of its value. On the R-50 hover model
//! (docs/published_model) the yaw damping N_r (CR 31 %) went to zero at +0.6 in J_ave and
//! the yaw damper's gain K_r moved +104 % (2.34 → 4.78), identified at CR 5.6 % after
//! the step, to give the same yaw response. In K_r's own bounds before the step (CR 24 %:
//! N_r, K_r and K_rfb correlated, their bounds wide until one of them is fixed) that was
//! 4.4 bounds, under the 10 of [`FitOptions::reduce_max_shift_cramer_rao`].
//!
//! A parameter kept by any of these rules while it breaks the Cramér–Rao or
//! insensitivity guideline is flagged [`AccuracyFlag::Needed`] with the reason.

use super::cost::PairGrid;
use super::error::FitError;
use super::model::Model;
use super::modes::{eigenvalue_text, modes, pair_modes, relative_error_percent, ModeName};
use super::options::FitOptions;
pub use super::result::ReductionStep;
use super::result::{AccuracyFlag, FitResult, ParameterReport, ParameterStatus};
use super::search::fit_on_grids;
use super::structure::ParameterKind;
use super::trim::TrimBalance;

/// How the refit `after` changed the hover modes of `before` (module documentation), in
/// words, when it moved one by more than `limit_percent` or added a pole at the origin;
/// None when they stayed. A model whose modes cannot be computed counts as a change; a
/// `before` without computable modes gives nothing to guard.
pub fn hover_mode_change(before: &Model, after: &Model, limit_percent: f64) -> Option<String> {
    let before_modes = modes(before).ok()?;
    let Ok(after_modes) = modes(after) else {
        return Some("has no computable modes".to_string());
    };
    let origin = |list: &[super::modes::Mode]| {
        list.iter()
            .filter(|m| m.name == ModeName::Origin)
            .map(|m| m.poles)
            .sum::<usize>()
    };
    let (origin_before, origin_after) = (origin(&before_modes), origin(&after_modes));
    if origin_after > origin_before {
        return Some(format!(
            "puts {} pole(s) at the origin",
            origin_after - origin_before
        ));
    }
    let pairing = pair_modes(&before_modes, &after_modes);
    let mut worst: Option<(f64, String)> = None;
    for (mode, paired) in before_modes.iter().zip(&pairing) {
        if !mode.is_hover_mode() {
            continue;
        }
        let (moved_to, percent) = match paired.and_then(|k| after_modes.get(k)) {
            Some(after_mode) => (
                eigenvalue_text([after_mode.eigenvalue.re, after_mode.eigenvalue.im]),
                relative_error_percent(after_mode.eigenvalue, mode.eigenvalue)
                    .unwrap_or(f64::INFINITY),
            ),
            None => ("nothing".to_string(), f64::INFINITY),
        };
        if percent > limit_percent && worst.as_ref().is_none_or(|(w, _)| percent > *w) {
            let text = format!(
                "moves the {} mode {} -> {} ({:.0} %)",
                mode.name.as_str(),
                eigenvalue_text([mode.eigenvalue.re, mode.eigenvalue.im]),
                moved_to,
                percent
            );
            worst = Some((percent, text));
        }
    }
    worst.map(|(_, text)| text)
}

/// Flag every free parameter that breaks a guideline and was kept by an undone step of
/// `result.reduction` [`AccuracyFlag::Needed`], with the reason of the last such step.
pub(crate) fn flag_needed(result: &mut FitResult) {
    let steps = &result.reduction;
    for report in result
        .parameters
        .iter_mut()
        .filter(|p| p.status == ParameterStatus::Free)
    {
        if !report
            .flags
            .iter()
            .any(AccuracyFlag::is_guideline_violation)
            || report
                .flags
                .iter()
                .any(|f| matches!(f, AccuracyFlag::Needed { .. }))
        {
            continue;
        }
        let reason = steps
            .iter()
            .rev()
            .filter(|step| step.dropped == report.name)
            .find_map(ReductionStep::needed_because);
        if let Some(reason) = reason {
            report.flags.push(AccuracyFlag::Needed { reason });
        }
    }
}

/// The parameter to drop next, with the reason, or None when every free parameter meets
/// the guidelines.
fn worst_parameter(
    result: &FitResult,
    options: &FitOptions,
    needed: &[String],
) -> Option<(String, String)> {
    // With the trim balances in the cost the derived parameters are the balances'
    // unknowns, informed by the points: not candidates for dropping.
    let balanced: &[String] = match (&options.trim_points, options.trim_balance) {
        (Some(_), TrimBalance::Joint { .. }) => &result.structure.trim_derived,
        _ => &[],
    };
    let free = || {
        result.parameters.iter().filter(|p| {
            p.status == ParameterStatus::Free
                && !needed.contains(&p.name)
                && !balanced.contains(&p.name)
                && !has_prior(&result.structure, &p.name)
        })
    };
    let worst_by = |key: fn(&ParameterReport) -> f64| {
        free()
            .map(|p| (p, key(p)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    };
    let insensitivity = |p: &ParameterReport| p.insensitivity_percent.unwrap_or(f64::INFINITY);
    let cramer_rao = |p: &ParameterReport| p.cramer_rao_percent.unwrap_or(f64::INFINITY);
    if let Some((parameter, value)) = worst_by(insensitivity) {
        if value > options.insensitivity_limit_percent || value.is_nan() {
            return Some((
                parameter.name.clone(),
                format!("insensitivity {value:.1} %"),
            ));
        }
    }
    if let Some((parameter, value)) = worst_by(cramer_rao) {
        if value > options.cramer_rao_limit_percent || value.is_nan() {
            return Some((parameter.name.clone(), format!("Cramér–Rao {value:.1} %")));
        }
    }
    None
}

/// The free parameter of `before` (other than `dropped`) that the refit moved furthest,
/// in units of its Cramér–Rao bound at `before`, and that distance. Near a minimum the
/// cost is quadratic, and fixing θ_k at zero moves each other θ_j by ρ_jk·θ_k/CR_k of its
/// own bounds (ρ the correlation). The reduction drops θ_k only for an insensitivity of
/// 10 % or more (then CR_k ≥ 10 % of |θ_k|, since CR ≥ insensitivity) or a bound of 20 % or
/// more, so that move is at most 10 bounds; a larger one means the refit left the
/// quadratic basin for another minimum. Parameters without a finite bound are not measured.
fn largest_shift(
    before: &[ParameterReport],
    after: &[ParameterReport],
    dropped: &str,
) -> Option<(String, f64)> {
    before
        .iter()
        .filter(|p| p.status == ParameterStatus::Free && p.name != dropped)
        .filter_map(|p| {
            let bound = p.cramer_rao_percent? / 100.0 * p.value.abs();
            let moved = after.iter().find(|q| q.name == p.name)?.value;
            let shift = (moved - p.value).abs() / bound;
            (bound > 0.0 && shift.is_finite()).then(|| (p.name.clone(), shift))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// The remaining free parameter of `after` (other than `dropped`) that moved furthest
/// from its value in `before`, in percent of that value, among those `after` identifies
/// within `cramer_rao_limit` percent, as text (`Kr +121 % (2.16 -> 4.78, CR 5.6 %)`), when
/// it moved more than `limit_percent`. A parameter the data determine that far less
/// loosely than it moved stands in for the dropped one: the fit is as good, the physics
/// not ([`FitOptions::reduce_max_shift_percent`]).
fn compensating_parameter(
    before: &[ParameterReport],
    after: &[ParameterReport],
    dropped: &str,
    cramer_rao_limit: f64,
    limit_percent: f64,
) -> Option<String> {
    after
        .iter()
        .filter(|q| q.status == ParameterStatus::Free && q.name != dropped)
        .filter(|q| {
            q.cramer_rao_percent
                .is_some_and(|cr| cr <= cramer_rao_limit)
        })
        .filter_map(|q| {
            let p = before
                .iter()
                .find(|p| p.name == q.name && p.status == ParameterStatus::Free)?;
            let percent = 100.0 * (q.value - p.value) / p.value.abs();
            (p.value != 0.0 && percent.is_finite()).then_some((p, q, percent))
        })
        .filter(|(_, _, percent)| percent.abs() > limit_percent)
        .max_by(|a, b| a.2.abs().total_cmp(&b.2.abs()))
        .map(|(p, q, percent)| {
            format!(
                "{} {percent:+.0} % ({:.4} -> {:.4}, CR {:.1} %)",
                q.name,
                p.value,
                q.value,
                q.cramer_rao_percent.unwrap_or(f64::NAN)
            )
        })
}

/// Whether `name` carries a prior: the prior informs it (its bounds are at most σ), and
/// zero is no value for it (a servo's ω_n), so it is never dropped.
fn has_prior(structure: &super::structure::ModelStructure, name: &str) -> bool {
    structure
        .parameter_index(name)
        .is_some_and(|index| structure.parameters[index].prior.is_some())
}

/// Whether the structure's mass matrix M at its current values can be inverted.
fn has_invertible_mass_matrix(structure: &super::structure::ModelStructure) -> bool {
    structure
        .model(&structure.values())
        .is_ok_and(|model| model.m.lu().is_invertible())
}

/// Reduce a fitted model step by step (see the module documentation).
pub fn reduce(
    initial: FitResult,
    grids: &[PairGrid],
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    let mut current = initial;
    let mut steps = Vec::new();
    // A refit starts at the previous minimum with one parameter zeroed: one start from
    // there and one perturbed restart to confirm it, not the whole restart budget.
    let refit_options = FitOptions {
        max_starts: options.max_starts.min(2),
        ..options.clone()
    };
    // Parameters whose removal cost too much, with the number of accepted drops at the
    // time: kept, and tried again only once more drops have been accepted since.
    let mut needed: Vec<(String, usize)> = Vec::new();
    let mut accepted_drops = 0usize;
    loop {
        let needed_names: Vec<String> = needed.iter().map(|(name, _)| name.clone()).collect();
        let Some((name, reason)) = worst_parameter(&current, options, &needed_names) else {
            let before = needed.len();
            needed.retain(|(_, at)| *at == accepted_drops);
            if needed.len() == before {
                break;
            }
            continue;
        };
        let mut smaller = current.structure.clone();
        let Some(index) = smaller.parameter_index(&name) else {
            break;
        };
        if smaller.free_indices().len() <= 1 {
            break;
        }
        smaller.parameters[index].kind = ParameterKind::Fixed;
        smaller.parameters[index].value = 0.0;
        smaller.parameters[index].lower = None;
        smaller.parameters[index].upper = None;
        if !has_invertible_mass_matrix(&smaller) {
            // A mass-matrix term (τ_f of the flapping) at zero leaves a model that is no
            // longer a state-space model (M singular: no time response, no verification),
            // however little it costs in the frequency domain: needed.
            steps.push(ReductionStep {
                dropped: name.clone(),
                reason: format!("{reason}; at zero M would be singular"),
                average_cost_before: current.objective(),
                average_cost_after: f64::INFINITY,
                accepted: false,
                left_the_minimum: false,
                moved_hover_mode: None,
                compensated_by: None,
            });
            needed.push((name, accepted_drops));
            continue;
        }
        let before = current.objective();
        let refit = match fit_on_grids(&smaller, grids, &refit_options) {
            Ok(refit) => Some(refit),
            // A smaller model that cannot be evaluated (e.g. a pole moved onto the jω
            // axis) is not an improvement.
            Err(FitError::SingularSystem { .. }) => None,
            Err(other) => return Err(other),
        };
        let after = refit.as_ref().map_or(f64::INFINITY, |r| r.objective());
        let shift = refit
            .as_ref()
            .and_then(|r| largest_shift(&current.parameters, &r.parameters, &name));
        let slid = shift
            .as_ref()
            .is_some_and(|(_, s)| *s > options.reduce_max_shift_cramer_rao);
        let moved_hover_mode = refit.as_ref().and_then(|r| {
            hover_mode_change(
                &current.model,
                &r.model,
                options.reduce_max_hover_mode_shift_percent,
            )
        });
        let compensated_by = refit.as_ref().and_then(|r| {
            compensating_parameter(
                &current.parameters,
                &r.parameters,
                &name,
                options.cramer_rao_limit_percent,
                options.reduce_max_shift_percent,
            )
        });
        let accepted = after - before < options.reduce_max_cost_rise
            && !slid
            && moved_hover_mode.is_none()
            && compensated_by.is_none();
        let reason = match shift {
            Some((moved, s)) if slid => {
                format!("{reason}; the refit moved {moved} by {s:.0} Cramér–Rao bounds")
            }
            _ => reason,
        };
        steps.push(ReductionStep {
            dropped: name.clone(),
            reason,
            average_cost_before: before,
            average_cost_after: after,
            accepted,
            left_the_minimum: slid,
            moved_hover_mode,
            compensated_by,
        });
        match refit {
            Some(refit) if accepted => {
                current = refit;
                accepted_drops += 1;
            }
            _ => needed.push((name, accepted_drops)),
        }
    }
    current.reduction = steps;
    flag_needed(&mut current);
    Ok(current)
}

#[cfg(test)]
mod tests;
