//! The matrices of `M ẋ = F x + G u(t − τ)`, `y = H0 x + H1 ẋ`, and a structure's
//! entries in them.

use super::parameter::ParameterExpression;

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
