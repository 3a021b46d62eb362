//! What several sections share: the key parameters, the half-page figure width, number
//! formatting, the text of a section without a fit, and a flown mode's summary.

use crate::artifacts::summary::ModeSummary;
use crate::report::inputs::ReportInputs;

/// Parameters the fit issue requires within 10 % of the truth (τ_f, L_β1s, M_β1c, Z_col,
/// N_ped and the four flapping control derivatives).
pub const KEY_PARAMETERS: [&str; 9] = [
    "tau_f", "Lb1s", "Mb1c", "Zcol", "Nped", "Lf_lat", "Lf_lon", "Mf_lat", "Mf_lon",
];

/// Width [px] of the figures shown two per row (about their width on a 1280 px page).
pub(super) const HALF_WIDTH: u32 = 600;

/// `value` with `digits` decimals, or `-`.
pub(super) fn fmt(value: Option<f64>, digits: usize) -> String {
    crate::report::html::number(value, digits)
}

/// What a section without a fit says.
pub(super) fn no_fit(inputs: &ReportInputs) -> &'static str {
    if inputs.summary.has_truth() {
        "No fit in this campaign."
    } else {
        "No fit in this folder (the fit did not complete)."
    }
}

/// The summary of the mode called `mode` (`cah`, `standard`, `noise`), when flown.
/// None in an identify folder.
pub(super) fn mode_of<'a>(inputs: &'a ReportInputs, mode: &str) -> Option<&'a ModeSummary> {
    let modes = &inputs.summary.campaign()?.modes;
    match mode {
        "cah" => modes.cah.as_ref(),
        "standard" => modes.standard.as_ref(),
        _ => modes.noise.as_ref(),
    }
}
