//! What the report reads of the campaign's `margins.json` and `margins-loops.json`
//! (docs/formats.md): the loops' and sticks' figures, the charts' boundaries, and the
//! nominal loops sampled for the Bode plots.
//!
//! Read through these narrow types rather than `control::MarginsDocument`, whose names
//! are `&'static str` constants of the analysis and cannot be read back.

use control::analysis::{Figure, MARGINS_DOCUMENT_VERSION};
use nalgebra::Complex;
use serde::Deserialize;

/// One loop broken at its actuator input.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct LoopRow {
    /// `roll_rate`, …, `heading`.
    pub name: String,
    /// `lat`, `lon`, `ped`.
    pub broken_at: String,
    /// `rate` or `level`.
    pub mode: String,
    /// The highest gain crossover [rad/s].
    pub crossover_rad_s: Figure,
    /// Its phase margin \[deg\].
    pub phase_margin_deg: Figure,
    /// The least phase margin over the crossovers \[deg\].
    pub min_phase_margin_deg: Figure,
    /// Gain margin \[dB\].
    pub gain_margin_db: Figure,
    /// Its phase crossover [rad/s].
    pub phase_crossover_rad_s: Figure,
    /// Disturbance-rejection bandwidth [rad/s].
    pub drb_rad_s: Figure,
    /// Every gain crossover: [ω_c, PM].
    pub all_crossovers: Vec<[f64; 2]>,
}

/// One chart's boundaries.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct ChartRow {
    /// `tracking` or `other`.
    pub task: String,
    /// Level 1/2 boundary corners [ω, τ_p].
    pub level1: Vec<[f64; 2]>,
    /// Level 2/3 boundary corners.
    pub level2: Vec<[f64; 2]>,
}

/// ADS-33 figures of one stick.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct HandlingRow {
    /// `roll`, `pitch`, `yaw`.
    pub axis: String,
    /// `rate` or `level`.
    pub mode: String,
    /// ω_BW [rad/s].
    pub bandwidth_rad_s: Figure,
    /// τ_p \[s\].
    pub phase_delay_s: Figure,
    /// Level, target acquisition and tracking.
    pub level_tracking: Option<u8>,
    /// Level, all other MTEs.
    pub level_other: Option<u8>,
    /// The two charts (tracking, other).
    pub boundaries: Vec<ChartRow>,
}

/// The law the figures assume.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct LawRow {
    /// Control tick \[s\].
    pub tick_s: f64,
    /// Whether the IMU filter bank is in the loop.
    pub filter_bank: bool,
    /// Computation delay \[s\].
    pub compute_delay_s: f64,
    /// Servo frame rate \[Hz\].
    pub servo_frame_hz: Option<f64>,
}

/// `margins.json`, the parts the report shows.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct MarginsFile {
    /// Layout version: [`MARGINS_DOCUMENT_VERSION`] is read.
    pub version: u32,
    /// The model's structure.
    pub structure: String,
    /// The law.
    pub law: LawRow,
    /// Draws for the spreads.
    pub samples: usize,
    /// Their seed.
    pub seed: u64,
    /// Free parameters drawn.
    pub drawn_parameters: usize,
    /// Draws left out.
    pub failed_draws: usize,
    /// Why there is no spread.
    pub notes: Vec<String>,
    /// The six loops.
    pub loops: Vec<LoopRow>,
    /// The five sticks.
    pub handling: Vec<HandlingRow>,
    /// The loop tests measured beside the predictions (`margins --measured`, `identify`'s
    /// margins stage; absent otherwise).
    #[serde(default)]
    pub measured: Vec<MeasuredRow>,
}

/// One loop test's measured broken loop beside the predicted figures of the loop it breaks.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct MeasuredRow {
    /// The dump it came from (`FILE` or `FILE test N`).
    pub source: String,
    /// The predicted loop it breaks.
    pub name: String,
    /// Valid points of all.
    pub valid_points: usize,
    /// Grid points.
    pub points: usize,
    /// The lowest frequency the measurement uses [rad/s] (0 in documents written before
    /// it was recorded).
    #[serde(default)]
    pub resolved_from_rad_s: f64,
    /// Measured crossover [rad/s].
    pub crossover_rad_s: Option<f64>,
    /// Measured phase margin \[deg\].
    pub phase_margin_deg: Option<f64>,
    /// Measured gain margin \[dB\].
    pub gain_margin_db: Option<f64>,
    /// One standard deviation of the measured phase margin \[deg\].
    #[serde(default)]
    pub phase_margin_random_error_deg: Option<f64>,
    /// One standard deviation of the measured gain margin \[dB\].
    #[serde(default)]
    pub gain_margin_random_error_db: Option<f64>,
    /// The nominal predicted figures.
    pub predicted: PredictedRow,
    /// Measured − predicted gain margin \[dB\].
    pub gain_margin_difference_db: Option<f64>,
    /// Measured − predicted phase margin \[deg\].
    pub phase_margin_difference_deg: Option<f64>,
    /// The measured broken loop on its grid.
    pub response: MeasuredCurve,
}

/// A measured broken loop on its grid (`margins.json`'s `measured[].response`).
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
pub struct MeasuredCurve {
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// Real parts (null where no window resolves the point).
    pub re: Vec<Option<f64>>,
    /// Imaginary parts.
    pub im: Vec<Option<f64>>,
    /// Normalized random error of each point (null where no window resolves it).
    #[serde(default)]
    pub random_error: Vec<Option<f64>>,
}

impl MeasuredCurve {
    /// The points a measured loop's margins use ([`crate::measured_loop::is_valid_point`]:
    /// random error ≤ `max_random_error` at or above `resolved_from`; a point without a
    /// random error is left out); the others NaN, so that a line breaks there.
    pub fn valid_values(
        &self,
        max_random_error: f64,
        resolved_from: f64,
    ) -> Vec<(f64, Complex<f64>)> {
        self.omega
            .iter()
            .enumerate()
            .map(|(k, &w)| {
                let valid = self
                    .random_error
                    .get(k)
                    .copied()
                    .flatten()
                    .is_some_and(|e| {
                        crate::measured_loop::is_valid_point(w, e, resolved_from, max_random_error)
                    });
                let value = match (
                    self.re.get(k).copied().flatten(),
                    self.im.get(k).copied().flatten(),
                ) {
                    (Some(re), Some(im)) if valid => Complex::new(re, im),
                    _ => Complex::new(f64::NAN, f64::NAN),
                };
                (w, value)
            })
            .collect()
    }
}

/// The predicted figures a measured loop is compared with.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct PredictedRow {
    /// Crossover [rad/s].
    pub crossover_rad_s: Option<f64>,
    /// Phase margin \[deg\].
    pub phase_margin_deg: Option<f64>,
    /// Gain margin \[dB\].
    pub gain_margin_db: Option<f64>,
}

impl MarginsFile {
    /// Why the file cannot be shown, when its layout is not the one read here.
    pub fn check(&self) -> Result<(), String> {
        if self.version == MARGINS_DOCUMENT_VERSION {
            Ok(())
        } else {
            Err(format!(
                "layout version {} (this report reads {MARGINS_DOCUMENT_VERSION})",
                self.version
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Only the points of random error within the bound, at or above the resolved
    /// frequency, are drawn; the others, and those no window resolves, break the line.
    #[test]
    fn a_measured_curve_keeps_its_valid_points_only() {
        let curve = MeasuredCurve {
            omega: vec![1.0, 2.0, 3.0, 4.0],
            re: vec![None, Some(1.0), Some(2.0), Some(3.0)],
            im: vec![None, Some(0.5), Some(0.0), Some(-1.0)],
            random_error: vec![None, Some(0.1), Some(0.2), Some(0.15)],
        };
        let values = curve.valid_values(0.15, 0.0);
        assert_eq!(values.len(), 4);
        assert!(values[0].1.re.is_nan() && values[2].1.re.is_nan());
        assert_eq!(values[1], (2.0, Complex::new(1.0, 0.5)));
        assert_eq!(values[3], (4.0, Complex::new(3.0, -1.0)));
        // Below the frequency the windows resolve, a point is not drawn either.
        let values = curve.valid_values(0.15, 3.0);
        assert!(values[1].1.re.is_nan());
        assert_eq!(values[3], (4.0, Complex::new(3.0, -1.0)));
    }
}
