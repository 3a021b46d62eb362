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
//! ([`ReportInputs::summary`]'s `has_truth`), nothing from the flights or the loops.

pub mod bode;
pub mod coherence;
pub mod costs;
pub mod identify_summary;
pub mod loops;
pub mod modes;
pub mod parameters;
pub mod summary;
pub mod sweep;
#[cfg(test)]
mod test_support;
pub mod verification;

use super::inputs::ReportInputs;
use crate::artifacts::summary::ModeSummary;

/// Section ids of the plot sections, in page order (each holds at least one `<svg>`).
pub const PLOT_SECTIONS: [&str; 5] = [
    "sweep-input",
    "cross-coherence",
    "bode",
    "verification",
    "loops",
];

/// Parameters the fit issue requires within 10 % of the truth (τ_f, L_β1s, M_β1c, Z_col,
/// N_ped and the four flapping control derivatives).
pub const KEY_PARAMETERS: [&str; 9] = [
    "tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Lf_lat", "Lf_lon", "Mf_lat", "Mf_lon",
];

/// Width [px] of the figures shown two per row (about their width on a 1280 px page).
const HALF_WIDTH: u32 = 600;

/// `value` with `digits` decimals, or `-`.
fn fmt(value: Option<f64>, digits: usize) -> String {
    super::html::number(value, digits)
}

/// What a section without a fit says.
fn no_fit(inputs: &ReportInputs) -> &'static str {
    if inputs.summary.has_truth() {
        "No fit in this campaign."
    } else {
        "No fit in this folder (the fit did not complete)."
    }
}

/// The summary of the mode called `mode` (`cah`, `standard`, `noise`), when flown.
/// None in an identify folder.
fn mode_of<'a>(inputs: &'a ReportInputs, mode: &str) -> Option<&'a ModeSummary> {
    let modes = &inputs.summary.campaign()?.modes;
    match mode {
        "cah" => modes.cah.as_ref(),
        "standard" => modes.standard.as_ref(),
        _ => modes.noise.as_ref(),
    }
}
