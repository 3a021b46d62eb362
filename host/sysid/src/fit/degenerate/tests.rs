use super::*;
use crate::fit::test_support::{shipped, values_with, SHIPPED_NAMES};

#[test]
fn every_shipped_structure_starts_off_its_range_bounds() {
    for name in SHIPPED_NAMES {
        let structure = shipped(name);
        let found = degenerate_reasons(&structure, &structure.values());
        assert!(found.is_empty(), "{name}: {found:?}");
    }
}

#[test]
fn tau_f_on_its_floor_is_degenerate_and_a_hair_above_the_tolerance_is_not() {
    // The TREX file: tau_f = { start = 0.03, min = 0.005, max = 0.5 }.
    let structure = shipped("trex700l-9dof-hybrid");
    let on = values_with(&structure, &[("tau_f", 0.005)]);
    assert_eq!(
        on_range_bounds(&structure, &on),
        vec![DegenerateReason {
            parameter: "tau_f".into(),
            value: 0.005,
            reason: DegenerateKind::OnLowerBound,
            limit: 0.005,
        }]
    );
    // Within 0.1 % of the bound: on it (5 µs above a 5 ms bound).
    let within = values_with(&structure, &[("tau_f", 0.005 + 0.005e-3)]);
    assert_eq!(on_range_bounds(&structure, &within).len(), 1);
    // 0.2 % above it: off.
    let off = values_with(&structure, &[("tau_f", 0.005 * 1.002)]);
    assert!(on_range_bounds(&structure, &off).is_empty());
    // The upper bound too, and the servo's ω_n range at either end.
    let top = values_with(&structure, &[("tau_f", 0.5), ("servo_omega", 5.0)]);
    let found = on_range_bounds(&structure, &top);
    let kinds: Vec<(&str, DegenerateKind)> = found
        .iter()
        .map(|r| (r.parameter.as_str(), r.reason))
        .collect();
    assert_eq!(
        kinds,
        [
            ("tau_f", DegenerateKind::OnUpperBound),
            ("servo_omega", DegenerateKind::OnLowerBound)
        ]
    );
}

#[test]
fn a_sign_bound_at_zero_is_physical() {
    // Zw, Yv, Xu <= 0 and the delays >= 0: resting at zero is a value the aircraft can
    // have (the shipped TREX models hold their delays and X_u at 0).
    let structure = shipped("trex700l-9dof-hybrid");
    let values = values_with(
        &structure,
        &[
            ("Zw", 0.0),
            ("Yv", 0.0),
            ("Xu", 0.0),
            ("tau_lat", 0.0),
            ("tau_col", 0.0),
        ],
    );
    assert!(degenerate_reasons(&structure, &values).is_empty());
    // The delays' upper bound (0.1 s) is a range: on it is degenerate.
    let long = values_with(&structure, &[("tau_lat", 0.1)]);
    let found = on_range_bounds(&structure, &long);
    assert_eq!(found.len(), 1);
    assert_eq!(found[0].reason, DegenerateKind::OnUpperBound);
}

#[test]
fn a_fixed_parameter_on_a_bound_is_not_judged_for_it() {
    let mut structure = shipped("trex700l-9dof-hybrid");
    let index = structure.parameter_index("tau_f").expect("tau_f");
    structure.parameters[index].kind = ParameterKind::Fixed;
    let values = values_with(&structure, &[("tau_f", 0.005)]);
    assert!(degenerate_reasons(&structure, &values).is_empty());
}

#[test]
fn outside_the_physical_ranges_first_then_the_bounds() {
    // The issue's TREX minimum: tau_f on its floor, and a flapping stiffness L_b1s of
    // 10¹⁴ /s² (the physical limit of its F entry is Ω² = 9·10⁴ /s²).
    let structure = shipped("trex700l-9dof-hybrid");
    let values = values_with(&structure, &[("tau_f", 0.005), ("Lb1s", 3.2e14)]);
    let found = degenerate_reasons(&structure, &values);
    let kinds: Vec<(&str, DegenerateKind)> = found
        .iter()
        .map(|r| (r.parameter.as_str(), r.reason))
        .collect();
    assert_eq!(
        kinds,
        [
            ("Lb1s", DegenerateKind::OutsidePhysicalRange),
            ("tau_f", DegenerateKind::OnLowerBound)
        ]
    );
    let line = describe(&found);
    assert!(
        line.starts_with("`Lb1s` = 3.200e14 outside its physical range"),
        "{line}"
    );
    assert!(
        line.ends_with("`tau_f` = 0.005 on its lower bound 0.005"),
        "{line}"
    );
    // model.json spelling.
    let json = serde_json::to_string(&found[1]).expect("serializes");
    assert_eq!(
        json,
        r#"{"parameter":"tau_f","value":0.005,"reason":"on_lower_bound","limit":0.005}"#
    );
}

/// The first-order lag of the fit tests with its pole's parameter `a` bounded at
/// `lower`, fitted to exact data of a = −2: with the bound at −1 the minimum rests on it.
fn lag_fit(lower: &str, recover: bool) -> crate::fit::FitResult {
    use crate::fit::test_support::{first_order_structure, synthetic_document, FIRST_ORDER};
    let truth = first_order_structure();
    let document = synthetic_document(&truth.model(&truth.values()).unwrap(), &truth, 20);
    let text = FIRST_ORDER.replace(
        "a = { start = -2.0, max = 0.0 }",
        &format!("a = {{ start = -0.5, min = {lower}, max = 0.0 }}"),
    );
    let bounded = ModelStructure::parse(&text, "lag.toml").unwrap();
    let options = crate::fit::FitOptions {
        recover_implausible: recover,
        ..crate::fit::FitOptions::default()
    };
    crate::fit::fit(&bounded, &document, &options).unwrap()
}

#[test]
fn a_fit_on_a_range_bound_runs_again_elsewhere_then_says_why_it_is_degenerate() {
    let result = lag_fit("-1.0", true);
    assert_eq!(result.parameter("a"), Some(-1.0));
    assert_eq!(
        result.degenerate,
        vec![DegenerateReason {
            parameter: "a".into(),
            value: -1.0,
            reason: DegenerateKind::OnLowerBound,
            limit: -1.0,
        }]
    );
    // Every restart elsewhere was made, with seeds drawn from the fit's (1).
    let seeds: Vec<u64> = (1..=crate::fit::DEGENERATE_RESTARTS)
        .map(|round| crate::fit::restart_seed(1, round))
        .collect();
    assert_eq!(result.degenerate_restarts, seeds);
    assert!(seeds.iter().all(|&s| s != 1) && seeds[0] != seeds[1] && seeds[1] != seeds[2]);
    // The document carries both; the same fit without the judgement (the campaign's
    // 6-DOF start) neither.
    let document = result.to_document();
    assert_eq!(document.degenerate, result.degenerate);
    assert_eq!(document.degenerate_restarts, seeds);
    let unjudged = lag_fit("-1.0", false);
    assert!(unjudged.degenerate.is_empty() && unjudged.degenerate_restarts.is_empty());
    assert_eq!(unjudged.parameter("a"), Some(-1.0));
}

#[test]
fn a_fit_inside_its_bounds_is_not_run_again() {
    // The bound at −3 lies beyond the truth's −2: the minimum is off it.
    let result = lag_fit("-3.0", true);
    assert!((result.parameter("a").unwrap() + 2.0).abs() < 1e-6);
    assert!(result.degenerate.is_empty());
    assert!(result.degenerate_restarts.is_empty());
    let json = serde_json::to_string(&result.to_document()).unwrap();
    assert!(!json.contains("degenerate"), "absent when empty");
}
