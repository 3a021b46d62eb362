//! State-space model fitting to frequency responses, as CIFER's DERIVID does it.
//!
//! A [`ModelStructure`] (TOML file, see `host/sysid/models/README.md`) says which entries
//! of `M ẋ = F x + G u(t − τ)`, `y = H0 x + H1 ẋ` are free, fixed, zero or constrained.
//! [`fit`] interpolates each pair's response at n_ω = 20 log-spaced frequencies of its
//! range, minimises the DERIVID cost ([`cost`]) with Levenberg–Marquardt from several
//! seeded starts until the same minimum is found twice ([`optimizer`]), and reports
//! Cramér–Rao bounds, insensitivities and correlations ([`accuracy`]); optionally it drops
//! poorly identified parameters one at a time ([`reduce`]).
//!
//! The fit as a whole ([`fit`], [`fit_from_alternative_starts`]) and the multi-start
//! search it runs are in the private modules `driver` and `search`; what it produces
//! ([`FitResult`] and its parts) in `result`; its settings ([`FitOptions`]) in `options`.
//! All four are re-exported here.

pub mod accuracy;
pub mod cost;
pub mod degenerate;
mod driver;
pub mod equation_error;
pub mod error;
pub mod expression;
pub mod measured;
pub mod model;
pub mod modes;
pub mod optimizer;
mod options;
pub mod plausible;
pub mod prior;
pub mod reduce;
pub mod report;
mod result;
mod search;
pub mod start;
mod start_box;
pub mod structure;
pub mod synthetic;
pub mod trim;
pub mod verify;

#[cfg(test)]
pub(crate) mod test_support;

pub use accuracy::{AccuracyAnalysis, ParameterAccuracy};
pub use cost::{cost_between_models, ModelComparison, PairBand, PairGrid};
pub use driver::{
    fit, fit_from_alternative_starts, restart_seed, usable_pairs, DEGENERATE_RESTARTS,
};
pub use error::{FitError, StructureError, StructureProblem};
pub use measured::{measured_outputs, reduce_to_measured};
pub use model::Model;
pub use optimizer::StopReason;
pub use options::FitOptions;
pub use report::ModelDocument;
pub use result::{
    AccuracyFlag, FitResult, FlagRecord, PairFit, ParameterReport, ParameterStatus, ReductionStep,
    SkippedPair, StartOutcome, StartSetOutcome,
};
pub use start::{start_from_quasi_steady, StartValueNote};
pub use structure::{ModelStructure, ParameterKind};

#[cfg(test)]
mod tests;
