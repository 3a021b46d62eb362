//! Truth scoring: the parameter values a model structure takes when it is fitted to the
//! simulator's own linearization, the truth `Model` built from them, and the cost of an
//! identified model against it.
//!
//! - [`VehicleTruth`]: an aircraft file's helicopter simulated, trimmed in hover and
//!   linearized, with its servos' equivalent delay.
//! - [`structure_truth()`]: that linearization mapped onto a structure's parameters by name
//!   (the rules are in the [`structure_truth`](mod@structure_truth) module), giving a
//!   [`StructureTruth`].
//! - [`score_fit`], [`score_fit_with_modes`]: an identified model against the structure's
//!   truth (the `truth` section of `model.json`).
//! - [`with_vehicle_data`], [`nine_dof_hybrid`]: a shipped structure with the flown
//!   vehicle's geometry, rotor data and trim attitude ([`TrimAttitude`]) in it.
//!
//! **Its room and what it may import.** It joins the simulator (`rotorsim`), the
//! identification library (`sysid`) and the aircraft files (`aircraft`), its only
//! workspace imports (besides nalgebra and thiserror); none of them imports it, nor does
//! it import the command-line tool (its one user) or read telemetry.

mod error;
pub mod file_constants;
mod flap_rows;
mod folded_flapping;
pub mod scoring;
pub mod structure_truth;
#[cfg(test)]
mod test_support;
pub mod vehicle_data;
pub mod vehicle_truth;

pub use error::Error;
pub use file_constants::{file_constants, FileConstant};
pub use scoring::{score_fit, score_fit_with_modes, ScoredFit, TRUTH_POINTS_PER_PAIR};
pub use structure_truth::{structure_truth, StructureTruth};
pub use vehicle_data::{hybrid_structures, nine_dof_hybrid, with_vehicle_data, TrimAttitude};
pub use vehicle_truth::VehicleTruth;
