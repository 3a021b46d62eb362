//! The Chirp-Z transform on the unit circle (Bluestein's algorithm on rustfft).
//!
//! For a sequence `x_n`, n = 0..N−1, and M frequencies `ω_k = ω_0 + kΔ` (rad/sample,
//! anywhere on the circle, any spacing) the transform is
//!
//! ```text
//!     X_k = Σ_n x_n e^{−i ω_k n}
//! ```
//!
//! Bluestein writes `nk = (n² + k² − (k−n)²)/2`, which turns the sum into a convolution:
//!
//! ```text
//!     X_k = c_k* · Σ_n a_n b_{k−n},   a_n = x_n e^{−iω_0 n} c_n*,
//!     c_j = e^{iΔ j²/2},              b_j = c_j   (j = −(N−1)..M−1)
//! ```
//!
//! computed as a circular convolution of length L ≥ N + M − 1 with two FFTs (the FFT of
//! `b` is computed once per plan).
//!
//! The chirp phases `Δj²/2` grow like j²: evaluated naively in f64 their rounding error
//! reaches 1e-6 rad for j ~ 10⁵, and errors in the three chirps no longer cancel. Here
//! every phase is computed *exactly modulo one turn*: the frequencies are converted once
//! to turns as 64-bit binary fractions (`t = ω/2π mod 1`, exact from the f64 value), and
//! `t·n + t_Δ·n²` is evaluated in wrapping u64 arithmetic, which is exact arithmetic
//! modulo 2⁶⁴ ≡ one turn. Only the final angle in [−π, π) is rounded to f64.

use std::sync::Arc;

use num_complex::Complex64;
use rustfft::{Fft, FftPlanner};

/// A frequency in turns per sample as a 64-bit binary fraction of a turn (2⁶⁴ = one turn).
fn turns_fixed(omega_rad_per_sample: f64) -> u64 {
    let turns = omega_rad_per_sample / std::f64::consts::TAU;
    let fraction = turns - turns.floor(); // in [0, 1]
                                          // Exact: multiplying by a power of two; the f64 fraction has at most 64 fractional
                                          // bits that matter. `as u128` then wrapping to u64 maps a rounded 1.0 to 0.
    (fraction * 18_446_744_073_709_551_616.0) as u128 as u64
}

/// e^{i·2π·phase/2⁶⁴}, the phase read as a signed fraction of a turn so that the angle
/// handed to `sin_cos` lies in [−π, π).
fn unit_phasor(phase: u64) -> Complex64 {
    let angle = (phase as i64) as f64 * (std::f64::consts::TAU / 18_446_744_073_709_551_616.0);
    let (sin, cos) = angle.sin_cos();
    Complex64::new(cos, sin)
}

/// `j²·t_Δ/2` modulo one turn, exactly: `t_half` is `t_Δ/2` as a 64-bit fraction.
fn chirp_phase(j: u64, t_half: u64) -> u64 {
    j.wrapping_mul(j).wrapping_mul(t_half)
}

/// The FFT length used for a transform of `n` inputs and `m` outputs: the smallest
/// 2^a·3^b·5^c ≥ n + m − 1 (rustfft is fastest on such sizes).
fn convolution_length(n: usize, m: usize) -> usize {
    let need = (n + m).saturating_sub(1).max(1);
    let mut best = need.next_power_of_two();
    let mut p5 = 1usize;
    while p5 < best {
        let mut p35 = p5;
        while p35 < best {
            let mut size = p35;
            while size < need {
                size *= 2;
            }
            best = best.min(size);
            p35 *= 3;
        }
        p5 *= 5;
    }
    best
}

/// A reusable Chirp-Z plan for a fixed input length, output count and frequency grid.
///
/// Build once, then call [`ChirpZ::transform_real`] for every window of every channel:
/// the chirps and the FFT of the convolution kernel are computed once.
pub struct ChirpZ {
    n: usize,
    m: usize,
    len: usize,
    /// `e^{−i(ω_0 n + Δn²/2)} / L`, n = 0..N−1 (input pre-multiplier, FFT scale folded in).
    pre: Vec<Complex64>,
    /// `e^{−iΔk²/2}`, k = 0..M−1 (output post-multiplier).
    post: Vec<Complex64>,
    /// FFT of the circular kernel `b`.
    kernel: Vec<Complex64>,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    buffer: Vec<Complex64>,
    scratch: Vec<Complex64>,
}

impl ChirpZ {
    /// Plan the transform of `n` samples onto `m` frequencies `ω_0 + kΔ` (rad/sample),
    /// creating FFT plans with `planner` (share one planner between plans).
    pub fn new(
        n: usize,
        m: usize,
        omega_start: f64,
        omega_step: f64,
        planner: &mut FftPlanner<f64>,
    ) -> ChirpZ {
        let len = convolution_length(n, m);
        let t_start = turns_fixed(omega_start);
        // Δ/2 in turns: the chirp is e^{iΔ j²/2}.
        let t_half = turns_fixed(omega_step / 2.0);
        let scale = 1.0 / len as f64;

        let pre = (0..n as u64)
            .map(|j| {
                let phase = j.wrapping_mul(t_start).wrapping_add(chirp_phase(j, t_half));
                unit_phasor(phase.wrapping_neg()) * scale
            })
            .collect();
        let post = (0..m as u64)
            .map(|k| unit_phasor(chirp_phase(k, t_half).wrapping_neg()))
            .collect();

        // b_j = e^{+iΔ j²/2} at index j for j = 0..M−1 and at L + j for j = −(N−1)..−1.
        let mut kernel = vec![Complex64::new(0.0, 0.0); len];
        for (j, slot) in kernel.iter_mut().enumerate().take(m) {
            *slot = unit_phasor(chirp_phase(j as u64, t_half));
        }
        for j in 1..n {
            kernel[len - j] = unit_phasor(chirp_phase(j as u64, t_half));
        }
        let forward = planner.plan_fft_forward(len);
        let inverse = planner.plan_fft_inverse(len);
        let scratch_len = forward
            .get_inplace_scratch_len()
            .max(inverse.get_inplace_scratch_len());
        let mut scratch = vec![Complex64::new(0.0, 0.0); scratch_len];
        forward.process_with_scratch(&mut kernel, &mut scratch);

        ChirpZ {
            n,
            m,
            len,
            pre,
            post,
            kernel,
            forward,
            inverse,
            buffer: vec![Complex64::new(0.0, 0.0); len],
            scratch,
        }
    }

    /// Input length N.
    pub fn input_len(&self) -> usize {
        self.n
    }

    /// Number of output frequencies M.
    pub fn output_len(&self) -> usize {
        self.m
    }

    /// FFT length L of the convolution.
    pub fn fft_len(&self) -> usize {
        self.len
    }

    /// Transform the real sequence `x_n = weight_n·(samples_n − offset)` into `out`
    /// (length M). `samples` and `weight` have length N. Folding the taper and the
    /// mean removal into the pre-multiplication saves a pass over the data.
    pub fn transform_real(
        &mut self,
        samples: &[f64],
        weight: &[f64],
        offset: f64,
        out: &mut [Complex64],
    ) {
        let zero = Complex64::new(0.0, 0.0);
        for (((slot, &x), &w), &pre) in self
            .buffer
            .iter_mut()
            .zip(samples)
            .zip(weight)
            .zip(&self.pre)
        {
            *slot = pre * ((x - offset) * w);
        }
        self.buffer[self.n.min(samples.len())..].fill(zero);
        self.convolve(out);
    }

    /// Transform two real sequences at once: `z_n = weight_n·((a_n − offset_a) +
    /// i(b_n − offset_b))` into `out` (length M). On a grid symmetric about zero the
    /// two spectra separate as `A(ω) = (Z(ω) + Z(−ω)*)/2`, `B(ω) = (Z(ω) − Z(−ω)*)/2i`
    /// (see [`separate_pair`]): one transform for two real channels.
    pub fn transform_real_pair(
        &mut self,
        a: &[f64],
        b: &[f64],
        weight: &[f64],
        offsets: (f64, f64),
        out: &mut [Complex64],
    ) {
        let zero = Complex64::new(0.0, 0.0);
        let (offset_a, offset_b) = offsets;
        for ((((slot, &a), &b), &w), &pre) in self
            .buffer
            .iter_mut()
            .zip(a)
            .zip(b)
            .zip(weight)
            .zip(&self.pre)
        {
            *slot = pre * Complex64::new((a - offset_a) * w, (b - offset_b) * w);
        }
        self.buffer[self.n.min(a.len()).min(b.len())..].fill(zero);
        self.convolve(out);
    }

    /// Transform a complex sequence of length N into `out` (length M).
    pub fn transform(&mut self, x: &[Complex64], out: &mut [Complex64]) {
        let zero = Complex64::new(0.0, 0.0);
        for ((slot, &x), &pre) in self.buffer.iter_mut().zip(x).zip(&self.pre) {
            *slot = pre * x;
        }
        self.buffer[self.n.min(x.len())..].fill(zero);
        self.convolve(out);
    }

    /// The common tail: circular convolution with the kernel, then the post-chirp.
    fn convolve(&mut self, out: &mut [Complex64]) {
        self.forward
            .process_with_scratch(&mut self.buffer, &mut self.scratch);
        for (b, &k) in self.buffer.iter_mut().zip(&self.kernel) {
            *b *= k;
        }
        self.inverse
            .process_with_scratch(&mut self.buffer, &mut self.scratch);
        for ((o, &y), &post) in out.iter_mut().zip(&self.buffer).zip(&self.post) {
            *o = y * post;
        }
    }
}

/// Split the transform `z` of `a + ib` (a, b real) into A(ω) and B(ω), given Z(ω) and
/// Z(−ω): `A = (Z(ω) + Z(−ω)*)/2`, `B = (Z(ω) − Z(−ω)*)/(2i)`.
#[inline]
pub fn separate_pair(z_positive: Complex64, z_negative: Complex64) -> (Complex64, Complex64) {
    let mirrored = z_negative.conj();
    let a = (z_positive + mirrored) * 0.5;
    let d = (z_positive - mirrored) * 0.5;
    // d/i = −i·d
    (a, Complex64::new(d.im, -d.re))
}

/// One-shot Chirp-Z transform: `X_k = Σ_n x_n e^{−i(ω_0 + kΔ)n}` for k = 0..m−1, with
/// `omega_start` = ω_0 and `omega_step` = Δ in rad/sample. For repeated transforms of
/// the same size build a [`ChirpZ`] plan instead.
pub fn chirp_z(x: &[Complex64], omega_start: f64, omega_step: f64, m: usize) -> Vec<Complex64> {
    if x.is_empty() || m == 0 {
        return vec![Complex64::new(0.0, 0.0); m];
    }
    let mut planner = FftPlanner::new();
    let mut plan = ChirpZ::new(x.len(), m, omega_start, omega_step, &mut planner);
    let mut out = vec![Complex64::new(0.0, 0.0); m];
    plan.transform(x, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The definition, summed directly: Σ x_n e^{−iωn}.
    fn direct_dft(x: &[Complex64], omega: f64) -> Complex64 {
        x.iter()
            .enumerate()
            .map(|(n, &v)| {
                let (sin, cos) = (omega * n as f64).sin_cos();
                v * Complex64::new(cos, -sin)
            })
            .sum()
    }

    /// A deterministic pseudo-random sequence (SplitMix64), values in [−1, 1).
    fn pseudo_random(len: usize, seed: u64) -> Vec<Complex64> {
        let mut random = crate::random::SplitMix64::new(seed);
        (0..len)
            .map(|_| Complex64::new(random.symmetric(), random.symmetric()))
            .collect()
    }

    fn relative_error(x: &[Complex64], start: f64, step: f64, m: usize) -> f64 {
        let fast = chirp_z(x, start, step, m);
        let mut worst_diff = 0.0f64;
        let mut largest = 0.0f64;
        for (k, &value) in fast.iter().enumerate() {
            let exact = direct_dft(x, start + k as f64 * step);
            worst_diff = worst_diff.max((value - exact).norm());
            largest = largest.max(exact.norm());
        }
        worst_diff / largest
    }

    #[test]
    fn matches_direct_dft_at_arbitrary_frequencies() {
        // Frequencies that are no FFT bins: irrational start and step, a zoom band, a
        // grid that wraps past π, and a long input where naive chirps lose precision.
        let cases = [
            (1000usize, 0.0123456789, 0.000987654321, 300usize),
            (777, 2.5, 0.0031415, 211),
            (4096, -0.7, 0.01, 257),
            (20_000, 0.3, 0.0002, 500),
        ];
        for (i, &(n, start, step, m)) in cases.iter().enumerate() {
            let x = pseudo_random(n, i as u64 + 1);
            let error = relative_error(&x, start, step, m);
            assert!(error < 1e-9, "case {i}: relative error {error:e}");
        }
    }

    #[test]
    fn equals_the_fft_on_fft_bins() {
        let x = pseudo_random(64, 9);
        let mut fft = x.clone();
        FftPlanner::new().plan_fft_forward(64).process(&mut fft);
        let czt = chirp_z(&x, 0.0, std::f64::consts::TAU / 64.0, 64);
        for (a, b) in czt.iter().zip(&fft) {
            assert!((a - b).norm() < 1e-10 * 64.0);
        }
    }

    #[test]
    fn real_transform_folds_weight_and_offset() {
        let samples: Vec<f64> = pseudo_random(300, 4).iter().map(|c| c.re + 3.0).collect();
        let weight: Vec<f64> = (0..300).map(|n| 0.5 + n as f64 / 600.0).collect();
        let complex: Vec<Complex64> = samples
            .iter()
            .zip(&weight)
            .map(|(&s, &w)| Complex64::new((s - 3.0) * w, 0.0))
            .collect();
        let mut planner = FftPlanner::new();
        let mut plan = ChirpZ::new(300, 40, 0.1, 0.013, &mut planner);
        let mut out = vec![Complex64::new(0.0, 0.0); 40];
        plan.transform_real(&samples, &weight, 3.0, &mut out);
        let expected = chirp_z(&complex, 0.1, 0.013, 40);
        for (a, b) in out.iter().zip(&expected) {
            assert!((a - b).norm() < 1e-11);
        }
    }

    #[test]
    fn two_real_channels_in_one_transform() {
        let a: Vec<f64> = pseudo_random(500, 5).iter().map(|c| c.re).collect();
        let b: Vec<f64> = pseudo_random(500, 6).iter().map(|c| c.im + 1.0).collect();
        let weight = vec![1.0; 500];
        // Symmetric grid: −20δ..20δ.
        let step = 0.0071;
        let mut planner = FftPlanner::new();
        let mut plan = ChirpZ::new(500, 41, -20.0 * step, step, &mut planner);
        let mut z = vec![Complex64::new(0.0, 0.0); 41];
        plan.transform_real_pair(&a, &b, &weight, (0.0, 1.0), &mut z);
        let as_complex = |x: &[f64], offset: f64| -> Vec<Complex64> {
            x.iter().map(|&v| Complex64::new(v - offset, 0.0)).collect()
        };
        let expected_a = chirp_z(&as_complex(&a, 0.0), 0.0, step, 21);
        let expected_b = chirp_z(&as_complex(&b, 1.0), 0.0, step, 21);
        for k in 0..21 {
            let (ak, bk) = separate_pair(z[20 + k], z[20 - k]);
            assert!((ak - expected_a[k]).norm() < 1e-10, "{k}");
            assert!((bk - expected_b[k]).norm() < 1e-10, "{k}");
        }
    }

    #[test]
    fn convolution_length_is_smooth_and_long_enough() {
        for (n, m) in [(1, 1), (400, 70), (18_000, 3600), (1000, 1)] {
            let len = convolution_length(n, m);
            assert!(len >= n + m - 1);
            let mut rest = len;
            for p in [2, 3, 5] {
                while rest.is_multiple_of(p) {
                    rest /= p;
                }
            }
            assert_eq!(rest, 1, "{len} has a factor other than 2, 3, 5");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn any_grid_matches_the_direct_sum(
            n in 1usize..300,
            m in 1usize..80,
            start in -4.0f64..4.0,
            step in -0.2f64..0.2,
            seed in 0u64..1000,
        ) {
            let x = pseudo_random(n, seed);
            prop_assert!(relative_error(&x, start, step, m) < 1e-9);
        }
    }
}
