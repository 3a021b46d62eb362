//! The report's sections, top to bottom as a flight-test engineer reads them: campaign
//! summary against the bars of the issues ([`summary`]), the sweep input (paper Fig. 1/6,
//! [`sweep`]), cross-control coherence (Fig. 3/7, [`coherence`]), Bode plots data vs model
//! vs truth (Fig. 10, [`bode`]), the parameter table (Table 3, [`parameters`]), the modes
//! of the identified model beside the truth's ([`modes`]), the cost table ([`costs`]), and
//! the verification time histories ([`verification`]), and the board's loops on the
//! identified model: Bode plots with margins, the ADS-33 charts ([`loops`]).

pub mod bode;
pub mod coherence;
pub mod costs;
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

/// The summary of the mode called `mode` (`cah`, `standard`, `noise`), when flown.
fn mode_of<'a>(inputs: &'a ReportInputs, mode: &str) -> Option<&'a ModeSummary> {
    match mode {
        "cah" => inputs.summary.modes.cah.as_ref(),
        "standard" => inputs.summary.modes.standard.as_ref(),
        _ => inputs.summary.modes.noise.as_ref(),
    }
}
