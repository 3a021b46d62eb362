use nalgebra::{DMatrix, DVector};

use super::*;
use crate::fit::structure::ModelStructure;
use crate::fit::test_support::{hybrid_structure, hybrid_truth_values, pitch_toy};

/// Trim points of the linear model `structure` at `values`: at each point the given
/// u, v, w, r (columns of `set`), every other state and the four sticks solved from
/// `0 = F x + G u` (as many unknowns as states).
pub(super) fn linear_trim_points(
    structure: &ModelStructure,
    values: &[f64],
    set: &[[f64; 4]],
) -> TrimPoints {
    let model = structure.model(values).unwrap();
    let n = model.states.len();
    let given = ["u", "v", "w", "r"];
    let given_index: Vec<usize> = given
        .iter()
        .map(|g| model.states.iter().position(|s| s == g).unwrap())
        .collect();
    let free_states: Vec<usize> = (0..n).filter(|i| !given_index.contains(i)).collect();
    assert_eq!(free_states.len() + model.controls.len(), n);
    let points = set
        .iter()
        .enumerate()
        .map(|(number, values4)| {
            // Unknowns [x_free, u]; equations F x + G u = 0.
            let mut a = DMatrix::zeros(n, n);
            let mut b = DVector::zeros(n);
            for row in 0..n {
                for (col, &state) in free_states.iter().enumerate() {
                    a[(row, col)] = model.f[(row, state)];
                }
                for control in 0..model.controls.len() {
                    a[(row, free_states.len() + control)] = model.g[(row, control)];
                }
                for (k, &state) in given_index.iter().enumerate() {
                    b[row] -= model.f[(row, state)] * values4[k];
                }
            }
            let solution = a.lu().solve(&b).unwrap();
            let mut x = vec![0.0; n];
            for (k, &state) in given_index.iter().enumerate() {
                x[state] = values4[k];
            }
            for (col, &state) in free_states.iter().enumerate() {
                x[state] = solution[col];
            }
            let mut states = [0.0; 8];
            for (k, name) in STATE_COLUMNS.iter().enumerate() {
                if let Some(i) = model.states.iter().position(|s| s == name) {
                    states[k] = x[i];
                }
            }
            let mut controls = [0.0; 4];
            for (k, name) in CONTROL_COLUMNS.iter().enumerate() {
                let i = model.controls.iter().position(|c| c == name).unwrap();
                controls[k] = solution[free_states.len() + i];
            }
            TrimPoint {
                label: format!("point {number}"),
                states,
                controls,
            }
        })
        .collect();
    TrimPoints { points }
}

/// Hover, ±u, ±v, ±w, ±r.
pub(super) const STEPS: [[f64; 4]; 9] = [
    [0.0, 0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0, 0.0],
    [0.0, 0.0, 0.5, 0.0],
    [0.0, 0.0, -0.5, 0.0],
    [0.0, 0.0, 0.0, 0.1],
    [0.0, 0.0, 0.0, -0.1],
];

pub(super) fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// Derive `derived` from `points` starting with them at zero, and compare with `truth`.
fn assert_derived_exactly(
    structure: &ModelStructure,
    truth: &[f64],
    points: &TrimPoints,
    derived: &[&str],
) {
    let derived_names = names(derived);
    let mut start = truth.to_vec();
    for name in &derived_names {
        start[structure.parameter_index(name).unwrap()] = 0.0;
    }
    for d in derive(structure, &start, points, &derived_names).unwrap() {
        let want = truth[structure.parameter_index(&d.name).unwrap()];
        assert!(
            (d.value - want).abs() <= 1e-9 * want.abs().max(1e-6),
            "{}: derived {}, truth {want}",
            d.name,
            d.value
        );
    }
}

#[test]
fn derivation_is_exact_on_a_linear_model() {
    // Points from the hybrid model at its reference values; the derived parameters start
    // anywhere (here zero) and come back exactly, flapping residualized.
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let points = linear_trim_points(&structure, &truth, &STEPS);
    assert_derived_exactly(&structure, &truth, &points, &["Lv", "Mu", "Nv", "Zw", "Nr"]);
}

#[test]
fn the_papers_formula_is_the_special_case_without_flapping_or_couplings() {
    // A 1-state-per-row toy: q̇ = Mu·u + Mlon·lon, u̇ = −g θ + Xu u, θ̇ = q. Forward trim
    // points with lon = −(Mu/Mlon)·u: the derivation returns M_u = −M_lon ∂lon/∂u.
    let structure = pitch_toy(false);
    let gradient = -0.011; // ∂lon/∂u [1/(m/s)]
    let points = TrimPoints {
        points: [-1.0, 0.0, 2.0]
            .iter()
            .map(|&u| TrimPoint {
                label: String::new(),
                states: [u, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.02 * u / 9.81],
                controls: [0.0, gradient * u, 0.0, 0.0],
            })
            .collect(),
    };
    let derived = derive(&structure, &structure.values(), &points, &names(&["Mu"])).unwrap();
    assert!(
        (derived[0].value - (-6.0 * gradient)).abs() < 1e-12,
        "{derived:?}"
    );
}

#[test]
fn a_state_the_points_do_not_vary_is_refused_by_name() {
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    // No climb or descent: Zw is not informed.
    let points = linear_trim_points(&structure, &truth, &STEPS[..5]);
    let error = derive(&structure, &truth, &points, &names(&["Mu", "Zw"])).unwrap_err();
    assert_eq!(
        error,
        TrimError::NotInformed {
            parameter: "Zw".into()
        }
    );
    // Mu alone is fine.
    assert!(derive(&structure, &truth, &points, &names(&["Mu"])).is_ok());
}

#[test]
fn the_rotors_flap_back_is_derived_exactly_through_the_flapping() {
    // M_f,u and L_f,u sit in the flapping rows: the steady flapping is affine in them, so
    // they come back exactly from the moment balances (the hybrid's choice: the rotor
    // carries the speed stability, the body's own M_u, L_v held).
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let points = linear_trim_points(&structure, &truth, &STEPS);
    assert_derived_exactly(
        &structure,
        &truth,
        &points,
        &["Mfu", "Lfu", "Nv", "Zw", "Nr"],
    );
}

#[test]
fn a_parameter_of_m_or_of_the_flapping_block_is_refused() {
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let points = linear_trim_points(&structure, &truth, &STEPS);
    // τ_f is in M (and F_hh); Kcs couples the two flapping states.
    let mut structure = structure;
    let kcs = structure.parameter_index("Kcs").unwrap();
    structure.parameters[kcs].kind = crate::fit::ParameterKind::Free;
    for name in ["tau_f", "Kcs"] {
        assert_eq!(
            derive(&structure, &truth, &points, &names(&[name])).unwrap_err(),
            TrimError::NotLinear(name.into()),
            "{name}"
        );
    }
}

#[test]
fn csv_round_trips_and_bad_files_are_refused_with_their_line() {
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let points = linear_trim_points(&structure, &truth, &STEPS);
    let text = points.to_csv();
    assert_eq!(TrimPoints::parse_csv(&text).unwrap(), points);
    // Columns in another order, a comment, no label.
    let reordered = "# pilot's trim points\ncol,lat,lon,ped,theta,phi,r,q,p,w,v,u\n\
                     0.1,0,0,0,0,0,0,0,0,0,0,0\n0.1,0,0.02,0,0,0,0,0,0,0,0,1\n";
    let parsed = TrimPoints::parse_csv(reordered).unwrap();
    assert_eq!(parsed.points[1].states[0], 1.0);
    assert_eq!(parsed.points[1].controls[1], 0.02);
    assert_eq!(parsed.points[0].controls[3], 0.1);
    let cases = [
        ("", "line 1: no header line"),
        ("u,v\n", "line 1: missing column `w`"),
        (
            "label,u,v,w,p,q,r,phi,theta,lat,lon,ped,col,extra\n",
            "line 1: unknown column `extra`",
        ),
        (
            "u,v,w,p,q,r,phi,theta,lat,lon,ped,col\n0,0,0,0,0,0,0,0,0,0,0,NaN\n",
            "line 2: `col` is not a finite number: `NaN`",
        ),
        (
            "u,v,w,p,q,r,phi,theta,lat,lon,ped,col\n0,0,0\n",
            "line 2: 3 fields, the header has 12",
        ),
        (
            "u,v,w,p,q,r,phi,theta,lat,lon,ped,col\n0,0,0,0,0,0,0,0,0,0,0,0\n",
            "1 trim point(s): at least two are needed for a gradient",
        ),
    ];
    for (text, message) in cases {
        assert_eq!(
            TrimPoints::parse_csv(text).unwrap_err().to_string(),
            message,
            "{text:?}"
        );
    }
}

#[test]
fn quasi_static_derivative_residualizes_the_flapping() {
    // For the hybrid: M_u,qs = Mu + M_b1c·β1c_ss/u with β1c_ss from the flapping rows at
    // zero rates and sticks: −β1c + Kcs β1s + Mfu u = 0, −β1s − Kcs β1c + Lfu u = 0, so
    // β1c/u = (Mfu + Kcs Lfu)/(1 + Kcs²) (M = diag(…, τ_f, τ_f) scales rows only, so
    // A = M⁻¹F has the same steady state).
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let model = structure.model(&truth).unwrap();
    let value = |name: &str| truth[structure.parameter_index(name).unwrap()];
    let (kcs, mfu, lfu) = (value("Kcs"), value("Mfu"), value("Lfu"));
    let b1c = (mfu + kcs * lfu) / (1.0 + kcs * kcs);
    let want = value("Mu") + value("Mb1c") * b1c;
    let got = quasi_static_derivative(&model, "q", "u").unwrap();
    assert!((got - want).abs() <= 1e-9 * want.abs(), "{got} vs {want}");
    assert_eq!(quasi_static_derivative(&model, "q", "nonesuch"), None);
}

const HEADER: &str = "label,u,v,w,p,q,r,phi,theta,lat,lon,ped,col\n";

#[test]
fn implausible_magnitudes_are_refused_when_read() {
    let hover = "hover,0,0,0,0,0,0,0,0,0,0,0,0.35\n";
    let cases = [
        (
            "fast,1e30,0,0,0,0,0,0,0,0,0,0,0.35\n",
            "`u` = 1e30 is not a plausible trim point: a speed lies within ±150.0000 m/s",
        ),
        ("spin,0,0,0,0,0,-25,0,0,0,0,0,0.35\n", "`r` = -25"),
        (
            "inverted,0,0,0,0,0,0,3.1,0,0,0,0,0.35\n",
            "`phi` = 3.1 is not a plausible trim point: an angle lies within ±1.5708 rad",
        ),
        ("stick,0,0,0,0,0,0,0,0,0,1.5,0,0.35\n", "`lon` = 1.5"),
    ];
    for (point, message) in cases {
        let text = format!("{HEADER}{hover}{point}");
        let error = TrimPoints::parse_csv(&text).unwrap_err().to_string();
        assert!(error.starts_with("line 3: "), "{error}");
        assert!(error.contains(message), "{error}");
    }
    // At the edges of the ranges: accepted.
    let edges = format!("{HEADER}{hover}edge,150,-150,0,20,0,-20,1.5707,-1.5707,1,-1,1,-1\n");
    assert!(TrimPoints::parse_csv(&edges).is_ok());
}

#[test]
fn duplicate_points_are_refused_naming_both_lines() {
    let text = format!(
        "{HEADER}hover,0,0,0,0,0,0,0,0,0,0,0,0.35\nforward,1,0,0,0,0,0,0,0,0,0.01,0,0.35\n\
         again,0,0,0,0,0,0,0,0,0,0,0,0.35\n"
    );
    assert_eq!(
        TrimPoints::parse_csv(&text).unwrap_err().to_string(),
        "line 4: the same flight as line 2 (every state and stick equal): a duplicate adds no gradient"
    );
}

#[test]
fn collinear_points_are_refused_naming_what_they_fail_to_vary() {
    // Five points on one line through (u, v, w, r): every column of the balance is
    // non-zero, but v and r (what Nv and Nr multiply in the yaw row) vary only together.
    let structure = hybrid_structure();
    let truth = hybrid_truth_values(&structure);
    let line: Vec<[f64; 4]> = [-2.0, -1.0, 0.0, 1.0, 2.0]
        .iter()
        .map(|&t| [0.5 * t, 0.3 * t, -0.2 * t, 0.05 * t])
        .collect();
    let points = linear_trim_points(&structure, &truth, &line);
    let error = derive(
        &structure,
        &truth,
        &points,
        &names(&["Lv", "Mu", "Nv", "Zw", "Nr"]),
    )
    .unwrap_err();
    let TrimError::NotIndependent {
        parameters,
        varied,
        directions,
    } = &error
    else {
        panic!("{error}");
    };
    assert!(parameters.contains(&"Nv".to_string()), "{error}");
    assert!(parameters.contains(&"Nr".to_string()), "{error}");
    assert!(varied.contains("u v w") && varied.contains('r'), "{error}");
    assert_eq!(*directions, 1, "{error}");
    // The same number of points spread over the four directions: accepted.
    let spread = linear_trim_points(&structure, &truth, &STEPS[..5]);
    assert!(derive(&structure, &truth, &spread, &names(&["Lv", "Mu", "Nv"])).is_ok());
}

#[test]
fn a_huge_residual_does_not_round_a_derived_parameters_column_to_zero() {
    // The toy with M_lon = 10²⁰ (a degenerate minimum's size): the balance's residual
    // with M_u at 0 is M_lon·Δlon ≈ 10¹⁸, where a unit step of M_u (a change of Δu ≈ 1)
    // is lost to rounding and the column read exactly zero ("the points do not vary what
    // `Mu` multiplies"). The scaled step keeps it, and the paper's formula comes back.
    let structure = pitch_toy(true);
    let mut values = structure.values();
    let m_lon = 1e20;
    values[structure.parameter_index("Mlon").unwrap()] = m_lon;
    let gradient = -0.011;
    let points = TrimPoints {
        points: [-1.0, 0.0, 2.0]
            .iter()
            .map(|&u| TrimPoint {
                label: String::new(),
                states: [u, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.02 * u / 9.81],
                controls: [0.0, gradient * u, 0.0, 0.0],
            })
            .collect(),
    };
    let derived = derive(&structure, &values, &points, &names(&["Mu"])).unwrap();
    let want = -m_lon * gradient;
    assert!(
        (derived[0].value - want).abs() <= 1e-9 * want,
        "{derived:?} vs {want}"
    );
    // The step stays 1 below residuals of 10⁶, so ordinary balances are computed as before.
    assert_eq!(derivation_step(&[DVector::from_element(3, 9.9e5)]), 1.0);
    assert_eq!(derivation_step(&[DVector::from_element(3, 1e18)]), 1e12);
}
