//! The checked structure ([`ModelStructure`]) and the numeric [`Model`] it builds for
//! parameter values.

use std::collections::BTreeMap;

use super::matrix::{MatrixEntry, MatrixName};
use super::pair::PairSpec;
use super::parameter::{DerivedParameter, Parameter, ParameterExpression, ParameterKind};
use crate::fit::error::FitError;
use crate::fit::model::{Actuator, Model};

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
    /// ([`crate::fit::trim`]) they are derived from the steady-state balance at the points
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
