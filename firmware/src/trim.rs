//! Trim capture: the average pilot sticks and attitude every command is built on.
//!
//! Heading is averaged on the circle (mean of sin ψ and cos ψ, then atan2) so that a
//! heading hovering around ±π does not average to 0.

use sweephold_protocol::{Controls, Measurements};

/// The captured trim.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Trim {
    /// Averaged pilot sticks (lat, lon, ped, col).
    pub sticks: [f32; 4],
    /// Averaged roll attitude \[rad\].
    pub phi: f32,
    /// Averaged pitch attitude \[rad\].
    pub theta: f32,
    /// Circular mean of the heading \[rad\], in (−π, π].
    pub psi: f32,
}

/// Running sums of a trim capture, in `f64` so that averaging n equal samples gives that
/// sample back exactly and long captures at 1 kHz lose nothing. This is the one `f64` left
/// on the tick path (soft-float on the Cortex-M4: eight additions a tick, during the trim
/// capture only, ~1 s; the divisions happen once, in [`trim`](Self::trim)): an `f32` sum
/// would bias the trim every command is built on by up to n·ε.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrimAccumulator {
    sticks: [f64; 4],
    phi: f64,
    theta: f64,
    sin_psi: f64,
    cos_psi: f64,
    count: u32,
}

impl TrimAccumulator {
    /// Add one tick's sticks and attitude.
    pub fn add(&mut self, sticks: &Controls, meas: &Measurements) {
        for (sum, value) in self.sticks.iter_mut().zip(sticks.to_array()) {
            *sum += f64::from(value);
        }
        self.phi += f64::from(meas.phi);
        self.theta += f64::from(meas.theta);
        // The f32 sine of `turns` (libm's sinf/cosf are f64 inside): ~2e-7 error, far
        // below what a heading average needs.
        let (sin_psi, cos_psi) = crate::turns::sin_cos(meas.psi);
        self.sin_psi += f64::from(sin_psi);
        self.cos_psi += f64::from(cos_psi);
        self.count = self.count.saturating_add(1);
    }

    /// Samples added so far.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Average sticks so far; `None` before the first sample. Called every tick of the
    /// capture (the pilot-override check): the division is in `f32` (hardware) on the
    /// `f64` sum rounded to `f32`, within an `f32` rounding or two of the exact mean,
    /// plenty for a threshold check.
    pub fn mean_sticks(&self) -> Option<[f32; 4]> {
        if self.count == 0 {
            return None;
        }
        let n = self.count as f32;
        Some(self.sticks.map(|sum| sum as f32 / n))
    }

    /// The trim from the samples so far (all zero before the first sample).
    pub fn trim(&self) -> Trim {
        let n = f64::from(self.count.max(1));
        Trim {
            sticks: self.sticks.map(|sum| (sum / n) as f32),
            phi: (self.phi / n) as f32,
            theta: (self.theta / n) as f32,
            psi: libm::atan2(self.sin_psi, self.cos_psi) as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn averages_sticks_attitude_and_heading_across_pi() {
        let mut acc = TrimAccumulator::default();
        assert_eq!(acc.mean_sticks(), None);
        for (i, psi) in [3.1f32, -3.1, 3.1, -3.1].into_iter().enumerate() {
            let sticks = Controls::from_array([0.1 * i as f32, 0.2, -0.1, 0.5]);
            let meas = Measurements {
                phi: 0.01 * i as f32,
                theta: 0.04,
                psi,
                ..Measurements::default()
            };
            acc.add(&sticks, &meas);
        }
        let trim = acc.trim();
        assert_eq!(acc.count(), 4);
        assert!((trim.sticks[0] - 0.15).abs() < 1e-6);
        assert!((trim.sticks[3] - 0.5).abs() < 1e-6);
        assert!((trim.phi - 0.015).abs() < 1e-6);
        assert!((trim.theta - 0.04).abs() < 1e-6);
        assert!(
            (trim.psi.abs() - core::f32::consts::PI).abs() < 1e-3,
            "{}",
            trim.psi
        );
    }
}
