//! The broken-loop response of a feedback loop measured at an injection point: a signal d
//! added to the loop's output c at the point where the loop is broken, the total
//! u = c + d going on round the loop (the firmware's loop test, docs/formats.md,
//! "Loop tests").
//!
//! With the loop closed, u = d/(1 + L) and c = −L·d/(1 + L), so the broken loop is
//!
//! ```text
//! L(jω) = −C/U = −G_dc/G_du
//! ```
//!
//! the ratio of the two responses to the injection (the "three-point" method of flight
//! test, CIFER's and ArduPilot's broken-loop identification): d is the instrument, so the
//! noise that enters the loop elsewhere (sensors, gusts) is uncorrelated with it and
//! averages out of both cross-spectra, where c/u from G_uc/G_uu would be biased towards
//! −1/K by the feedback. Spectra are those of [`super::spectra`] (Hann windows of several
//! lengths, Chirp-Z). The coherence of the broken loop is the lower of the two responses'
//! coherences γ²_du and γ²_dc (L is as good as the worse of the two), each corrected for
//! its estimation bias ([`debiased_coherence`]), and per frequency the window length whose
//! estimate has the least random error ([`random_error`], which counts the independent
//! windows) is kept. Picking the highest raw coherence instead favoured the longest
//! windows' few averages, whose coherence is biased up: on a TREX 700L heading loop test
//! (board-sim, seed 4) a point at 61 rad/s read γ² 0.77 at −2.3 dB where its neighbours
//! read −16 dB, and gave a gain margin of 3.1 dB against 10.9 dB predicted.

use num_complex::Complex64;

use super::coherence::{debiased_coherence, random_error};
use super::error::FrfError;
use super::spectra::{compute_spectra, log_grid, lowest_resolved, window_lengths, SpectraSettings};

/// How [`broken_loop`] estimates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrokenLoopOptions {
    /// Log-spaced grid points over the band.
    pub points: usize,
    /// Window lengths (log-spaced, [`window_lengths`]).
    pub windows: usize,
    /// Window overlap fraction.
    pub overlap: f64,
    /// Chirp-Z points per resolution bin.
    pub oversampling: usize,
}

impl Default for BrokenLoopOptions {
    /// The frequency responses' defaults ([`super::FrfOptions`]): five windows, 80 %
    /// overlap, eight points per bin; 200 points.
    fn default() -> Self {
        BrokenLoopOptions {
            points: 200,
            windows: 5,
            overlap: 0.8,
            oversampling: 8,
        }
    }
}

/// A measured broken loop on a log grid.
#[derive(Clone, Debug, PartialEq)]
pub struct BrokenLoop {
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// L(jω) at each.
    pub values: Vec<Complex64>,
    /// Its coherence min(γ²_du, γ²_dc), bias-corrected, at each (0 where no window
    /// resolves it).
    pub coherence: Vec<f64>,
    /// The normalized random error of each value ([`random_error`] of its coherence and
    /// its window's independent averages; infinite where no window resolves it).
    pub random_error: Vec<f64>,
    /// The lowest frequency the estimate is free of the windows' resolution bias
    /// [rad/s]: [`RESOLVED_PERIODS`] times the lowest the longest window resolves.
    pub resolved_from_rad_s: f64,
}

/// How far above the longest window's lowest resolved frequency (4π/T, two periods per
/// window) the estimate is trusted. Below it the window holds a few periods only and its
/// Hann main lobe (±4π/T) spans a large part of the frequency, which biases the ratio of
/// two spectra that change fast there (a loop with an integrator: |L| ∝ 1/ω). Measured
/// on a known loop (`measured_loop`'s test, a 90 s sweep from 0.5 rad/s, windows up to
/// 50 s): −2.3 dB and −18° at 0.5 rad/s with γ² 0.99, within 0.2 dB and 2° from 5 times
/// 4π/T on; on the Bo-105's heading loop test the biased points made a −180° crossing at
/// 0.5 rad/s, 20 dB above 0 dB, that `margins` then picked as the gain margin.
pub const RESOLVED_PERIODS: f64 = 5.0;

/// The broken loop from the injection `injection` (d) and the total `total` (u = c + d)
/// sampled at `sample_rate_hz`, on `band` [rad/s] (see the module documentation).
pub fn broken_loop(
    injection: &[f64],
    total: &[f64],
    sample_rate_hz: f64,
    band: [f64; 2],
    options: &BrokenLoopOptions,
) -> Result<BrokenLoop, FrfError> {
    let [low, high] = band;
    if injection.len() != total.len() || injection.is_empty() {
        return Err(FrfError::InvalidOption(
            "injection and total must be equally long and not empty".into(),
        ));
    }
    if !(sample_rate_hz > 0.0 && low > 0.0 && high > low && high.is_finite()) {
        return Err(FrfError::InvalidOption(format!(
            "band {low}..{high} rad/s at {sample_rate_hz} Hz"
        )));
    }
    let own: Vec<f64> = total.iter().zip(injection).map(|(u, d)| u - d).collect();
    let duration_s = injection.len() as f64 / sample_rate_hz;
    let windows = window_lengths(duration_s, high, options.windows).ok_or_else(|| {
        FrfError::InvalidOption(format!(
            "a record of {duration_s:.1} s is too short for windows of ten periods of {high} rad/s"
        ))
    })?;
    let omega = log_grid(low, high, options.points.max(2));
    let spectra = compute_spectra(
        &[injection],
        &[total, &own],
        &omega,
        &windows,
        SpectraSettings {
            sample_rate_hz,
            overlap: options.overlap,
            oversampling: options.oversampling,
        },
    );
    let mut values = vec![Complex64::new(f64::NAN, f64::NAN); omega.len()];
    let mut coherence = vec![0.0; omega.len()];
    let mut least_error = vec![f64::INFINITY; omega.len()];
    for window in &spectra {
        if window.averaged == 0 {
            continue;
        }
        for k in window.valid_from..omega.len() {
            let gdd = window.input_input(k, 0, 0).re;
            let gdu = window.input_output(k, 0, 0);
            let gdc = window.input_output(k, 0, 1);
            let (guu, gcc) = (window.output_auto(k, 0), window.output_auto(k, 1));
            let gamma = |g: Complex64, auto: f64| {
                let denominator = gdd * auto;
                if denominator > 0.0 {
                    (g.norm_sqr() / denominator).min(1.0)
                } else {
                    0.0
                }
            };
            let raw = gamma(gdu, guu).min(gamma(gdc, gcc));
            let Some(gamma2) = debiased_coherence(raw, window.welch_averages) else {
                continue;
            };
            let error = random_error(gamma2, window.independent);
            if gdu.norm_sqr() > 0.0 && gamma2 > 0.0 && error < least_error[k] {
                least_error[k] = error;
                coherence[k] = gamma2;
                values[k] = -gdc / gdu;
            }
        }
    }
    let longest = windows.iter().copied().fold(0.0, f64::max);
    Ok(BrokenLoop {
        omega,
        values,
        coherence,
        random_error: least_error,
        resolved_from_rad_s: RESOLVED_PERIODS * lowest_resolved(longest),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frf::testing::Sweep;

    /// A static loop c = −k·u with a swept injection: L = k at every frequency, the
    /// coherence 1.
    #[test]
    fn a_static_loop_measures_its_gain() {
        let rate = 200.0;
        let sweep = Sweep {
            omega_min: 0.5,
            omega_max: 30.0,
            duration: 60.0,
            amplitude: 0.05,
        };
        let k = 2.5;
        let d: Vec<f64> = (0..12_000).map(|n| sweep.value(n as f64 / rate)).collect();
        let u: Vec<f64> = d.iter().map(|d| d / (1.0 + k)).collect();
        let measured =
            broken_loop(&d, &u, rate, [1.0, 25.0], &BrokenLoopOptions::default()).unwrap();
        for ((w, l), g) in measured
            .omega
            .iter()
            .zip(&measured.values)
            .zip(&measured.coherence)
        {
            assert!((l - Complex64::new(k, 0.0)).norm() < 1e-9, "{w}: {l}");
            assert!(*g > 0.999, "{w}: {g}");
        }
    }

    #[test]
    fn bad_inputs_are_refused() {
        let o = BrokenLoopOptions::default();
        assert!(broken_loop(&[], &[], 200.0, [1.0, 2.0], &o).is_err());
        assert!(broken_loop(&[0.0; 10], &[0.0; 9], 200.0, [1.0, 2.0], &o).is_err());
        assert!(broken_loop(&[0.0; 10], &[0.0; 10], 200.0, [2.0, 1.0], &o).is_err());
        assert!(broken_loop(&[0.0; 10], &[0.0; 10], 200.0, [1.0, 20.0], &o).is_err());
    }
}
