//! What `tune` is asked for: the options of a design, and the loops it designs.

use crate::loops::Configuration;

/// How the gains are designed.
#[derive(Clone, Debug, PartialEq)]
pub struct TuneOptions {
    /// Stated rate-loop crossover per axis (roll, pitch, yaw) [rad/s]; `None`: the
    /// highest that meets the constraints up to the cap.
    pub crossovers: [Option<f64>; 3],
    /// Highest rate-loop crossover tried per axis [rad/s].
    pub crossover_caps: [f64; 3],
    /// Lowest rate-loop crossover tried [rad/s].
    pub lowest_crossover_rad_s: f64,
    /// Candidates per search.
    pub candidates: usize,
    /// Least phase margin \[deg\].
    pub min_phase_margin_deg: f64,
    /// Least gain margin \[dB\].
    pub min_gain_margin_db: f64,
    /// Percentile of the draws the margins must hold on \[%\].
    pub percentile: f64,
    /// The PI's zero as a fraction of the crossover: the candidates tried at each
    /// crossover.
    pub integral_fractions: Vec<f64>,
    /// Highest outer-loop gain as a fraction of the inner loop's crossover: ½ (the outer
    /// loops' own margins are checked, so it only bounds the search; with ⅓ the fbl700's
    /// pitch attitude loop, its rate loop held low by the servos' rate limit, kept the
    /// shipped crossover: decision 2026-11-27-outer-loop-cap).
    pub outer_fraction: f64,
    /// Models drawn over the covariance.
    pub samples: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Points of the analysis grid.
    pub grid_points: usize,
    /// Lowest frequency of the grid [rad/s].
    pub low_rad_s: f64,
    /// The servos' rate limit [stick/s] (`None`: not checked).
    pub servo_rate_limit_per_s: Option<f64>,
    /// The Rate-stick step of the servo-rate check (fraction of full stick).
    pub stick_step: f64,
}

impl Default for TuneOptions {
    fn default() -> Self {
        TuneOptions {
            crossovers: [None; 3],
            crossover_caps: [20.0, 20.0, 15.0],
            lowest_crossover_rad_s: 0.5,
            candidates: 40,
            min_phase_margin_deg: 45.0,
            min_gain_margin_db: 6.0,
            percentile: 5.0,
            integral_fractions: vec![0.2, 0.5, 1.0, 2.0, 4.0, 8.0],
            outer_fraction: 0.5,
            samples: 100,
            seed: 1,
            grid_points: 600,
            low_rad_s: 0.05,
            servo_rate_limit_per_s: None,
            stick_step: 1.0,
        }
    }
}

/// The six loops: name, configuration, axis.
pub const LOOPS: [(&str, Configuration, usize); 6] = crate::analysis::LOOP_NAMES;
