//! A mode as it is written in `model.json` and `summary.json` ([`ModeRecord`]).

use std::collections::BTreeMap;

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

use super::eigen::{modes, Mode, ModeError};
use super::naming::ModeName;
use crate::fit::model::Model;

/// A mode as written in `model.json` and `summary.json`; the `truth*` and
/// `error_percent` fields are null without a truth comparison (or when no truth mode was
/// left to pair with).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModeRecord {
    /// The mode's name ([`ModeName::as_str`]).
    pub name: String,
    /// `[Re λ, Im λ]` [rad/s]; Im ≥ 0 (a complex pair by its upper member).
    pub eigenvalue: [f64; 2],
    /// ω_n = |λ| [rad/s]; null at the origin.
    pub omega_n: Option<f64>,
    /// ζ = −Re λ/|λ| of a complex pair; null for a real pole.
    pub zeta: Option<f64>,
    /// ln 2 / Re λ \[s\] when unstable; else null.
    pub time_to_double_s: Option<f64>,
    /// ln 2 / (−Re λ) \[s\] when stable; else null.
    pub time_to_half_s: Option<f64>,
    /// Poles the mode stands for: 1 (real) or 2 (complex pair).
    #[serde(default = "one_pole")]
    pub poles: usize,
    /// Share of each state in the mode ([`naming`](super::naming)), states with ≥ 1 %.
    #[serde(default)]
    pub shares: BTreeMap<String, f64>,
    /// `[Re, Im]` of the paired truth mode.
    #[serde(default)]
    pub truth: Option<[f64; 2]>,
    /// Name of the paired truth mode.
    #[serde(default)]
    pub truth_name: Option<String>,
    /// `100·|λ_id − λ_true| / |λ_true|`.
    #[serde(default)]
    pub error_percent: Option<f64>,
}

fn one_pole() -> usize {
    1
}

/// Shares below this are left out of a [`ModeRecord`].
const RECORDED_SHARE: f64 = 0.01;

impl ModeRecord {
    /// The record of `mode`, without truth.
    pub fn new(mode: &Mode, states: &[String]) -> ModeRecord {
        ModeRecord {
            name: mode.name.as_str().to_string(),
            eigenvalue: [mode.eigenvalue.re, mode.eigenvalue.im],
            omega_n: mode.natural_frequency(),
            zeta: mode.damping_ratio(),
            time_to_double_s: mode.time_to_double_s(),
            time_to_half_s: mode.time_to_half_s(),
            poles: mode.poles,
            shares: states
                .iter()
                .zip(&mode.shares)
                .filter(|(_, share)| **share >= RECORDED_SHARE)
                .map(|(state, share)| (state.clone(), *share))
                .collect(),
            truth: None,
            truth_name: None,
            error_percent: None,
        }
    }

    /// The eigenvalue as a complex number.
    pub fn lambda(&self) -> Complex64 {
        Complex64::new(self.eigenvalue[0], self.eigenvalue[1])
    }

    /// The largest shares, e.g. `w 79 %, r 21 %` (at most three, each ≥ 10 %).
    pub fn shape(&self) -> String {
        let mut shares: Vec<(&String, &f64)> = self.shares.iter().collect();
        shares.sort_by(|x, y| y.1.total_cmp(x.1).then(x.0.cmp(y.0)));
        shares
            .iter()
            .filter(|(_, share)| **share >= 0.1)
            .take(3)
            .map(|(state, share)| format!("{state} {:.0} %", 100.0 * **share))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The records of `model`'s modes (no truth).
pub fn mode_records(model: &Model) -> Result<Vec<ModeRecord>, ModeError> {
    Ok(modes(model)?
        .iter()
        .map(|mode| ModeRecord::new(mode, &model.states))
        .collect())
}

/// Poles of `records` at the origin (a pair counts 2).
pub fn poles_at_origin(records: &[ModeRecord]) -> usize {
    records
        .iter()
        .filter(|r| r.name == ModeName::Origin.as_str())
        .map(|r| r.poles)
        .sum()
}
