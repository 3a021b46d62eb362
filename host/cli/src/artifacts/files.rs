//! Where each file of a campaign folder lies, relative to the folder (layout in
//! docs/formats.md).

/// The campaign's summary.
pub const SUMMARY: &str = "summary.json";
/// The report.
pub const REPORT: &str = "report.html";
/// Frequency responses of the `cah` records.
pub const FRF: &str = "frf.json";
/// The trim points the fits derive `trim_derived` parameters from.
pub const TRIM_POINTS: &str = "trim-points.csv";
/// The 6-DOF fit.
pub const MODEL_6DOF: &str = "model6.json";
/// The 9-DOF hybrid fit (with its truth section).
pub const MODEL_9DOF: &str = "model9.json";
/// The 9-DOF structure at the truth values.
pub const TRUTH_MODEL_9DOF: &str = "truth-model9.json";
/// Verification time histories and scores.
pub const VERIFY: &str = "verify.json";
/// Loop margins and handling qualities of the 9-DOF fit (`sweephold margins --out`).
pub const MARGINS: &str = "margins.json";
/// The 9-DOF fit's broken loops, sensitivities and stick responses, sampled for the
/// report's plots (`sweephold margins --export-loops` on a coarser grid).
pub const MARGINS_LOOPS: &str = "margins-loops.json";
/// Folder of the held-out doublets.
pub const VERIFICATION_FOLDER: &str = "verify-doublet";
/// The folder of the steady flights' log and GNSS file (`--fc board-sim` campaigns).
pub const STEADY_FOLDER: &str = "fly-steady";

/// Folder of the sweeps flown in `mode` (`cah`, `standard`, `noise`).
pub fn fly_folder(mode: &str) -> String {
    format!("fly-{mode}")
}
