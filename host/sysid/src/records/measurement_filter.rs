//! The digital filter a record's measured outputs went through before they were logged,
//! as the flight controller announced it ([`sweephold_protocol::MeasurementFilter`]).
//!
//! The board filters every IMU channel — a low-pass and the rotor notches, at the IMU
//! rate — before its control tick reads (and logs) the newest value. Below 10 Hz such a
//! bank is close to a pure delay of a few milliseconds, and an identification that does
//! not know it puts that delay into the aircraft: on a 700-class helicopter, whose flap
//! time constant is about 25 ms, that is a 15–20 % error in the rotor terms. The
//! frequency responses divide it out ([`crate::frf`]); the time-domain verification
//! passes the model's outputs through it.
//!
//! # The response
//!
//! Section `k`, `[b₀, b₁, b₂, a₁, a₂]`, run at f_s, has at ω \[rad/s\], with
//! z = e^{jω/f_s},
//!
//! ```text
//! H_k(ω) = (b₀ + b₁ z⁻¹ + b₂ z⁻²) / (1 + a₁ z⁻¹ + a₂ z⁻²)
//! ```
//!
//! and the chain is the product. The log keeps every `f_s/f_tick`-th output: the value
//! the tick reads is the newest filtered sample, so the logged sequence is the filtered
//! signal sampled at the tick — its response below the tick's Nyquist frequency is
//! `H(ω)` itself.

use num_complex::Complex64;

/// The outputs of a telemetry dump the board's IMU filter bank acts on: the body rates
/// and specific forces it filters, and the attitude its estimator integrates from them.
pub const IMU_OUTPUTS: [&str; 8] = ["p", "q", "r", "ax", "ay", "az", "phi", "theta"];

/// A chain of biquad sections and the outputs it acted on.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasurementFilter {
    /// Rate the sections ran at \[Hz\].
    pub sample_rate_hz: f64,
    /// The sections in the order they ran, each `[b₀, b₁, b₂, a₁, a₂]` (a₀ = 1).
    pub sections: Vec<[f64; 5]>,
    /// The record's outputs that went through it.
    pub outputs: Vec<String>,
}

impl MeasurementFilter {
    /// The filter a board announced, acting on the [`IMU_OUTPUTS`].
    pub fn of_imu(frame: &sweephold_protocol::MeasurementFilter) -> MeasurementFilter {
        MeasurementFilter {
            sample_rate_hz: f64::from(frame.sample_rate_hz),
            sections: frame.sections.map(|s| s.map(f64::from)).to_vec(),
            outputs: IMU_OUTPUTS.iter().map(|s| s.to_string()).collect(),
        }
    }

    /// Whether the output called `name` went through the filter.
    pub fn acts_on(&self, name: &str) -> bool {
        self.outputs.iter().any(|o| o == name)
    }

    /// The filter's frequency response at `omega` rad/s (module docs).
    pub fn response(&self, omega: f64) -> Complex64 {
        let z1 = Complex64::from_polar(1.0, -omega / self.sample_rate_hz);
        let z2 = z1 * z1;
        self.sections
            .iter()
            .map(|&[b0, b1, b2, a1, a2]| (b0 + b1 * z1 + b2 * z2) / (1.0 + a1 * z1 + a2 * z2))
            .product()
    }

    /// The filter's phase at `omega` rad/s, unwrapped from 0 at ω = 0: the sum of the
    /// sections' phases, each continuous from 0 until its own zero on the unit circle (a
    /// notch's centre), where it jumps by 180°.
    pub fn phase_rad(&self, omega: f64) -> f64 {
        let z1 = Complex64::from_polar(1.0, -omega / self.sample_rate_hz);
        let z2 = z1 * z1;
        self.sections
            .iter()
            .map(|&[b0, b1, b2, a1, a2]| {
                ((b0 + b1 * z1 + b2 * z2) / (1.0 + a1 * z1 + a2 * z2)).arg()
            })
            .sum()
    }

    /// Filter `values`, sampled at `record_rate_hz`, as the board did: between two
    /// record samples the signal is taken to move on a straight line (the board's IMU
    /// samples the motion between its ticks; the newest filter step of a tick sees the
    /// tick's own value), `sample_rate_hz / record_rate_hz` filter steps per sample, and
    /// the output is read at the last step. The filter starts settled on the first
    /// value. `None` when the filter's rate is not a whole multiple of the record's.
    pub fn apply(&self, values: &[f64], record_rate_hz: f64) -> Option<Vec<f64>> {
        let ratio = self.sample_rate_hz / record_rate_hz;
        let steps = ratio.round();
        if !(steps >= 1.0 && (ratio - steps).abs() < 1e-9 * ratio) {
            return None;
        }
        let steps = steps as usize;
        let first = values.first().copied().unwrap_or(0.0);
        // Transposed direct form II, each section settled on a constant `first`.
        let mut states: Vec<[f64; 2]> = Vec::with_capacity(self.sections.len());
        let mut level = first;
        for &[b0, b1, b2, a1, a2] in &self.sections {
            let gain = (b0 + b1 + b2) / (1.0 + a1 + a2);
            let y = gain * level;
            states.push([y - b0 * level, b2 * level - a2 * y]);
            level = y;
        }
        let mut out = Vec::with_capacity(values.len());
        let mut previous = first;
        for &x in values {
            let mut y = x;
            for step in 1..=steps {
                y = previous + (x - previous) * step as f64 / steps as f64;
                for (state, &[b0, b1, b2, a1, a2]) in states.iter_mut().zip(&self.sections) {
                    let out = b0 * y + state[0];
                    state[0] = b1 * y - a1 * out + state[1];
                    state[1] = b2 * y - a2 * out;
                    y = out;
                }
            }
            previous = x;
            out.push(y);
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2nd-order Butterworth low-pass at 60 Hz at 1 kHz, coefficients from
    /// `scipy.signal.butter(2, 60, fs=1000)` (scipy 1.17.1):
    /// b = [0.02785976611713602, 0.05571953223427204, 0.02785976611713602],
    /// a = [1, -1.4754804435926461, 0.5869195080611902].
    fn butterworth_60() -> MeasurementFilter {
        MeasurementFilter {
            sample_rate_hz: 1000.0,
            sections: vec![[
                0.027_859_766_117_136_02,
                0.055_719_532_234_272_04,
                0.027_859_766_117_136_02,
                -1.475_480_443_592_646,
                0.586_919_508_061_190_2,
            ]],
            outputs: IMU_OUTPUTS.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn response_matches_scipy_freqz() {
        // scipy.signal.freqz(b, a, worN=[5, 20, 60], fs=1000): H at 5, 20 and 60 Hz.
        let filter = butterworth_60();
        let cases = [
            (5.0, 0.999_977_005_375_530_7, -0.116_723_809_782_531_77),
            (20.0, 0.994_136_008_219_557_9, -0.482_152_107_270_680_8),
            (
                60.0,
                std::f64::consts::FRAC_1_SQRT_2,
                -std::f64::consts::FRAC_PI_2,
            ),
        ];
        for (hz, magnitude, phase) in cases {
            let h = filter.response(2.0 * std::f64::consts::PI * hz);
            assert!(
                (h.norm() - magnitude).abs() < 1e-9,
                "{hz} Hz: |H| {}",
                h.norm()
            );
            assert!((h.arg() - phase).abs() < 1e-9, "{hz} Hz: ∠H {}", h.arg());
        }
    }

    #[test]
    fn apply_on_a_tone_gives_the_response() {
        // A 5 Hz tone logged at 200 Hz and filtered at 1 kHz on the line between its
        // samples: in the steady state its gain and phase are H(5 Hz)'s, up to the
        // interpolation's own small error (the line through a sine's samples 72° apart).
        let filter = butterworth_60();
        let (rate, hz) = (200.0, 5.0);
        let omega = 2.0 * std::f64::consts::PI * hz;
        let n = 800;
        let x: Vec<f64> = (0..n).map(|k| (omega * k as f64 / rate).sin()).collect();
        let y = filter.apply(&x, rate).unwrap();
        // Least-squares fit of a·sin + b·cos over the last 400 samples (10 periods).
        let (mut ss, mut sc, mut cc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (k, &v) in y.iter().enumerate().skip(400) {
            let (s, c) = (omega * k as f64 / rate).sin_cos();
            ss += s * s;
            sc += s * c;
            cc += c * c;
            ys += v * s;
            yc += v * c;
        }
        let det = ss * cc - sc * sc;
        let (a, b) = ((ys * cc - yc * sc) / det, (yc * ss - ys * sc) / det);
        let (gain, phase) = ((a * a + b * b).sqrt(), b.atan2(a));
        let h = filter.response(omega);
        assert!(
            (gain - h.norm()).abs() < 0.01,
            "gain {gain} against {}",
            h.norm()
        );
        assert!(
            (phase - h.arg()).abs() < 0.01,
            "phase {phase} against {}",
            h.arg()
        );
    }

    #[test]
    fn apply_starts_settled_and_refuses_other_rates() {
        let filter = butterworth_60();
        let y = filter.apply(&[3.0; 10], 200.0).unwrap();
        assert!(y.iter().all(|v| (v - 3.0).abs() < 1e-12), "{y:?}");
        assert!(filter.apply(&[1.0], 300.0).is_none());
    }

    #[test]
    fn phase_is_unwrapped_through_a_notch() {
        let mut filter = butterworth_60();
        // A notch at 30 Hz, Q 3 (the board's 1/rev notch at 1800 rpm), from the same
        // cookbook formulas the firmware uses.
        let w0 = 2.0 * std::f64::consts::PI * 30.0 / 1000.0;
        let alpha = w0.sin() / 6.0;
        let a0 = 1.0 + alpha;
        filter.sections.push([
            1.0 / a0,
            -2.0 * w0.cos() / a0,
            1.0 / a0,
            -2.0 * w0.cos() / a0,
            (1.0 - alpha) / a0,
        ]);
        // Below the notch the phase is the sum of small lags, continuous from 0.
        let lag = |hz: f64| filter.phase_rad(2.0 * std::f64::consts::PI * hz);
        assert!(lag(1.0) < 0.0 && lag(1.0) > -0.1);
        assert!(lag(10.0) < lag(5.0) && lag(5.0) < lag(1.0));
        let h = filter.response(2.0 * std::f64::consts::PI * 10.0);
        assert!((lag(10.0) - h.arg()).abs() < 1e-12);
    }

    #[test]
    fn the_firmware_bank_as_announced_has_the_firmware_response() {
        // What a board at 1800 rpm announces, evaluated here, against the firmware's own
        // evaluation of its bank (`FilterBank::response`, in f32).
        use sweephold_firmware::filters::{FilterBank, FilterBankConfig};
        let config = FilterBankConfig::helicopter(1000.0, 30.0, 135.0);
        let announced = MeasurementFilter::of_imu(&config.measurement_filter().unwrap());
        let bank = FilterBank::new(config).unwrap();
        for hz in [0.5f64, 1.0, 2.0, 5.0, 10.0, 20.0] {
            let (gain, phase) = bank.response(hz as f32);
            let omega = 2.0 * std::f64::consts::PI * hz;
            let h = announced.response(omega);
            assert!((h.norm() - f64::from(gain)).abs() < 1e-5, "{hz} Hz gain");
            assert!((h.arg() - f64::from(phase)).abs() < 1e-4, "{hz} Hz phase");
            assert!(
                (announced.phase_rad(omega) - h.arg()).abs() < 1e-12,
                "{hz} Hz unwrapped"
            );
        }
    }
}
