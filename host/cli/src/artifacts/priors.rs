//! The a-priori knowledge of an identification as `summary.json` lists it: every
//! constant the 9-DOF structure took from the aircraft file (with the file's σ) and every
//! parameter the fit estimated under a prior (the servo's ω_n and ζ), each with its file
//! value, the estimate, σ and how far the data moved it in σ. A prior moved by more than
//! [`MOVED_WARNING_SIGMA`] is flagged: the data disagree with the aircraft file, which
//! is worth a look before the model is trusted (a wrong servo prior biased the TREX's
//! key parameters by up to 25 % while nothing else showed it).

use serde::{Deserialize, Serialize};
use sysid::fit::FitResult;
use truth::FileConstant;

/// A prior moved by more than this many σ is flagged (`warning`): under a correct prior
/// and Gaussian errors that happens with a probability of 0.3 %.
pub const MOVED_WARNING_SIGMA: f64 = 3.0;

/// One prior of [`crate::artifacts::summary::FitSummary::priors`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PriorSummary {
    /// The structure's name for it: a constant (`hub_height`, `Kcs`) or, when estimated,
    /// the parameter (`servo_omega`).
    pub name: String,
    /// The `[constants]` name of the aircraft file's value an estimated parameter starts
    /// from (`servo_natural_frequency`); null for a constant or a number.
    pub constant: Option<String>,
    /// The value the aircraft file gives (or the structure file's prior).
    pub file_value: f64,
    /// Its σ: the file's (propagated to the structure's constant), or the default of its
    /// kind for an estimated servo; null when the file states none.
    pub sigma: Option<f64>,
    /// Whether the fit estimated it (a free parameter under its prior) or held it.
    pub estimated: bool,
    /// The fit's value (the file value when held).
    pub estimate: f64,
    /// (estimate − file value)/σ; null without σ.
    pub moved_sigma: Option<f64>,
    /// |moved_sigma| > [`MOVED_WARNING_SIGMA`].
    pub warning: bool,
}

/// The priors of `result`: its parameters with a prior (estimated when free), then the
/// aircraft file's `constants` that no such parameter stands for (held).
pub fn prior_summaries(result: &FitResult, constants: &[FileConstant]) -> Vec<PriorSummary> {
    let structure = &result.structure;
    let mut list: Vec<PriorSummary> = structure
        .parameters
        .iter()
        .zip(&result.values)
        .filter_map(|(parameter, &value)| {
            let prior = parameter.prior?;
            let estimated = parameter.kind == sysid::fit::ParameterKind::Free;
            Some(summary(
                &parameter.name,
                parameter.prior_constant.clone(),
                prior.value,
                Some(prior.sigma),
                estimated,
                value,
            ))
        })
        .collect();
    for constant in constants {
        let stands_for = |p: &sysid::fit::structure::Parameter| {
            p.prior_constant.as_deref() == Some(constant.name.as_str())
        };
        if structure.parameters.iter().any(stands_for) {
            continue;
        }
        list.push(summary(
            &constant.name,
            None,
            constant.value,
            constant.sigma,
            false,
            constant.value,
        ));
    }
    list
}

fn summary(
    name: &str,
    constant: Option<String>,
    file_value: f64,
    sigma: Option<f64>,
    estimated: bool,
    estimate: f64,
) -> PriorSummary {
    let moved_sigma = sigma.map(|sigma| (estimate - file_value) / sigma);
    PriorSummary {
        name: name.to_string(),
        constant,
        file_value,
        sigma,
        estimated,
        estimate,
        moved_sigma,
        warning: moved_sigma.is_some_and(|moved| moved.abs() > MOVED_WARNING_SIGMA),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sysid::fit::synthetic::exact_frf_document;
    use sysid::fit::synthetic::SyntheticGrid;
    use sysid::fit::{fit, FitOptions, ModelStructure, PairBand};

    /// ẋ = −5x + 8·A(s)u, the servo's ω_n under a prior of `prior` ± `sigma` rad/s; the
    /// data are those of a 51 rad/s servo.
    fn fitted(prior: f64, sigma: f64) -> FitResult {
        let text = |frequency: &str| {
            format!(
                r#"
name = "servo"
states = ["x"]
controls = ["u"]
outputs = ["x"]
pairs = [{{ output = "x", input = "u", range = [1.0, 80.0] }}]
[constants]
servo_natural_frequency = {prior}
servo_sigma = {sigma}
[parameters]
a = -5.0
b = 8.0
wn = {{ {frequency}, min = 1.0 }}
[F.x]
x = "a"
[G.x]
u = "b"
[actuators]
u = {{ natural_frequency = "wn", damping = 0.7 }}
"#
            )
        };
        let truth = ModelStructure::parse_str(&text("start = 51.0")).unwrap();
        let model = truth.model(&truth.values()).unwrap();
        let band = PairBand {
            input: "u".into(),
            output: "x".into(),
            range: [1.0, 80.0],
        };
        let data = exact_frf_document(&model, &[band], SyntheticGrid::FitPoints(20));
        let structure = ModelStructure::parse_str(&text(
            "prior = \"servo_natural_frequency\", sigma = \"servo_sigma\"",
        ))
        .unwrap();
        fit(&structure, &data, &FitOptions::default()).unwrap()
    }

    #[test]
    fn an_estimated_prior_reports_how_far_the_data_moved_it_and_warns_beyond_three_sigma() {
        let constants = vec![
            FileConstant {
                name: "servo_natural_frequency".into(),
                value: 60.0,
                sigma: None,
            },
            FileConstant {
                name: "hub_height".into(),
                value: 0.25,
                sigma: Some(0.01),
            },
        ];
        // σ 12 rad/s: the data move it by about −9/12 σ, no warning.
        let wide = prior_summaries(&fitted(60.0, 12.0), &constants);
        assert_eq!(wide.len(), 2, "{wide:?}");
        let servo = &wide[0];
        assert_eq!(servo.name, "wn");
        assert_eq!(servo.constant.as_deref(), Some("servo_natural_frequency"));
        assert!(servo.estimated && servo.file_value == 60.0 && servo.sigma == Some(12.0));
        assert!((servo.estimate - 51.0).abs() < 1.0, "{servo:?}");
        let moved = servo.moved_sigma.unwrap();
        assert!((moved - (servo.estimate - 60.0) / 12.0).abs() < 1e-12);
        assert!(moved < -0.6 && !servo.warning, "{servo:?}");
        // The held constant: not estimated, moved 0, its file σ.
        let hub = &wide[1];
        assert_eq!(hub.name, "hub_height");
        assert!(!hub.estimated && hub.estimate == 0.25 && hub.moved_sigma == Some(0.0));
        // A prior of 80 ± 2 rad/s: the data (their bound on ω_n is about 2 rad/s) move
        // it by about 7σ: flagged. (Moved = error·d·σ/(d·σ² + 1) with d the data's
        // information, at most error·√d/2: 60 ± σ, 9 rad/s off, can never reach 3σ here.)
        let wrong = prior_summaries(&fitted(80.0, 2.0), &constants);
        assert!(wrong[0].moved_sigma.unwrap() < -3.0, "{:?}", wrong[0]);
        assert!(wrong[0].warning);
        let calm = prior_summaries(&fitted(60.0, 2.0), &constants);
        assert!(!calm[0].warning, "{:?}", calm[0]);
    }
}
