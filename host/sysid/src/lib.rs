//! Frequency-domain system identification in the manner of CIFER: frequency responses
//! (FRESPID, MISOSA, COMPOSITE) and state-space fits with accuracy metrics (DERIVID,
//! VERIFY).
//!
//! The modules, in the order of the work:
//!
//! * [`records`] — the sweep [`Record`](records::Record) and the files it is read from:
//!   telemetry dumps, CSV files and other tools' flight logs (PX4 ULog, ArduPilot
//!   DataFlash);
//! * [`frf`] — sweep records → frequency responses;
//! * [`document`] — the frequency-response document `frf.json` they are written to and
//!   read back from;
//! * [`fit`] — state-space model structures fitted to those responses, with their
//!   accuracy, modes, trim-derived parameters and time-domain verification;
//! * [`models`] — the structure files shipped with the crate, by name;
//! * [`random`] — the one small deterministic generator (seeded restarts, test noise).
//!
//! Inside the crate the dependencies run one way: `models` → `fit` → `frf` → `records`,
//! and `fit`, `frf` → `document` (`random` is a leaf that any of them may use); `records`
//! imports no other module of the crate. A module imports its siblings and their public
//! items, never the internals of its parent's siblings.
//!
//! **What it may import.** This crate is numerics and file formats, and nothing else: it
//! depends on numeric crates (nalgebra, num-complex, rustfft, and rand_core with
//! rand_xoshiro for [`random`]), serialization crates
//! (serde, serde_json, toml, and the project's wire protocol `sweephold-protocol`, for
//! the telemetry dumps it reads) and thiserror for its error types; plots are drawn by
//! the command-line program. It never imports the simulator (`bo105`) or the command-line program
//! (`sweephold`): they use it. What it needs to know of a vehicle (the TREX 700L's
//! geometry and trim, say) the caller passes in.

pub mod document;
pub mod fit;
pub mod frf;
pub mod models;
pub mod random;
pub mod records;
