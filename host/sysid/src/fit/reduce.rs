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
//! origin. A parameter kept by any of these rules while it breaks the Cramér–Rao or
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
        let accepted =
            after - before < options.reduce_max_cost_rise && !slid && moved_hover_mode.is_none();
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
mod tests {
    use super::{has_invertible_mass_matrix, largest_shift, ReductionStep};
    use crate::fit::structure::ModelStructure;
    use crate::fit::test_support::hybrid_structure;
    use crate::fit::test_support::synthetic_document;
    use crate::fit::{fit, FitOptions, ParameterStatus};
    use crate::fit::{ParameterReport, ParameterStatus as Status};

    /// The truth of both tests: ẋ = −2x + 3u, no delay, no zero.
    const LAG_TRUTH: &str = r#"
name = "truth"
states = ["x"]
controls = ["u"]
outputs = ["x"]
pairs = [{ output = "x", input = "u", range = [0.1, 20.0] }]
[parameters]
a = -2.0
b = 3.0
[F.x]
x = "a"
[G.x]
u = "b"
"#;

    /// Exact responses of [`LAG_TRUTH`].
    fn lag_data() -> crate::document::FrfDocument {
        let truth = ModelStructure::parse(LAG_TRUTH, "truth.toml").unwrap();
        synthetic_document(&truth.model(&truth.values()).unwrap(), &truth, 20)
    }

    #[test]
    fn drops_a_parameter_the_data_do_not_need() {
        // The lag's structure plus a feed-through-like
        // H1 term `d` whose true value is 0 and a delay `tau` whose true value is 0:
        // both are unidentifiable (insensitive) around zero and get dropped.
        let document = lag_data();
        let candidate_text = LAG_TRUTH.replace(
            "b = 3.0",
            "b = 3.0\nd = 0.001\ntau = { start = 0.0001, min = 0.0 }",
        ) + "[H1.x]\nx = \"d\"\n[H0.x]\nx = 1.0\n[delays]\nu = \"tau\"\n";
        let candidate = ModelStructure::parse(&candidate_text, "candidate.toml").unwrap();
        let options = FitOptions {
            reduce: true,
            ..FitOptions::default()
        };
        let result = fit(&candidate, &document, &options).unwrap();
        assert!(!result.reduction.is_empty());
        let dropped: Vec<&str> = result
            .reduction
            .iter()
            .filter(|s| s.accepted)
            .map(|s| s.dropped.as_str())
            .collect();
        for name in &dropped {
            let report = result.parameters.iter().find(|p| p.name == *name).unwrap();
            assert_eq!(report.status, ParameterStatus::Fixed);
            assert_eq!(report.value, 0.0);
        }
        // The true parameters survive and are recovered.
        assert!(!dropped.contains(&"a") && !dropped.contains(&"b"));
        assert!((result.parameter("a").unwrap() + 2.0).abs() < 1e-3);
        assert!((result.parameter("b").unwrap() - 3.0).abs() < 1e-3);
        for step in &result.reduction {
            assert!(step.average_cost_after.is_finite());
        }
    }

    #[test]
    fn a_flapping_time_constant_at_zero_leaves_no_state_space_model() {
        let mut structure = hybrid_structure();
        assert!(has_invertible_mass_matrix(&structure));
        let tau_f = structure.parameter_index("tau_f").unwrap();
        structure.parameters[tau_f].value = 0.0;
        assert!(!has_invertible_mass_matrix(&structure));
    }

    fn report(name: &str, value: f64, status: Status, cramer_rao_percent: f64) -> ParameterReport {
        ParameterReport {
            name: name.into(),
            value,
            status,
            cramer_rao_percent: Some(cramer_rao_percent),
            insensitivity_percent: None,
            flags: Vec::new(),
            prior: None,
        }
    }

    #[test]
    fn the_shift_is_counted_in_the_moved_parameters_own_bounds() {
        // Zw −0.9 at CR 50 % (bound 0.45) moving to −52 is 113.6 bounds; Zcol −14.7 at CR
        // 2 % (bound 0.294) moving to −14.1 is 2.04 bounds; Nv is the dropped one and
        // a fixed parameter is not measured, however far it "moves".
        let before = [
            report("Zw", -0.9, Status::Free, 50.0),
            report("Zcol", -14.7, Status::Free, 2.0),
            report("Nv", 0.4, Status::Free, 25.0),
            report("Kcs", 0.066, Status::Fixed, 1.0),
        ];
        let mut after = before.clone();
        after[0].value = -52.0;
        after[1].value = -14.1;
        after[2].value = 0.0;
        after[3].value = 5.0;
        let (name, shift) = largest_shift(&before, &after, "Nv").unwrap();
        assert_eq!(name, "Zw");
        assert!((shift - 51.1 / 0.45).abs() < 1e-9, "{shift}");
        // Without Zw the largest is Zcol's small, ordinary move.
        let (name, shift) = largest_shift(&before[1..], &after[1..], "Nv").unwrap();
        assert_eq!(name, "Zcol");
        assert!((shift - 0.6 / 0.294).abs() < 1e-9, "{shift}");
        // No bound, nothing measured.
        let mut unbounded = before.clone();
        unbounded
            .iter_mut()
            .for_each(|p| p.cramer_rao_percent = None);
        assert_eq!(largest_shift(&unbounded, &after, "Nv"), None);
    }

    /// A heave-only model ẇ = Zw·w + Zcol·col at `zw`.
    fn heave_model(zw: f64) -> crate::fit::Model {
        let text = format!(
            "name = \"heave\"\nstates = [\"w\"]\ncontrols = [\"col\"]\noutputs = [\"w\"]\n\
             pairs = [{{ output = \"w\", input = \"col\", range = [0.1, 10.0] }}]\n\
             [parameters]\nZw = {zw:?}\nZcol = -14.0\n[F.w]\nw = \"Zw\"\n[G.w]\ncol = \"Zcol\"\n"
        );
        let structure = ModelStructure::parse(&text, "heave.toml").unwrap();
        structure.model(&structure.values()).unwrap()
    }

    #[test]
    fn the_guard_names_a_hover_mode_that_moves_or_goes_to_the_origin() {
        let before = heave_model(-0.32);
        // 3 % is within the 10 % limit.
        assert_eq!(
            super::hover_mode_change(&before, &heave_model(-0.31), 10.0),
            None
        );
        // To −0.001: the heave mode is gone in all but name.
        let moved = super::hover_mode_change(&before, &heave_model(-0.001), 10.0).unwrap();
        assert!(moved.starts_with("moves the heave mode -0.32"), "{moved}");
        assert!(moved.ends_with("(100 %)"), "{moved}");
        // Exactly zero: a pole at the origin.
        let origin = super::hover_mode_change(&before, &heave_model(0.0), 10.0).unwrap();
        assert_eq!(origin, "puts 1 pole(s) at the origin");
        // A mode above 3 rad/s is not guarded.
        assert_eq!(
            super::hover_mode_change(&heave_model(-5.0), &heave_model(-9.0), 10.0),
            None
        );
    }

    #[test]
    fn needed_parameters_carry_the_reason_of_their_step() {
        let step = |dropped: &str, accepted: bool, mode: Option<&str>| ReductionStep {
            dropped: dropped.into(),
            reason: "insensitivity 12.0 %".into(),
            average_cost_before: 10.0,
            average_cost_after: 14.5,
            accepted,
            left_the_minimum: false,
            moved_hover_mode: mode.map(str::to_string),
        };
        assert_eq!(step("Xr", true, None).needed_because(), None);
        assert_eq!(
            step(
                "Zw",
                false,
                Some("moves the heave mode -0.32 -> -0.001 (100 %)")
            )
            .needed_because()
            .unwrap(),
            "without it the refit moves the heave mode -0.32 -> -0.001 (100 %)"
        );
        assert_eq!(
            step("Lfu", false, None).needed_because().unwrap(),
            "without it J_ave rises 10.00 -> 14.50"
        );
    }

    #[test]
    fn a_step_that_could_not_be_evaluated_survives_a_json_round_trip() {
        let step = ReductionStep {
            dropped: "tau_f".into(),
            reason: "insensitivity 80.0 %; at zero M would be singular".into(),
            average_cost_before: 12.5,
            average_cost_after: f64::INFINITY,
            accepted: false,
            left_the_minimum: false,
            moved_hover_mode: None,
        };
        let json = serde_json::to_string(&step).unwrap();
        assert!(json.contains("\"average_cost_after\":null"), "{json}");
        let back: ReductionStep = serde_json::from_str(&json).unwrap();
        assert_eq!(back, step);
    }

    #[test]
    fn a_needed_parameter_does_not_end_the_reduction() {
        // The lag plus a feed-through-like H1 `d` whose truth is 0. Limits so tight that
        // every parameter is flagged: the reduction must try them all, restore the needed
        // ones (a, b) and still drop `d`.
        let document = lag_data();
        let candidate_text = LAG_TRUTH.replace("b = 3.0", "b = 3.0\nd = 0.001")
            + "[H1.x]\nx = \"d\"\n[H0.x]\nx = 1.0\n";
        let candidate = ModelStructure::parse(&candidate_text, "candidate.toml").unwrap();
        let options = FitOptions {
            reduce: true,
            // Every parameter violates these: a and b are needed, d is not.
            insensitivity_limit_percent: 0.0,
            cramer_rao_limit_percent: 0.0,
            ..FitOptions::default()
        };
        let result = fit(&candidate, &document, &options).unwrap();
        let tried: Vec<(&str, bool)> = result
            .reduction
            .iter()
            .map(|s| (s.dropped.as_str(), s.accepted))
            .collect();
        // Each parameter tried once; a and b restored, d dropped. (d, the most
        // insensitive at its truth of 0, goes first; a and b are found needed after the
        // last accepted drop, so the final pass has nothing to try again.)
        assert_eq!(tried.len(), 3, "{tried:?}");
        for (name, accepted) in &tried {
            assert_eq!(*accepted, *name == "d", "{tried:?}");
        }
        assert!((result.parameter("a").unwrap() + 2.0).abs() < 1e-3);
        assert!((result.parameter("b").unwrap() - 3.0).abs() < 1e-3);
    }
}
