use super::*;
use crate::fit::cost::{
    build_pair_grids, coherence_weight, residuals, residuals_and_jacobian as data_jacobian,
    PHASE_WEIGHT,
};
use crate::fit::test_support::synthetic_document;
use crate::fit::{fit, FitOptions, ParameterStatus};

/// ẋ = −2x + 3u(t − τ) with τ free under a prior: the phase residual is linear in τ
/// (−ωτ·180/π) and the magnitude does not depend on it, so the cost is exactly
/// quadratic in τ and its minimum and Cramér–Rao bound have a closed form.
fn delay_structure(prior: &str) -> ModelStructure {
    let text = format!(
        r#"
name = "delay"
states = ["x"]
controls = ["u"]
outputs = ["x"]
pairs = [{{ output = "x", input = "u", range = [0.5, 5.0] }}]
[parameters]
a = {{ fixed = -2.0 }}
b = {{ fixed = 3.0 }}
tau = {{ {prior} }}
[F.x]
x = "a"
[G.x]
u = "b"
[delays]
u = "tau"
"#
    );
    ModelStructure::parse(&text, "delay.toml").unwrap()
}

#[test]
fn a_gaussian_prior_on_a_linear_measurement_gives_the_closed_form_posterior() {
    let data_tau = 0.02;
    let truth = delay_structure(&format!("start = {data_tau}"));
    let model = truth.model(&truth.values()).unwrap();
    let data = synthetic_document(&model, &truth, 20);
    let (mean, sigma) = (0.05, 0.004);
    let structure = delay_structure(&format!("prior = {mean}, sigma = {sigma}, min = 0.0"));
    let tau = structure.parameter_index("tau").unwrap();
    assert_eq!(structure.parameters[tau].value, mean, "starts at the prior");
    assert_eq!(
        structure.parameters[tau].prior,
        Some(Prior { value: mean, sigma })
    );

    // The data's information about τ: Σ (20/n)·W_γ·W_p·(ω·180/π)² over the fit points.
    let grids = build_pair_grids(&structure, &data, 20).unwrap();
    let omega = &grids[0].omega;
    let data_information: f64 = omega
        .iter()
        .map(|w| {
            20.0 / omega.len() as f64
                * coherence_weight(1.0)
                * PHASE_WEIGHT
                * (w * 180.0 / std::f64::consts::PI).powi(2)
        })
        .sum();
    let prior_information = 1.0 / (sigma * sigma);
    let expected = (data_information * data_tau + prior_information * mean)
        / (data_information + prior_information);
    let expected_bound = 1.0 / (data_information + prior_information).sqrt();
    // The prior and the data pull with comparable weight: the answer lies between.
    assert!(
        expected > data_tau + 0.002 && expected < mean - 0.002,
        "{expected}"
    );

    let result = fit(&structure, &data, &FitOptions::default()).unwrap();
    let report = result.parameters.iter().find(|p| p.name == "tau").unwrap();
    assert_eq!(report.status, ParameterStatus::Free);
    assert!(
        (report.value - expected).abs() < 1e-9,
        "{} vs {expected}",
        report.value
    );
    let bound = report.cramer_rao_percent.unwrap() / 100.0 * report.value.abs();
    assert!(
        (bound / expected_bound - 1.0).abs() < 1e-6,
        "{bound} {expected_bound}"
    );
    // The priors' share of the cost is ((τ* − μ)/σ)², and the pairs' J the rest.
    let prior_share = ((expected - mean) / sigma).powi(2);
    assert!((result.prior_cost() - prior_share).abs() < 1e-6 * prior_share);
    let data_share = data_information * (expected - data_tau).powi(2);
    assert!((result.average_cost - data_share).abs() < 1e-6 * data_share.max(1e-9));
    assert!(
        (result.objective() - (data_share + prior_share)).abs() < 1e-6 * (data_share + prior_share)
    );
}

#[test]
fn without_data_information_the_bound_is_the_priors_sigma() {
    // A second delay parameter on a control no pair uses: only the prior sees it.
    let structure = ModelStructure::parse(
        r#"
name = "unseen"
states = ["x"]
controls = ["u", "v"]
outputs = ["x"]
pairs = [{ output = "x", input = "u", range = [0.5, 5.0] }]
[parameters]
a = -2.0
b = 3.0
tau_v = { prior = 0.03, sigma = 0.01, min = 0.0 }
[F.x]
x = "a"
[G.x]
u = "b"
[delays]
v = "tau_v"
"#,
        "unseen.toml",
    )
    .unwrap();
    let model = structure.model(&structure.values()).unwrap();
    let data = synthetic_document(&model, &structure, 20);
    let result = fit(&structure, &data, &FitOptions::default()).unwrap();
    let report = result
        .parameters
        .iter()
        .find(|p| p.name == "tau_v")
        .unwrap();
    assert!((report.value - 0.03).abs() < 1e-12, "{}", report.value);
    let bound = report.cramer_rao_percent.unwrap() / 100.0 * report.value;
    assert!((bound - 0.01).abs() < 1e-9, "{bound}");
}

/// ẋ = −5x + 8·A(s)u with a servo A of ω_n, ζ free under priors.
fn servo_structure(frequency: &str, damping: &str) -> ModelStructure {
    ModelStructure::parse(&servo_text(frequency, damping), "servo.toml").unwrap()
}

fn servo_text(frequency: &str, damping: &str) -> String {
    format!(
        r#"
name = "servo"
states = ["x"]
controls = ["u"]
outputs = ["x"]
pairs = [{{ output = "x", input = "u", range = [1.0, 80.0] }}]
[parameters]
a = -5.0
b = 8.0
wn = {{ {frequency} }}
zeta = {{ {damping} }}
[F.x]
x = "a"
[G.x]
u = "b"
[actuators]
u = {{ natural_frequency = "wn", damping = "zeta" }}
"#
    )
}

#[test]
fn the_actuator_jacobian_matches_central_differences() {
    let structure = servo_structure(
        "prior = 60.0, sigma = 9.0, min = 1.0",
        "prior = 0.7, sigma = 0.2, min = 0.05",
    );
    let model = structure.model(&structure.values()).unwrap();
    let data = synthetic_document(&model, &structure, 20);
    let grids = build_pair_grids(&structure, &data, 20).unwrap();
    let values = vec![-4.0, 7.0, 55.0, 0.6];
    let free = structure.free_indices();
    let (_, jacobian) = data_jacobian(&structure, &values, &free, &grids).unwrap();
    for (column, &index) in free.iter().enumerate() {
        let step = 1e-6 * values[index].abs();
        let at = |delta: f64| {
            let mut moved = values.clone();
            moved[index] += delta;
            residuals(&structure.model(&moved).unwrap(), &grids).unwrap()
        };
        let (up, down) = (at(step), at(-step));
        for row in 0..up.len() {
            let numeric = (up[row] - down[row]) / (2.0 * step);
            let analytic = jacobian[(row, column)];
            assert!(
                (numeric - analytic).abs() < 1e-5 * (1.0 + analytic.abs()),
                "parameter {index} row {row}: {numeric} vs {analytic}"
            );
        }
    }
}

#[test]
fn the_data_move_a_wrong_servo_prior_to_the_servo() {
    // Data of a 51 rad/s, ζ 0.6 servo; the priors say 60 ± 9 rad/s and 0.7 ± 0.2.
    let truth = servo_structure("start = 51.0, min = 1.0", "start = 0.6, min = 0.05");
    let model = truth.model(&truth.values()).unwrap();
    let data = synthetic_document(&model, &truth, 20);
    let structure = servo_structure(
        "prior = 60.0, sigma = 9.0, min = 1.0",
        "prior = 0.7, sigma = 0.2, min = 0.05",
    );
    let result = fit(&structure, &data, &FitOptions::default()).unwrap();
    let value = |name: &str| result.parameter(name).unwrap();
    // Exact data: the data's information dwarfs the priors', the estimate is the truth
    // to within what the priors pull (measured: ω_n +0.9 %, 1/17 of the prior's +17.6 %).
    assert!((value("wn") / 51.0 - 1.0).abs() < 0.015, "{}", value("wn"));
    assert!(
        (value("zeta") / 0.6 - 1.0).abs() < 0.05,
        "{}",
        value("zeta")
    );
    assert!((value("a") / -5.0 - 1.0).abs() < 0.02 && (value("b") / 8.0 - 1.0).abs() < 0.02);
    // The model carries the fitted servo.
    let servo = result.model.actuators[0].unwrap();
    assert_eq!(servo.natural_frequency_rad_s, value("wn"));
    // And the prior's σ is no longer the bound: the data's is tighter (measured 1.8 rad/s).
    let report = result.parameters.iter().find(|p| p.name == "wn").unwrap();
    let bound = report.cramer_rao_percent.unwrap() / 100.0 * report.value;
    assert!(bound < 9.0 / 3.0, "{bound}");
}

#[test]
fn prior_syntax_errors_name_the_parameter() {
    let error = |prior: &str| {
        let text = format!(
            "name = \"x\"\nstates = [\"x\"]\ncontrols = [\"u\"]\noutputs = [\"x\"]\n\
             pairs = [{{ output = \"x\", input = \"u\" }}]\n[constants]\nk = 0.0\n\
             [parameters]\na = {{ {prior} }}\n[F.x]\nx = \"a\"\n"
        );
        ModelStructure::parse(&text, "x.toml")
            .unwrap_err()
            .to_string()
    };
    assert!(error("prior = 1.0").contains("give `prior` and `sigma` together"));
    assert!(error("prior = 1.0, sigma = 0.0").contains("sigma finite and positive"));
    assert!(error("prior = 1.0, sigma = \"k\"").contains("sigma finite and positive"));
    assert!(error("prior = 1.0, sigma = \"nope\"").contains("`nope` is neither"));
    assert!(error("prior = 1.0, sigma = 0.1, fixed = 1.0").contains("is free"));
    assert!(error("prior = 1.0, sigma = 0.1, min = 2.0").contains("outside [min, max]"));
    let unbounded = ModelStructure::parse(
        &servo_text("prior = 60.0, sigma = 9.0, min = 1.0", "start = 0.7"),
        "servo.toml",
    )
    .unwrap_err();
    assert!(
        unbounded
            .to_string()
            .contains("`zeta` is a parameter: give it `min` > 0"),
        "{unbounded}"
    );
}
