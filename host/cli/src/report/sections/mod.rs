//! The report's sections, top to bottom as a flight-test engineer reads them: campaign
//! summary against the bars of the issues ([`summary`]), the sweep input (paper Fig. 1/6,
//! [`sweep`]), cross-control coherence (Fig. 3/7, [`coherence`]), Bode plots data vs model
//! vs truth (Fig. 10, [`bode`]), the parameter table (Table 3, [`parameters`]), the modes
//! of the identified model beside the truth's ([`modes`]), the cost table ([`costs`]), and
//! the verification time histories ([`verification`]), and the board's loops on the
//! identified model: Bode plots with margins, the ADS-33 charts ([`loops`]).
//!
//! An identify folder's page has its own summary ([`identify_summary`]: the tests read
//! and what became of each) and the model's sections without their truth parts
//! ([`ReportInputs::summary`](crate::report::ReportInputs::summary)'s `has_truth`), nothing from the flights or the loops.

pub mod bode;
pub mod coherence;
pub mod costs;
pub mod identify_summary;
pub mod loops;
pub mod modes;
pub mod parameters;
mod shared;
pub mod summary;
pub mod sweep;
#[cfg(test)]
mod test_support;
pub mod verification;

pub use shared::KEY_PARAMETERS;

/// Section ids of the plot sections, in page order (each holds at least one `<svg>`).
pub const PLOT_SECTIONS: [&str; 5] = [
    "sweep-input",
    "cross-coherence",
    "bode",
    "verification",
    "loops",
];
