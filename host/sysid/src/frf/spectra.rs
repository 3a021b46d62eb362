//! Windowed auto- and cross-spectra on a log-spaced frequency grid (CIFER FRESPID).
//!
//! **Window lengths.** CIFER averages spectra over several window lengths. The shortest
//! window holds ten periods of the highest grid frequency, `T_min = 20π/ω_hi`, which
//! keeps the leakage of the Hann taper small there while giving many averages (low
//! random error) at high frequency. The longest is half the record, `T_max = T_rec/2`,
//! so that at least two windows (and, with 80 % overlap, six) are averaged. Lengths in
//! between are log-spaced. A window of length T resolves frequencies down to about
//! `4π/T` (two periods per window): below that the Hann main lobe (±4π/T wide) spans
//! DC. Each window length therefore contributes only at grid frequencies ≥ 4π/T.
//!
//! **Independent windows.** The random error uses `n_d = T_rec/T` — the number of
//! non-overlapping windows that fit the record — not the count of overlapped windows:
//! overlapped Hann windows are strongly correlated, and this conservative count does not
//! overstate the accuracy.
//!
//! **Transforms.** Each window of each channel is mean-removed, Hann-tapered
//! (`w_n = sin²(π(n + ½)/N)`) and transformed once with the Chirp-Z transform onto a
//! *linear* grid from the lowest resolved grid frequency to ω_hi with spacing
//! `δ = 2π/(os·T)` (`os` points per resolution bin, default 8). All auto- and
//! cross-spectra `G_ab = Σ_windows X_a*·X_b` are formed from those transforms (never per
//! pair). A Chirp-Z transform evaluates on an arithmetic progression of frequencies, not
//! a geometric one, so the averaged spectra are then interpolated linearly onto the log
//! grid. They are smooth on the scale of the Hann resolution (main lobe 8 bins of δ at
//! os = 8), where linear interpolation errs by well under 1 % and in the same direction
//! for numerator and denominator of a response.
//!
//! Spectra are left unscaled (no 2/(fs·Σw²) factor): everything reported — responses,
//! coherences — is a ratio of spectra.

use num_complex::Complex64;
use rustfft::FftPlanner;

use super::chirp_z::{separate_pair, ChirpZ};

/// `points` frequencies log-spaced from `lo` to `hi` inclusive.
pub fn log_grid(lo: f64, hi: f64, points: usize) -> Vec<f64> {
    if points < 2 {
        return vec![lo];
    }
    let ratio = (hi / lo).ln() / (points - 1) as f64;
    (0..points)
        .map(|k| {
            if k + 1 == points {
                hi
            } else {
                lo * (ratio * k as f64).exp()
            }
        })
        .collect()
}

/// Window lengths \[s\]: `count` lengths log-spaced from `20π/omega_hi` to
/// `duration_s/2` (module docs). `None` when the record is shorter than two of the
/// shortest windows.
pub fn window_lengths(duration_s: f64, omega_hi: f64, count: usize) -> Option<Vec<f64>> {
    let shortest = 20.0 * std::f64::consts::PI / omega_hi;
    let longest = duration_s / 2.0;
    if longest < shortest || count == 0 {
        return None;
    }
    if count == 1 {
        return Some(vec![longest]);
    }
    let ratio = (longest / shortest).ln() / (count - 1) as f64;
    Some(
        (0..count)
            .map(|i| shortest * (ratio * i as f64).exp())
            .collect(),
    )
}

/// Lowest frequency [rad/s] a window of `seconds` resolves: two periods per window.
pub fn lowest_resolved(seconds: f64) -> f64 {
    4.0 * std::f64::consts::PI / seconds
}

/// Spectral matrices of one window length on the log grid.
///
/// Entries exist for grid indices `valid_from..`; `uu`, `uy` and `yy` are indexed by
/// `k − valid_from`. Input index `i`, output index `o`:
/// `uu[(k·n_in + i)·n_in + j] = G_{u_i u_j}`, `uy[(k·n_in + i)·n_out + o] = G_{u_i y_o}`,
/// `yy[k·n_out + o] = G_{y_o y_o}` with `G_ab = Σ X_a*·X_b`.
#[derive(Clone, Debug)]
pub struct WindowSpectra {
    /// Window length \[s\].
    pub seconds: f64,
    /// Window length \[samples\].
    pub samples: usize,
    /// Number of overlapped windows averaged.
    pub averaged: usize,
    /// Independent windows n_d = T_rec/T (CIFER's count, used for the random error).
    pub independent: f64,
    /// Equivalent number of independent averages of the overlapped Hann windows
    /// (Welch 1967), used to correct the bias of coherence estimates.
    pub welch_averages: f64,
    /// First grid index this window resolves.
    pub valid_from: usize,
    /// Number of inputs.
    pub n_in: usize,
    /// Number of outputs.
    pub n_out: usize,
    /// Input cross-spectral matrices (full, Hermitian).
    pub uu: Vec<Complex64>,
    /// Input–output cross-spectra.
    pub uy: Vec<Complex64>,
    /// Output autospectra.
    pub yy: Vec<f64>,
}

impl WindowSpectra {
    /// G_{u_i u_j} at grid index k (k ≥ valid_from).
    pub fn input_input(&self, k: usize, i: usize, j: usize) -> Complex64 {
        self.uu[((k - self.valid_from) * self.n_in + i) * self.n_in + j]
    }

    /// G_{u_i y_o} at grid index k.
    pub fn input_output(&self, k: usize, i: usize, o: usize) -> Complex64 {
        self.uy[((k - self.valid_from) * self.n_in + i) * self.n_out + o]
    }

    /// G_{y_o y_o} at grid index k.
    pub fn output_auto(&self, k: usize, o: usize) -> f64 {
        self.yy[(k - self.valid_from) * self.n_out + o]
    }
}

/// Settings of [`compute_spectra`].
#[derive(Clone, Copy, Debug)]
pub struct SpectraSettings {
    /// Sample rate \[Hz\].
    pub sample_rate_hz: f64,
    /// Window overlap fraction.
    pub overlap: f64,
    /// Chirp-Z points per resolution bin.
    pub oversampling: usize,
}

/// Spectra of `inputs` and `outputs` (equal lengths) on `grid` [rad/s] for each window
/// length in `window_seconds`.
pub fn compute_spectra(
    inputs: &[&[f64]],
    outputs: &[&[f64]],
    grid: &[f64],
    window_seconds: &[f64],
    settings: SpectraSettings,
) -> Vec<WindowSpectra> {
    let mut planner = FftPlanner::new();
    window_seconds
        .iter()
        .map(|&seconds| one_window_length(inputs, outputs, grid, seconds, settings, &mut planner))
        .collect()
}

fn one_window_length(
    inputs: &[&[f64]],
    outputs: &[&[f64]],
    grid: &[f64],
    seconds: f64,
    settings: SpectraSettings,
    planner: &mut FftPlanner<f64>,
) -> WindowSpectra {
    let fs = settings.sample_rate_hz;
    let total = inputs.first().or(outputs.first()).map_or(0, |c| c.len());
    let (n_in, n_out) = (inputs.len(), outputs.len());
    let samples = ((seconds * fs).round() as usize).clamp(2, total.max(2));
    let seconds = samples as f64 / fs;
    let lowest = lowest_resolved(seconds) * (1.0 - 1e-9);
    let valid_from = grid.iter().position(|&w| w >= lowest).unwrap_or(grid.len());
    let mut spectra = WindowSpectra {
        seconds,
        samples,
        averaged: 0,
        independent: total as f64 / samples as f64,
        welch_averages: 0.0,
        valid_from,
        n_in,
        n_out,
        uu: Vec::new(),
        uy: Vec::new(),
        yy: Vec::new(),
    };
    if valid_from >= grid.len() || total < samples {
        return spectra;
    }

    // The linear grid ω_k = (k0 + k)·δ, k = 0..m−1, covers grid[valid_from..]. It sits on
    // multiples of δ so that its mirror image −ω_k is on the Chirp-Z grid too: the
    // transform runs over −(k0+m−1)δ..(k0+m−1)δ and carries two real channels at once
    // (real part and imaginary part), separated with Z(−ω) (`separate_pair`).
    let hi = grid[grid.len() - 1];
    let step = std::f64::consts::TAU / (settings.oversampling as f64 * seconds);
    let k0 = (grid[valid_from] / step).floor() as usize;
    let lo = k0 as f64 * step;
    let m = ((hi - lo) / step).ceil() as usize + 2;
    let top = k0 + m - 1; // ω = top·δ is the highest point
    let full = 2 * top + 1; // −top·δ ..= top·δ
    let mut czt = ChirpZ::new(samples, full, -(top as f64) * step / fs, step / fs, planner);

    let hann: Vec<f64> = (0..samples)
        .map(|n| {
            let s = (std::f64::consts::PI * (n as f64 + 0.5) / samples as f64).sin();
            s * s
        })
        .collect();
    let hop = ((samples as f64 * (1.0 - settings.overlap)).round() as usize).max(1);

    // All channels, inputs first, with running sums for the window means.
    let channels: Vec<&[f64]> = inputs.iter().chain(outputs).copied().collect();
    let sums: Vec<Vec<f64>> = channels
        .iter()
        .map(|x| {
            let mut sums = Vec::with_capacity(x.len() + 1);
            let mut acc = 0.0;
            sums.push(0.0);
            for &v in x.iter() {
                acc += v;
                sums.push(acc);
            }
            sums
        })
        .collect();

    let zero = Complex64::new(0.0, 0.0);
    let mut transformed = vec![vec![zero; m]; channels.len()];
    let mut packed = vec![zero; full];
    // Upper triangle of the input matrix, input×output, output autos: on the linear grid.
    let mut acc_uu = vec![vec![zero; m]; n_in * n_in];
    let mut acc_uy = vec![vec![zero; m]; n_in * n_out];
    let mut acc_yy = vec![vec![0.0f64; m]; n_out];

    let mut start = 0;
    while start + samples <= total {
        let end = start + samples;
        let mean = |c: usize| (sums[c][end] - sums[c][start]) / samples as f64;
        for first in (0..channels.len()).step_by(2) {
            let second = (first + 1).min(channels.len() - 1);
            czt.transform_real_pair(
                &channels[first][start..end],
                &channels[second][start..end],
                &hann,
                (mean(first), mean(second)),
                &mut packed,
            );
            // +ω_k is at index top + k0 + k, −ω_k at top − k0 − k.
            let (head, tail) = transformed.split_at_mut(first + 1);
            let out_a = &mut head[first];
            let mut out_b = tail.first_mut();
            for k in 0..m {
                let (a, b) = separate_pair(packed[top + k0 + k], packed[top - k0 - k]);
                out_a[k] = a;
                if let Some(out_b) = out_b.as_mut() {
                    out_b[k] = b;
                }
            }
        }
        let (x_in, x_out) = transformed.split_at(n_in);
        for i in 0..n_in {
            for j in i..n_in {
                accumulate_cross(&mut acc_uu[i * n_in + j], &x_in[i], &x_in[j]);
            }
            for o in 0..n_out {
                accumulate_cross(&mut acc_uy[i * n_out + o], &x_in[i], &x_out[o]);
            }
        }
        for o in 0..n_out {
            for (acc, y) in acc_yy[o].iter_mut().zip(&x_out[o]) {
                *acc += y.norm_sqr();
            }
        }
        spectra.averaged += 1;
        start += hop;
    }
    spectra.welch_averages = welch_independent_averages(&hann, hop, spectra.averaged);

    // Interpolate onto the log grid.
    let points = grid.len() - valid_from;
    spectra.uu = vec![zero; points * n_in * n_in];
    spectra.uy = vec![zero; points * n_in * n_out];
    spectra.yy = vec![0.0; points * n_out];
    for (p, &omega) in grid[valid_from..].iter().enumerate() {
        let position = ((omega - lo) / step).max(0.0);
        let below = (position.floor() as usize).min(m - 2);
        let t = position - below as f64;
        let lerp = |v: &[Complex64]| v[below] * (1.0 - t) + v[below + 1] * t;
        for i in 0..n_in {
            for j in i..n_in {
                let g = lerp(&acc_uu[i * n_in + j]);
                spectra.uu[(p * n_in + i) * n_in + j] = g;
                spectra.uu[(p * n_in + j) * n_in + i] = g.conj();
            }
            for o in 0..n_out {
                spectra.uy[(p * n_in + i) * n_out + o] = lerp(&acc_uy[i * n_out + o]);
            }
        }
        for (o, v) in acc_yy.iter().enumerate() {
            spectra.yy[p * n_out + o] = v[below] * (1.0 - t) + v[below + 1] * t;
        }
        // The diagonal of a Hermitian matrix is real: drop interpolation round-off.
        for i in 0..n_in {
            let d = &mut spectra.uu[(p * n_in + i) * n_in + i];
            *d = Complex64::new(d.re, 0.0);
        }
    }
    spectra
}

/// Equivalent number of independent averages of a Welch estimate: `segments` windows
/// `window` long, each moved by `hop` samples (Welch 1967, Eq. 17):
///
/// ```text
/// n_eq = K / (1 + 2 Σ_{j=1}^{K−1} (1 − j/K) ρ(j)²),   ρ(j) = Σ_i w_i w_{i+jH} / Σ_i w_i²
/// ```
///
/// For a Hann window at 50 % overlap ρ(1) = 1/6 (so n_eq ≈ 0.95·K); at 80 % overlap
/// neighbouring windows share most of their data and n_eq ≈ 0.42·K.
pub fn welch_independent_averages(window: &[f64], hop: usize, segments: usize) -> f64 {
    let energy: f64 = window.iter().map(|w| w * w).sum();
    if segments == 0 || energy <= 0.0 || hop == 0 {
        return segments as f64;
    }
    let k = segments as f64;
    let mut correlation = 0.0;
    for j in 1..segments {
        let shift = j * hop;
        if shift >= window.len() {
            break;
        }
        let overlap: f64 = window
            .iter()
            .zip(&window[shift..])
            .map(|(a, b)| a * b)
            .sum();
        let rho = overlap / energy;
        correlation += (1.0 - j as f64 / k) * rho * rho;
    }
    k / (1.0 + 2.0 * correlation)
}

/// acc_k += a_k*·b_k
fn accumulate_cross(acc: &mut [Complex64], a: &[Complex64], b: &[Complex64]) {
    for ((acc, a), b) in acc.iter_mut().zip(a).zip(b) {
        // Written out so the compiler keeps it to four multiplies and adds per point.
        acc.re += a.re * b.re + a.im * b.im;
        acc.im += a.re * b.im - a.im * b.re;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_grid_spans_the_band_geometrically() {
        let grid = log_grid(0.3, 31.4, 200);
        assert_eq!(grid.len(), 200);
        assert!((grid[0] - 0.3).abs() < 1e-15 && grid[199] == 31.4);
        let r0 = grid[1] / grid[0];
        for pair in grid.windows(2) {
            assert!((pair[1] / pair[0] - r0).abs() < 1e-9);
        }
    }

    #[test]
    fn window_lengths_follow_the_rule() {
        let lengths = window_lengths(180.0, 31.4, 5).unwrap();
        assert!((lengths[0] - 20.0 * std::f64::consts::PI / 31.4).abs() < 1e-12);
        assert!((lengths[4] - 90.0).abs() < 1e-9);
        assert!(lengths.windows(2).all(|w| w[1] > w[0]));
        assert!(window_lengths(3.0, 31.4, 5).is_none());
    }

    /// H and coherence of `y` per `x` from the given spectra at grid index k.
    fn h1(s: &WindowSpectra, k: usize) -> (Complex64, f64) {
        let gxx = s.input_input(k, 0, 0).re;
        let gxy = s.input_output(k, 0, 0);
        (gxy / gxx, gxy.norm_sqr() / (gxx * s.output_auto(k, 0)))
    }

    #[test]
    fn a_pure_gain_and_a_delay_are_recovered() {
        // y_n = 2·x_{n−d} for a broadband x: H = 2·e^{−iωdΔt}, coherence 1 for d = 0.
        // A delay misaligns the taper on x and y by d samples, which acts like a little
        // noise (≈ d·π/N relative): hence the looser tolerance.
        let fs = 100.0;
        let mut noise = super::super::testing::Noise::new(3);
        let x: Vec<f64> = (0..4000).map(|_| noise.gaussian()).collect();
        let grid = log_grid(2.0, 100.0, 40);
        let settings = SpectraSettings {
            sample_rate_hz: fs,
            overlap: 0.5,
            oversampling: 8,
        };
        for (delay, tolerance, min_coherence) in [(0usize, 1e-9, 1.0 - 1e-9), (3, 0.05, 0.99)] {
            let y: Vec<f64> = (0..4000)
                .map(|n| if n >= delay { 2.0 * x[n - delay] } else { 0.0 })
                .collect();
            let spectra = compute_spectra(&[&x], &[&y], &grid, &[4.0, 10.0], settings);
            for s in &spectra {
                assert!(s.averaged >= 3);
                for (k, &omega) in grid.iter().enumerate().skip(s.valid_from) {
                    let (h, coherence) = h1(s, k);
                    let expected = Complex64::from_polar(2.0, -(delay as f64) * omega / fs);
                    assert!(
                        (h - expected).norm() < tolerance * 2.0,
                        "{} s, ω {}: {h} vs {expected}",
                        s.seconds,
                        omega
                    );
                    assert!(coherence > min_coherence, "{coherence}");
                }
            }
        }
    }

    #[test]
    fn welch_averages_of_hann_windows() {
        let hann = |n: usize| -> Vec<f64> {
            (0..n)
                .map(|i| {
                    (std::f64::consts::PI * (i as f64 + 0.5) / n as f64)
                        .sin()
                        .powi(2)
                })
                .collect()
        };
        let w = hann(1000);
        // No overlap: every window independent.
        assert!((welch_independent_averages(&w, 1000, 10) - 10.0).abs() < 1e-12);
        // 50 % overlap: ρ(1) = 1/6 exactly for the periodic Hann window.
        let k = 10.0;
        let expected = k / (1.0 + 2.0 * (1.0 - 1.0 / k) / 36.0);
        assert!((welch_independent_averages(&w, 500, 10) - expected).abs() < 1e-3);
        // 80 % overlap: n_eq ≈ 0.42·K.
        let n80 = welch_independent_averages(&w, 200, 100);
        assert!((0.40..0.44).contains(&(n80 / 100.0)), "{n80}");
    }
}
