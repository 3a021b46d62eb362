//! Degenerate minima: fitted models no helicopter is, whatever their J_ave.
//!
//! A minimum of the output-error cost is degenerate when
//! - a parameter lies outside its physical range ([`super::plausible`]: its part of an F
//!   or G entry beyond that entry's dimension's limit), or
//! - a free parameter rests on a bound of the structure file that is not physical
//!   ([`on_range_bounds`]).
//!
//! **Which bounds count.** A structure file bounds a parameter for one of two reasons:
//! - a *sign* (a bound of exactly zero): a drag or heave damping cannot push an aircraft
//!   along (`Xu`, `Yv`, `Zw` ≤ 0), a delay cannot be negative (`tau_*` ≥ 0). A minimum at
//!   zero is a physical value: the data want no such term, or less than they can resolve
//!   (the shipped TREX models hold their delays at 0, X_u at 0);
//! - a *range* (any other bound): a box around what the aircraft can have, so that the
//!   search does not wander, e.g. the flap time constant τ_f ≥ 0.005 s, the servo's
//!   ω_n in 5–1000 rad/s, a delay ≤ 0.1 s. The file's author put it outside every value
//!   the aircraft can take. A minimum resting on it is one the cost would carry further,
//!   where the file says the aircraft is not: the TREX fit with τ_f on its 0.005 s floor
//!   has L_β1s = L_b1s off by 10¹²–10¹⁶ % and still J_ave 43–45.
//!
//! "On" a bound is within [`ON_BOUND_RELATIVE`] of it: the optimizer projects its steps onto
//! the bounds, so a parameter the cost pushes there ends exactly on it, and one within
//! 0.1 % of it is pushed there as well (its step was cut by the projection).
//!
//! Trim-derived parameters held at the balance's values and fixed parameters are not
//! judged for bounds (they were not searched); the physical ranges judge them all.

use serde::{Deserialize, Serialize};

use super::plausible::{implausible_parameters, Implausible};
use super::structure::{ModelStructure, ParameterKind};

/// How close to a range bound a free parameter counts as on it, relative to the bound.
pub const ON_BOUND_RELATIVE: f64 = 1e-3;

/// Why a fitted model is degenerate: one parameter and what is wrong with it
/// (`model.json` `degenerate`, layout in the models README).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DegenerateReason {
    /// The parameter.
    pub parameter: String,
    /// Its fitted value.
    pub value: f64,
    /// What is wrong.
    pub reason: DegenerateKind,
    /// The physical limit of |value| (`outside_physical_range`) or the bound it rests on.
    pub limit: f64,
}

/// The kinds of [`DegenerateReason`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DegenerateKind {
    /// |value| beyond what its F or G entry's dimension allows ([`super::plausible`]).
    OutsidePhysicalRange,
    /// On the structure file's lower range bound.
    OnLowerBound,
    /// On the structure file's upper range bound.
    OnUpperBound,
}

impl DegenerateReason {
    /// One phrase, e.g. `` `tau_f` = 0.005 on its lower bound 0.005 ``.
    pub fn describe(&self) -> String {
        match self.reason {
            DegenerateKind::OutsidePhysicalRange => format!(
                "`{}` = {:.3e} outside its physical range (|value| <= {:.3e})",
                self.parameter, self.value, self.limit
            ),
            DegenerateKind::OnLowerBound => format!(
                "`{}` = {} on its lower bound {}",
                self.parameter, self.value, self.limit
            ),
            DegenerateKind::OnUpperBound => format!(
                "`{}` = {} on its upper bound {}",
                self.parameter, self.value, self.limit
            ),
        }
    }
}

/// Every reason the model of `structure` at `values` is degenerate (module
/// documentation): the parameters outside their physical ranges (furthest first), then
/// the free parameters on range bounds (in the structure's order). Empty when it is not.
pub fn degenerate_reasons(structure: &ModelStructure, values: &[f64]) -> Vec<DegenerateReason> {
    let mut reasons: Vec<DegenerateReason> = implausible_parameters(structure, values)
        .into_iter()
        .map(|found: Implausible| DegenerateReason {
            parameter: found.name,
            value: found.value,
            reason: DegenerateKind::OutsidePhysicalRange,
            limit: found.limit,
        })
        .collect();
    reasons.extend(on_range_bounds(structure, values));
    reasons
}

/// The free parameters of `structure` at `values` that rest on a bound other than zero
/// (module documentation, "Which bounds count").
pub fn on_range_bounds(structure: &ModelStructure, values: &[f64]) -> Vec<DegenerateReason> {
    let mut found = Vec::new();
    for (parameter, &value) in structure.parameters.iter().zip(values) {
        if parameter.kind != ParameterKind::Free {
            continue;
        }
        let sides = [
            (parameter.lower, DegenerateKind::OnLowerBound),
            (parameter.upper, DegenerateKind::OnUpperBound),
        ];
        for (bound, kind) in sides {
            let Some(bound) = bound.filter(|b| *b != 0.0 && b.is_finite()) else {
                continue;
            };
            if (value - bound).abs() <= ON_BOUND_RELATIVE * bound.abs() {
                found.push(DegenerateReason {
                    parameter: parameter.name.clone(),
                    value,
                    reason: kind,
                    limit: bound,
                });
            }
        }
    }
    found
}

/// One line naming the first three of `reasons` (and how many more).
pub fn describe(reasons: &[DegenerateReason]) -> String {
    let mut parts: Vec<String> = reasons.iter().take(3).map(|r| r.describe()).collect();
    if reasons.len() > 3 {
        parts.push(format!("and {} more", reasons.len() - 3));
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests;
