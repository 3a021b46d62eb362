//! Tests of the mode computation and naming on exact synthetic systems.

use std::f64::consts::LN_2;

use nalgebra::DMatrix;
use num_complex::Complex64;

use super::eigen::*;
use super::naming::*;
use super::*;
use crate::fit::model::Model;
use crate::fit::test_support::*;

fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// A model with identity M, the given F and no controls or outputs.
fn model_of(states: &[&str], f: DMatrix<f64>) -> Model {
    let mut model = Model::zeros(names(states), Vec::new(), Vec::new());
    model.m = DMatrix::identity(states.len(), states.len());
    model.f = f;
    model
}

fn state(states: &[&str], name: &str) -> usize {
    states.iter().position(|s| *s == name).unwrap()
}

/// Block-diagonal: a longitudinal hover oscillation on u/q/θ with poles
/// −0.2 ± 0.5j and a real pole on u/q/θ at −1.5, heave −0.4 on w, yaw −0.7 on r.
fn block_diagonal() -> (Vec<&'static str>, Model) {
    let states = vec!["u", "q", "theta", "w", "r"];
    let mut f = DMatrix::zeros(5, 5);
    let (u, q, theta, w, r) = (0, 1, 2, 3, 4);
    // θ̇ = q, u̇ = −g θ, q̇ = a u + b q + c θ: characteristic polynomial
    // s³ − b s² − c s + a g = (s + 1.5)(s² + 0.4 s + 0.29).
    let g = STANDARD_GRAVITY;
    f[(theta, q)] = 1.0;
    f[(u, theta)] = -g;
    // (s + 1.5)(s² + 0.4 s + 0.29) = s³ + 1.9 s² + 0.89 s + 0.435.
    f[(q, q)] = -1.9;
    f[(q, theta)] = -0.89;
    f[(q, u)] = 0.435 / g;
    f[(w, w)] = -0.4;
    f[(r, r)] = -0.7;
    (states.clone(), model_of(&states, f))
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance
}

#[test]
fn block_diagonal_system_has_the_known_modes_and_names() {
    let (states, model) = block_diagonal();
    let found = modes(&model).unwrap();
    let summary: Vec<(ModeName, f64, f64)> = found
        .iter()
        .map(|m| (m.name, m.eigenvalue.re, m.eigenvalue.im))
        .collect();
    assert_eq!(found.len(), 4, "{summary:?}");
    // Sorted by |λ|: heave 0.4, oscillation √0.29 = 0.539, yaw 0.7, pitch 1.5.
    let heave = &found[0];
    assert_eq!(heave.name, ModeName::Heave);
    assert!(close(heave.eigenvalue.re, -0.4, 1e-12) && heave.eigenvalue.im == 0.0);
    assert_eq!(heave.poles, 1);
    assert!(close(heave.shares[state(&states, "w")], 1.0, 1e-12));
    assert!(close(heave.time_to_half_s().unwrap(), LN_2 / 0.4, 1e-12));
    assert_eq!(heave.time_to_double_s(), None);
    assert_eq!(heave.damping_ratio(), None);
    assert!(close(heave.natural_frequency().unwrap(), 0.4, 1e-12));

    let oscillation = &found[1];
    assert_eq!(oscillation.name, ModeName::HoverOscillationLongitudinal);
    assert_eq!(oscillation.poles, 2);
    assert!(close(oscillation.eigenvalue.re, -0.2, 1e-10));
    assert!(close(oscillation.eigenvalue.im, 0.5, 1e-10));
    let omega = 0.29f64.sqrt();
    assert!(close(
        oscillation.natural_frequency().unwrap(),
        omega,
        1e-10
    ));
    assert!(close(
        oscillation.damping_ratio().unwrap(),
        0.2 / omega,
        1e-10
    ));
    assert!(close(
        oscillation.time_to_half_s().unwrap(),
        LN_2 / 0.2,
        1e-9
    ));
    assert!(close(oscillation.groups.longitudinal, 1.0, 1e-12));
    // θ̇ = q and u̇ = −g θ: rate, attitude and speed carry equal attitude-equivalent
    // amplitudes, a third of the share each.
    for name in ["u", "q", "theta"] {
        assert!(
            close(oscillation.shares[state(&states, name)], 1.0 / 3.0, 1e-9),
            "{name}: {:?}",
            oscillation.shares
        );
    }

    let yaw = &found[2];
    assert_eq!(yaw.name, ModeName::Yaw);
    assert!(close(yaw.eigenvalue.re, -0.7, 1e-12));
    let pitch = &found[3];
    assert_eq!(pitch.name, ModeName::PitchSubsidence);
    assert!(close(pitch.eigenvalue.re, -1.5, 1e-10) && pitch.eigenvalue.im == 0.0);
}

#[test]
fn unstable_pole_has_a_time_to_double_and_a_zero_pole_is_the_origin() {
    // ṗ = 0.5 p (unstable roll), ẇ = 0 (no heave damping: a pole at the origin).
    let states = ["p", "w"];
    let f = DMatrix::from_row_slice(2, 2, &[0.5, 0.0, 0.0, 0.0]);
    let found = modes(&model_of(&states, f)).unwrap();
    assert_eq!(found[0].name, ModeName::Origin);
    assert_eq!(found[0].natural_frequency(), None);
    assert_eq!(found[0].time_to_half_s(), None);
    assert_eq!(found[0].time_to_double_s(), None);
    // The origin's eigenvector: all w.
    assert!(close(found[0].shares[1], 1.0, 1e-12));
    assert_eq!(found[1].name, ModeName::RollSubsidence);
    assert!(close(
        found[1].time_to_double_s().unwrap(),
        LN_2 / 0.5,
        1e-12
    ));
    assert_eq!(found[1].time_to_half_s(), None);
    let records = mode_records(&model_of(&states, DMatrix::zeros(2, 2))).unwrap();
    assert_eq!(poles_at_origin(&records), 2);
    assert_eq!(records[0].omega_n, None);
}

#[test]
fn rotor_and_spiral_rules() {
    // Roll–flap: ṗ = L b1s, τ ḃ1s = −b1s − τ p (the 9-DOF structure's roll axis):
    // s² + s/τ + L = 0 with τ = 0.07, L = 200 → −7.14 ± 11.8j, rotor share ≈ 0.25.
    let states = ["p", "phi", "b1s"];
    let (tau, l) = (0.07, 200.0);
    let mut model = model_of(
        &states,
        DMatrix::from_row_slice(3, 3, &[0.0, 0.0, l, 1.0, 0.0, 0.0, -tau, 0.0, -1.0]),
    );
    model.m[(2, 2)] = tau;
    let found = modes(&model).unwrap();
    let roll_flap = found.iter().find(|m| m.poles == 2).unwrap();
    assert_eq!(roll_flap.name, ModeName::RollFlap);
    let expected = Complex64::new(-0.5 / tau, (l - 0.25 / (tau * tau)).sqrt());
    assert!((roll_flap.eigenvalue - expected).norm() < 1e-9);
    assert!(roll_flap.groups.rotor() > ROTOR_SHARE_LIMIT);
    // The φ integrator of this system is at the origin.
    assert_eq!(found[0].name, ModeName::Origin);

    // Spiral: a slow real mode on r and φ together: φ̇ = −0.2 φ + r, ṙ = −0.1 r. Its
    // eigenvector has r = (λ + 0.2) φ = 0.1 φ, so r/|λ| and φ weigh the same: 0.5 each.
    let states = ["phi", "r"];
    let f = DMatrix::from_row_slice(2, 2, &[-0.2, 1.0, 0.0, -0.1]);
    let found = modes(&model_of(&states, f)).unwrap();
    let spiral = found.iter().find(|m| close(m.eigenvalue.re, -0.1, 1e-12));
    assert_eq!(spiral.unwrap().name, ModeName::Spiral);
    assert!(close(spiral.unwrap().groups.yaw, 0.5, 1e-9));
    // The other one (−0.2) is φ alone: a roll subsidence.
    let roll = found.iter().find(|m| close(m.eigenvalue.re, -0.2, 1e-12));
    assert_eq!(roll.unwrap().name, ModeName::RollSubsidence);
}

#[test]
fn a_heave_mode_without_damping_is_still_heave() {
    // Z_w = 0 with a trace of pitch attitude in the eigenvector (seed 2 of the default
    // campaign: λ = −0.0007, θ/w = 0.0018): θ̇ = −2 θ + 0.0036 w, ẇ = −0.0007 w.
    let states = ["theta", "w"];
    let f = DMatrix::from_row_slice(2, 2, &[-2.0, 0.0036, 0.0, -0.0007]);
    let found = modes(&model_of(&states, f)).unwrap();
    let slow = &found[0];
    assert!(close(slow.eigenvalue.re, -0.0007, 1e-15));
    // Scaled with |λ| itself, w would weigh 0.0007/g = 7·10⁻⁵ against θ's 0.0018.
    assert_eq!(slow.name, ModeName::Heave, "{:?}", slow.shares);
    assert!(slow.shares[1] > 0.9, "{:?}", slow.shares);
    assert_eq!(found[1].name, ModeName::PitchSubsidence);
}

#[test]
fn a_double_root_at_the_origin_is_two_modes() {
    // ẇ = r, ṙ = −10⁻²⁰ w: eigenvalues ±10⁻¹⁰j, a conjugate pair at the origin (as a
    // double root at 0 may come out of the Schur form; seed 7 of the default campaign,
    // with heave and yaw damping both lost). It is two lost modes, each paired with a
    // truth mode of its own.
    let states = ["w", "r", "p"];
    let f = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, -1e-20, 0.0, 0.0, 0.0, 0.0, -3.0]);
    let records = mode_records(&model_of(&states, f)).unwrap();
    let origins: Vec<&ModeRecord> = records.iter().filter(|r| r.name == "origin").collect();
    assert_eq!(origins.len(), 2, "{records:?}");
    assert!(origins.iter().all(|r| r.poles == 1), "{records:?}");
    assert_eq!(poles_at_origin(&records), 2);
}

#[test]
fn bad_models_are_errors_not_panics() {
    let states = ["u", "w"];
    let mut model = model_of(&states, DMatrix::identity(2, 2));
    model.m[(1, 1)] = 0.0;
    assert_eq!(modes(&model), Err(ModeError::SingularMassMatrix));
    let mut model = model_of(&states, DMatrix::identity(2, 2));
    model.f[(0, 1)] = f64::NAN;
    assert_eq!(modes(&model), Err(ModeError::NotFinite));
    let mut model = model_of(&states, DMatrix::identity(2, 2));
    model.m[(0, 0)] = f64::INFINITY;
    assert_eq!(modes(&model), Err(ModeError::NotFinite));
    // A nearly singular M whose inverse overflows.
    let mut model = model_of(&states, DMatrix::from_element(2, 2, 1e300));
    model.m[(0, 0)] = 1e-300;
    assert_eq!(modes(&model), Err(ModeError::NotFinite));
    let empty = model_of(&[], DMatrix::zeros(0, 0));
    assert_eq!(modes(&empty).unwrap(), Vec::new());
    assert!(ModeError::SingularMassMatrix
        .to_string()
        .contains("singular"));
}

#[test]
fn pairing_prefers_the_name_then_the_nearest_eigenvalue() {
    let (_, truth) = block_diagonal();
    // Identified: heave and yaw swapped in speed (heave −0.72 near the truth's yaw
    // −0.7, yaw −0.42 near the truth's heave −0.4), oscillation 10 % slower, and the
    // pitch subsidence lost to a pole at the origin on θ alone.
    let mut f = truth.f.clone();
    f[(3, 3)] = -0.72;
    f[(4, 4)] = -0.42;
    let g = STANDARD_GRAVITY;
    // (s + 1.5)(s² + 0.36 s + 0.2349): Re −0.18, |λ| 0.4847.
    let (a2, a1, a0) = (1.5 + 0.36, 1.5 * 0.36 + 0.2349, 1.5 * 0.2349);
    f[(1, 1)] = -a2;
    f[(1, 2)] = -a1;
    f[(1, 0)] = a0 / g;
    let identified = model_of(&["u", "q", "theta", "w", "r"], f);
    let comparison = compare_modes(&identified, &truth).unwrap();
    let by_name = |name: ModeName| {
        comparison
            .identified
            .iter()
            .find(|r| r.name == name.as_str())
            .unwrap()
    };
    // Heave is paired with the truth's heave although the truth's yaw is nearer.
    let heave = by_name(ModeName::Heave);
    assert_eq!(heave.truth, Some([-0.4, 0.0]));
    assert!(close(heave.error_percent.unwrap(), 80.0, 1e-9));
    let yaw = by_name(ModeName::Yaw);
    assert_eq!(yaw.truth_name.as_deref(), Some("yaw"));
    assert!(close(yaw.error_percent.unwrap(), 40.0, 1e-9));
    let oscillation = by_name(ModeName::HoverOscillationLongitudinal);
    let expected = Complex64::new(-0.18, (0.2349f64 - 0.0324).sqrt());
    let truth_lambda = Complex64::new(-0.2, 0.5);
    assert!(close(
        oscillation.error_percent.unwrap(),
        100.0 * (expected - truth_lambda).norm() / truth_lambda.norm(),
        1e-6
    ));
    assert!(oscillation.error_percent.unwrap() < HOVER_MODE_TOLERANCE_PERCENT);
    // Hover modes of the truth: heave, oscillation, yaw, pitch subsidence (1.5).
    assert_eq!(comparison.hover.of, 4);
    assert_eq!(comparison.hover.matched, 2, "{:?}", comparison.truth);
    assert!(close(
        comparison.hover.worst_error_percent.unwrap(),
        80.0,
        1e-9
    ));
    assert_eq!(comparison.poles_at_origin, 0);
    assert_eq!(comparison.truth.len(), 4);
    assert!(comparison.truth.iter().all(|t| t.identified.is_some()));

    // The same model compared with itself: every mode within 0 %.
    let same = compare_modes(&truth, &truth).unwrap();
    assert_eq!(same.hover.matched, same.hover.of);
    assert!(same
        .identified
        .iter()
        .all(|r| r.error_percent.unwrap() < 1e-9));
}

#[test]
fn a_lost_mode_at_the_origin_is_counted_and_fails_its_match() {
    let (_, truth) = block_diagonal();
    let mut f = truth.f.clone();
    f[(3, 3)] = 0.0; // heave damping lost
    let identified = model_of(&["u", "q", "theta", "w", "r"], f);
    let comparison = compare_modes(&identified, &truth).unwrap();
    assert_eq!(comparison.poles_at_origin, 1);
    let origin = &comparison.identified[0];
    assert_eq!(origin.name, "origin");
    // Paired by the nearest eigenvalue with the truth's heave: 100 % off.
    assert_eq!(origin.truth_name.as_deref(), Some("heave"));
    assert!(close(origin.error_percent.unwrap(), 100.0, 1e-9));
    assert_eq!(comparison.hover.matched, 3);
    assert!(!comparison.hover.all_matched());
    assert_eq!(comparison.hover.worst_error_percent, Some(100.0));
    assert!(mode_records(&truth)
        .unwrap()
        .iter()
        .all(|r| r.truth.is_none() && r.error_percent.is_none()));
}

#[test]
fn bo105_reference_hybrid_has_its_hover_modes() {
    // The 9-DOF hybrid at the simulator's mapped truth (BO105_HYBRID_REFERENCE).
    let structure = hybrid_structure();
    let model = structure.model(&hybrid_truth_values(&structure)).unwrap();
    let records = mode_records(&model).unwrap();
    let names: Vec<&str> = records.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "heave",
            "yaw",
            "hover oscillation (coupled)",
            "hover oscillation (coupled)",
            "pitch–flap",
            "roll–flap"
        ],
        "{records:#?}"
    );
    assert_eq!(poles_at_origin(&records), 0);
    let hover = records
        .iter()
        .filter(|r| r.omega_n.is_some_and(|w| w < HOVER_MODE_LIMIT_RAD_S))
        .count();
    assert_eq!(hover, 4);
    // One hover oscillation is unstable (time to double), the other stable.
    let oscillations: Vec<&ModeRecord> = records
        .iter()
        .filter(|r| r.name.starts_with("hover oscillation"))
        .collect();
    assert_ne!(
        oscillations[0].time_to_double_s.is_some(),
        oscillations[1].time_to_double_s.is_some()
    );
}

#[test]
fn records_round_trip_through_json() {
    let (_, truth) = block_diagonal();
    let comparison = compare_modes(&truth, &truth).unwrap();
    let json = serde_json::to_string(&comparison.identified).unwrap();
    assert!(json.contains(r#""zeta":null"#), "{json}");
    let back: Vec<ModeRecord> = serde_json::from_str(&json).unwrap();
    assert_eq!(back.len(), comparison.identified.len());
    assert_eq!(back[1].name, comparison.identified[1].name);
    // The brief form (no poles, shares, truth_name) reads with defaults.
    let minimal = r#"{"name":"heave","eigenvalue":[-0.3,0.0],"omega_n":0.3,"zeta":null,
        "time_to_double_s":null,"time_to_half_s":2.3,"truth":null,"error_percent":null}"#;
    let record: ModeRecord = serde_json::from_str(minimal).unwrap();
    assert_eq!(record.poles, 1);
    assert!(record.shares.is_empty() && record.truth_name.is_none());
}
