//! Physical ranges of fitted parameters: what a helicopter's linear model can contain.
//!
//! The output-error cost can be as low in a degenerate minimum as in a physical one: a
//! control derivative of 10⁸ whose path to the fitted outputs a coupling of 10⁻⁸ cancels
//! fits the responses as well as two ordinary values do (the campaigns' 6-DOF fits land
//! there on most seeds, X_ped or Z_ped of 10⁶–10¹⁰). The responses cannot tell them apart,
//! but the aircraft can: no helicopter has such derivatives. This module judges every
//! identified parameter (free or trim-derived) by what it does in the model, so that such
//! a fit is never written as a success ([`implausible_parameters`]).
//!
//! **The rule.** A parameter enters matrix entries of `M ẋ = F x + G u` with a
//! coefficient each (a structure entry is a linear expression of parameters). Each F or
//! G entry has a physical dimension, the unit of the row's state derivative over the
//! unit of the column's state or control; its part `coefficient · value` must stay
//! within the limit of that dimension (`limit`):
//!
//! | row \ column | speed [m/s] | rate [rad/s] | angle \[rad\] | stick \[travel\] |
//! |---|---|---|---|---|
//! | speed [m/s²] | 300 /s | 300 m | 1000 m/s² | 1000 m/s² |
//! | rate [rad/s²] | 100 /(m·s) | 300 /s | 9·10⁴ /s² | 10⁴ rad/s² |
//! | angle [rad/s] | 100 rad/m | 300 | 300 /s | 300 rad/s |
//!
//! From two scales no helicopter exceeds: its rotor turns at less than Ω = 300 rad/s
//! (full-size rotors 25–45 rad/s, 700-size models 200–280 rad/s) and nothing in its
//! rigid-body or flapping dynamics is faster, so a rate per rate, speed per speed or
//! angle per angle is below Ω, a flapping stiffness (angular acceleration per rad of
//! tip-path tilt) below Ω²; no stick, attitude or flapping angle gives 100 g (1000 m/s²).
//! The rest are a hundred times the largest the shipped aircraft identify (their
//! `model9.json` and the simulator's linearizations): a roll or pitch acceleration per
//! m/s (L_v, M_u, N_v ≤ 1.5, the trim points' derivatives), a full stick's angular
//! acceleration (≤ 100 rad/s²: a 700-size model's flapping L_b1s·L_f,lat), a speed per rate
//! (X_q, Y_p: lengths of a few metres). The shipped models lie two or more orders of
//! magnitude inside every limit; degenerate minima lie orders of magnitude outside.
//!
//! Entries of M (time constants) and of the output matrices, delays (bounded by the
//! structure file) and parameters only in rows or columns of states without a known unit
//! (the names above: u v w, p q r, phi theta psi b1c b1s) are not judged. A flapping
//! row written `τ_f ḃ = …` is judged as if its M entry were 1: τ_f is 0.01–0.1 s, well
//! inside the margin. A value that is not finite is always implausible.

use serde::{Deserialize, Serialize};

use super::structure::{MatrixName, ModelStructure, ParameterKind};

/// The fastest a helicopter's dynamics can be [rad/s]: above any rotor's speed.
pub const FASTEST_RATE: f64 = 300.0;
/// The largest linear acceleration a stick, attitude or flapping angle can give [m/s²]
/// (100 g).
pub const LARGEST_ACCELERATION: f64 = 1000.0;

/// What a state measures, for the dimension of an entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Unit {
    /// m/s.
    Speed,
    /// rad/s.
    Rate,
    /// rad.
    Angle,
    /// A control, fraction of stick travel.
    Stick,
}

/// The unit of a state from its name; None for a state of no known unit.
fn state_unit(name: &str) -> Option<Unit> {
    match name {
        "u" | "v" | "w" => Some(Unit::Speed),
        "p" | "q" | "r" => Some(Unit::Rate),
        "phi" | "theta" | "psi" | "b1c" | "b1s" => Some(Unit::Angle),
        _ => None,
    }
}

/// The largest magnitude an F or G entry may have, by the unit of its row's state and
/// of its column (module documentation's table), with the dimension as text.
fn limit(row: Unit, column: Unit) -> Option<(f64, &'static str)> {
    use Unit::*;
    let omega = FASTEST_RATE;
    Some(match (row, column) {
        (Speed, Speed) => (omega, "1/s"),
        (Speed, Rate) => (omega, "m"),
        (Speed, Angle) => (LARGEST_ACCELERATION, "m/s² per rad"),
        (Speed, Stick) => (LARGEST_ACCELERATION, "m/s² per stick"),
        (Rate, Speed) => (100.0, "rad/s² per m/s"),
        (Rate, Rate) => (omega, "1/s"),
        (Rate, Angle) => (omega * omega, "1/s²"),
        (Rate, Stick) => (1e4, "rad/s² per stick"),
        (Angle, Speed) => (100.0, "rad per m"),
        (Angle, Rate) => (omega, "rad/s per rad/s"),
        (Angle, Angle) => (omega, "1/s"),
        (Angle, Stick) => (omega, "rad/s per stick"),
        (Stick, _) => return None,
    })
}

/// A parameter outside its physical range.
#[derive(Clone, Debug, PartialEq)]
pub struct Implausible {
    /// The parameter.
    pub name: String,
    /// Its value.
    pub value: f64,
    /// The largest magnitude its entry allows, as a value of the parameter
    /// (limit / |coefficient|).
    pub limit: f64,
    /// The entry's dimension (`1/s`, `m/s² per stick`, …).
    pub dimension: &'static str,
}

impl Implausible {
    /// How far outside: |value| / limit (infinite for a value that is not finite).
    pub fn excess(&self) -> f64 {
        if self.value.is_finite() {
            self.value.abs() / self.limit
        } else {
            f64::INFINITY
        }
    }
}

/// The identified parameters (free or trim-derived) of `structure` at `values` that lie
/// outside their physical range (module documentation), the furthest outside first.
pub fn implausible_parameters(structure: &ModelStructure, values: &[f64]) -> Vec<Implausible> {
    let mut found: Vec<Implausible> = Vec::new();
    for (index, parameter) in structure.parameters.iter().enumerate() {
        if parameter.kind == ParameterKind::Fixed {
            continue;
        }
        let value = values[index];
        // The tightest limit among the entries it enters, as a limit on the value.
        let mut tightest: Option<(f64, &'static str)> = None;
        for entry in &structure.entries {
            let (row, column) = match entry.matrix {
                MatrixName::F => (
                    state_unit(&structure.states[entry.row]),
                    state_unit(&structure.states[entry.column]),
                ),
                MatrixName::G => (state_unit(&structure.states[entry.row]), Some(Unit::Stick)),
                MatrixName::M | MatrixName::H0 | MatrixName::H1 => continue,
            };
            let (Some(row), Some(column)) = (row, column) else {
                continue;
            };
            let Some((entry_limit, dimension)) = limit(row, column) else {
                continue;
            };
            for &(term, coefficient) in &entry.expression.terms {
                if term != index || coefficient == 0.0 {
                    continue;
                }
                let allowed = entry_limit / coefficient.abs();
                if tightest.is_none_or(|(t, _)| allowed < t) {
                    tightest = Some((allowed, dimension));
                }
            }
        }
        let Some((allowed, dimension)) = tightest else {
            if !value.is_finite() {
                found.push(Implausible {
                    name: parameter.name.clone(),
                    value,
                    limit: f64::INFINITY,
                    dimension: "",
                });
            }
            continue;
        };
        if !value.is_finite() || value.abs() > allowed {
            found.push(Implausible {
                name: parameter.name.clone(),
                value,
                limit: allowed,
                dimension,
            });
        }
    }
    found.sort_by(|a, b| b.excess().total_cmp(&a.excess()));
    found
}

/// A parameter the fit held at its a-priori value (the structure file's; or zero) because a minimum put it outside
/// its physical range (`model.json` `implausible_held`; the fit driver's recovery).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeldParameter {
    /// The parameter.
    pub name: String,
    /// The value the degenerate minimum gave it.
    pub value: f64,
}

/// Whether `name` may be held by the recovery: free in `structure` and in no M entry (a
/// time constant held at zero would make M singular).
pub fn droppable(structure: &ModelStructure, name: &str) -> bool {
    let Some(index) = structure.parameter_index(name) else {
        return false;
    };
    structure.parameters[index].kind == ParameterKind::Free
        && !structure.entries.iter().any(|entry| {
            entry.matrix == MatrixName::M
                && entry
                    .expression
                    .terms
                    .iter()
                    .any(|&(term, _)| term == index)
        })
}

/// One line naming the worst of `found` (at most three) with their values and limits,
/// e.g. `` `Zped` = -1.145e7 (|value| <= 1000 m/s² per stick) ``.
pub fn describe(found: &[Implausible]) -> String {
    let mut parts: Vec<String> = found
        .iter()
        .take(3)
        .map(|p| {
            if p.limit.is_finite() {
                format!(
                    "`{}` = {:.3e} (|value| <= {} {})",
                    p.name,
                    p.value,
                    short(p.limit),
                    p.dimension
                )
            } else {
                format!("`{}` = {}", p.name, p.value)
            }
        })
        .collect();
    if found.len() > 3 {
        parts.push(format!("and {} more", found.len() - 3));
    }
    parts.join(", ")
}

/// A limit in a few digits.
fn short(value: f64) -> String {
    if !(1e-2..1e5).contains(&value) {
        format!("{value:.0e}")
    } else {
        format!("{}", (value * 1000.0).round() / 1000.0)
    }
}

#[cfg(test)]
mod tests;
