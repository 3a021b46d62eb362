use super::*;
use crate::fit::test_support::{first_order_structure, synthetic_document};

#[test]
fn weights_and_wrapping() {
    assert!((coherence_weight(1.0) - (1.58f64 * (1.0 - (-1.0f64).exp())).powi(2)).abs() < 1e-15);
    assert_eq!(coherence_weight(0.0), 0.0);
    assert_eq!(wrap_degrees(190.0), -170.0);
    assert_eq!(wrap_degrees(-190.0), 170.0);
    assert_eq!(wrap_degrees(540.0), 180.0);
    assert!((wrap_degrees(-720.5) + 0.5).abs() < 1e-12);
    let grid = log_spaced(0.1, 10.0, 3);
    assert!((grid[1] - 1.0).abs() < 1e-12 && (grid[2] - 10.0).abs() < 1e-12);
}

#[test]
fn cost_matches_hand_computation() {
    // Data = model with a constant +1 dB and +10° offset at coherence 1: every point
    // contributes W_γ (1·1² + 0.01745·10²), and (20/n)·n·that = 20·W_γ·2.745.
    let structure = first_order_structure();
    let truth = structure.model(&structure.values()).unwrap();
    let mut document = synthetic_document(&truth, &structure, 20);
    for pair in &mut document.pairs {
        for value in &mut pair.mag_db {
            *value -= 1.0;
        }
        for value in &mut pair.phase_deg {
            *value -= 10.0;
        }
    }
    let grids = build_pair_grids(&structure, &document, 20).unwrap();
    let costs = pair_costs(&truth, &grids).unwrap();
    let expected = 20.0 * coherence_weight(1.0) * (1.0 + PHASE_WEIGHT * 100.0);
    for cost in costs {
        assert!(
            (cost - expected).abs() < 1e-6 * expected,
            "{cost} vs {expected}"
        );
    }
}

#[test]
fn analytic_jacobian_matches_central_differences() {
    let structure = crate::fit::test_support::hybrid_structure();
    let values = crate::fit::test_support::hybrid_truth_values(&structure);
    let truth = structure.model(&values).unwrap();
    let document = synthetic_document(&truth, &structure, 80);
    // Evaluate away from the minimum so residuals are not all zero.
    let moved: Vec<f64> = values.iter().map(|v| v * 1.1 + 0.001).collect();
    let free = structure.free_indices();
    let grids = build_pair_grids(&structure, &document, 8).unwrap();
    let (_, jacobian) = residuals_and_jacobian(&structure, &moved, &free, &grids).unwrap();
    for (column, &parameter) in free.iter().enumerate() {
        // Five-point stencil, f' = (−f(x+2h) + 8f(x+h) − 8f(x−h) + f(x−2h))/12h, error
        // O(h⁴): the low-frequency poles make the responses curved in the tiny speed
        // derivatives, where a plain central difference is not accurate enough.
        let step = 1e-5 * moved[parameter].abs().max(1e-2);
        let at = |offset: f64| {
            let mut shifted = moved.clone();
            shifted[parameter] += offset * step;
            residuals(&structure.model(&shifted).unwrap(), &grids).unwrap()
        };
        let (r_plus2, r_plus, r_minus, r_minus2) = (at(2.0), at(1.0), at(-1.0), at(-2.0));
        for row in 0..r_plus.len() {
            let numeric = (-r_plus2[row] + 8.0 * r_plus[row] - 8.0 * r_minus[row] + r_minus2[row])
                / (12.0 * step);
            let analytic = jacobian[(row, column)];
            assert!(
                (numeric - analytic).abs() <= 1e-5 * (1.0 + analytic.abs()),
                "{} row {row}: numeric {numeric} analytic {analytic}",
                structure.parameters[parameter].name
            );
        }
    }
}

#[test]
fn cost_between_identical_models_is_zero() {
    let structure = crate::fit::test_support::hybrid_structure();
    let values = crate::fit::test_support::hybrid_truth_values(&structure);
    let truth = structure.model(&values).unwrap();
    let bands = vec![
        PairBand {
            input: "lat".into(),
            output: "p".into(),
            range: [0.5, 30.0],
        },
        PairBand {
            input: "col".into(),
            output: "az".into(),
            range: [0.2, 30.0],
        },
    ];
    let same = cost_between_models(&truth, &truth, &bands, 20).unwrap();
    assert!(same.average < 1e-20);
    let mut other = truth.clone();
    other.delays[0] += 0.01;
    let shifted = cost_between_models(&truth, &other, &bands, 20).unwrap();
    assert!(
        shifted.costs[0] > 1.0 && shifted.costs[1] < 1e-20,
        "{shifted:?}"
    );
    let missing = PairBand {
        input: "lat".into(),
        output: "nope".into(),
        range: [1.0, 2.0],
    };
    assert!(matches!(
        cost_between_models(&truth, &truth, &[missing], 20),
        Err(FitError::UnknownPairName { .. })
    ));
}

proptest::proptest! {
    #[test]
    fn wrapped_phase_is_in_range_and_congruent(angle in -1e5f64..1e5) {
        let wrapped = wrap_degrees(angle);
        proptest::prop_assert!(wrapped > -180.0 && wrapped <= 180.0);
        let turns = (angle - wrapped) / 360.0;
        proptest::prop_assert!((turns - turns.round()).abs() < 1e-9);
    }

    #[test]
    fn jacobian_matches_differences_for_random_lags(
        a in -5.0f64..-0.2,
        b in 0.1f64..10.0,
        tau in 0.0f64..0.1,
    ) {
        let structure = first_order_structure();
        let values = vec![a, b, tau];
        let truth = structure.model(&[-1.0, 1.0, 0.02]).unwrap();
        let document = synthetic_document(&truth, &structure, 20);
        let grids = build_pair_grids(&structure, &document, 20).unwrap();
        let free = structure.free_indices();
        let (_, jacobian) = residuals_and_jacobian(&structure, &values, &free, &grids).unwrap();
        for (column, &parameter) in free.iter().enumerate() {
            let step = 1e-6 * values[parameter].abs().max(1e-3);
            let mut plus = values.clone();
            plus[parameter] += step;
            let mut minus = values.clone();
            minus[parameter] -= step;
            let r_plus = residuals(&structure.model(&plus).unwrap(), &grids).unwrap();
            let r_minus = residuals(&structure.model(&minus).unwrap(), &grids).unwrap();
            for row in 0..r_plus.len() {
                let numeric = (r_plus[row] - r_minus[row]) / (2.0 * step);
                let analytic = jacobian[(row, column)];
                proptest::prop_assert!((numeric - analytic).abs() <= 1e-5 * (1.0 + analytic.abs()));
            }
        }
    }
}
