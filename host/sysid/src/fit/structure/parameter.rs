//! A structure's parameters: base parameters (free, fixed or derived from trim points),
//! their priors, and the parameters constrained to linear expressions of them.

/// Whether the optimizer moves a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ParameterKind {
    /// Identified by the fit, starting from `value`.
    Free,
    /// Held at `value` (by the file, or dropped by `--reduce` at zero).
    Fixed,
    /// Held at the value the trim points give ([`crate::fit::trim`]); the fit re-derives it as
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
