//! Start values of a hybrid (rotor-flapping) fit from a quasi-steady 6-DOF fit, paper
//! Eq. 26–27, generalised to the sign convention of the structure file.
//!
//! 1. Every free parameter whose name the 6-DOF model also has starts at that value —
//!    except a speed derivative (`Xu`, `Lv`, …) when the hybrid's flap rows depend on that
//!    speed: the 6-DOF value then holds the rotor's share too, which the hybrid carries
//!    through its flapping, so the body term keeps the file's start.
//! 2. The rotor moment derivatives come from the quasi-steady damping. A flapping row
//!    `τ_f β̇ = −β + c·ω_body + Σ f_k δ_k` settles to β_ss = (c·ω + Σ f_k δ_k)/1, so a body
//!    moment L_β·β contributes L_β·c·ω (the 6-DOF damping) and L_β·f_k·δ_k (its control
//!    derivatives). Hence
//!
//!    ```text
//!    L_b1s = L_p / g_p,   M_b1c = M_q / g_q,   g = −F[β, ω]/F[β, β]  (the β_ss/ω gain)
//!    Lf_k  = L_k·(−F[b1s, b1s]) / L_b1s,   Mf_k = M_k·(−F[b1c, b1c]) / M_b1c
//!    ```
//!
//!    With the paper's convention (β_ss = +τ_f ω) this is L_b1s = L_p/τ_f, M_b1c = M_q/τ_f
//!    (Eq. 26–27); with the shipped file's −τ_f coupling it is L_b1s = −L_p/τ_f. τ_f is the
//!    hybrid structure's own start value.
//!
//! The names are those of the shipped structures (`Lp`, `Mq`, `Llat`, … in the 6-DOF;
//! `Lb1s`, `Mb1c`, `Lf_lat`, … and states `b1s`, `b1c` in the hybrid); a mapping whose
//! names are missing is skipped and said so in the notes.

use super::error::FitError;
use super::report::ModelDocument;
use super::structure::{MatrixName, ModelStructure, ParameterKind};

/// Where one start value came from.
#[derive(Clone, Debug, PartialEq)]
pub struct StartValueNote {
    /// The hybrid parameter.
    pub parameter: String,
    /// Its new start value.
    pub value: f64,
    /// How it was obtained, e.g. `Lb1s = Lp / g_p = -11.1 / -0.0642`.
    pub source: String,
}

/// One flapping mapping: hybrid rotor derivative from a 6-DOF derivative.
struct RotorMapping {
    /// Rotor moment derivative in the hybrid (`Lb1s`).
    moment: &'static str,
    /// Flapping state (`b1s`).
    flap_state: &'static str,
    /// Body rate state driving it (`p`).
    rate_state: &'static str,
    /// 6-DOF damping derivative (`Lp`).
    damping: &'static str,
    /// (hybrid flap control derivative, 6-DOF moment control derivative).
    controls: [(&'static str, &'static str); 2],
}

const ROTOR_MAPPINGS: [RotorMapping; 2] = [
    RotorMapping {
        moment: "Lb1s",
        flap_state: "b1s",
        rate_state: "p",
        damping: "Lp",
        controls: [("Lf_lat", "Llat"), ("Lf_lon", "Llon")],
    },
    RotorMapping {
        moment: "Mb1c",
        flap_state: "b1c",
        rate_state: "q",
        damping: "Mq",
        controls: [("Mf_lat", "Mlat"), ("Mf_lon", "Mlon")],
    },
];

/// Whether `name` is a body speed derivative (`X|Y|Z|L|M|N` + `u|v|w`) whose speed also
/// drives one of the hybrid's flapping rows (`b1c`, `b1s`).
fn speed_derivative_carried_by_flapping(hybrid: &ModelStructure, name: &str) -> bool {
    let mut chars = name.chars();
    let (Some(axis), Some(speed), None) = (chars.next(), chars.next(), chars.next()) else {
        return false;
    };
    if !"XYZLMN".contains(axis) || !"uvw".contains(speed) {
        return false;
    }
    let index = |state: &str| hybrid.states.iter().position(|s| s == state);
    let Some(speed_index) = index(&speed.to_string()) else {
        return false;
    };
    ["b1c", "b1s"]
        .iter()
        .filter_map(|flap| index(flap))
        .any(|flap| {
            hybrid
                .entries
                .iter()
                .any(|e| e.matrix == MatrixName::F && e.row == flap && e.column == speed_index)
        })
}

/// The hybrid structure with start values taken from a 6-DOF result, and notes saying
/// which value came from where.
pub fn start_from_quasi_steady(
    hybrid: &ModelStructure,
    six_dof: &ModelDocument,
) -> Result<(ModelStructure, Vec<StartValueNote>), FitError> {
    let mut values = hybrid.values();
    let mut notes = Vec::new();
    let free = |structure: &ModelStructure, name: &str| {
        structure
            .parameter_index(name)
            .filter(|&i| structure.parameters[i].kind == ParameterKind::Free)
    };

    for (index, parameter) in hybrid.parameters.iter().enumerate() {
        if parameter.kind != ParameterKind::Free {
            continue;
        }
        if speed_derivative_carried_by_flapping(hybrid, &parameter.name) {
            continue;
        }
        if let Some(value) = six_dof.parameter(&parameter.name) {
            if value.is_finite() {
                values[index] = value;
                notes.push(StartValueNote {
                    parameter: parameter.name.clone(),
                    value,
                    source: "same name in the 6-DOF model".into(),
                });
            }
        }
    }

    let model = hybrid.model(&values)?;
    let state = |name: &str| hybrid.states.iter().position(|s| s == name);
    for mapping in &ROTOR_MAPPINGS {
        let (Some(moment_index), Some(flap), Some(rate), Some(damping)) = (
            free(hybrid, mapping.moment),
            state(mapping.flap_state),
            state(mapping.rate_state),
            six_dof.parameter(mapping.damping),
        ) else {
            notes.push(StartValueNote {
                parameter: mapping.moment.into(),
                value: values
                    .get(hybrid.parameter_index(mapping.moment).unwrap_or(usize::MAX))
                    .copied()
                    .unwrap_or(f64::NAN),
                source: format!(
                    "kept: needs free `{}`, states `{}` `{}` and 6-DOF `{}`",
                    mapping.moment, mapping.flap_state, mapping.rate_state, mapping.damping
                ),
            });
            continue;
        };
        let flap_decay = model.f[(flap, flap)];
        let rate_gain = -model.f[(flap, rate)] / flap_decay;
        if !(rate_gain.is_finite() && rate_gain != 0.0 && flap_decay != 0.0) {
            return Err(FitError::StartValues(format!(
                "flapping row `{}` has no rate coupling to `{}` at the start values",
                mapping.flap_state, mapping.rate_state
            )));
        }
        let moment = damping / rate_gain;
        values[moment_index] = moment;
        notes.push(StartValueNote {
            parameter: mapping.moment.into(),
            value: moment,
            source: format!(
                "{} / g = {damping:.6} / {rate_gain:.6} (g = -F[{},{}]/F[{},{}])",
                mapping.damping,
                mapping.flap_state,
                mapping.rate_state,
                mapping.flap_state,
                mapping.flap_state
            ),
        });
        for (flap_control, six_control) in mapping.controls {
            let (Some(index), Some(control_derivative)) =
                (free(hybrid, flap_control), six_dof.parameter(six_control))
            else {
                continue;
            };
            // Only valid when the flap control derivative enters G directly.
            let direct = hybrid.entries.iter().any(|entry| {
                entry.matrix == MatrixName::G
                    && entry.row == flap
                    && entry.expression.terms == [(index, 1.0)]
            });
            if !direct {
                continue;
            }
            let value = control_derivative * (-flap_decay) / moment;
            values[index] = value;
            notes.push(StartValueNote {
                parameter: flap_control.into(),
                value,
                source: format!(
                    "{six_control}·(-F[{0},{0}]) / {1}",
                    mapping.flap_state, mapping.moment
                ),
            });
        }
    }
    Ok((hybrid.with_values(&values)?, notes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::report::{CorrelationMatrix, ModelMatrices, MODEL_DOCUMENT_VERSION};
    use crate::fit::test_support::hybrid_structure;
    use crate::fit::{ParameterReport, ParameterStatus};

    fn six_dof_document(parameters: &[(&str, f64)]) -> ModelDocument {
        let empty = crate::fit::model::RowMajor {
            rows: 0,
            cols: 0,
            data: Vec::new(),
        };
        ModelDocument {
            version: MODEL_DOCUMENT_VERSION,
            structure: "bo105-6dof".into(),
            description: String::new(),
            states: Vec::new(),
            controls: Vec::new(),
            outputs: Vec::new(),
            matrices: ModelMatrices {
                m: empty.clone(),
                f: empty.clone(),
                g: empty.clone(),
                h0: empty.clone(),
                h1: empty,
            },
            delays: Vec::new(),
            actuators: Vec::new(),
            parameters: parameters
                .iter()
                .map(|(name, value)| ParameterReport {
                    name: name.to_string(),
                    value: *value,
                    status: ParameterStatus::Free,
                    cramer_rao_percent: None,
                    insensitivity_percent: None,
                    flags: Vec::new(),
                    prior: None,
                })
                .collect(),
            pairs: Vec::new(),
            average_cost: 0.0,
            correlation: None::<CorrelationMatrix>,
            starts: Vec::new(),
            minimum_confirmed: true,
            reduction: Vec::new(),
            skipped_pairs: Vec::new(),
            trim: None,
            implausible_held: Vec::new(),
            degenerate: Vec::new(),
            degenerate_restarts: Vec::new(),
            outside_physical_range: Vec::new(),
        }
    }

    #[test]
    fn maps_damping_and_control_derivatives() {
        let hybrid = hybrid_structure();
        let tau_f = hybrid.parameter_value("tau_f", &hybrid.values()).unwrap();
        let six = six_dof_document(&[
            ("Lp", -11.0),
            ("Mq", -3.5),
            ("Llat", 140.0),
            ("Mlon", -48.0),
            ("Zw", -0.33),
            ("Xu", 5.0), // the hybrid's flapping depends on u: must not be copied
        ]);
        let (started, notes) = start_from_quasi_steady(&hybrid, &six).unwrap();
        let value = |name: &str| started.parameter_value(name, &started.values()).unwrap();
        // The shipped file couples β1s to −τ_f p, so g_p = −τ_f and L_b1s = −L_p/τ_f.
        assert!((value("Lb1s") - 11.0 / tau_f).abs() < 1e-9);
        assert!((value("Mb1c") - 3.5 / tau_f).abs() < 1e-9);
        // Lf_lat·L_b1s reproduces the quasi-steady L_lat (F[b1s,b1s] = −1).
        assert!((value("Lf_lat") * value("Lb1s") - 140.0).abs() < 1e-9);
        assert!((value("Mf_lon") * value("Mb1c") + 48.0).abs() < 1e-9);
        assert_eq!(value("Zw"), -0.33);
        assert_eq!(
            value("Xu"),
            hybrid.parameter_value("Xu", &hybrid.values()).unwrap()
        );
        assert!(notes.iter().any(|n| n.parameter == "Lb1s"));
        // Lf_lon has no 6-DOF `Llon` here: it keeps the file's start.
        assert_eq!(
            value("Lf_lon"),
            hybrid.parameter_value("Lf_lon", &hybrid.values()).unwrap()
        );
    }

    #[test]
    fn paper_sign_convention_gives_equation_26() {
        // Flip the rate coupling to +τ_f p (the paper's convention): L_b1s = L_p/τ_f.
        let text = crate::fit::synthetic::BO105_HYBRID_STRUCTURE
            .replace("p = \"-tau_f\"", "p = \"tau_f\"");
        let hybrid = ModelStructure::parse(&text, "paper.toml").unwrap();
        let tau_f = hybrid.parameter_value("tau_f", &hybrid.values()).unwrap();
        let (started, _) =
            start_from_quasi_steady(&hybrid, &six_dof_document(&[("Lp", -11.0)])).unwrap();
        let lb1s = started.parameter_value("Lb1s", &started.values()).unwrap();
        assert!((lb1s - (-11.0 / tau_f)).abs() < 1e-9);
    }
}
