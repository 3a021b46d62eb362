//! The frequency-response document (`frf.json`): what `sweephold frf` writes and
//! `sweephold fit` reads. Its layout is part of the user interface (README, section
//! `frf.json`); change it only compatibly.

use serde::{Deserialize, Serialize};

/// Version of the `frf.json` layout.
pub const FRF_DOCUMENT_VERSION: u32 = 1;

/// One input → output frequency response on a frequency grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairResponse {
    /// Input (control) name: `lat`, `lon`, `ped`, `col`.
    pub input: String,
    /// Output name: `u v w p q r ax ay az phi theta`.
    pub output: String,
    /// Frequencies [rad/s], ascending.
    pub omega: Vec<f64>,
    /// Magnitude [dB] (20·log10|H|; output units per unit of stick fraction).
    pub mag_db: Vec<f64>,
    /// Phase [deg], unwrapped along frequency.
    pub phase_deg: Vec<f64>,
    /// Coherence γ² in [0, 1] (partial coherence for MISO-conditioned responses).
    pub coherence: Vec<f64>,
    /// Normalised random error εr = √(1−γ²)/(|γ|·√(2·n_d)).
    pub random_error: Vec<f64>,
    /// Frequency band [lo, hi] rad/s where coherence ≥ the threshold and, when
    /// `max_random_error` is set, the random error is at most that (the widest such run),
    /// or null.
    pub valid_range: Option<[f64; 2]>,
}

/// Average cross-control coherence between two controls for one record group.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossCoherence {
    /// Primary (swept) axis of the record group.
    pub axis: String,
    /// First control.
    pub a: String,
    /// Second control.
    pub b: String,
    /// Mean coherence between `a` and `b` over the sweep band.
    pub mean: f64,
}

/// The whole `frf.json` document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrfDocument {
    /// Layout version ([`FRF_DOCUMENT_VERSION`]).
    pub version: u32,
    /// Composite, MISO-conditioned responses: one per input/output pair.
    pub pairs: Vec<PairResponse>,
    /// Plain single-input (SISO) composite responses, same pairs, for comparison.
    pub siso: Vec<PairResponse>,
    /// Cross-control coherence per record group and control pair.
    pub cross_coherence: Vec<CrossCoherence>,
    /// Coherence threshold used for `valid_range`.
    pub coherence_threshold: f64,
    /// Largest random error a point of a `valid_range` may have, when one was set
    /// (`frf --max-random-error`); absent: the coherence alone decided.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_random_error: Option<f64>,
    /// Notes: controls left out of conditioning, ill-conditioned bands, etc.
    #[serde(default)]
    pub notes: Vec<String>,
}

impl FrfDocument {
    /// The conditioned response of one pair, if present.
    pub fn pair(&self, input: &str, output: &str) -> Option<&PairResponse> {
        self.pairs
            .iter()
            .find(|p| p.input == input && p.output == output)
    }
}
