//! The frequency-response document (`frf.json`): what `sweephold frf` writes and
//! `sweephold fit` reads. Its layout is part of the user interface (docs/formats.md,
//! section `frf.json`); change it only compatibly.
//!
//! **Every reading is checked.** [`FrfDocument`] deserialises through
//! [`FrfDocument::validate`], so whichever reader parses a document (`fit`, `report`, a
//! campaign) gets one whose version is the supported one, whose per-pair arrays all have
//! one value per frequency, whose frequencies rise strictly from above zero, and whose
//! values are finite and plausible; otherwise the parse fails with a one-line message
//! naming the pair and the field (`frf.json: pair lat→p: mag_db has 199 values, omega
//! 200`). [`FrfDocument::from_json`] gives the same check without serde_json's position
//! suffix.

use serde::{Deserialize, Serialize};

/// Version of the `frf.json` layout.
pub const FRF_DOCUMENT_VERSION: u32 = 1;

/// Largest |magnitude| a response may have \[dB\]. 400 dB is a gain of 10²⁰: no
/// helicopter response (output units per stick fraction) comes near it, and a document
/// holding more was damaged or computed from a degenerate record. The bound also keeps
/// the fit's cost finite: its magnitude residuals are differences of dB values, squared.
pub const MAX_PLAUSIBLE_MAG_DB: f64 = 400.0;

/// Largest |phase| a response may have \[deg\], about 2800 turns. The unwrapped phase of a
/// 200-point response moves by at most 180° per point (36 000° in all); past this bound
/// the value is damage, and squared in the fit's cost it would no longer be finite
/// arithmetic worth trusting.
pub const MAX_PLAUSIBLE_PHASE_DEG: f64 = 1.0e6;

/// One input → output frequency response on a frequency grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairResponse {
    /// Input (control) name: `lat`, `lon`, `ped`, `col`.
    pub input: String,
    /// Output name: `u v w p q r ax ay az phi theta`.
    pub output: String,
    /// Frequencies [rad/s], ascending.
    pub omega: Vec<f64>,
    /// Magnitude \[dB\] (20·log10|H|; output units per unit of stick fraction).
    pub mag_db: Vec<f64>,
    /// Phase \[deg\], unwrapped along frequency.
    pub phase_deg: Vec<f64>,
    /// Coherence γ² in [0, 1] (partial coherence for MISO-conditioned responses: the
    /// share of the output, left after the other conditioning inputs, that this input
    /// explains).
    pub coherence: Vec<f64>,
    /// Normalised random error εr = √(1−γ²)/(|γ|·√(2·n_d)).
    pub random_error: Vec<f64>,
    /// Frequency band [lo, hi] rad/s where coherence ≥ the threshold and, when
    /// `max_random_error` is set, the random error is at most that (the widest such run),
    /// or null.
    pub valid_range: Option<[f64; 2]>,
    /// Swept axis of the record group this pair was computed from, written for every pair
    /// of a group whose responses to all its excited inputs were computed (`frf --excited
    /// all`, or CSV records whose swept input nothing named). Absent: the group that
    /// sweeps `input`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    /// Multiple coherence γ²_y:u of the output with all the conditioning inputs of the
    /// group, one per `omega` (composited with the same weights as the response): how
    /// much of the output the excited inputs explain together, where `coherence` is the
    /// share of this input alone. Written with `group` (MISO pairs only); empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub multiple_coherence: Vec<f64>,
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

/// The whole `frf.json` document. Deserialising it checks it ([`FrfDocument::validate`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "UncheckedFrfDocument")]
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

/// The document as parsed, before [`FrfDocument::validate`]; same layout.
#[derive(Deserialize)]
struct UncheckedFrfDocument {
    version: u32,
    pairs: Vec<PairResponse>,
    siso: Vec<PairResponse>,
    cross_coherence: Vec<CrossCoherence>,
    coherence_threshold: f64,
    #[serde(default)]
    max_random_error: Option<f64>,
    #[serde(default)]
    notes: Vec<String>,
}

impl TryFrom<UncheckedFrfDocument> for FrfDocument {
    type Error = InvalidFrfDocument;

    fn try_from(raw: UncheckedFrfDocument) -> Result<FrfDocument, InvalidFrfDocument> {
        let document = FrfDocument {
            version: raw.version,
            pairs: raw.pairs,
            siso: raw.siso,
            cross_coherence: raw.cross_coherence,
            coherence_threshold: raw.coherence_threshold,
            max_random_error: raw.max_random_error,
            notes: raw.notes,
        };
        document.validate()?;
        Ok(document)
    }
}

/// Why a frequency-response document was refused: one line, starting `frf.json:` and
/// naming the pair and field, e.g. `frf.json: pair lat→p: mag_db has 199 values, omega 200`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("frf.json: {0}")]
pub struct InvalidFrfDocument(pub String);

impl FrfDocument {
    /// The conditioned response of one pair, if present.
    pub fn pair(&self, input: &str, output: &str) -> Option<&PairResponse> {
        self.pairs
            .iter()
            .find(|p| p.input == input && p.output == output)
    }

    /// Parse and check a document ([`FrfDocument::validate`]); the error is one line.
    pub fn from_json(text: &str) -> Result<FrfDocument, InvalidFrfDocument> {
        let raw: UncheckedFrfDocument =
            serde_json::from_str(text).map_err(|e| InvalidFrfDocument(e.to_string()))?;
        FrfDocument::try_from(raw)
    }

    /// Check the document: the supported `version`; a coherence threshold in [0, 1] and a
    /// positive finite random-error bound; in `pairs` and `siso`, each (input, output)
    /// at most once, and per pair every array as long as `omega`, `omega` finite,
    /// positive and strictly increasing, `mag_db` within ±[`MAX_PLAUSIBLE_MAG_DB`],
    /// `phase_deg` within ±[`MAX_PLAUSIBLE_PHASE_DEG`], coherences in [0, 1], random
    /// errors finite and ≥ 0, and a `valid_range` inside `omega`; finite cross-control
    /// coherences. The first problem found is the error.
    pub fn validate(&self) -> Result<(), InvalidFrfDocument> {
        let bad = |message: String| Err(InvalidFrfDocument(message));
        if self.version != FRF_DOCUMENT_VERSION {
            return bad(format!(
                "version {}, but this build reads version {FRF_DOCUMENT_VERSION}",
                self.version
            ));
        }
        if !(0.0..=1.0).contains(&self.coherence_threshold) {
            return bad(format!(
                "coherence_threshold {} is not in [0, 1]",
                self.coherence_threshold
            ));
        }
        if let Some(bound) = self.max_random_error {
            if !(bound.is_finite() && bound > 0.0) {
                return bad(format!(
                    "max_random_error {bound} is not a finite value > 0"
                ));
            }
        }
        for (list, label) in [(&self.pairs, "pair"), (&self.siso, "siso pair")] {
            for (index, pair) in list.iter().enumerate() {
                let name = format!("{label} {}→{}", pair.input, pair.output);
                pair.validate()
                    .map_err(|m| InvalidFrfDocument(format!("{name}: {m}")))?;
                if list[..index]
                    .iter()
                    .any(|p| p.input == pair.input && p.output == pair.output)
                {
                    return bad(format!("{name} appears twice"));
                }
            }
        }
        for cc in &self.cross_coherence {
            if !cc.mean.is_finite() {
                return bad(format!(
                    "cross_coherence {}–{} ({} sweep): mean {} is not finite",
                    cc.a, cc.b, cc.axis, cc.mean
                ));
            }
        }
        Ok(())
    }
}

impl PairResponse {
    /// The checks of [`FrfDocument::validate`] for one pair; the message names the field.
    fn validate(&self) -> Result<(), String> {
        if self.input.is_empty() || self.output.is_empty() {
            return Err("empty input or output name".into());
        }
        let n = self.omega.len();
        let mut arrays: Vec<(&str, &[f64])> = vec![
            ("mag_db", &self.mag_db),
            ("phase_deg", &self.phase_deg),
            ("coherence", &self.coherence),
            ("random_error", &self.random_error),
        ];
        if !self.multiple_coherence.is_empty() {
            arrays.push(("multiple_coherence", &self.multiple_coherence));
        }
        for (field, values) in &arrays {
            if values.len() != n {
                return Err(format!("{field} has {} values, omega {n}", values.len()));
            }
        }
        for (k, &w) in self.omega.iter().enumerate() {
            if !(w.is_finite() && w > 0.0) {
                return Err(format!(
                    "omega[{k}] = {} is not a finite frequency > 0",
                    shown(w)
                ));
            }
            if k > 0 && w <= self.omega[k - 1] {
                return Err(format!(
                    "omega is not strictly increasing: omega[{k}] = {w} after {}",
                    self.omega[k - 1]
                ));
            }
        }
        // (field, lowest, highest, what a value outside means)
        let mut limits: Vec<(&str, &[f64], f64, f64, &str)> = vec![
            (
                "mag_db",
                &self.mag_db,
                -MAX_PLAUSIBLE_MAG_DB,
                MAX_PLAUSIBLE_MAG_DB,
                "not a plausible response magnitude",
            ),
            (
                "phase_deg",
                &self.phase_deg,
                -MAX_PLAUSIBLE_PHASE_DEG,
                MAX_PLAUSIBLE_PHASE_DEG,
                "not a plausible phase",
            ),
            ("coherence", &self.coherence, 0.0, 1.0, "not a coherence"),
            (
                "random_error",
                &self.random_error,
                0.0,
                f64::MAX,
                "not a random error",
            ),
        ];
        if !self.multiple_coherence.is_empty() {
            limits.push((
                "multiple_coherence",
                &self.multiple_coherence,
                0.0,
                1.0,
                "not a coherence",
            ));
        }
        for (field, values, lowest, highest, meaning) in limits {
            if let Some(k) = values
                .iter()
                .position(|v| !(v.is_finite() && (lowest..=highest).contains(v)))
            {
                let allowed = if highest == f64::MAX {
                    format!("≥ {lowest}")
                } else {
                    format!("{lowest}..{highest}")
                };
                return Err(format!(
                    "{field}[{k}] = {} at {} rad/s: {meaning} (allowed {allowed})",
                    shown(values[k]),
                    shown(self.omega[k])
                ));
            }
        }
        if let Some([lo, hi]) = self.valid_range {
            let inside = match (self.omega.first(), self.omega.last()) {
                // A grid computed from the band's ends may miss them by rounding.
                (Some(&first), Some(&last)) => {
                    let slack = 1e-9 * last.abs().max(1.0);
                    first - slack <= lo && lo <= hi && hi <= last + slack
                }
                _ => false,
            };
            if !inside {
                return Err(format!(
                    "valid_range [{lo}, {hi}] is not a band inside omega"
                ));
            }
        }
        Ok(())
    }
}

/// A number for a one-line message: huge values in exponent form, not 300 digits.
fn shown(value: f64) -> String {
    if value.is_finite() && value.abs() >= 1e6 {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(input: &str, output: &str) -> PairResponse {
        let omega: Vec<f64> = (1..=5).map(f64::from).collect();
        PairResponse {
            input: input.into(),
            output: output.into(),
            mag_db: vec![-3.0; 5],
            phase_deg: vec![-45.0; 5],
            coherence: vec![0.9; 5],
            random_error: vec![0.05; 5],
            valid_range: Some([1.0, 5.0]),
            group: None,
            multiple_coherence: Vec::new(),
            omega,
        }
    }

    fn document() -> FrfDocument {
        FrfDocument {
            version: FRF_DOCUMENT_VERSION,
            pairs: vec![pair("lat", "p"), pair("lon", "q")],
            siso: vec![pair("lat", "p"), pair("lon", "q")],
            cross_coherence: vec![CrossCoherence {
                axis: "lat".into(),
                a: "lat".into(),
                b: "lon".into(),
                mean: 0.2,
            }],
            coherence_threshold: 0.6,
            max_random_error: Some(0.15),
            notes: Vec::new(),
        }
    }

    /// The message of parsing `document` after `damage`, through serde (every reader's
    /// path) and through `from_json`; both must refuse it with the same one-line reason.
    fn refusal(damage: impl Fn(&mut FrfDocument)) -> String {
        let mut damaged = document();
        damage(&mut damaged);
        let json = serde_json::to_string(&damaged).unwrap();
        let via_serde = serde_json::from_str::<FrfDocument>(&json)
            .expect_err("serde accepted a bad document")
            .to_string();
        let message = FrfDocument::from_json(&json)
            .expect_err("from_json accepted a bad document")
            .to_string();
        assert!(via_serde.starts_with(&message), "{via_serde} vs {message}");
        assert!(!message.contains('\n'), "{message}");
        assert_eq!(damaged.validate().unwrap_err().to_string(), message);
        message
    }

    #[test]
    fn a_good_document_round_trips() {
        let json = serde_json::to_string_pretty(&document()).unwrap();
        assert_eq!(FrfDocument::from_json(&json).unwrap(), document());
        assert_eq!(
            serde_json::from_str::<FrfDocument>(&json).unwrap(),
            document()
        );
        // The fields of multi-input groups are absent unless set, and read back.
        assert!(!json.contains("group") && !json.contains("multiple_coherence"));
        let mut multi = document();
        multi.pairs[1].group = Some("lat".into());
        multi.pairs[1].multiple_coherence = vec![0.95; 5];
        let json = serde_json::to_string(&multi).unwrap();
        assert_eq!(FrfDocument::from_json(&json).unwrap(), multi);
    }

    #[test]
    fn another_version_is_refused() {
        let message = refusal(|d| d.version = 2);
        assert_eq!(
            message,
            "frf.json: version 2, but this build reads version 1"
        );
    }

    #[test]
    fn arrays_of_another_length_than_omega_are_refused() {
        let message = refusal(|d| {
            d.pairs[0].mag_db.pop();
        });
        assert_eq!(
            message,
            "frf.json: pair lat→p: mag_db has 4 values, omega 5"
        );
        for (field, expected) in [
            (0, "phase_deg has 6 values"),
            (1, "coherence has 6 values"),
            (2, "random_error has 6 values"),
        ] {
            let message = refusal(|d| {
                let p = &mut d.siso[1];
                [&mut p.phase_deg, &mut p.coherence, &mut p.random_error][field].push(0.5);
            });
            assert!(message.contains("siso pair lon→q: "), "{message}");
            assert!(message.contains(expected), "{message}");
        }
        let message = refusal(|d| d.pairs[1].multiple_coherence = vec![0.9; 3]);
        assert!(
            message.ends_with("pair lon→q: multiple_coherence has 3 values, omega 5"),
            "{message}"
        );
    }

    #[test]
    fn frequencies_must_rise_from_above_zero() {
        let message = refusal(|d| d.pairs[0].omega[3] = 3.0);
        assert!(
            message.contains("pair lat→p: omega is not strictly increasing: omega[3] = 3 after 3"),
            "{message}"
        );
        let message = refusal(|d| d.pairs[0].omega[0] = 0.0);
        assert!(
            message.contains("omega[0] = 0 is not a finite frequency > 0"),
            "{message}"
        );
        let message = refusal(|d| d.pairs[0].omega[0] = -1.0);
        assert!(message.contains("omega[0] = -1"), "{message}");
    }

    #[test]
    fn implausible_and_non_finite_values_are_refused() {
        // JSON has no NaN or infinity: a number too large for f64 is how an infinite
        // value arrives, and serde_json refuses it while parsing.
        let json = serde_json::to_string(&document())
            .unwrap()
            .replacen("-3.0", "-3e999", 1);
        assert!(FrfDocument::from_json(&json).is_err());
        let message = refusal(|d| d.pairs[1].mag_db[2] = 1.0e300);
        assert!(
            message.contains(
                "pair lon→q: mag_db[2] = 1e300 at 3 rad/s: not a plausible response magnitude"
            ),
            "{message}"
        );
        let message = refusal(|d| d.pairs[0].mag_db[0] = -401.0);
        assert!(message.contains("mag_db[0] = -401"), "{message}");
        let message = refusal(|d| d.siso[0].phase_deg[4] = 2.0e6);
        assert!(
            message.contains("siso pair lat→p: phase_deg[4]"),
            "{message}"
        );
        let message = refusal(|d| d.pairs[0].coherence[1] = 1.5);
        assert!(message.contains("coherence[1] = 1.5"), "{message}");
        let message = refusal(|d| d.pairs[0].random_error[1] = -0.1);
        assert!(message.contains("random_error[1] = -0.1"), "{message}");
        let message = refusal(|d| d.pairs[1].multiple_coherence = vec![0.9, 0.9, 1.2, 0.9, 0.9]);
        assert!(message.contains("multiple_coherence[2] = 1.2"), "{message}");
        // In memory (a document built by code, not parsed) NaN is caught as well.
        let mut in_memory = document();
        in_memory.pairs[0].phase_deg[2] = f64::NAN;
        let message = in_memory.validate().unwrap_err().to_string();
        assert!(
            message.contains("pair lat→p: phase_deg[2] = NaN"),
            "{message}"
        );
    }

    #[test]
    fn other_inconsistencies_are_refused() {
        let message = refusal(|d| d.pairs[0].valid_range = Some([0.5, 4.0]));
        assert!(
            message.contains("pair lat→p: valid_range [0.5, 4]"),
            "{message}"
        );
        let message = refusal(|d| d.pairs[1] = pair("lat", "p"));
        assert_eq!(message, "frf.json: pair lat→p appears twice");
        let message = refusal(|d| d.coherence_threshold = 1.5);
        assert!(message.contains("coherence_threshold 1.5"), "{message}");
        let message = refusal(|d| d.max_random_error = Some(0.0));
        assert!(message.contains("max_random_error 0"), "{message}");
        let message = refusal(|d| d.pairs[0].output = String::new());
        assert!(message.contains("empty input or output name"), "{message}");
    }
}
