//! Tests of the reduction ([`super`]).
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

#[test]
fn a_well_determined_parameter_that_moves_far_compensates_the_dropped_one() {
    // The R-50's step: Nr dropped, Kr 2.16 -> 4.78 at CR 5.6 % after the refit; Krfb
    // moves −25 % (within the limit); Zw moves +80 % but at CR 40 % (not determined).
    let before = [
        report("Nr", -4.1, Status::Free, 30.6),
        report("Kr", 2.16, Status::Free, 30.0),
        report("Krfb", -8.3, Status::Free, 20.0),
        report("Zw", -0.6, Status::Free, 10.0),
    ];
    let after = [
        report("Nr", 0.0, Status::Fixed, 0.0),
        report("Kr", 4.78, Status::Free, 5.6),
        report("Krfb", -6.2, Status::Free, 5.5),
        report("Zw", -1.08, Status::Free, 40.0),
    ];
    let text = super::compensating_parameter(&before, &after, "Nr", 20.0, 50.0).unwrap();
    assert_eq!(text, "Kr +121 % (2.1600 -> 4.7800, CR 5.6 %)");
    // Within 150 % nothing compensates.
    assert_eq!(
        super::compensating_parameter(&before, &after, "Nr", 20.0, 150.0),
        None
    );
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
        compensated_by: None,
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
        compensated_by: None,
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
    let candidate_text =
        LAG_TRUTH.replace("b = 3.0", "b = 3.0\nd = 0.001") + "[H1.x]\nx = \"d\"\n[H0.x]\nx = 1.0\n";
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
