//! The parameters of a structure's flap equations, read from the simulator's flapping
//! rows of A and B in the structure's flap scaling.

use std::collections::BTreeMap;

use sysid::fit::structure::MatrixName;
use sysid::fit::ModelStructure;

use crate::vehicle_truth::VehicleTruth;

/// Truth values of the parameters that stand alone (`c·θ`) in an entry of a flap row of F
/// or G — the structure's flap equations `M[f,f]·ḃ_f = F[f,·]·x + G[f,·]·u`. With
/// `b_f = s_f·β_f` the simulator's `β̇_f = A[β_f,·]·x + B[β_f,·]·u` reads
/// `F[f,j] = M[f,f]·s_f·A[β_f, j]/s_j` (`s_j` the scale of column j when it is a flap
/// state, else 1) and `G[f,k] = M[f,f]·s_f·B[β_f,k]`. `tau_f` itself is the flap time constant
/// (it also sits in the rate coupling `−τ_f q`, where the simulator's 1.05 is not 1).
pub(crate) fn flap_row_parameters(
    structure: &ModelStructure,
    truth: &VehicleTruth,
    flap_signs: &BTreeMap<String, f64>,
    tau_f: f64,
) -> BTreeMap<String, f64> {
    let simulator_name = |state: &str| match state {
        "b1c" => Some("beta1c"),
        "b1s" => Some("beta1s"),
        _ => None,
    };
    let mut values = structure.values();
    if let Some(index) = structure.parameter_index("tau_f") {
        values[index] = tau_f;
    }
    let mut candidates: BTreeMap<String, Vec<(f64, bool)>> = BTreeMap::new();
    for entry in &structure.entries {
        let Some(row_name) = structure.states.get(entry.row) else {
            continue;
        };
        let (Some(simulator_row), Some(&row_sign)) =
            (simulator_name(row_name), flap_signs.get(row_name.as_str()))
        else {
            continue;
        };
        let [(index, coefficient)] = entry.expression.terms[..] else {
            continue;
        };
        if entry.expression.constant != 0.0 || coefficient == 0.0 {
            continue;
        }
        let name = &structure.parameters[index].name;
        if name == "tau_f" {
            continue;
        }
        let mass = structure
            .entries
            .iter()
            .find(|e| e.matrix == MatrixName::M && e.row == entry.row && e.column == entry.row)
            .map_or(1.0, |e| e.expression.evaluate(&values));
        let simulator_entry = match entry.matrix {
            MatrixName::F => {
                let Some(column) = structure.states.get(entry.column) else {
                    continue;
                };
                match simulator_name(column) {
                    Some(flap) => flap_signs
                        .get(column.as_str())
                        .and_then(|s| truth.a(simulator_row, flap).map(|a| a / s)),
                    None => truth.a(simulator_row, column),
                }
            }
            MatrixName::G => structure
                .controls
                .get(entry.column)
                .and_then(|control| truth.b(simulator_row, control)),
            _ => None,
        };
        if let Some(a) = simulator_entry {
            let unit = coefficient.abs() == 1.0;
            candidates
                .entry(name.clone())
                .or_default()
                .push((mass * row_sign * a / coefficient, unit));
        }
    }
    // A parameter may stand alone in several entries: written directly (`u = "Lfu"`),
    // through a constraint (`v = "Mfv"` with Mfv = Lfu) or scaled by a constant
    // (`p = "Kpq"` with Kpq = hub_height·Lfu). The last entry that carries it with a unit
    // coefficient maps it; a scaled one only when there is no other.
    candidates
        .into_iter()
        .filter_map(|(name, list)| {
            let chosen = list
                .iter()
                .rev()
                .find(|(_, unit)| *unit)
                .or(list.last())
                .map(|(value, _)| *value)?;
            Some((name, chosen))
        })
        .collect()
}
