//! How large a structure may be: checked before any work, at the line of the first
//! name beyond a limit.

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
