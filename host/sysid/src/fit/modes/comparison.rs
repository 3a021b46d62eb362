//! The modes of an identified model compared with a truth model's.
//!
//! [`compare_modes`] pairs each identified mode with at most one truth mode, one to one:
//! first modes of the same name, then the rest by the nearest eigenvalue (each pass takes
//! the closest pairs `|λ_id − λ_true|` first). Its error is `|λ_id − λ_true| / |λ_true|`
//! (both by their Im ≥ 0 member). The truth's hover modes are its modes with
//! `|λ| < 3` rad/s, the origin excepted; one is matched when its counterpart is within
//! 25 % ([`HOVER_MODE_TOLERANCE_PERCENT`]). Both thresholds are the acceptance criteria of
//! the hover-modes issue (20).

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use super::eigen::{modes, Mode, ModeError};
use super::record::{poles_at_origin, ModeRecord};
use crate::fit::model::Model;

/// A truth hover mode is matched when its identified counterpart is within this relative
/// error [%] of its eigenvalue.
pub const HOVER_MODE_TOLERANCE_PERCENT: f64 = 25.0;
/// `|λ_id − λ_true| / |λ_true|` in %; None when the truth is at 0.
pub fn relative_error_percent(identified: Complex64, truth: Complex64) -> Option<f64> {
    let scale = truth.norm();
    (scale > 0.0).then(|| 100.0 * (identified - truth).norm() / scale)
}

/// Pair each identified mode with at most one truth mode, one to one: same name first,
/// then the nearest eigenvalue; each pass takes the closest pairs first (ties by index).
/// Returns, per identified mode, the index of its truth mode.
pub fn pair_modes(identified: &[Mode], truth: &[Mode]) -> Vec<Option<usize>> {
    let mut pairing = vec![None; identified.len()];
    let mut truth_taken = vec![false; truth.len()];
    for same_name_only in [true, false] {
        let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
        for (i, mode) in identified.iter().enumerate() {
            for (t, reference) in truth.iter().enumerate() {
                if !same_name_only || mode.name == reference.name {
                    let distance = (mode.eigenvalue - reference.eigenvalue).norm();
                    candidates.push((distance, i, t));
                }
            }
        }
        candidates.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        for (_, i, t) in candidates {
            if pairing[i].is_none() && !truth_taken[t] {
                pairing[i] = Some(t);
                truth_taken[t] = true;
            }
        }
    }
    pairing
}

/// A truth mode and the identified mode paired with it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthModeRecord {
    /// The truth mode's name.
    pub name: String,
    /// `[Re λ, Im λ]` [rad/s], Im ≥ 0.
    pub eigenvalue: [f64; 2],
    /// ω_n = |λ| [rad/s]; null at the origin.
    pub omega_n: Option<f64>,
    /// ζ of a complex pair; null for a real pole.
    pub zeta: Option<f64>,
    /// Whether it is a hover mode (10⁻⁶ ≤ |λ| < 3 rad/s).
    pub hover: bool,
    /// `[Re, Im]` of the identified mode paired with it; null when none was left.
    pub identified: Option<[f64; 2]>,
    /// Name of that identified mode.
    pub identified_name: Option<String>,
    /// `100·|λ_id − λ_true| / |λ_true|`; null without a pair.
    pub error_percent: Option<f64>,
}

impl TruthModeRecord {
    /// Whether an identified mode is paired with it within
    /// [`HOVER_MODE_TOLERANCE_PERCENT`].
    pub fn within_tolerance(&self) -> bool {
        self.error_percent
            .is_some_and(|e| e <= HOVER_MODE_TOLERANCE_PERCENT)
    }
}

/// How the identified model reproduces the truth's hover modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HoverModeScore {
    /// Truth hover modes with an identified counterpart within 25 %.
    pub matched: usize,
    /// Truth hover modes (10⁻⁶ ≤ |λ| < 3 rad/s).
    pub of: usize,
    /// The largest error [%] among the truth hover modes that have a counterpart; null
    /// when none has.
    pub worst_error_percent: Option<f64>,
}

impl HoverModeScore {
    /// Every truth hover mode matched.
    pub fn all_matched(&self) -> bool {
        self.matched == self.of
    }
}

/// The modes of an identified model compared with those of a truth model.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeComparison {
    /// The identified modes, with their truth counterparts.
    pub identified: Vec<ModeRecord>,
    /// The truth's modes, with their identified counterparts.
    pub truth: Vec<TruthModeRecord>,
    /// The truth hover modes matched within 25 %.
    pub hover: HoverModeScore,
    /// Poles of the identified model at the origin (a pair counts 2).
    pub poles_at_origin: usize,
}

/// Compare the modes of `identified` with those of `truth` (this module's documentation).
pub fn compare_modes(identified: &Model, truth: &Model) -> Result<ModeComparison, ModeError> {
    let identified_modes = modes(identified)?;
    let truth_modes = modes(truth)?;
    let pairing = pair_modes(&identified_modes, &truth_modes);
    let mut identified_records: Vec<ModeRecord> = identified_modes
        .iter()
        .map(|mode| ModeRecord::new(mode, &identified.states))
        .collect();
    let mut truth_records: Vec<TruthModeRecord> = truth_modes
        .iter()
        .map(|mode| TruthModeRecord {
            name: mode.name.as_str().to_string(),
            eigenvalue: [mode.eigenvalue.re, mode.eigenvalue.im],
            omega_n: mode.natural_frequency(),
            zeta: mode.damping_ratio(),
            hover: mode.is_hover_mode(),
            identified: None,
            identified_name: None,
            error_percent: None,
        })
        .collect();
    for (i, paired) in pairing.iter().enumerate() {
        let Some(t) = *paired else { continue };
        let (mode, reference) = (&identified_modes[i], &truth_modes[t]);
        let error = relative_error_percent(mode.eigenvalue, reference.eigenvalue);
        let record = &mut identified_records[i];
        record.truth = Some([reference.eigenvalue.re, reference.eigenvalue.im]);
        record.truth_name = Some(reference.name.as_str().to_string());
        record.error_percent = error;
        let truth_record = &mut truth_records[t];
        truth_record.identified = Some([mode.eigenvalue.re, mode.eigenvalue.im]);
        truth_record.identified_name = Some(mode.name.as_str().to_string());
        truth_record.error_percent = error;
    }
    let hover_modes: Vec<&TruthModeRecord> = truth_records.iter().filter(|t| t.hover).collect();
    let hover = HoverModeScore {
        matched: hover_modes.iter().filter(|t| t.within_tolerance()).count(),
        of: hover_modes.len(),
        worst_error_percent: hover_modes
            .iter()
            .filter_map(|t| t.error_percent)
            .fold(None, |worst: Option<f64>, e| {
                Some(worst.map_or(e, |w| w.max(e)))
            }),
    };
    let poles_at_origin = poles_at_origin(&identified_records);
    Ok(ModeComparison {
        identified: identified_records,
        truth: truth_records,
        hover,
        poles_at_origin,
    })
}
