//! Model structure files (TOML): which entries of M, F, G, H0, H1 and which delays are
//! free, fixed, zero or constrained, and which input/output pairs to fit over which
//! frequency range. The format is documented in `host/sysid/models/README.md`.
//!
//! Every error names the line it is on: syntax errors through the span that
//! `toml::de::Error` carries, semantic errors (unknown state, undefined parameter, …)
//! through `toml::Spanned` values.
//!
//! This module holds the checked structure and builds the numeric [`Model`] from it. The
//! file is read by its submodules: `schema` (the TOML form serde reads), `parse` (text →
//! [`ModelStructure`]) and `validate` (the checks that span several of its tables).

use std::collections::BTreeMap;

use super::error::FitError;
use super::model::{Actuator, Model};

mod parse;
mod schema;
mod validate;

/// Most states a structure may declare. A fit's work grows with the cube of the states
/// (one complex n×n solve per frequency and parameter): the shipped structures have 8
/// and 10, and 32 leaves room for a larger rotor model while keeping that work bounded.
/// Checked before any work.
pub const MAX_STATES: usize = 32;
/// Most controls a structure may declare.
pub const MAX_CONTROLS: usize = 16;
/// Most outputs a structure may declare.
pub const MAX_OUTPUTS: usize = 32;
/// Most parameters (free, fixed and constrained) a structure may declare: each free one
/// costs a model evaluation per Jacobian.
pub const MAX_PARAMETERS: usize = 256;
/// Most input/output pairs a structure may fit.
pub const MAX_PAIRS: usize = 128;

/// Whether the optimizer moves a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ParameterKind {
    /// Identified by the fit, starting from `value`.
    Free,
    /// Held at `value` (by the file, or dropped by `--reduce` at zero).
    Fixed,
    /// Held at the value the trim points give ([`super::trim`]); the fit re-derives it as
    /// the other parameters move. Only parameters the file lists in `trim_derived` become
    /// `trim`, and only when trim points are given.
    Trim,
}

/// A base parameter: free or fixed. Constrained parameters are [`DerivedParameter`]s.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Engineering name (`Lb1s`, `tau_f`, `Zcol`, …).
    pub name: String,
    /// Start value (free) or value (fixed).
    pub value: f64,
    /// Free or fixed.
    pub kind: ParameterKind,
    /// Optional lower bound the optimizer respects (e.g. 0 for a time constant).
    pub lower: Option<f64>,
    /// Optional upper bound.
    pub upper: Option<f64>,
    /// Line of the definition in the structure file.
    pub line: usize,
    /// A-priori value ± σ (`prior`, `sigma`): a weighted term of the cost
    /// ([`crate::fit::prior`]).
    pub prior: Option<Prior>,
    /// The `[constants]` name the prior's value was given as (`prior =
    /// "servo_natural_frequency"`), when it was a name: the a-priori constant this
    /// parameter estimates.
    pub prior_constant: Option<String>,
}

/// A parameter's prior: value ± one standard deviation.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Prior {
    /// θ_p: the a-priori value.
    pub value: f64,
    /// σ > 0: its standard uncertainty, in the parameter's units.
    pub sigma: f64,
}

impl Prior {
    /// (θ − θ_p)/σ: how far `value` lies from the prior, in σ.
    pub fn distance(&self, value: f64) -> f64 {
        (value - self.value) / self.sigma
    }
}

/// `constant + Σ coefficient·θ_k` over base-parameter indices.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ParameterExpression {
    /// Constant part.
    pub constant: f64,
    /// (base parameter index, coefficient) pairs.
    pub terms: Vec<(usize, f64)>,
}

impl ParameterExpression {
    /// Value for a vector of base-parameter values.
    pub fn evaluate(&self, values: &[f64]) -> f64 {
        self.terms
            .iter()
            .fold(self.constant, |sum, &(index, coefficient)| {
                sum + coefficient * values[index]
            })
    }
}

/// A parameter constrained to a linear expression of base parameters (paper Table 3,
/// note d: `Yb1s = -Xb1c`).
#[derive(Clone, Debug, PartialEq)]
pub struct DerivedParameter {
    /// Engineering name.
    pub name: String,
    /// The constraint, in base parameters.
    pub expression: ParameterExpression,
    /// Line of the definition.
    pub line: usize,
}

/// The five matrices of `M ẋ = F x + G u(t − τ)`, `y = H0 x + H1 ẋ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MatrixName {
    /// Mass matrix (states × states); defaults to the identity.
    M,
    /// Dynamics (states × states).
    F,
    /// Control (states × controls).
    G,
    /// Output from states (outputs × states).
    H0,
    /// Output from state derivatives (outputs × states).
    H1,
}

impl MatrixName {
    /// The name as written in structure files.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::M => "M",
            Self::F => "F",
            Self::G => "G",
            Self::H0 => "H0",
            Self::H1 => "H1",
        }
    }
}

/// One non-default matrix entry.
#[derive(Clone, Debug, PartialEq)]
pub struct MatrixEntry {
    /// Which matrix.
    pub matrix: MatrixName,
    /// Row index (state for M F G, output for H0 H1).
    pub row: usize,
    /// Column index (state, or control for G).
    pub column: usize,
    /// Value as a linear expression of base parameters.
    pub expression: ParameterExpression,
    /// Line in the structure file.
    pub line: usize,
}

/// Frequency range of a pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PairRange {
    /// The pair's `valid_range` from the frequency-response document (clipped by the
    /// structure's `auto_range_limit`, if any).
    Auto,
    /// An explicit [lo, hi] rad/s.
    Explicit([f64; 2]),
}

/// One input → output pair to fit.
#[derive(Clone, Debug, PartialEq)]
pub struct PairSpec {
    /// Control name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Index into `controls`.
    pub input_index: usize,
    /// Index into `outputs`.
    pub output_index: usize,
    /// Range to fit over.
    pub range: PairRange,
    /// Line in the structure file.
    pub line: usize,
}

/// A parsed, checked model structure.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelStructure {
    /// Structure name (`bo105-9dof-hybrid`).
    pub name: String,
    /// Free text.
    pub description: String,
    /// State names, in order.
    pub states: Vec<String>,
    /// Control names, in order.
    pub controls: Vec<String>,
    /// Output names, in order.
    pub outputs: Vec<String>,
    /// Base parameters (free and fixed), in file order.
    pub parameters: Vec<Parameter>,
    /// Constrained parameters, in file order.
    pub derived: Vec<DerivedParameter>,
    /// Matrix entries that differ from the defaults (M = I, H0 selects states that are
    /// also outputs, everything else zero).
    pub entries: Vec<MatrixEntry>,
    /// Delay τ per control \[s\], as expressions (constant 0 when not given).
    pub delays: Vec<ParameterExpression>,
    /// Known actuator per control (`[actuators]`; `None` when not given), at the values
    /// of the file (its numbers and constants; base parameters at their start values).
    pub actuators: Vec<Option<Actuator>>,
    /// Per control, the base parameters (indices) that give its actuator's natural
    /// frequency and damping when the file names parameters there: the model takes
    /// them from the parameter values.
    pub actuator_parameters: Vec<[Option<usize>; 2]>,
    /// Pairs to fit.
    pub pairs: Vec<PairSpec>,
    /// Clips every `auto` range to this band [rad/s] (e.g. 6-DOF fits stop below the
    /// rotor modes).
    pub auto_range_limit: Option<[f64; 2]>,
    /// Outputs measured directly as a state by default (no H0/H1 row given): output
    /// index → state index.
    pub default_output_states: Vec<(usize, usize)>,
    /// File name used in error messages.
    pub source_name: String,
    /// Named numbers of the file's `[constants]` (e.g. `hub_height`), with any override
    /// the caller gave ([`Self::parse_with_constants`]); expressions were built with these.
    pub constants: BTreeMap<String, f64>,
    /// Base parameters the file's `trim_derived` names: with trim points
    /// ([`super::trim`]) they are derived from the steady-state balance at the points
    /// instead of fitted; without, they are fitted like the others.
    pub trim_derived: Vec<String>,
}

impl ModelStructure {
    /// Index of a base (free or fixed) parameter.
    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p.name == name)
    }

    /// Current base-parameter values (the start values of a fresh structure).
    pub fn values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// Indices of the free parameters, in order.
    pub fn free_indices(&self) -> Vec<usize> {
        (0..self.parameters.len())
            .filter(|&i| self.parameters[i].kind == ParameterKind::Free)
            .collect()
    }

    /// Value of any parameter (base or constrained) by name.
    pub fn parameter_value(&self, name: &str, values: &[f64]) -> Option<f64> {
        if let Some(index) = self.parameter_index(name) {
            return values.get(index).copied();
        }
        self.derived
            .iter()
            .find(|d| d.name == name)
            .map(|d| d.expression.evaluate(values))
    }

    /// The numeric model for a vector of base-parameter values.
    pub fn model(&self, values: &[f64]) -> Result<Model, FitError> {
        if values.len() != self.parameters.len() {
            return Err(FitError::ParameterCount {
                expected: self.parameters.len(),
                got: values.len(),
            });
        }
        let n = self.states.len();
        let mut model = Model::zeros(
            self.states.clone(),
            self.controls.clone(),
            self.outputs.clone(),
        );
        for i in 0..n {
            model.m[(i, i)] = 1.0;
        }
        for &(output, state) in &self.default_output_states {
            model.h0[(output, state)] = 1.0;
        }
        for entry in &self.entries {
            let value = entry.expression.evaluate(values);
            let matrix = match entry.matrix {
                MatrixName::M => &mut model.m,
                MatrixName::F => &mut model.f,
                MatrixName::G => &mut model.g,
                MatrixName::H0 => &mut model.h0,
                MatrixName::H1 => &mut model.h1,
            };
            matrix[(entry.row, entry.column)] = value;
        }
        for (control, delay) in self.delays.iter().enumerate() {
            model.delays[control] = delay.evaluate(values);
        }
        model.actuators = self.actuators.clone();
        for (control, [frequency, damping]) in self.actuator_parameters.iter().enumerate() {
            if let Some(actuator) = model.actuators[control].as_mut() {
                if let Some(index) = *frequency {
                    actuator.natural_frequency_rad_s = values[index];
                }
                if let Some(index) = *damping {
                    actuator.damping = values[index];
                }
            }
        }
        Ok(model)
    }

    /// A copy whose base parameters take `values` (as new start / fixed values).
    pub fn with_values(&self, values: &[f64]) -> Result<Self, FitError> {
        if values.len() != self.parameters.len() {
            return Err(FitError::ParameterCount {
                expected: self.parameters.len(),
                got: values.len(),
            });
        }
        let mut copy = self.clone();
        for (parameter, &value) in copy.parameters.iter_mut().zip(values) {
            parameter.value = value;
        }
        Ok(copy)
    }
}

#[cfg(test)]
mod tests;
