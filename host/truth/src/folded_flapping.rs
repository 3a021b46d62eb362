//! What the simulator's flapping does that a structure's flap equations do not carry,
//! folded quasi-statically into the structure's body derivatives.

use std::collections::BTreeMap;

use sysid::fit::structure::MatrixName;
use sysid::fit::ModelStructure;

use crate::vehicle_truth::{VehicleTruth, BODY_STATES, CONTROLS};
use crate::Error;

/// The simulator's flapping responds to more than the structure's flap equations carry
/// (speed and cross-axis rates, the other flap state, a rate coupling of 1.05 instead of
/// 1). Quasi-statically that difference is
///
/// ```text
/// Δβ = Q − P,   Q = −A_ff⁻¹ [A_fs | B_f]   (the simulator's quasi-static flapping)
///               P = τ_f [S_fs | B_f]          (the structure's: β̇ = −β/τ_f + S_fs x + B_f u)
/// ```
///
/// per body state or control (simulator flap coordinates). A body row whose structure row
/// has a flapping column only gets the part its flapping misses, `A_if·(Q − P)`; a row
/// without one (yaw) gets the whole quasi-static flapping, `A_if·Q`. This is how the
/// speed derivatives Xu, Lv, Mu, Nv come to their quasi-static values (the paper fixes
/// them from trim) and how the yaw row takes the roll-flap moment.
pub(crate) struct FoldedFlapping {
    /// Simulator flap state names, `[beta1c, beta1s]`.
    flaps: [&'static str; 2],
    /// Q per column name (body states and controls): `[for beta1c, for beta1s]`.
    simulator: BTreeMap<&'static str, [f64; 2]>,
    /// P per column name.
    structure: BTreeMap<&'static str, [f64; 2]>,
    /// Body rows (simulator state names) whose structure row has each flapping column.
    rows_with_flap: [Vec<&'static str>; 2],
    /// A[row, flap] per body row.
    flap_moment: BTreeMap<&'static str, [f64; 2]>,
}

impl FoldedFlapping {
    /// `values`: base-parameter values with the flap-row parameters at their truth (the
    /// structure's flap equations are evaluated there).
    pub(crate) fn new(
        structure: &ModelStructure,
        truth: &VehicleTruth,
        flap_signs: &BTreeMap<String, f64>,
        values: &[f64],
    ) -> Result<FoldedFlapping, Error> {
        let flaps = ["beta1c", "beta1s"];
        let structure_flaps = ["b1c", "b1s"];
        let a = |row: &str, column: &str| truth.a(row, column).ok_or(Error::NoFlappingStates);
        let a_ff = nalgebra::Matrix2::new(
            a(flaps[0], flaps[0])?,
            a(flaps[0], flaps[1])?,
            a(flaps[1], flaps[0])?,
            a(flaps[1], flaps[1])?,
        );
        let a_ff_inverse = a_ff.try_inverse().ok_or(Error::SingularFlappingBlock)?;
        let state_index = |name: &str| structure.states.iter().position(|s| s == name);
        let sign = |flap: usize| {
            flap_signs
                .get(structure_flaps[flap])
                .copied()
                .unwrap_or(1.0)
        };
        let entry = |matrix: MatrixName, row: usize, column: usize| {
            structure
                .entries
                .iter()
                .find(|e| e.matrix == matrix && e.row == row && e.column == column)
                .map(|e| e.expression.evaluate(values))
        };
        // The structure's flap rows in simulator coordinates (b = S β, S = diag(s_c, s_s)):
        // β̇_f = Σ_g F[f,g]/M[f,f]·s_g/s_f β_g + F[f,j]/(M[f,f]·s_f) x_j.
        let mut structure_block = nalgebra::Matrix2::zeros();
        for f in 0..2 {
            for g in 0..2 {
                if let (Some(row), Some(col)) = (
                    state_index(structure_flaps[f]),
                    state_index(structure_flaps[g]),
                ) {
                    let mass = entry(MatrixName::M, row, row).unwrap_or(1.0);
                    structure_block[(f, g)] =
                        entry(MatrixName::F, row, col).unwrap_or(0.0) / mass * sign(g) / sign(f);
                }
            }
        }
        // A structure without one of the flap states has no row for it: its diagonal entry
        // takes the simulator's decay so that the block stays invertible (that flapping's
        // quasi-static effect is then folded entirely into the body rows).
        for f in 0..2 {
            if state_index(structure_flaps[f]).is_none() {
                structure_block[(f, f)] = a_ff[(f, f)];
            }
        }
        let structure_block_inverse = structure_block
            .try_inverse()
            .ok_or(Error::SingularStructureFlappingBlock)?;
        // The structure's ∂β̇/∂x_j of flap row `flap`, in simulator coordinates.
        let structure_coupling = |flap: usize, column: &str| -> f64 {
            let (Some(row), Some(col)) = (state_index(structure_flaps[flap]), state_index(column))
            else {
                return 0.0;
            };
            let mass = entry(MatrixName::M, row, row).unwrap_or(1.0);
            entry(MatrixName::F, row, col).unwrap_or(0.0) / mass / sign(flap)
        };
        let mut simulator = BTreeMap::new();
        let mut structure_flapping = BTreeMap::new();
        for column in BODY_STATES.iter().chain(CONTROLS.iter()) {
            let (forcing, modelled) = if BODY_STATES.contains(column) {
                (
                    nalgebra::Vector2::new(a(flaps[0], column)?, a(flaps[1], column)?),
                    nalgebra::Vector2::new(
                        structure_coupling(0, column),
                        structure_coupling(1, column),
                    ),
                )
            } else {
                let b = |flap: &str| truth.b(flap, column).ok_or(Error::NoFlappingStates);
                let forcing = nalgebra::Vector2::new(b(flaps[0])?, b(flaps[1])?);
                // The structure's flap control terms are mapped from B exactly.
                (forcing, forcing)
            };
            // Quasi-static flapping β = −A_ff⁻¹ (forcing), for the simulator and the structure.
            let quasi_static = -(a_ff_inverse * forcing);
            let structure_quasi_static = -(structure_block_inverse * modelled);
            simulator.insert(*column, [quasi_static[0], quasi_static[1]]);
            structure_flapping.insert(
                *column,
                [structure_quasi_static[0], structure_quasi_static[1]],
            );
        }
        let mut rows_with_flap = [Vec::new(), Vec::new()];
        let mut flap_moment = BTreeMap::new();
        for row in BODY_STATES {
            flap_moment.insert(row, [a(row, flaps[0])?, a(row, flaps[1])?]);
            for (f, list) in rows_with_flap.iter_mut().enumerate() {
                let has = match (state_index(row), state_index(structure_flaps[f])) {
                    (Some(r), Some(c)) => structure
                        .entries
                        .iter()
                        .any(|e| e.matrix == MatrixName::F && e.row == r && e.column == c),
                    _ => false,
                };
                if has {
                    list.push(row);
                }
            }
        }
        Ok(FoldedFlapping {
            flaps,
            simulator,
            structure: structure_flapping,
            rows_with_flap,
            flap_moment,
        })
    }

    /// The quasi-static flapping correction to body derivative `row`/`column`.
    pub(crate) fn correction(&self, row: &str, column: &str) -> Option<f64> {
        let moment = self.flap_moment.get(row)?;
        let simulator = self.simulator.get(column)?;
        let structure = self.structure.get(column)?;
        let mut total = 0.0;
        for f in 0..self.flaps.len() {
            let modelled = if self.rows_with_flap[f].contains(&row) {
                structure[f]
            } else {
                0.0
            };
            total += moment[f] * (simulator[f] - modelled);
        }
        Some(total)
    }
}
