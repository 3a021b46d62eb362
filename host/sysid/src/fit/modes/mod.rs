//! The modes of a linear model `M ẋ = F x + G u`: the eigenvalues of the state matrix
//! `A = M⁻¹F`, each named from its eigenvector by a fixed rule set, and the comparison of
//! an identified model's modes with a truth model's.
//!
//! * [`eigen`] — the eigenvalues of `A = M⁻¹F` and their eigenvectors, as [`Mode`]s
//!   (the figures of one mode);
//! * [`naming`] — how a mode is named from its eigenvector (the rules);
//! * [`state_kinds`] — each state's unit and group for the naming, by its name or, for
//!   a state of another name, by what drives it in the model;
//! * [`record`] — a mode as written in `model.json` ([`ModeRecord`]);
//! * [`comparison`] — an identified model's modes paired with a truth model's;
//! * [`text`] — an eigenvalue as text.
//!
//! The console tables of modes are the command-line program's.

pub mod comparison;
pub mod eigen;
pub mod naming;
pub mod record;
pub mod state_kinds;
pub mod text;

pub use comparison::{
    compare_modes, pair_modes, relative_error_percent, HoverModeScore, ModeComparison,
    TruthModeRecord, HOVER_MODE_TOLERANCE_PERCENT,
};
pub use eigen::{modes, state_matrix, Mode, ModeError};
pub use naming::{
    GroupShares, ModeName, AXIS_DOMINANCE, HOVER_MODE_LIMIT_RAD_S, ORIGIN_LIMIT_RAD_S,
    ROTOR_SHARE_LIMIT, SCALING_FLOOR_RAD_S, SPIRAL_LIMIT_RAD_S, SPIRAL_SHARE,
};
pub use record::{mode_records, poles_at_origin, ModeRecord};
pub use state_kinds::{FOOT_GRAVITY, STANDARD_GRAVITY};
pub use text::eigenvalue_text;

#[cfg(test)]
mod tests;
