//! Model structure files (TOML): which entries of M, F, G, H0, H1 and which delays are
//! free, fixed, zero or constrained, and which input/output pairs to fit over which
//! frequency range. The format is documented in `host/sysid/models/README.md`.
//!
//! Every error names the line it is on: syntax errors through the span that
//! `toml::de::Error` carries, semantic errors (unknown state, undefined parameter, …)
//! through `toml::Spanned` values.
//!
//! The checked structure and the numeric [`Model`](crate::fit::Model) it builds are in
//! `model_structure`, its parts in `parameter`, `matrix` and `pair`, its size limits in
//! `limits`; all are re-exported here. The file is read by `schema` (the TOML form serde
//! reads), `parse` (text → [`ModelStructure`]) and `validate` (the checks that span
//! several of its tables).

mod limits;
mod matrix;
mod model_structure;
mod pair;
mod parameter;
mod parse;
mod schema;
mod validate;

pub use limits::{MAX_CONTROLS, MAX_OUTPUTS, MAX_PAIRS, MAX_PARAMETERS, MAX_STATES};
pub use matrix::{MatrixEntry, MatrixName};
pub use model_structure::ModelStructure;
pub use pair::{PairRange, PairSpec};
pub use parameter::{DerivedParameter, Parameter, ParameterExpression, ParameterKind, Prior};

#[cfg(test)]
mod tests;
