//! Cross-control coherence: how much the controls of a group move together (the
//! guideline is ≤ 0.5 between the swept control and each other one), per frequency and
//! as a mean over the band.

use crate::document::CrossCoherence;
use crate::frf::coherence::debiased_coherence;
use crate::frf::error::FrfError;
use crate::frf::groups::RecordGroup;
use crate::frf::options::FrfOptions;
use crate::frf::spectra::WindowSpectra;
use crate::records::Record;

use super::prepare::{prepare_group, spectra_of, PreparedGroup};

/// Coherence between two controls versus frequency, for one record group.
#[derive(Clone, Debug, PartialEq)]
pub struct CoherenceCurve {
    /// Primary axis of the group.
    pub axis: String,
    /// First control.
    pub a: String,
    /// Second control.
    pub b: String,
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// Composite coherence γ²_ab.
    pub coherence: Vec<f64>,
}

impl CoherenceCurve {
    /// Mean coherence over the curve's (log-spaced) points; 0 for an empty curve.
    pub fn mean(&self) -> f64 {
        if self.coherence.is_empty() {
            0.0
        } else {
            self.coherence.iter().sum::<f64>() / self.coherence.len() as f64
        }
    }
}

/// Mean cross-control coherence, over the sweep band, between the swept control of
/// `record` and each other control that is excited in it (the guideline is ≤ 0.5; the
/// paper's conditional attitude hold reaches 0.17).
///
/// The coherence of each control pair is computed with the same windows as the
/// responses ([`FrfOptions`]: band, windows, overlap, points); at each frequency the
/// bias-corrected estimates ([`debiased_coherence`]) of the windows spanning at least four
/// periods of it (at the bottom of the band, where none does, the longest window) are
/// averaged with weights equal to their equivalent numbers of independent averages
/// ([`welch_independent_averages`]), and the result is averaged over the log-spaced grid
/// points, i.e. evenly in log frequency. Four periods rather than the responses' two:
/// a control driven through delayed or lightly damped dynamics reads as partly unrelated
/// in windows only two periods long (see `a_control_driven_through_dynamics_reads_coherent`). Controls with no excitation
/// (RMS below `excitation_ratio` of the swept control's) have no defined coherence and
/// are left out of the result.
///
/// [`welch_independent_averages`]: crate::frf::spectra::welch_independent_averages
pub fn cross_control_coherence(
    record: &Record,
    opts: &FrfOptions,
) -> Result<Vec<CrossCoherence>, FrfError> {
    opts.validate()?;
    let group = RecordGroup::new(vec![record.clone()])?;
    let prepared = prepare_group(&group, opts, false)?;
    let primary = prepared.primary.clone();
    Ok(cross_control_curves(&prepared, opts)
        .into_iter()
        .filter(|curve| curve.a == primary || curve.b == primary)
        .map(|curve| {
            let other = if curve.a == primary {
                curve.b.clone()
            } else {
                curve.a.clone()
            };
            CrossCoherence {
                axis: primary.clone(),
                a: primary.clone(),
                b: other,
                mean: curve.mean(),
            }
        })
        .collect())
}

/// Cross-control coherence curves of a prepared group (inputs only).
fn cross_control_curves(prepared: &PreparedGroup, opts: &FrfOptions) -> Vec<CoherenceCurve> {
    let spectra = spectra_of(prepared, opts, false);
    curves_from_spectra(prepared, &spectra)
}

/// Composite coherence of every pair of excited controls, in the controls' record order.
pub(super) fn curves_from_spectra(
    prepared: &PreparedGroup,
    spectra: &[WindowSpectra],
) -> Vec<CoherenceCurve> {
    // Positions in the conditioning order, sorted by record order of the controls.
    let mut order: Vec<(usize, usize)> = prepared
        .conditioning
        .iter()
        .enumerate()
        .map(|(position, &input)| (input, position))
        .collect();
    order.sort_unstable();
    let mut curves = Vec::new();
    for (x, &(input_a, a)) in order.iter().enumerate() {
        for &(input_b, b) in &order[x + 1..] {
            let mut curve = CoherenceCurve {
                axis: prepared.primary.clone(),
                a: prepared.joined.inputs[input_a].name.clone(),
                b: prepared.joined.inputs[input_b].name.clone(),
                omega: Vec::new(),
                coherence: Vec::new(),
            };
            for (k, &omega) in prepared.grid.iter().enumerate() {
                // Bias-corrected coherence of the windows that span enough periods of ω
                // (`cross_coherence_windows`), weighted by their equivalent numbers of
                // independent averages. The response composite's 1/εr² weighting would
                // favour the long windows, whose few averages inflate coherence by
                // ~1/n_d: two unrelated controls would read ~0.4.
                let (mut sum, mut weight) = (0.0, 0.0);
                for s in cross_coherence_windows(spectra, k, omega) {
                    let (gaa, gbb) = (s.input_input(k, a, a).re, s.input_input(k, b, b).re);
                    if !(gaa > 0.0 && gbb > 0.0) {
                        continue;
                    }
                    let raw = s.input_input(k, a, b).norm_sqr() / (gaa * gbb);
                    if let Some(coherence) = debiased_coherence(raw, s.welch_averages) {
                        sum += s.welch_averages * coherence;
                        weight += s.welch_averages;
                    }
                }
                if weight > 0.0 && sum.is_finite() {
                    curve.omega.push(omega);
                    curve.coherence.push(sum / weight);
                }
            }
            if !curve.omega.is_empty() {
                curves.push(curve);
            }
        }
    }
    curves
}

/// Periods of ω a window must span to count towards the cross-control coherence at ω.
///
/// Two periods (the responses' resolution limit, [`lowest_resolved`]) are too few here.
/// A control that follows the swept one through dynamics with a delay or a lightly
/// damped mode is exactly coherent with it, but in a window only a couple of periods
/// long the chirp's frequency moves on within the window and the answer arrives late,
/// so such windows read it as partly unrelated (Carter's misalignment bias). With the
/// averages-weighted mean below, the shortest window that resolves ω dominates: a
/// noise-free second-order response (1 rad/s, ζ 0.3) of a 0.2–31.4 rad/s sweep read 0.77
/// from two periods on and 0.90 from four (`a_control_driven_through_dynamics_reads_coherent`),
/// while unrelated noise stays near zero either way.
///
/// [`lowest_resolved`]: crate::frf::spectra::lowest_resolved
const CROSS_COHERENCE_MIN_PERIODS: f64 = 4.0;

/// The windows that estimate the cross-control coherence at grid point `k` (frequency
/// `omega`): those spanning at least [`CROSS_COHERENCE_MIN_PERIODS`] periods; where
/// none does (the bottom of the band), the longest window that resolves ω at all.
fn cross_coherence_windows(spectra: &[WindowSpectra], k: usize, omega: f64) -> Vec<&WindowSpectra> {
    let resolving = spectra.iter().filter(|s| k >= s.valid_from);
    let periods = |s: &WindowSpectra| omega * s.seconds / std::f64::consts::TAU;
    let long_enough: Vec<&WindowSpectra> = resolving
        .clone()
        .filter(|s| periods(s) >= CROSS_COHERENCE_MIN_PERIODS)
        .collect();
    if long_enough.is_empty() {
        resolving
            .max_by(|a, b| a.seconds.total_cmp(&b.seconds))
            .into_iter()
            .collect()
    } else {
        long_enough
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frf::testing::{record, Block, Noise, Sweep};

    #[test]
    fn independent_and_dependent_controls() {
        let fs = 50.0;
        let sweep = Sweep {
            omega_min: 0.5,
            omega_max: 20.0,
            duration: 60.0,
            amplitude: 0.05,
        };
        let len = (60.0 * fs) as usize;
        let lat: Vec<f64> = (0..len).map(|k| sweep.value(k as f64 / fs)).collect();
        let mut noise = Noise::new(11);
        // lon: independent noise; ped: half the sweep plus a little noise; col: constant.
        let lon: Vec<f64> = (0..len).map(|_| 0.02 * noise.gaussian()).collect();
        let ped: Vec<f64> = lat
            .iter()
            .map(|v| 0.5 * v + 0.002 * noise.gaussian())
            .collect();
        let col = vec![0.3; len];
        let p: Vec<f64> = lat.iter().map(|v| 2.0 * v).collect();
        let rec = record(
            fs,
            [0.5, 20.0],
            vec![("lat", lat), ("lon", lon), ("ped", ped), ("col", col)],
            vec![("p", p)],
        );
        let result = cross_control_coherence(&rec, &FrfOptions::default()).unwrap();
        assert_eq!(result.len(), 2, "{result:?}");
        let lon = result.iter().find(|c| c.b == "lon").unwrap();
        let ped = result.iter().find(|c| c.b == "ped").unwrap();
        assert!(lon.mean < 0.3, "independent noise: {}", lon.mean);
        assert!(ped.mean > 0.9, "dependent control: {}", ped.mean);
        assert!(result.iter().all(|c| c.a == "lat" && c.axis == "lat"));
    }

    /// A control that follows the swept one through a lightly damped mode and nothing
    /// else is exactly coherent with it; the estimate must read it so (two periods per
    /// window gave 0.77 here), while unrelated noise stays near zero.
    #[test]
    fn a_control_driven_through_dynamics_reads_coherent() {
        let fs = 50.0;
        let sweep = Sweep {
            omega_min: 0.2,
            omega_max: 31.4,
            duration: 90.0,
            amplitude: 0.05,
        };
        let len = (95.0 * fs) as usize;
        let lat: Vec<f64> = (0..len).map(|k| sweep.value(k as f64 / fs)).collect();
        let lon = Block::second_order(1.0, 1.0, 0.3, 0.0).simulate(&|t| sweep.value(t), fs, len, 4);
        let mut noise = Noise::new(3);
        let ped: Vec<f64> = (0..len).map(|_| 0.02 * noise.gaussian()).collect();
        let p: Vec<f64> = lat.iter().map(|v| 2.0 * v).collect();
        let rec = record(
            fs,
            [0.2, 31.4],
            vec![("lat", lat), ("lon", lon), ("ped", ped)],
            vec![("p", p)],
        );
        let result = cross_control_coherence(&rec, &FrfOptions::default()).unwrap();
        let mean = |name: &str| result.iter().find(|c| c.b == name).unwrap().mean;
        assert!(
            mean("lon") > 0.85,
            "driven through dynamics: {}",
            mean("lon")
        );
        assert!(mean("ped") < 0.1, "unrelated noise: {}", mean("ped"));
    }
}
