//! Exact frequency-response documents computed from a known model, and a reference
//! parameter set for the shipped Bo-105 hybrid structure: test and benchmark data whose
//! right answer is known.

use super::cost::{log_spaced, PairBand};
use super::model::Model;
use crate::document::{FrfDocument, PairResponse, FRF_DOCUMENT_VERSION};

/// The shipped 9-DOF hybrid structure file (`models/bo105-9dof-hybrid.toml`, the text
/// `sysid::models` ships; read here directly, so that the fit does not depend on the
/// catalogue of shipped structures, which depends on it).
pub const BO105_HYBRID_STRUCTURE: &str = include_str!("../../models/bo105-9dof-hybrid.toml");
/// The shipped quasi-steady 6-DOF structure file (`models/bo105-6dof.toml`).
pub const BO105_SIX_DOF_STRUCTURE: &str = include_str!("../../models/bo105-6dof.toml");

/// Frequency ranges with acceptable coherence in the paper's Table 1 (Bo-105 hover):
/// (output, input, [lo, hi] rad/s). Pairs marked "None" there are absent.
pub const PAPER_TABLE1_RANGES: [(&str, &str, [f64; 2]); 29] = [
    ("p", "lat", [0.48, 31.4]),
    ("p", "lon", [0.93, 12.0]),
    ("p", "ped", [0.95, 10.0]),
    ("p", "col", [1.0, 10.0]),
    ("q", "lat", [1.19, 22.5]),
    ("q", "lon", [0.46, 31.4]),
    ("q", "ped", [0.59, 5.0]),
    ("r", "lat", [1.51, 23.0]),
    ("r", "lon", [1.41, 12.1]),
    ("r", "ped", [0.21, 31.4]),
    ("r", "col", [0.53, 31.4]),
    ("ax", "lat", [0.50, 12.0]),
    ("ax", "lon", [2.37, 31.4]),
    ("ax", "ped", [0.88, 4.02]),
    ("ax", "col", [0.38, 7.19]),
    ("ay", "lat", [0.71, 31.0]),
    ("ay", "lon", [0.58, 4.9]),
    ("ay", "ped", [0.21, 31.4]),
    ("ay", "col", [0.59, 3.46]),
    ("az", "ped", [0.21, 20.0]),
    ("az", "col", [0.21, 31.4]),
    ("u", "lon", [0.52, 5.41]),
    ("u", "ped", [0.93, 4.12]),
    ("u", "col", [1.25, 7.3]),
    ("v", "lat", [0.5, 31.4]),
    ("v", "lon", [0.94, 10.0]),
    ("v", "ped", [0.97, 31.4]),
    ("w", "ped", [0.21, 20.0]),
    ("w", "col", [0.21, 31.4]),
];

/// The pairs a default Bo-105 campaign fits (`sweephold fly` + `frf`, seed 1): the others
/// of Table 1 carry no coherent response there, and the hybrid barely couples them (w/ped,
/// az/ped, …), so exact data for them is near zero and its dB meaningless.
pub const CAMPAIGN_FITTED_PAIRS: [(&str, &str); 16] = [
    ("p", "lat"),
    ("p", "lon"),
    ("p", "ped"),
    ("q", "lat"),
    ("q", "lon"),
    ("r", "lat"),
    ("r", "ped"),
    ("r", "col"),
    ("ax", "lon"),
    ("ax", "col"),
    ("ay", "lat"),
    ("ay", "ped"),
    ("az", "col"),
    ("u", "lon"),
    ("v", "lon"),
    ("w", "col"),
];

/// The Table 1 range of a pair, if the paper lists one.
pub fn paper_table1_range(output: &str, input: &str) -> Option<[f64; 2]> {
    PAPER_TABLE1_RANGES
        .iter()
        .find(|(o, i, _)| *o == output && *i == input)
        .map(|(_, _, range)| *range)
}

/// A Bo-105 hover parameter set for `bo105-9dof-hybrid.toml`: the simulator's (`host/rotorsim`)
/// linearization at hover mapped onto the structure (`sweephold fit --truth bo105` prints
/// the same values; a test in `host/cli/src/truth.rs` keeps them within 0.1 % of that
/// mapping), rounded to five significant figures. It is the "truth" of synthetic tests and
/// of the fit benchmark; the delays are the servos' equivalent delay.
pub const BO105_HYBRID_REFERENCE: [(&str, f64); 39] = [
    ("tau_f", 0.069562),
    ("Kcs", 0.066254),
    ("Mfu", 0.0020702),
    ("Lfu", 0.0027085),
    ("Nb1s", 35.533),
    ("Xu", -0.00021145),
    ("Lv", -0.021672),
    ("Mu", 0.00011646),
    ("Nv", 0.051167),
    ("Xw", 0.011336),
    ("Xr", -0.00011171),
    ("Xb1c", -10.23),
    ("Yv", -0.017162),
    ("Yp", -0.029525),
    ("Yr", 0.10455),
    ("Zw", -0.31908),
    ("Zr", 0.0002821),
    ("Lr", 0.16078),
    ("Lb1s", 204.62),
    ("Mv", 1.6678e-05),
    ("Mb1c", 54.346),
    ("Np", 0.088136),
    ("Nr", -0.30518),
    ("Xcol", 0.57218),
    ("Yped", -1.455),
    ("Zcol", -14.562),
    ("Lcol", 0.7802),
    ("Mcol", -0.89022),
    ("Lped", -1.819),
    ("Ncol", 3.0999),
    ("Nped", 4.3927),
    ("Mf_lat", 0.037649),
    ("Mf_lon", 0.14847),
    ("Lf_lat", 0.11891),
    ("Lf_lon", -0.047115),
    ("tau_lat", 0.023333),
    ("tau_lon", 0.023333),
    ("tau_ped", 0.023333),
    ("tau_col", 0.023333),
];

/// Unwrap a phase sequence [deg] along frequency (jumps over 180° are 360° wraps).
fn unwrap_degrees(phases: &mut [f64]) {
    for k in 1..phases.len() {
        let jump = phases[k] - phases[k - 1];
        phases[k] -= 360.0 * (jump / 360.0).round();
    }
}

/// Where the frequencies of a synthetic document lie.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SyntheticGrid {
    /// The same `n` log-spaced frequencies over [lo, hi] rad/s for every pair.
    Span {
        /// Lowest frequency.
        lo: f64,
        /// Highest frequency.
        hi: f64,
        /// Number of frequencies.
        n: usize,
    },
    /// `n` log-spaced frequencies over each pair's own range: with `n` equal to the fit's
    /// points per pair, the data sit exactly on the fit frequencies (no interpolation).
    FitPoints(usize),
}

/// An `FrfDocument` holding the exact responses of `model` for each band, coherence 1,
/// random error 0, and the band's range as `valid_range`. Bands naming unknown
/// controls/outputs are skipped.
pub fn exact_frf_document(model: &Model, bands: &[PairBand], grid: SyntheticGrid) -> FrfDocument {
    let pairs = bands
        .iter()
        .filter_map(|band| {
            let input = model.control_index(&band.input)?;
            let output = model.output_index(&band.output)?;
            let omega = match grid {
                SyntheticGrid::Span { lo, hi, n } => log_spaced(lo, hi, n.max(2)),
                SyntheticGrid::FitPoints(n) => log_spaced(band.range[0], band.range[1], n.max(2)),
            };
            let responses: Vec<_> = omega
                .iter()
                .map(|&w| model.frequency_response(input, output, w))
                .collect();
            let mut phase_deg: Vec<f64> = responses
                .iter()
                .map(|t| t.im.atan2(t.re).to_degrees())
                .collect();
            unwrap_degrees(&mut phase_deg);
            Some(PairResponse {
                input: band.input.clone(),
                output: band.output.clone(),
                mag_db: responses.iter().map(|t| 20.0 * t.norm().log10()).collect(),
                phase_deg,
                coherence: vec![1.0; omega.len()],
                random_error: vec![0.0; omega.len()],
                omega,
                valid_range: Some(band.range),
                group: None,
                multiple_coherence: Vec::new(),
            })
        })
        .collect();
    FrfDocument {
        version: FRF_DOCUMENT_VERSION,
        pairs,
        siso: Vec::new(),
        cross_coherence: Vec::new(),
        coherence_threshold: 0.6,
        max_random_error: None,
        notes: vec!["synthetic: exact responses of a known model".into()],
    }
}

/// Table 1 bands for every (output, input) listed there.
pub fn paper_table1_bands() -> Vec<PairBand> {
    PAPER_TABLE1_RANGES
        .iter()
        .map(|(output, input, range)| PairBand {
            input: input.to_string(),
            output: output.to_string(),
            range: *range,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::structure::ModelStructure;

    #[test]
    fn shipped_structures_parse_and_reference_covers_the_hybrid() {
        let hybrid =
            ModelStructure::parse(BO105_HYBRID_STRUCTURE, "bo105-9dof-hybrid.toml").unwrap();
        assert_eq!(hybrid.states.len(), 10);
        assert_eq!(hybrid.pairs.len(), 29);
        for parameter in &hybrid.parameters {
            assert!(
                BO105_HYBRID_REFERENCE
                    .iter()
                    .any(|(n, _)| *n == parameter.name),
                "{} has no reference value",
                parameter.name
            );
        }
        assert_eq!(hybrid.parameters.len(), BO105_HYBRID_REFERENCE.len());
        for pair in &hybrid.pairs {
            assert!(paper_table1_range(&pair.output, &pair.input).is_some());
        }
        let six = ModelStructure::parse(BO105_SIX_DOF_STRUCTURE, "bo105-6dof.toml").unwrap();
        assert_eq!(six.states.len(), 8);
        assert_eq!(six.pairs.len(), 29);
        assert_eq!(six.auto_range_limit, Some([0.05, 12.0]));
    }

    #[test]
    fn exact_document_reproduces_the_model() {
        let hybrid = ModelStructure::parse(BO105_HYBRID_STRUCTURE, "hybrid").unwrap();
        let model = hybrid.model(&hybrid.values()).unwrap();
        let document = exact_frf_document(
            &model,
            &paper_table1_bands(),
            SyntheticGrid::Span {
                lo: 0.1,
                hi: 40.0,
                n: 50,
            },
        );
        assert_eq!(document.pairs.len(), 29);
        let pair = document.pair("lat", "p").unwrap();
        let t = model.frequency_response(0, 3, pair.omega[10]);
        assert!((pair.mag_db[10] - 20.0 * t.norm().log10()).abs() < 1e-12);
        // Unwrapped: no jump over 180° between neighbours.
        for pair in &document.pairs {
            assert!(pair
                .phase_deg
                .windows(2)
                .all(|w| (w[1] - w[0]).abs() < 180.0));
        }
    }
}
