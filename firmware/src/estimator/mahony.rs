//! The Mahony complementary filter (see the [module doc](super) for the maths).

use super::quaternion::Quaternion;

/// Standard gravity g₀ \[m/s²\].
pub const STANDARD_GRAVITY: f32 = 9.806_65;

/// A gyro sample with any |ω| above this \[rad/s\] (≈ 5700 °/s, beyond the full scale of
/// any MEMS gyro) is a corrupt sample and is rejected like a non-finite one. The bound
/// also keeps the rotation per sample finite and small.
pub const MAX_GYRO_RAD_S: f32 = 100.0;

/// Largest K_p·Δt accepted: the correction may turn the estimate by at most 0.1 rad
/// per sample (the explicit update is accurate only for K_p·Δt ≪ 1).
pub const MAX_KP_DT: f32 = 0.1;

/// Largest accepted level offset \[rad\] (45°: beyond that it is a mounting
/// orientation, not a misalignment).
pub const MAX_LEVEL_OFFSET_RAD: f32 = core::f32::consts::FRAC_PI_4;

/// Roll and pitch of the IMU relative to the airframe: the attitude the IMU reports
/// when the airframe sits level.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LevelOffset {
    /// Roll misalignment φ₀ \[rad\].
    pub roll_rad: f32,
    /// Pitch misalignment θ₀ \[rad\].
    pub pitch_rad: f32,
}

/// Settings of the filter.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MahonyConfig {
    /// The IMU rate the filter is updated at \[Hz\]; Δt = 1/rate.
    pub sample_rate_hz: f32,
    /// Proportional gain K_p \[rad/s per unit error\]: the complementary filter's
    /// crossover frequency.
    pub kp: f32,
    /// Integral gain K_i \[rad/s² per unit error\]: the bias estimator's.
    pub ki: f32,
    /// The accelerometer is used only while | |f| − g | ≤ band·g.
    pub accel_band: f32,
    /// g \[m/s²\].
    pub gravity_m_s2: f32,
    /// Each bias component is limited to ± this \[rad/s\] (anti-windup).
    pub bias_limit_rad_s: f32,
    /// IMU mounting misalignment removed from the outputs.
    pub level_offset: LevelOffset,
}

impl MahonyConfig {
    /// Defaults for a helicopter at IMU rate `sample_rate_hz`: K_p = 0.5 rad/s (the
    /// gyro rules above ≈ 0.08 Hz, where rotor vibration and manoeuvre accelerations
    /// live), K_i = 0.02 rad/s² (bias time constant K_p/K_i = 25 s), accelerometer band
    /// ±10 % of g, bias limit 0.1 rad/s (5.7 °/s), no level offset.
    pub const fn helicopter(sample_rate_hz: f32) -> Self {
        MahonyConfig {
            sample_rate_hz,
            kp: 0.5,
            ki: 0.02,
            accel_band: 0.1,
            gravity_m_s2: STANDARD_GRAVITY,
            bias_limit_rad_s: 0.1,
            level_offset: LevelOffset {
                roll_rad: 0.0,
                pitch_rad: 0.0,
            },
        }
    }

    /// Check every setting (see [`EstimatorError`]).
    pub fn validate(&self) -> Result<(), EstimatorError> {
        let all = [
            self.sample_rate_hz,
            self.kp,
            self.ki,
            self.accel_band,
            self.gravity_m_s2,
            self.bias_limit_rad_s,
            self.level_offset.roll_rad,
            self.level_offset.pitch_rad,
        ];
        if !all.iter().all(|v| v.is_finite()) {
            return Err(EstimatorError::NotFinite);
        }
        if !(self.sample_rate_hz > 0.0 && self.sample_rate_hz <= 100_000.0) {
            return Err(EstimatorError::SampleRateOutOfRange);
        }
        if self.kp < 0.0 || self.ki < 0.0 || self.kp / self.sample_rate_hz > MAX_KP_DT {
            return Err(EstimatorError::GainOutOfRange);
        }
        if !(self.accel_band > 0.0 && self.accel_band < 1.0) || self.gravity_m_s2 <= 0.0 {
            return Err(EstimatorError::AccelBandInvalid);
        }
        if self.bias_limit_rad_s < 0.0 {
            return Err(EstimatorError::BiasLimitNegative);
        }
        let offset = self.level_offset;
        if offset.roll_rad.abs() > MAX_LEVEL_OFFSET_RAD
            || offset.pitch_rad.abs() > MAX_LEVEL_OFFSET_RAD
        {
            return Err(EstimatorError::LevelOffsetOutOfRange);
        }
        Ok(())
    }
}

/// Why a setting or an initialisation is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EstimatorError {
    /// A setting is NaN or infinite.
    NotFinite,
    /// Sample rate not in (0, 100 000] Hz.
    SampleRateOutOfRange,
    /// K_p or K_i negative, or K_p·Δt above [`MAX_KP_DT`].
    GainOutOfRange,
    /// Accelerometer band not in (0, 1), or g ≤ 0.
    AccelBandInvalid,
    /// Negative bias limit.
    BiasLimitNegative,
    /// A level offset beyond ±[`MAX_LEVEL_OFFSET_RAD`].
    LevelOffsetOutOfRange,
    /// [`Mahony::initialise_from_accel`]: the specific force is not finite or not within
    /// the band around g (the vehicle is not at rest).
    AccelUnusable,
}

impl core::fmt::Display for EstimatorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            EstimatorError::NotFinite => "estimator setting is NaN or infinite",
            EstimatorError::SampleRateOutOfRange => "sample rate outside (0, 100000] Hz",
            EstimatorError::GainOutOfRange => "gains must be >= 0 with kp*dt <= 0.1",
            EstimatorError::AccelBandInvalid => "accelerometer band outside (0, 1) or g <= 0",
            EstimatorError::BiasLimitNegative => "bias limit must be >= 0",
            EstimatorError::LevelOffsetOutOfRange => "level offset beyond 45 degrees",
            EstimatorError::AccelUnusable => "specific force not finite or not near g",
        })
    }
}

/// What one update did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum UpdateKind {
    /// Gyro propagation with the accelerometer correction and bias update.
    Fused,
    /// Gyro propagation only: |f| outside the band around g (manoeuvring).
    AccelOutOfBand,
    /// Gyro propagation only: an accelerometer component is NaN or infinite.
    AccelNotFinite,
    /// Gyro propagation only: the caller gated the accelerometer
    /// ([`Mahony::propagate`]).
    AccelGated,
    /// Nothing changed: a gyro component is NaN, infinite or beyond
    /// [`MAX_GYRO_RAD_S`].
    GyroRejected,
}

/// The estimator's outputs, in airframe axes (level offsets removed).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate {
    /// Roll φ \[rad\], in (−π, π].
    pub phi: f32,
    /// Pitch θ \[rad\], in [−π/2, π/2].
    pub theta: f32,
    /// Yaw ψ \[rad\], in (−π, π] (relative: no magnetometer, so it starts at 0 and
    /// drifts with the unobservable part of the yaw-rate bias).
    pub psi: f32,
    /// Bias-corrected roll rate p \[rad/s\].
    pub p: f32,
    /// Bias-corrected pitch rate q \[rad/s\].
    pub q: f32,
    /// Bias-corrected yaw rate r \[rad/s\].
    pub r: f32,
}

/// Counts of each [`UpdateKind`] (saturating).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UpdateCounts {
    /// [`UpdateKind::Fused`].
    pub fused: u32,
    /// [`UpdateKind::AccelOutOfBand`], [`UpdateKind::AccelNotFinite`] and
    /// [`UpdateKind::AccelGated`].
    pub gyro_only: u32,
    /// [`UpdateKind::GyroRejected`].
    pub rejected: u32,
}

/// The attitude estimator. State: the IMU's attitude quaternion and the gyro bias.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Mahony {
    config: MahonyConfig,
    dt: f32,
    /// IMU-to-airframe rotation q_m (from the level offsets).
    mount: Quaternion,
    /// The IMU's attitude (IMU axes to earth axes).
    attitude: Quaternion,
    /// Gyro bias estimate b̂ \[rad/s\], IMU axes.
    bias: [f32; 3],
    /// The last accepted gyro sample minus b̂ \[rad/s\], IMU axes.
    rates: [f32; 3],
    counts: UpdateCounts,
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    let ([ax, ay, az], [bx, by, bz]) = (a, b);
    [ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx]
}

fn zip3(a: [f32; 3], b: [f32; 3], f: impl Fn(f32, f32) -> f32) -> [f32; 3] {
    let ([a0, a1, a2], [b0, b1, b2]) = (a, b);
    [f(a0, b0), f(a1, b1), f(a2, b2)]
}

impl Mahony {
    /// A filter at the identity attitude with zero bias (use
    /// [`Mahony::initialise_from_accel`] for a fast start).
    pub fn new(config: MahonyConfig) -> Result<Self, EstimatorError> {
        config.validate()?;
        let offset = config.level_offset;
        Ok(Mahony {
            config,
            dt: 1.0 / config.sample_rate_hz,
            mount: Quaternion::from_euler(offset.roll_rad, offset.pitch_rad, 0.0),
            attitude: Quaternion::IDENTITY,
            bias: [0.0; 3],
            rates: [0.0; 3],
            counts: UpdateCounts::default(),
        })
    }

    /// The settings.
    pub const fn config(&self) -> &MahonyConfig {
        &self.config
    }

    /// The IMU's attitude quaternion (IMU axes to earth axes), unit norm.
    pub const fn imu_attitude(&self) -> Quaternion {
        self.attitude
    }

    /// The airframe's attitude quaternion q ⊗ q_m* (airframe axes to earth axes).
    pub fn attitude(&self) -> Quaternion {
        self.attitude * self.mount.conjugate()
    }

    /// The gyro bias estimate b̂ \[rad/s\], IMU axes.
    pub const fn bias(&self) -> [f32; 3] {
        self.bias
    }

    /// Set the bias estimate (e.g. from a calibration at rest); components are clamped
    /// to the bias limit, non-finite ones set to 0.
    pub fn set_bias(&mut self, bias: [f32; 3]) {
        let limit = self.config.bias_limit_rad_s;
        self.bias = bias.map(|b| {
            if b.is_finite() {
                b.clamp(-limit, limit)
            } else {
                0.0
            }
        });
    }

    /// How many updates of each kind have run.
    pub const fn counts(&self) -> &UpdateCounts {
        &self.counts
    }

    /// Back to the identity attitude and zero bias.
    pub fn reset(&mut self) {
        self.attitude = Quaternion::IDENTITY;
        self.bias = [0.0; 3];
        self.rates = [0.0; 3];
    }

    /// Set roll and pitch from one specific-force sample `accel` \[m/s²\], IMU axes,
    /// taken at rest; yaw and bias are kept. At rest f = (g sin θ, −g sin φ cos θ,
    /// −g cos φ cos θ), so
    ///
    /// ```text
    /// φ = atan2(−f_y, −f_z),   θ = atan2(f_x, √(f_y² + f_z²))
    /// ```
    ///
    /// Refused ([`EstimatorError::AccelUnusable`], state unchanged) unless the sample is
    /// finite and within the accelerometer band around g.
    pub fn initialise_from_accel(&mut self, accel: [f32; 3]) -> Result<(), EstimatorError> {
        if self.accel_direction(accel).is_err() {
            return Err(EstimatorError::AccelUnusable);
        }
        let [fx, fy, fz] = accel;
        let phi = libm::atan2f(-fy, -fz);
        let theta = libm::atan2f(fx, libm::sqrtf(fy * fy + fz * fz));
        let (_, _, psi) = self.attitude.to_euler();
        self.attitude = Quaternion::from_euler(phi, theta, psi);
        Ok(())
    }

    /// −f/|f| (the measured down direction) if `accel` is usable.
    fn accel_direction(&self, accel: [f32; 3]) -> Result<[f32; 3], UpdateKind> {
        if !accel.iter().all(|f| f.is_finite()) {
            return Err(UpdateKind::AccelNotFinite);
        }
        let [fx, fy, fz] = accel;
        let norm = libm::sqrtf(fx * fx + fy * fy + fz * fz);
        let g = self.config.gravity_m_s2;
        // Written so that an overflowed (infinite) norm fails the test.
        let in_band = (norm - g).abs() <= self.config.accel_band * g;
        if !in_band {
            return Err(UpdateKind::AccelOutOfBand);
        }
        let inverse = -1.0 / norm;
        Ok(accel.map(|f| f * inverse))
    }

    /// One IMU sample: `gyro` \[rad/s\] and specific force `accel` \[m/s²\], IMU axes.
    /// Bounded time: one exponential map, one square root, no loops over data.
    pub fn update(&mut self, gyro: [f32; 3], accel: [f32; 3]) -> UpdateKind {
        self.step(gyro, Some(accel))
    }

    /// One IMU sample propagated on the gyro alone, the accelerometer gated by the caller
    /// (a manoeuvre in which the specific force is known not to point along gravity): as
    /// [`update`](Self::update) with the correction and the bias update off. Returns
    /// [`UpdateKind::AccelGated`], or [`UpdateKind::GyroRejected`] for a corrupt gyro.
    pub fn propagate(&mut self, gyro: [f32; 3]) -> UpdateKind {
        self.step(gyro, None)
    }

    fn step(&mut self, gyro: [f32; 3], accel: Option<[f32; 3]>) -> UpdateKind {
        if !gyro
            .iter()
            .all(|w| w.is_finite() && w.abs() <= MAX_GYRO_RAD_S)
        {
            self.counts.rejected = self.counts.rejected.saturating_add(1);
            return UpdateKind::GyroRejected;
        }
        let corrected = zip3(gyro, self.bias, |w, b| w - b);
        let direction = match accel {
            Some(accel) => self.accel_direction(accel),
            None => Err(UpdateKind::AccelGated),
        };
        let (error, kind) = match direction {
            Ok(measured) => (
                cross(measured, self.attitude.down_in_body()),
                UpdateKind::Fused,
            ),
            Err(kind) => ([0.0; 3], kind),
        };
        let (kp, ki, dt) = (self.config.kp, self.config.ki, self.dt);
        // ω_used = ω − b̂ + K_p e; rotation over the sample: ω_used·Δt.
        let rotation = zip3(corrected, error, |w, e| (w + kp * e) * dt);
        let next = (self.attitude * Quaternion::from_rotation_vector(rotation)).normalized();
        if let Some(next) = next {
            self.attitude = next;
        }
        if kind == UpdateKind::Fused {
            // b̂ ← clamp(b̂ − K_i e Δt, ±limit)
            let limit = self.config.bias_limit_rad_s;
            self.bias = zip3(self.bias, error, |b, e| {
                (b - ki * e * dt).clamp(-limit, limit)
            });
            self.counts.fused = self.counts.fused.saturating_add(1);
        } else {
            self.counts.gyro_only = self.counts.gyro_only.saturating_add(1);
        }
        self.rates = corrected;
        kind
    }

    /// Attitude and bias-corrected rates in airframe axes:
    ///
    /// ```text
    /// q_airframe = q ⊗ q_m*,  (φ, θ, ψ) = euler(q_airframe),  (p, q, r) = q_m ⊗ (ω − b̂) ⊗ q_m*
    /// ```
    pub fn estimate(&self) -> Estimate {
        let (phi, theta, psi) = self.attitude().to_euler();
        let [p, q, r] = self.mount.rotate(self.rates);
        Estimate {
            phi,
            theta,
            psi,
            p,
            q,
            r,
        }
    }
}
