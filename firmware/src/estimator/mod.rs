//! Attitude estimation: a Mahony-class complementary filter on a unit quaternion, run
//! at the IMU rate, fusing the gyro with the gravity direction the accelerometer sees.
//!
//! # Axes and signs
//!
//! Body axes x forward, y right, z down; earth axes north, east, down. The quaternion
//! `q` takes body vectors to earth axes ([`Quaternion`]). The accelerometer measures
//! specific force `f = a − g_vec`: at rest and level it reads `(0, 0, −g)`.
//!
//! # The filter
//!
//! With ω the gyro rate, b̂ the bias estimate, K_p and K_i the gains:
//!
//! ```text
//! v̂ = q* ⊗ (0, 0, 0, 1) ⊗ q                 predicted down direction, body axes
//! â = −f / |f|                              measured down direction, body axes
//! e = â × v̂                                 |e| = sin(angle between them)
//! q̇ = ½ q ⊗ (0, ω − b̂ + K_p e)
//! ḃ = −K_i e
//! ```
//!
//! Why it converges: a fixed earth direction seen from the body evolves as
//! `v̂̇ = v̂ × ω_used`, so the correction term contributes
//! `v̂ × K_p(â × v̂) = K_p (â − (v̂·â) v̂)`: the part of â perpendicular to v̂, turning
//! the prediction toward the measurement at rate K_p (the crossover of the
//! complementary filter: below K_p rad/s the accelerometer rules, above it the gyro).
//! With a gyro bias b the steady state needs K_p e = b̂ − b, and ḃ = −K_i e then drives
//! b̂ → b with time constant K_p/K_i. e is always perpendicular to v̂, so the bias
//! component along the vertical (yaw rate when level) is not observable from gravity:
//! it stays where it was and ψ drifts with it.
//!
//! # Discrete update (Δt = 1/f_IMU)
//!
//! ```text
//! ω_c   = ω − b̂ₙ
//! eₙ    = â × v̂(qₙ)                     (0 if the accelerometer is gated)
//! qₙ₊₁  = normalise(qₙ ⊗ exp(½ (ω_c + K_p eₙ) Δt))
//! b̂ₙ₊₁  = clamp(b̂ₙ − K_i eₙ Δt, ±b_max)  (frozen while gated)
//! ```
//!
//! The exponential map `exp(½ θ) = (cos |θ|/2, sin(|θ|/2) θ/|θ|)` integrates a rate that
//! is constant over the sample exactly, so with zero gains a constant-rate rotation
//! gives the closed-form attitude, up to `f32` rounding; renormalising every step keeps
//! |q| = 1 to within a few ulps.
//!
//! # Accelerometer gating
//!
//! A helicopter manoeuvring, or vibrating through a resonance, adds acceleration to
//! gravity, and `f` stops pointing along the vertical. The correction (and the bias
//! integration) is used only while
//!
//! ```text
//! | |f| − g | ≤ band · g          (default band 0.1: 0.9 g … 1.1 g)
//! ```
//!
//! Outside it the filter coasts on the gyro. The test is on magnitude only: a steady
//! coordinated turn keeps |f| = g/cos φ close to g for small banks (1.064 g at 20°) and
//! pulls the estimate toward the apparent vertical; the hover and low-speed flight this
//! estimator is meant for keep that error small, and K_p sets how fast it builds.
//!
//! # Non-finite and corrupt input
//!
//! A NaN, infinite or out-of-range (> [`MAX_GYRO_RAD_S`]) gyro component *rejects* the
//! sample: nothing changes. A NaN or infinite accelerometer component, or a magnitude
//! outside the band, *gates* the accelerometer: the sample propagates on the gyro
//! alone. The state therefore stays finite whatever is fed, and [`UpdateKind`] reports
//! which path ran.
//!
//! # Level offsets
//!
//! A mounting misalignment (φ₀, θ₀) — the attitude the IMU reads when the airframe sits
//! level — is removed as a rotation, not by subtracting angles:
//! `q_airframe = q ⊗ q_m*` with `q_m = euler(φ₀, θ₀, 0)`, and the rates are rotated by
//! q_m into airframe axes. A level airframe then reads exactly zero roll and pitch; to
//! first order in the offsets the outputs are φ − φ₀ and θ − θ₀.
//!
//! # Why not the `ahrs` crate
//!
//! The `ahrs` crate's Mahony filter was considered. It is generic over `nalgebra`
//! (0.34, plus `simba` and `num-traits`), a second `nalgebra` beside the host tools'
//! one and a large amount of generic code for a 4-component quaternion. More to the
//! point it lacks what this vehicle needs: a NaN in the gyro or accelerometer
//! propagates into its quaternion; it has no accelerometer gating; its integral term is
//! unbounded (no anti-windup); it integrates with a first-order step; and it has no
//! Euler output, level offsets or rate output. Adding those means wrapping every update
//! anyway, so the filter is written here in plain `f32` with `libm`, on a four-field
//! [`Quaternion`].
//!
//! ```
//! use sweephold_firmware::estimator::{Mahony, MahonyConfig, UpdateKind};
//!
//! let mut ahrs = Mahony::new(MahonyConfig::helicopter(1000.0)).unwrap();
//! // At rest, rolled right by 0.1 rad: f = (0, −g sin φ, −g cos φ).
//! let g = 9.806_65_f32;
//! let accel = [0.0, -g * 0.1f32.sin(), -g * 0.1f32.cos()];
//! ahrs.initialise_from_accel(accel).unwrap();
//! assert_eq!(ahrs.update([0.0; 3], accel), UpdateKind::Fused);
//! assert!((ahrs.estimate().phi - 0.1).abs() < 1e-5);
//! ```

pub mod mahony;
pub mod quaternion;

pub use mahony::{
    Estimate, EstimatorError, LevelOffset, Mahony, MahonyConfig, UpdateCounts, UpdateKind,
    MAX_GYRO_RAD_S, STANDARD_GRAVITY,
};
pub use quaternion::Quaternion;

#[cfg(test)]
mod tests;
