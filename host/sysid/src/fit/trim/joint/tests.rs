use super::*;
use crate::fit::test_support::{
    hybrid_structure, hybrid_truth_values, pitch_toy, synthetic_document,
};
use crate::fit::trim::tests::{linear_trim_points, names, STEPS};
use crate::fit::trim::{TrimBalance, TrimPoint};
use crate::fit::{fit, FitOptions, ParameterStatus};

const DERIVED: [&str; 5] = ["Mfu", "Lfu", "Nv", "Zw", "Nr"];

#[test]
fn the_balances_vanish_at_the_model_the_points_come_from() {
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let points = linear_trim_points(&structure, &truth, &STEPS);
    let balance = JointBalance::new(&structure, &points, &names(&DERIVED), 1e-3).unwrap();
    // Rows p, q, r (moments) and w (Z_w enters it directly), at each of the 9 points.
    assert_eq!(balance.len(), 4 * 9);
    let e = balance.residuals(&structure, &truth).unwrap();
    assert!(e.amax() < 1e-9, "{e}");
    // Away from it they do not, and the Jacobian is that of the residuals.
    let mut moved = truth.clone();
    let mfu = structure.parameter_index("Mfu").unwrap();
    moved[mfu] *= 1.2;
    let free = structure.free_indices();
    let (e, jacobian) = balance
        .residuals_and_jacobian(&structure, &moved, &free)
        .unwrap();
    assert!(e.amax() > 1.0, "{e}");
    let column = free.iter().position(|&i| i == mfu).unwrap();
    let step = 1e-3 * moved[mfu];
    let mut plus = moved.clone();
    plus[mfu] += step;
    let slope = (balance.residuals(&structure, &plus).unwrap() - &e) / step;
    // The residuals are affine in M_fu (module documentation of `trim`): exact slope.
    for row in 0..e.len() {
        assert!(
            (slope[row] - jacobian[(row, column)]).abs() <= 1e-5 * (1.0 + slope[row].abs()),
            "row {row}: {} vs {}",
            slope[row],
            jacobian[(row, column)]
        );
    }
}

#[test]
fn a_residual_is_the_stick_error_that_closes_the_balance() {
    // q̇ = Mu·u + Mlon·lon: forward points trimmed with lon = −(Mu/Mlon)·u. With M_u off
    // by δ the pitch balance misses by δ·Δu_i, which the stick closes with δ·Δu_i/M_lon:
    // e_i = δ·Δu_i/(M_lon·σ).
    let structure = pitch_toy(true);
    let speeds = [-1.0, 0.0, 2.0];
    let points = TrimPoints {
        points: speeds
            .iter()
            .map(|&u| TrimPoint {
                label: String::new(),
                states: [u, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.02 * u / 9.81],
                controls: [0.0, -0.05 / 6.0 * u, 0.0, 0.0],
            })
            .collect(),
    };
    let sigma = 3e-4;
    let balance = JointBalance::new(&structure, &points, &names(&["Mu"]), sigma).unwrap();
    let delta = 0.01;
    let values = [0.05 + delta, 6.0, -0.02];
    let e = balance.residuals(&structure, &values).unwrap();
    let mean = speeds.iter().sum::<f64>() / 3.0;
    assert_eq!(e.len(), 3);
    for (k, &u) in speeds.iter().enumerate() {
        let want = delta * (u - mean) / (6.0 * sigma);
        assert!((e[k] - want).abs() < 1e-9, "{} vs {want}", e[k]);
    }
    assert!(JointBalance::new(&structure, &points, &names(&["Mu"]), 0.0).is_err());
}

#[test]
fn the_joint_fit_is_exact_on_a_linear_model() {
    // Responses and trim points of the same linear model, every free parameter 10 % off
    // and the derived ones 30 % off: the fit (held, then released into the joint cost)
    // returns the model, the derived parameters fitted (status free) and balanced.
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let document = synthetic_document(&structure.model(&truth).unwrap(), &structure, 20);
    let points = linear_trim_points(&structure, &truth, &STEPS);
    let mut start = truth.clone();
    for (k, index) in structure.free_indices().into_iter().enumerate() {
        start[index] *= if k % 2 == 0 { 1.1 } else { 0.9 };
    }
    for name in DERIVED {
        start[structure.parameter_index(name).unwrap()] *= 1.3;
    }
    let options = FitOptions {
        max_starts: 3,
        trim_points: Some(points),
        trim_balance: TrimBalance::Joint { stick_sigma: 1e-3 },
        ..FitOptions::default()
    };
    let result = fit(&structure.with_values(&start).unwrap(), &document, &options).unwrap();
    assert!(result.average_cost < 1e-9, "J_ave {}", result.average_cost);
    assert!(result.balance_cost < 1e-12, "{}", result.balance_cost);
    for (index, parameter) in structure.parameters.iter().enumerate() {
        let got = result.parameter(&parameter.name).unwrap();
        assert!(
            (got - truth[index]).abs() <= 1e-5 * truth[index].abs().max(1e-3),
            "{}: {got} vs {}",
            parameter.name,
            truth[index]
        );
    }
    for name in DERIVED {
        let report = result.parameters.iter().find(|p| p.name == name).unwrap();
        assert_eq!(report.status, ParameterStatus::Free, "{name}");
    }
    let outcome = result.trim.as_ref().unwrap();
    assert_eq!(outcome.parameters.len(), DERIVED.len());
}
