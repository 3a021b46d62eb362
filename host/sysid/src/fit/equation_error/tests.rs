use super::*;
use crate::fit::cost::PairBand;
use crate::fit::synthetic::{
    exact_frf_document, SyntheticGrid, BO105_HYBRID_STRUCTURE, BO105_SIX_DOF_STRUCTURE,
};

/// Values away from the file's start values for every free parameter: couplings that
/// start at 0 get a value of their own, delays differ from their starts by 10–40 ms.
fn known_values(structure: &ModelStructure) -> Vec<f64> {
    let mut values = structure.values();
    for (k, parameter) in structure.parameters.iter().enumerate() {
        if parameter.kind != ParameterKind::Free {
            continue;
        }
        let x = k as f64;
        values[k] = if parameter.name.starts_with("teq_") {
            0.02 + 0.01 * (k % 5) as f64
        } else {
            parameter.value * (1.0 + 0.3 * x.sin()) + 0.1 * x.cos()
        };
        if let Some(upper) = parameter.upper {
            values[k] = values[k].min(upper - 0.05);
        }
    }
    values
}

/// Exact responses of every state output to every control on one shared grid.
fn exact_state_responses(structure: &ModelStructure, values: &[f64]) -> FrfDocument {
    let model = structure.model(values).unwrap();
    let bands: Vec<PairBand> = ["u", "v", "w", "p", "q", "r"]
        .iter()
        .flat_map(|output| {
            structure.controls.iter().map(move |input| PairBand {
                input: input.clone(),
                output: output.to_string(),
                range: [0.3, 12.0],
            })
        })
        .collect();
    exact_frf_document(
        &model,
        &bands,
        SyntheticGrid::Span {
            lo: 0.1,
            hi: 20.0,
            n: 300,
        },
    )
}

#[test]
fn recovers_every_parameter_of_the_six_dof_from_exact_responses() {
    let structure = ModelStructure::parse(BO105_SIX_DOF_STRUCTURE, "bo105-6dof.toml").unwrap();
    let truth = known_values(&structure);
    let data = exact_state_responses(&structure, &truth);
    let fit = equation_error_start(&structure, &data).unwrap();
    assert!(
        fit.uninformed.is_empty(),
        "uninformed: {:?}",
        fit.uninformed
    );
    // 6 rows × 4 controls.
    assert_eq!(fit.blocks.len(), 24);
    let solved = fit.structure.values();
    for index in structure.free_indices() {
        let name = &structure.parameters[index].name;
        let (got, want) = (solved[index], truth[index]);
        assert!(
            (got - want).abs() <= 1e-6 * want.abs().max(1.0),
            "{name}: {got} against {want} (start {})",
            structure.parameters[index].value
        );
    }
    assert!(
        fit.cost[1] <= 1e-16 * fit.cost[0].max(1.0),
        "cost {:?}",
        fit.cost
    );
}

#[test]
fn a_row_without_valid_responses_keeps_its_start_values() {
    let structure = ModelStructure::parse(BO105_SIX_DOF_STRUCTURE, "bo105-6dof.toml").unwrap();
    let truth = known_values(&structure);
    let mut data = exact_state_responses(&structure, &truth);
    // No valid range for r: its row's parameters are informed by nothing.
    for pair in data.pairs.iter_mut().filter(|p| p.output == "r") {
        pair.valid_range = None;
    }
    let fit = equation_error_start(&structure, &data).unwrap();
    assert_eq!(fit.blocks.len(), 20);
    for name in ["Np", "Nr", "Nped", "Nlat"] {
        assert!(
            fit.uninformed.contains(&name.to_string()),
            "{name}: {:?}",
            fit.uninformed
        );
        let index = structure.parameter_index(name).unwrap();
        assert_eq!(
            fit.structure.values()[index],
            structure.parameters[index].value
        );
    }
    // The other rows are still solved exactly.
    let index = structure.parameter_index("Lp").unwrap();
    assert!((fit.structure.values()[index] - truth[index]).abs() < 1e-6 * truth[index].abs());
}

#[test]
fn refuses_a_structure_with_an_unmeasured_state_of_free_parameters() {
    let structure =
        ModelStructure::parse(BO105_HYBRID_STRUCTURE, "bo105-9dof-hybrid.toml").unwrap();
    let six = ModelStructure::parse(BO105_SIX_DOF_STRUCTURE, "bo105-6dof.toml").unwrap();
    let data = exact_state_responses(&six, &known_values(&six));
    let error = equation_error_start(&structure, &data)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("`b1c`") || error.contains("`b1s`"),
        "{error}"
    );
}

#[test]
fn refuses_data_without_any_valid_response() {
    let structure = ModelStructure::parse(BO105_SIX_DOF_STRUCTURE, "bo105-6dof.toml").unwrap();
    let mut data = exact_state_responses(&structure, &known_values(&structure));
    for pair in &mut data.pairs {
        pair.valid_range = None;
    }
    let error = equation_error_start(&structure, &data)
        .unwrap_err()
        .to_string();
    assert!(error.contains("no state has a valid response"), "{error}");
}
