//! Boot calibration: gyro bias and level offsets from a window of still samples.
//!
//! [`GyroCalibration`] is fed one [`ImuSample`] per read (no loop of its own, O(1) per
//! sample). It averages `window_samples` samples (1000: 1 s at 1 kHz) and checks each
//! one for stillness against the mean of the window so far:
//!
//! * every gyro axis within `max_gyro_deviation_rad_s` (1 °/s) of its running mean —
//!   a hand on the airframe or a gust turns it by far more; the noise at rest (≈ 0.05 °/s
//!   rms) does not come close;
//! * every gyro axis within `max_gyro_rate_rad_s` (5 °/s, ten times the chip's typical
//!   ±0.5 °/s zero-rate offset) of zero — a *steady* rotation keeps each sample near the
//!   window mean and would pass the first check;
//! * the specific-force norm within `max_accel_norm_deviation_m_s2` (0.2 m/s²) of its
//!   running mean — a push or a bump;
//! * the norm within `max_gravity_error_m_s2` (1 m/s²) of g — a reading that is not
//!   gravity at rest (wrong range, a moving vehicle) cannot give a level reference;
//! * every value finite.
//!
//! A sample that fails restarts the window at the next sample ([`CalibrationStatus::Moved`]).
//! The whole procedure is bounded by `timeout_samples` (10 000: 10 s):
//! [`CalibrationStatus::TimedOut`] then, and the caller decides (e.g. refuse to arm).
//! It is a rotor-stopped procedure: rotor vibration exceeds the limits on purpose.
//!
//! Sums are kept in `f64`, so N identical `f32` samples average to exactly that value
//! (f32 has 24 significant bits; 2²⁹ samples still add exactly in 53). The Earth's rate
//! (≤ 7.3·10⁻⁵ rad/s) is part of the bias found; it is far below the noise.
//!
//! # Level offsets
//!
//! With body axes x forward, y right, z down and the Euler angles roll φ, pitch θ, the
//! NED "down" unit vector seen in body axes is the third column of the direction-cosine
//! matrix, `d = (−sin θ, sin φ cos θ, cos φ cos θ)`. An accelerometer measures specific
//! force `f = a − g·d`; at rest `a = 0`, so
//!
//! ```text
//! f_x = g sin θ,   f_y = −g sin φ cos θ,   f_z = −g cos φ cos θ.
//! ```
//!
//! Hence `−f_y / −f_z = tan φ` and `f_x / √(f_y² + f_z²) = tan θ` (for |θ| < 90°,
//! cos θ > 0):
//!
//! ```text
//! φ₀ = atan2(−f_y, −f_z),   θ₀ = atan2(f_x, √(f_y² + f_z²)).
//! ```
//!
//! Both use the window's mean specific force, so noise averages out, and neither depends
//! on g or on the accelerometer's scale. Taken with the aircraft standing level, φ₀ and
//! θ₀ are the mounting misalignment of the IMU, which the estimator subtracts from its
//! attitude; on a slope the slope is counted as misalignment.

use super::{ImuSample, GRAVITY_M_S2};

/// Calibration window and stillness limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationConfig {
    /// Samples averaged, all still (0 counts as 1).
    pub window_samples: u32,
    /// Largest deviation of any gyro axis from its running window mean \[rad/s\].
    pub max_gyro_deviation_rad_s: f32,
    /// Largest reading of any gyro axis \[rad/s\] (bias included).
    pub max_gyro_rate_rad_s: f32,
    /// Largest deviation of the specific-force norm from its running window mean
    /// \[m/s²\].
    pub max_accel_norm_deviation_m_s2: f32,
    /// Largest difference between the specific-force norm and g \[m/s²\].
    pub max_gravity_error_m_s2: f32,
    /// Samples fed in total (restarts included) before giving up.
    pub timeout_samples: u32,
}

impl CalibrationConfig {
    /// 1 s window and 10 s timeout at 1 kHz, 1 °/s, 5 °/s, 0.2 m/s², 1 m/s² (see the
    /// module documentation).
    pub const DEFAULT: CalibrationConfig = CalibrationConfig {
        window_samples: 1000,
        max_gyro_deviation_rad_s: core::f32::consts::PI / 180.0,
        max_gyro_rate_rad_s: 5.0 * core::f32::consts::PI / 180.0,
        max_accel_norm_deviation_m_s2: 0.2,
        max_gravity_error_m_s2: 1.0,
        timeout_samples: 10_000,
    };

    /// Whether every limit is finite and positive, the window non-empty and the timeout
    /// at least one window long. An invalid configuration is still safe to run: a NaN
    /// limit fails every sample, so the calibration times out.
    pub fn is_valid(&self) -> bool {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        self.window_samples > 0
            && self.timeout_samples >= self.window_samples
            && positive(self.max_gyro_deviation_rad_s)
            && positive(self.max_gyro_rate_rad_s)
            && positive(self.max_accel_norm_deviation_m_s2)
            && positive(self.max_gravity_error_m_s2)
    }
}

impl Default for CalibrationConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the calibration found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bias {
    /// Gyro bias, body axes \[rad/s\]: subtract from every gyro reading.
    pub gyro_rad_s: [f32; 3],
    /// Roll of the IMU at rest, φ₀ = atan2(−f_y, −f_z) \[rad\].
    pub roll_rad: f32,
    /// Pitch of the IMU at rest, θ₀ = atan2(f_x, √(f_y² + f_z²)) \[rad\].
    pub pitch_rad: f32,
    /// Mean specific force over the window, body axes \[m/s²\].
    pub accel_mean_m_s2: [f32; 3],
    /// Mean die temperature over the window \[°C\] (the bias drifts with it).
    pub temperature_c: f32,
}

impl Bias {
    /// `gyro − bias`, per axis.
    pub fn correct_gyro(&self, gyro_rad_s: [f32; 3]) -> [f32; 3] {
        let [x, y, z] = gyro_rad_s;
        let [bx, by, bz] = self.gyro_rad_s;
        [x - bx, y - by, z - bz]
    }
}

/// Which stillness check a sample failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Motion {
    /// A gyro axis left its running mean, or zero, by more than its limit.
    Rotation,
    /// The specific-force norm left its running mean by more than the limit.
    Acceleration,
    /// The specific-force norm is too far from g.
    NotGravity,
    /// A value was NaN or infinite.
    NotFinite,
}

/// A restart of the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Restart {
    /// Restarts so far, this one included.
    pub count: u32,
    /// The check that failed.
    pub cause: Motion,
}

/// Result of feeding one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CalibrationStatus {
    /// The window is filling.
    Collecting,
    /// The sample failed a stillness check; the window restarts with the next sample.
    Moved(Restart),
    /// Finished (every later feed returns the same).
    Done(Bias),
    /// `timeout_samples` fed without a complete still window (final).
    TimedOut,
}

/// Gyro-bias and level calibration, fed one sample at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroCalibration {
    config: CalibrationConfig,
    fed: u32,
    restarts: u32,
    count: u32,
    gyro_sum: [f64; 3],
    accel_sum: [f64; 3],
    norm_sum: f64,
    temperature_sum: f64,
    finished: Option<CalibrationStatus>,
}

impl Default for GyroCalibration {
    fn default() -> Self {
        Self::new(CalibrationConfig::DEFAULT)
    }
}

impl GyroCalibration {
    /// A calibration that has seen nothing.
    pub const fn new(config: CalibrationConfig) -> Self {
        GyroCalibration {
            config,
            fed: 0,
            restarts: 0,
            count: 0,
            gyro_sum: [0.0; 3],
            accel_sum: [0.0; 3],
            norm_sum: 0.0,
            temperature_sum: 0.0,
            finished: None,
        }
    }

    /// The configuration.
    pub const fn config(&self) -> CalibrationConfig {
        self.config
    }

    /// Still samples in the current window.
    pub const fn collected(&self) -> u32 {
        self.count
    }

    /// Window restarts so far.
    pub const fn restarts(&self) -> u32 {
        self.restarts
    }

    /// Samples fed so far (restarts included).
    pub const fn fed(&self) -> u32 {
        self.fed
    }

    /// The final status, once done or timed out.
    pub const fn result(&self) -> Option<CalibrationStatus> {
        self.finished
    }

    /// Start over, as if new.
    pub fn reset(&mut self) {
        *self = Self::new(self.config);
    }

    /// Feed one sample.
    pub fn feed(&mut self, sample: &ImuSample) -> CalibrationStatus {
        if let Some(done) = self.finished {
            return done;
        }
        self.fed = self.fed.saturating_add(1);
        let status = match self.check(sample) {
            Some(cause) => {
                self.restarts = self.restarts.saturating_add(1);
                self.clear_window();
                debug!("gyro calibration restart {=u32}", self.restarts);
                CalibrationStatus::Moved(Restart {
                    count: self.restarts,
                    cause,
                })
            }
            None => {
                self.accumulate(sample);
                if self.count >= self.config.window_samples.max(1) {
                    CalibrationStatus::Done(self.bias())
                } else {
                    CalibrationStatus::Collecting
                }
            }
        };
        let status = match status {
            CalibrationStatus::Done(_) => status,
            _ if self.fed >= self.config.timeout_samples => CalibrationStatus::TimedOut,
            _ => status,
        };
        if matches!(
            status,
            CalibrationStatus::Done(_) | CalibrationStatus::TimedOut
        ) {
            self.finished = Some(status);
        }
        status
    }

    /// The stillness check that `sample` fails against the window so far, if any.
    fn check(&self, sample: &ImuSample) -> Option<Motion> {
        let finite = sample
            .gyro_rad_s
            .iter()
            .chain(sample.accel_m_s2.iter())
            .chain(core::iter::once(&sample.temperature_c))
            .all(|v| v.is_finite());
        if !finite {
            return Some(Motion::NotFinite);
        }
        let norm = norm(sample.accel_m_s2);
        // `!(x <= limit)`: a NaN limit or deviation fails.
        let within = |deviation: f64, limit: f32| deviation.abs() <= f64::from(limit);
        if !within(
            norm - f64::from(GRAVITY_M_S2),
            self.config.max_gravity_error_m_s2,
        ) {
            return Some(Motion::NotGravity);
        }
        let turning = sample
            .gyro_rad_s
            .iter()
            .any(|&w| !within(f64::from(w), self.config.max_gyro_rate_rad_s));
        if turning {
            return Some(Motion::Rotation);
        }
        if self.count == 0 {
            return None;
        }
        let n = f64::from(self.count);
        let rotating = sample
            .gyro_rad_s
            .iter()
            .zip(self.gyro_sum.iter())
            .any(|(&w, &sum)| {
                !within(f64::from(w) - sum / n, self.config.max_gyro_deviation_rad_s)
            });
        if rotating {
            return Some(Motion::Rotation);
        }
        if !within(
            norm - self.norm_sum / n,
            self.config.max_accel_norm_deviation_m_s2,
        ) {
            return Some(Motion::Acceleration);
        }
        None
    }

    fn accumulate(&mut self, sample: &ImuSample) {
        for (sum, &w) in self.gyro_sum.iter_mut().zip(sample.gyro_rad_s.iter()) {
            *sum += f64::from(w);
        }
        for (sum, &a) in self.accel_sum.iter_mut().zip(sample.accel_m_s2.iter()) {
            *sum += f64::from(a);
        }
        self.norm_sum += norm(sample.accel_m_s2);
        self.temperature_sum += f64::from(sample.temperature_c);
        self.count = self.count.saturating_add(1);
    }

    fn clear_window(&mut self) {
        self.count = 0;
        self.gyro_sum = [0.0; 3];
        self.accel_sum = [0.0; 3];
        self.norm_sum = 0.0;
        self.temperature_sum = 0.0;
    }

    /// Means of the current (non-empty) window and the level offsets.
    fn bias(&self) -> Bias {
        let n = f64::from(self.count.max(1));
        let gyro = self.gyro_sum.map(|sum| (sum / n) as f32);
        let accel = self.accel_sum.map(|sum| sum / n);
        let [fx, fy, fz] = accel;
        Bias {
            gyro_rad_s: gyro,
            roll_rad: libm::atan2(-fy, -fz) as f32,
            pitch_rad: libm::atan2(fx, libm::sqrt(fy * fy + fz * fz)) as f32,
            accel_mean_m_s2: accel.map(|a| a as f32),
            temperature_c: (self.temperature_sum / n) as f32,
        }
    }
}

/// Euclidean norm, in `f64`.
fn norm(v: [f32; 3]) -> f64 {
    let [x, y, z] = v.map(f64::from);
    libm::sqrt(x * x + y * y + z * z)
}

#[cfg(test)]
#[path = "calibration_tests.rs"]
mod tests;
