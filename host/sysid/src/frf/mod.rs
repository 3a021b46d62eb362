//! Frequency responses from sweep records, the way CIFER computes them:
//! FRESPID (windowed Chirp-Z spectra), MISOSA (multi-input conditioning) and COMPOSITE
//! (blending several window lengths).
//!
//! The records come from [`crate::records`] (telemetry dumps, CSV files, other tools'
//! logs); this module never reads a file. The chain, one module per step:
//!
//! 1. [`groups`] — [`Record`]s are gathered into one [`RecordGroup`] per swept axis; the
//!    records of a group are detrended and joined into one excitation record.
//! 2. [`spectra`] — Hann-tapered, overlapped windows of several lengths; each window of
//!    each channel is transformed once with the [`chirp_z()`] transform and all auto- and
//!    cross-spectra are formed from those transforms, then interpolated onto a
//!    log-spaced frequency grid.
//! 3. [`miso`] — per frequency and window length, the conditioned responses
//!    `H = Guu⁻¹·Guy` (Cholesky solve), partial and multiple coherence.
//!    With a feedback controller in the loop, [`reference`](mod@reference) solves `G_zu·H = G_zy`
//!    with the recorded sweep as instrument z instead (an option).
//! 4. [`composite`] — per frequency, the window-length estimates are blended with
//!    weights 1/εr².
//! 5. [`coherence`] — random error, valid ranges, coherence bias.
//! 6. [`analysis`] — the whole computation into an [`FrfDocument`], and the
//!    cross-control coherence.
//!
//! [`broken_loop`](mod@broken_loop) measures a feedback loop's broken-loop response from a
//! loop test's injection and total command with the same spectra.
//!
//! [`Record`], [`Channel`] and the dump reader [`load_dump_bytes`] are re-exported from
//! [`crate::records`]: the record is this module's input, and the flight loop goes from
//! a dump in memory straight to its cross-control coherence.
//!
//! ```no_run
//! use sysid::frf::{compute_frequency_responses, group_by_primary, FrfOptions};
//! use sysid::records::load_dump;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let records = vec![load_dump("lat-1.dump")?, load_dump("lat-2.dump")?, load_dump("lon.dump")?];
//! let groups = group_by_primary(records)?; // lat (two records joined), lon
//! let document = compute_frequency_responses(&groups, &FrfOptions::default())?;
//! if let Some(pair) = document.pair("lat", "p") {
//!     println!("lat → p valid over {:?} rad/s", pair.valid_range);
//! }
//! # Ok(())
//! # }
//! ```
//!
//! [`FrfDocument`]: crate::document::FrfDocument

pub mod analysis;
pub mod broken_loop;
pub mod chirp_z;
pub mod coherence;
pub mod composite;
mod error;
pub mod groups;
pub mod miso;
pub mod options;
pub mod reference;
pub mod spectra;

#[cfg(test)]
pub(crate) mod testing;

pub use analysis::{
    analyse, compute_frequency_responses, cross_control_coherence, CoherenceCurve, FrfAnalysis,
    GroupSummary, MultipleCoherence,
};
pub use chirp_z::{chirp_z, ChirpZ};
pub use coherence::{debiased_coherence, random_error, valid_range};
pub use error::FrfError;
pub use groups::{group_by_primary, RecordGroup};
pub use options::{FrfOptions, RangeSource, ResponseEstimator, ResponseInputs};
pub use spectra::welch_independent_averages;

pub use crate::records::{load_dump_bytes, Channel, Record};
