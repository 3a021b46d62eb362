//! IMU filtering: biquad sections (RBJ audio-EQ cookbook) and the per-channel filter
//! bank that runs at the IMU rate, ahead of the control tick.
//!
//! # Why filter at the IMU rate
//!
//! The control tick samples the IMU at f_c = 200 Hz. A tone at frequency `f` sampled at
//! f_c is indistinguishable from one at its alias `|f − k·f_c|` (the integer `k` that
//! brings it into [0, f_c/2]). A TREX 700L-class helicopter at ≈ 2100 rpm shakes its
//! IMU at the main-rotor 1/rev (≈ 35 Hz) and 2/rev (≈ 70 Hz) and at the tail-rotor
//! frequency (≈ 160 Hz with a tail drive ratio of ≈ 4.6). Sampled at 200 Hz:
//!
//! ```text
//! 35 Hz  → 35 Hz            (inside the band: must be notched before the tick reads it)
//! 70 Hz  → 70 Hz
//! 160 Hz → |160 − 200| = 40 Hz
//! ```
//!
//! Once aliased, the tail-rotor vibration sits at 40 Hz, among real airframe motion, and
//! no filter at 200 Hz can take it out again. At the IMU rate (1 kHz, Nyquist 500 Hz)
//! every one of these tones is still at its true frequency, so the bank runs there: a
//! notch on each rotor harmonic and a low-pass that attenuates whatever else lies above
//! the tick's Nyquist frequency (100 Hz) before the tick keeps every fifth sample.
//! Content above 500 Hz is the IMU's own on-chip low-pass' business.
//!
//! # Sections
//!
//! Each section is the cookbook's bilinear-transform design. With
//!
//! ```text
//! ω₀ = 2π·f₀/f_s,   α = sin ω₀ / (2Q)
//! low-pass:  b = [(1 − cos ω₀)/2,  1 − cos ω₀,  (1 − cos ω₀)/2],  a = [1 + α, −2 cos ω₀, 1 − α]
//! notch:     b = [1,               −2 cos ω₀,   1],                a = [1 + α, −2 cos ω₀, 1 − α]
//! ```
//!
//! normalised by a₀, the transfer function is
//!
//! ```text
//! H(z) = (b₀ + b₁ z⁻¹ + b₂ z⁻²) / (1 + a₁ z⁻¹ + a₂ z⁻²)
//! ```
//!
//! and its frequency response is that of the analogue prototype at the prewarped
//! frequency Ω = tan(ω/2) / tan(ω₀/2):
//!
//! ```text
//! low-pass:  |H|² = 1 / ((1 − Ω²)² + (Ω/Q)²)             (|H(ω₀)| = Q: −3.01 dB at Q = 1/√2)
//! notch:     |H|² = (1 − Ω²)² / ((1 − Ω²)² + (Ω/Q)²)     (zero at ω₀, −3 dB width f₀/Q)
//! ```
//!
//! cos ω₀ and α are computed in `f64` (design runs once, at configuration), and a₁ and
//! a₂ are rounded to multiples of 2⁻²³ (≈ 1.2·10⁻⁷, the spacing `f32` itself has on
//! [1, 2)). On that grid every number below 2 in magnitude is an exact `f32`, so 1 + a₂
//! is always exact and 1 + a₁ + a₂, summed as (1 + a₂) + a₁, is exact whenever it is
//! below 2 — for every f₀ < f_s/4, where it is small and its precision matters. The
//! numerator is derived *from the stored* a₁, a₂, so the structural identities hold for
//! the `f32` values themselves, not just up to rounding:
//!
//! ```text
//! low-pass:  b₀ = b₂ = ((1 + a₂) + a₁)/4,  b₁ = 2·b₀      ⇒ H(1) = 1, H(−1) = 0
//! notch:     b₀ = b₂ = (1 + a₂)/2,       b₁ = a₁          ⇒ H(1) = H(−1) = 1, and the zeros
//!                                                           e^{±jω̂}, cos ω̂ = −a₁/(1 + a₂),
//!                                                           lie exactly on the unit circle
//! ```
//!
//! (analytically (1 + a₁ + a₂) = 2(1 − cos ω₀)/a₀ and (1 + a₂)/2 = 1/a₀, so these are
//! the cookbook's values; the divisions by 2 and 4 are exact in binary). This matters
//! for f₀ ≪ f_s: 1 + a₁ + a₂ ≈ ω₀²/a₀ is then small, and one rounding of a coefficient
//! of size ≈ 2 would move the DC gain by ulp(2)/(1 + a₁ + a₂) — 10⁻⁴ for a 5 Hz notch at
//! 1 kHz. The poles of a designed section have radius √a₂ < 1 (α > 0 for
//! 0 < f₀ < f_s/2 and Q > 0); a design so sharp that rounding would put them on the
//! unit circle is refused ([`FilterError::TooSharp`]).
//!
//! A section runs in transposed direct form II, two `f32` states:
//!
//! ```text
//! y  = b₀·x + s₁
//! s₁ ← b₁·x − a₁·y + s₂
//! s₂ ← b₂·x − a₂·y
//! ```
//!
//! # Non-finite input
//!
//! A NaN or infinite input is returned unchanged (so the fault stays visible downstream)
//! and *resets* the section: its state is discarded and the next finite input `x`
//! starts it in the steady state of a constant `x` (output H(1)·x at once, no
//! transient). A freshly built [`FilterBank`] starts the same way, so the 1 g on the
//! z accelerometer does not ring through the low-pass at start-up. The state is never
//! non-finite: an update whose arithmetic would overflow resets the section likewise.

use core::f64::consts::PI;

use sweephold_protocol::{MeasurementFilter, MEASUREMENT_FILTER_SECTIONS};

/// Why a section cannot be designed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FilterError {
    /// f₀, Q or f_s is NaN or infinite.
    NotFinite,
    /// f_s ≤ 0.
    SampleRateNotPositive,
    /// f₀ ≤ 0 or f₀ ≥ f_s/2.
    FrequencyOutOfRange,
    /// Q ≤ 0.
    QNotPositive,
    /// Q so high for f₀/f_s (α below ≈ 10⁻⁷) that the poles round onto the unit circle.
    TooSharp,
}

impl core::fmt::Display for FilterError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            FilterError::NotFinite => "filter parameter is NaN or infinite",
            FilterError::SampleRateNotPositive => "sample rate must be positive",
            FilterError::FrequencyOutOfRange => "centre frequency outside (0, fs/2)",
            FilterError::QNotPositive => "Q must be positive",
            FilterError::TooSharp => "Q too high for f0/fs: poles on the unit circle",
        })
    }
}

/// Normalised biquad coefficients (a₀ = 1). Only the designs below (and the identity)
/// can be built, so every value of this type is a stable section.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Coefficients {
    b0: f32,
    b1: f32,
    b2: f32,
    a1: f32,
    a2: f32,
}

/// The grid a₁ and a₂ are rounded to: 2⁻²³.
const GRID: f64 = 8_388_608.0;

/// (a₁, a₂) of the cookbook designs, from f64 cos ω₀ and α, rounded to multiples of
/// 2⁻²³ (see the module doc).
fn poles(f0_hz: f32, q: f32, fs_hz: f32) -> Result<(f32, f32), FilterError> {
    if !(f0_hz.is_finite() && q.is_finite() && fs_hz.is_finite()) {
        return Err(FilterError::NotFinite);
    }
    if fs_hz <= 0.0 {
        return Err(FilterError::SampleRateNotPositive);
    }
    if f0_hz <= 0.0 || f0_hz >= 0.5 * fs_hz {
        return Err(FilterError::FrequencyOutOfRange);
    }
    if q <= 0.0 {
        return Err(FilterError::QNotPositive);
    }
    let omega0 = 2.0 * PI * f64::from(f0_hz) / f64::from(fs_hz);
    let (sin, cos) = libm::sincos(omega0);
    let alpha = sin / (2.0 * f64::from(q));
    let a0 = 1.0 + alpha;
    let on_grid = |v: f64| (libm::round(v * GRID) / GRID) as f32;
    let (a1, a2) = (on_grid(-2.0 * cos / a0), on_grid((1.0 - alpha) / a0));
    // Stability triangle |a₂| < 1, |a₁| < 1 + a₂ (1 + a₂ is exact on the grid).
    if !(a2 < 1.0 && a2 > -1.0 && a1.abs() < 1.0 + a2) {
        return Err(FilterError::TooSharp);
    }
    Ok((a1, a2))
}

impl Coefficients {
    /// The pass-through section: H(z) = 1.
    pub const IDENTITY: Coefficients = Coefficients {
        b0: 1.0,
        b1: 0.0,
        b2: 0.0,
        a1: 0.0,
        a2: 0.0,
    };

    /// Second-order low-pass with corner `f0_hz` and quality `q` at sample rate `fs_hz`
    /// (Q = 1/√2: Butterworth, −3 dB at f₀).
    pub fn low_pass(f0_hz: f32, q: f32, fs_hz: f32) -> Result<Coefficients, FilterError> {
        let (a1, a2) = poles(f0_hz, q, fs_hz)?;
        let b0 = ((1.0 + a2) + a1) * 0.25;
        Ok(Coefficients {
            b0,
            b1: 2.0 * b0,
            b2: b0,
            a1,
            a2,
        })
    }

    /// Notch at `f0_hz` with quality `q` (−3 dB width f₀/Q) at sample rate `fs_hz`.
    pub fn notch(f0_hz: f32, q: f32, fs_hz: f32) -> Result<Coefficients, FilterError> {
        let (a1, a2) = poles(f0_hz, q, fs_hz)?;
        let b0 = (1.0 + a2) * 0.5;
        Ok(Coefficients {
            b0,
            b1: a1,
            b2: b0,
            a1,
            a2,
        })
    }

    /// Numerator [b₀, b₁, b₂].
    pub const fn numerator(&self) -> [f32; 3] {
        [self.b0, self.b1, self.b2]
    }

    /// Denominator [a₁, a₂] (a₀ = 1).
    pub const fn denominator(&self) -> [f32; 2] {
        [self.a1, self.a2]
    }

    /// H(1) = (b₀ + b₁ + b₂)/(1 + a₁ + a₂).
    pub fn dc_gain(&self) -> f32 {
        (self.b0 + self.b1 + self.b2) / (1.0 + self.a1 + self.a2)
    }

    /// Gain |H(e^{jω})| and phase ∠H(e^{jω}) \[rad, in (−π, π]\] at `f_hz` for sample
    /// rate `fs_hz`, ω = 2π·f/f_s, evaluated from the coefficients:
    ///
    /// ```text
    /// N = b₀ + b₁ e^{−jω} + b₂ e^{−2jω},   D = 1 + a₁ e^{−jω} + a₂ e^{−2jω},   H = N/D
    /// ```
    pub fn response(&self, f_hz: f32, fs_hz: f32) -> (f32, f32) {
        let omega = 2.0 * core::f32::consts::PI * f_hz / fs_hz;
        let (s1, c1) = libm::sincosf(omega);
        let (s2, c2) = libm::sincosf(2.0 * omega);
        let n_re = self.b0 + self.b1 * c1 + self.b2 * c2;
        let n_im = -(self.b1 * s1 + self.b2 * s2);
        let d_re = 1.0 + self.a1 * c1 + self.a2 * c2;
        let d_im = -(self.a1 * s1 + self.a2 * s2);
        let gain = libm::hypotf(n_re, n_im) / libm::hypotf(d_re, d_im);
        let phase = wrap_pi(libm::atan2f(n_im, n_re) - libm::atan2f(d_im, d_re));
        (gain, phase)
    }
}

/// An angle reduced to (−π, π] (one step each way suffices for a difference of two
/// `atan2` values).
fn wrap_pi(angle: f32) -> f32 {
    use core::f32::consts::{PI, TAU};
    if angle > PI {
        angle - TAU
    } else if angle <= -PI {
        angle + TAU
    } else {
        angle
    }
}

/// One biquad section with its state.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Biquad {
    coefficients: Coefficients,
    s1: f32,
    s2: f32,
    /// `false`: the next finite input sets the steady state.
    primed: bool,
}

impl Biquad {
    /// A section at rest (zero state): the impulse response starts from the first
    /// input.
    pub const fn new(coefficients: Coefficients) -> Self {
        Biquad {
            coefficients,
            s1: 0.0,
            s2: 0.0,
            primed: true,
        }
    }

    /// The coefficients.
    pub const fn coefficients(&self) -> &Coefficients {
        &self.coefficients
    }

    /// Change the coefficients and keep the state (retuning a notch to a new rotor
    /// speed without a reset).
    pub fn set_coefficients(&mut self, coefficients: Coefficients) {
        self.coefficients = coefficients;
    }

    /// Forget the past: the next finite input `x` starts the section in the steady
    /// state of a constant `x`.
    pub fn reset(&mut self) {
        self.s1 = 0.0;
        self.s2 = 0.0;
        self.primed = false;
    }

    /// Set the state to the steady state of a constant input `x`: with y = H(1)·x,
    ///
    /// ```text
    /// s₂ = b₂·x − a₂·y,   s₁ = b₁·x − a₁·y + s₂   ⇒   next y = b₀·x + s₁ = H(1)·x
    /// ```
    ///
    /// A non-finite `x` (or a result that overflows) resets the section instead.
    pub fn settle(&mut self, x: f32) {
        let c = &self.coefficients;
        let y = c.dc_gain() * x;
        let s2 = c.b2 * x - c.a2 * y;
        let s1 = c.b1 * x - c.a1 * y + s2;
        if s1.is_finite() && s2.is_finite() {
            self.s1 = s1;
            self.s2 = s2;
            self.primed = true;
        } else {
            self.reset();
        }
    }

    /// Filter one sample (see the module doc for non-finite input).
    pub fn process(&mut self, x: f32) -> f32 {
        if !x.is_finite() {
            self.reset();
            return x;
        }
        if !self.primed {
            self.settle(x);
            if !self.primed {
                return x;
            }
        }
        let c = &self.coefficients;
        let y = c.b0 * x + self.s1;
        let s1 = c.b1 * x - c.a1 * y + self.s2;
        let s2 = c.b2 * x - c.a2 * y;
        if y.is_finite() && s1.is_finite() && s2.is_finite() {
            self.s1 = s1;
            self.s2 = s2;
            y
        } else {
            self.reset();
            x
        }
    }
}

/// IMU channels filtered by the bank: gyro x, y, z then accelerometer x, y, z.
pub const IMU_CHANNELS: usize = 6;
/// Notches per channel: main-rotor 1/rev, main-rotor 2/rev, tail rotor.
pub const NOTCHES: usize = 3;
/// Sections per channel: the low-pass, then the notches.
const SECTIONS: usize = 1 + NOTCHES;
// The telemetry describes the bank section by section.
const _: () = assert!(SECTIONS == MEASUREMENT_FILTER_SECTIONS);

/// One notch of the bank.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NotchSpec {
    /// Centre frequency \[Hz\].
    pub centre_hz: f32,
    /// Quality factor (−3 dB width = centre/Q).
    pub q: f32,
}

/// The bank's design: one low-pass and up to three notches, the same for all six
/// channels.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FilterBankConfig {
    /// The IMU sample rate the bank runs at \[Hz\].
    pub sample_rate_hz: f32,
    /// Low-pass corner \[Hz\].
    pub low_pass_hz: f32,
    /// Low-pass quality factor (1/√2: Butterworth).
    pub low_pass_q: f32,
    /// Main-rotor 1/rev, main-rotor 2/rev and tail-rotor notches; `None` passes through.
    pub notches: [Option<NotchSpec>; NOTCHES],
}

/// Notch quality of the presets: −3 dB width f₀/3 (±1/6 of f₀), wide enough for the
/// governor's few-percent headspeed variation, still −18 dB at 2 % detuning.
pub const ROTOR_NOTCH_Q: f32 = 3.0;

impl FilterBankConfig {
    /// The bank for a helicopter with main rotor at `main_rotor_hz` (1/rev) and tail
    /// rotor at `tail_rotor_hz`, at `sample_rate_hz`: Butterworth low-pass at 60 Hz and
    /// notches of Q = [`ROTOR_NOTCH_Q`] at 1/rev, 2/rev and the tail frequency.
    pub const fn helicopter(sample_rate_hz: f32, main_rotor_hz: f32, tail_rotor_hz: f32) -> Self {
        FilterBankConfig {
            sample_rate_hz,
            low_pass_hz: 60.0,
            low_pass_q: core::f32::consts::FRAC_1_SQRT_2,
            notches: [
                Some(NotchSpec {
                    centre_hz: main_rotor_hz,
                    q: ROTOR_NOTCH_Q,
                }),
                Some(NotchSpec {
                    centre_hz: 2.0 * main_rotor_hz,
                    q: ROTOR_NOTCH_Q,
                }),
                Some(NotchSpec {
                    centre_hz: tail_rotor_hz,
                    q: ROTOR_NOTCH_Q,
                }),
            ],
        }
    }

    /// A TREX 700L-class helicopter at 2100 rpm, IMU at 1 kHz: notches at 35, 70 and
    /// 160 Hz, low-pass at 60 Hz.
    ///
    /// What the bank does to the signals the flight logic uses
    /// ([`FilterBank::response`]); below 10 Hz it is close to a pure delay of ≈ 6.3 ms
    /// (1.25 ticks at 200 Hz), which a frequency-response identification sees as part of
    /// the vehicle unless it is accounted for:
    ///
    /// | f \[Hz\] | gain   | phase   | delay −φ/ω |
    /// |---------:|-------:|--------:|-----------:|
    /// | 1        | 0.9999 | −2.26°  | 6.27 ms    |
    /// | 2        | 0.9998 | −4.52°  | 6.27 ms    |
    /// | 5        | 0.9985 | −11.35° | 6.31 ms    |
    /// | 10       | 0.9930 | −23.19° | 6.44 ms    |
    /// | 20       | 0.9513 | −51.37° | 7.13 ms    |
    pub const fn trex700l() -> Self {
        FilterBankConfig::helicopter(1000.0, 35.0, 160.0)
    }

    /// The designed sections: low-pass first, then the notches (identity where `None`).
    pub fn design(&self) -> Result<[Coefficients; SECTIONS], FilterError> {
        let mut sections = [Coefficients::IDENTITY; SECTIONS];
        let mut slots = sections.iter_mut();
        if let Some(slot) = slots.next() {
            *slot = Coefficients::low_pass(self.low_pass_hz, self.low_pass_q, self.sample_rate_hz)?;
        }
        for (slot, notch) in slots.zip(self.notches.iter()) {
            if let Some(spec) = notch {
                *slot = Coefficients::notch(spec.centre_hz, spec.q, self.sample_rate_hz)?;
            }
        }
        Ok(sections)
    }

    /// The bank as the telemetry describes it to the host ([`MeasurementFilter`]): the
    /// designed sections' coefficients, in the order they run, at the bank's rate.
    pub fn measurement_filter(&self) -> Result<MeasurementFilter, FilterError> {
        let sections = self.design()?;
        Ok(MeasurementFilter {
            sample_rate_hz: self.sample_rate_hz,
            sections: sections.map(|c| [c.b0, c.b1, c.b2, c.a1, c.a2]),
        })
    }
}

/// One channel's cascade.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Chain {
    sections: [Biquad; SECTIONS],
}

impl Chain {
    fn process(&mut self, x: f32) -> f32 {
        self.sections
            .iter_mut()
            .fold(x, |signal, section| section.process(signal))
    }
}

/// The IMU filter bank: six channels (gyro x, y, z, accelerometer x, y, z), each a
/// low-pass followed by three notches, run once per IMU sample. Per call: 24 sections,
/// 5 multiplies each; no branches on the data beyond the non-finite checks.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FilterBank {
    config: FilterBankConfig,
    chains: [Chain; IMU_CHANNELS],
}

impl FilterBank {
    /// Design the bank; every section starts reset (the first sample sets the steady
    /// state).
    pub fn new(config: FilterBankConfig) -> Result<Self, FilterError> {
        let designed = config.design()?;
        let mut chain = Chain {
            sections: designed.map(Biquad::new),
        };
        chain.sections.iter_mut().for_each(Biquad::reset);
        Ok(FilterBank {
            config,
            chains: [chain; IMU_CHANNELS],
        })
    }

    /// The design in force.
    pub const fn config(&self) -> &FilterBankConfig {
        &self.config
    }

    /// Replace the design (a new headspeed) keeping every section's state. A refused
    /// design leaves the bank as it was.
    ///
    /// The state of a notch settled on a level x is s₁ = s₂ = (1 − a₂)x/2, so with the
    /// new coefficients its output moves at once by ≈ ½(a₂′ − a₂)·x, and the transient
    /// that follows peaks at about twice the sum of those steps before it decays at the
    /// new poles' rate. Moving the three TREX 700L notches by 3 % of headspeed moves
    /// a steady signal by ≈ 0.5 % at first and < 1.1 % at the peak; a reset instead
    /// would turn the whole vibration present at that instant into a transient.
    pub fn retune(&mut self, config: FilterBankConfig) -> Result<(), FilterError> {
        let designed = config.design()?;
        for chain in self.chains.iter_mut() {
            for (section, coefficients) in chain.sections.iter_mut().zip(designed.iter()) {
                section.set_coefficients(*coefficients);
            }
        }
        self.config = config;
        Ok(())
    }

    /// Reset every section (see [`Biquad::reset`]).
    pub fn reset(&mut self) {
        for chain in self.chains.iter_mut() {
            chain.sections.iter_mut().for_each(Biquad::reset);
        }
    }

    /// Filter one IMU sample, channels in the order gyro x, y, z, accel x, y, z.
    pub fn process(&mut self, sample: [f32; IMU_CHANNELS]) -> [f32; IMU_CHANNELS] {
        let mut out = sample;
        for (value, chain) in out.iter_mut().zip(self.chains.iter_mut()) {
            *value = chain.process(*value);
        }
        out
    }

    /// Filter one IMU sample given as gyro \[rad/s\] and specific force \[m/s²\].
    pub fn process_imu(&mut self, gyro: [f32; 3], accel: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        let ([gx, gy, gz], [ax, ay, az]) = (gyro, accel);
        let [gx, gy, gz, ax, ay, az] = self.process([gx, gy, gz, ax, ay, az]);
        ([gx, gy, gz], [ax, ay, az])
    }

    /// Gain and phase \[rad\] of one channel's whole cascade at `f_hz` (the product of
    /// the sections' responses): the lag the bank adds to a signal at that frequency.
    pub fn response(&self, f_hz: f32) -> (f32, f32) {
        let fs = self.config.sample_rate_hz;
        self.chains
            .first()
            .map(|chain| {
                chain.sections.iter().fold((1.0, 0.0), |(gain, phase), s| {
                    let (g, p) = s.coefficients().response(f_hz, fs);
                    (gain * g, wrap_pi(phase + p))
                })
            })
            .unwrap_or((1.0, 0.0))
    }
}

#[cfg(test)]
mod tests;
