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
//! * [`steady`] — trim points from a flight: the steady segments of a log with a GNSS
//!   unit's velocities;
//! * [`random`] — the one small deterministic generator (seeded restarts, test noise).
//!
//! Inside the crate the dependencies run one way, in layers: `models`, `steady` > `fit` >
//! `frf` > `document`, `records`, `random`. A module imports only the modules of the layers
//! below its own: `models` and `steady` → `fit` → `frf` → `records`, `fit` and `frf` →
//! `document`, and any
//! of them → `random`; `document`, `records` and `random` import no other module of the
//! crate. Inside each module too, imports go down: a module imports its siblings and
//! their public items, never the internals of its parent's siblings, and never an item
//! from its parent's own file (what children share lives in a child of its own); it
//! imports an item from the module that defines it, not through a parent's re-export.
//! `cargo xtask layers` (run by CI) enforces both, with this order written in its table
//! of crates.
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
pub mod steady;
