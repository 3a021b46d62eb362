//! Loop margins and handling qualities of the board's pilot-mode loops, predicted from
//! an identified model (`model.json`).
//!
//! The board flies its pilot mode with the loops of `sweephold_firmware::app::pilot_mode`
//! (rate loops on p, q, r; a level loop on φ, θ; a heading hold on ψ). This crate puts
//! that control law — the gains of the firmware's own `PilotModeGains`, its control
//! tick's sample-and-hold, the board's IMU filter bank, a computation delay and the
//! servo frame — around the identified model and reports, per loop broken at the
//! actuator input, the crossover, gain and phase margins and the disturbance-rejection
//! bandwidth, and per stick the ADS-33E-PRF bandwidth and phase delay of the attitude
//! response, each with its spread over the model's Cramér–Rao bounds.
//!
//! Why a crate of its own: `sysid` is "numerics and file formats, nothing else" and
//! knows nothing of the flight controller; this crate joins the two (firmware control
//! law and identified model), which neither may depend on the other for.
//!
//! **Its room and what it may import.** The pilot-mode law around a model, nothing
//! else: no fitting, and no file read or written (the caller hands it the model). Of the workspace: the firmware (`sweephold-firmware` with
//! `std`: the gains, tick and IMU filter bank), the wire protocol and `sysid` (the model
//! and its structure); otherwise nalgebra, num-complex and serde. Only the command-line
//! tool imports it.
//!
//! Modules: [`plant`] (the model's responses at the board's sensors), [`law`] (the
//! control law as it runs), [`loops`] (loop matrix, broken loops, stick responses),
//! [`margins`] (crossover, margins, DRB of a sampled loop), [`handling`] (ADS-33
//! bandwidth, phase delay, level), [`uncertainty`] (Monte-Carlo over the parameter
//! covariance), [`analysis`] (everything for one model, the JSON document), [`tune`]
//! (pilot-mode gains designed on the model).

pub mod analysis;
pub mod handling;
pub mod law;
pub mod loops;
pub mod margins;
pub mod plant;
pub mod tune;
pub mod uncertainty;

pub use analysis::{analyse, AnalysisOptions, MarginsDocument};
pub use law::BoardLaw;
pub use plant::Plant;
