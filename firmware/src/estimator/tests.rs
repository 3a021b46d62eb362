//! Estimator tests against closed forms: constant-rate rotation, the specific force of
//! a static tilt, the observable part of a constant gyro bias.

use super::*;
use proptest::prelude::*;

const G: f32 = STANDARD_GRAVITY;
const FS: f32 = 1000.0;

fn gains(kp: f32, ki: f32) -> MahonyConfig {
    MahonyConfig {
        kp,
        ki,
        ..MahonyConfig::helicopter(FS)
    }
}

/// Specific force at rest for attitude (φ, θ): f = q* ⊗ (0, 0, −g) ⊗ q.
fn at_rest(phi: f32, theta: f32) -> [f32; 3] {
    Quaternion::from_euler(phi, theta, 0.3).rotate_inverse([0.0, 0.0, -G])
}

fn close(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() <= tolerance
}

/// |a − b| modulo 2π.
fn angle_between(a: f32, b: f32) -> f32 {
    let d = (a - b).rem_euclid(core::f32::consts::TAU);
    d.min(core::f32::consts::TAU - d)
}

#[test]
fn the_specific_force_at_rest_has_the_documented_form() {
    let (phi, theta) = (0.4f32, -0.3f32);
    let f = at_rest(phi, theta);
    let expected = [
        G * theta.sin(),
        -G * phi.sin() * theta.cos(),
        -G * phi.cos() * theta.cos(),
    ];
    for (a, b) in f.iter().zip(expected.iter()) {
        assert!(close(*a, *b, 1e-5), "{f:?} vs {expected:?}");
    }
    assert_eq!(at_rest(0.0, 0.0)[2], -G);
}

#[test]
fn constant_rate_about_each_axis_integrates_to_the_closed_form_angle() {
    // 0.7 rad/s for 1 s, gains 0, accelerometer NaN (ignored either way).
    for axis in 0..3 {
        let mut ahrs = Mahony::new(gains(0.0, 0.0)).unwrap();
        let mut gyro = [0.0; 3];
        gyro[axis] = 0.7;
        for _ in 0..1000 {
            assert_eq!(ahrs.update(gyro, [f32::NAN; 3]), UpdateKind::AccelNotFinite);
        }
        let e = ahrs.estimate();
        let mut expected = [0.0; 3];
        expected[axis] = 0.7;
        for (got, want) in [e.phi, e.theta, e.psi].iter().zip(expected.iter()) {
            assert!(close(*got, *want, 2e-5), "axis {axis}: {e:?}");
        }
        let rates = [e.p, e.q, e.r];
        assert_eq!(rates, gyro);
    }
}

#[test]
fn yaw_wraps_into_minus_pi_to_pi() {
    let mut ahrs = Mahony::new(gains(0.0, 0.0)).unwrap();
    // 2 rad/s for 2 s: ψ = 4 rad ≡ 4 − 2π.
    for _ in 0..2000 {
        ahrs.update([0.0, 0.0, 2.0], [0.0, 0.0, -G]);
    }
    let psi = ahrs.estimate().psi;
    assert!(close(psi, 4.0 - core::f32::consts::TAU, 5e-5), "{psi}");
}

#[test]
fn a_constant_rate_about_any_axis_gives_the_exponential_map() {
    let omega = [0.3f32, -0.2, 0.5];
    let mut ahrs = Mahony::new(gains(0.0, 0.0)).unwrap();
    for _ in 0..2000 {
        ahrs.update(omega, [f32::NAN; 3]);
    }
    // q(t) = exp(½ ω t), t = 2 s, computed in f64.
    let t = 2.0f64;
    let w = omega.map(f64::from);
    let angle = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt() * t;
    let s = (angle / 2.0).sin() / (angle / t);
    let expected = [(angle / 2.0).cos(), w[0] * s, w[1] * s, w[2] * s];
    let got = ahrs.imu_attitude().to_array();
    for (g, e) in got.iter().zip(expected.iter()) {
        assert!((f64::from(*g) - e).abs() < 2e-5, "{got:?} vs {expected:?}");
    }
}

#[test]
fn a_static_tilt_converges_to_the_exact_angles() {
    for (phi, theta) in [(0.3f32, -0.2f32), (-1.0, 0.5), (0.05, 1.2), (2.5, 0.1)] {
        let mut ahrs = Mahony::new(gains(2.0, 0.0)).unwrap();
        let accel = at_rest(phi, theta);
        for _ in 0..10_000 {
            ahrs.update([0.0; 3], accel);
        }
        let e = ahrs.estimate();
        assert!(close(e.phi, phi, 1e-4), "{phi} {theta}: {e:?}");
        assert!(close(e.theta, theta, 1e-4), "{phi} {theta}: {e:?}");
    }
}

#[test]
fn the_correction_rate_is_kp() {
    // Small error: e ≈ angle, so the error decays as exp(−K_p t).
    let mut ahrs = Mahony::new(gains(1.0, 0.0)).unwrap();
    let accel = at_rest(0.01, 0.0);
    for _ in 0..1000 {
        ahrs.update([0.0; 3], accel);
    }
    let remaining = 0.01 - ahrs.estimate().phi;
    let expected = 0.01 * (-1.0f32).exp();
    assert!(
        close(remaining, expected, 2e-5),
        "{remaining} vs {expected}"
    );
}

#[test]
fn a_constant_gyro_bias_is_estimated_and_the_attitude_error_stays_bounded() {
    let (phi, theta) = (0.1f32, -0.05f32);
    let bias = [0.02f32, -0.015, 0.01];
    let (kp, ki) = (1.0, 0.1);
    let mut ahrs = Mahony::new(MahonyConfig {
        bias_limit_rad_s: 0.1,
        ..gains(kp, ki)
    })
    .unwrap();
    let accel = at_rest(phi, theta);
    ahrs.initialise_from_accel(accel).unwrap();
    let mut worst = 0.0f32;
    for _ in 0..120_000 {
        assert_eq!(ahrs.update(bias, accel), UpdateKind::Fused);
        let e = ahrs.estimate();
        worst = worst.max((e.phi - phi).abs()).max((e.theta - theta).abs());
    }
    // The bound: the error grows only until the correction K_p·e matches the
    // unestimated bias, |e| ≤ |b|/K_p.
    let magnitude = bias.iter().map(|b| b * b).sum::<f32>().sqrt();
    assert!(worst < magnitude / kp, "worst {worst}");
    let e = ahrs.estimate();
    assert!(
        close(e.phi, phi, 1e-4) && close(e.theta, theta, 1e-4),
        "{e:?}"
    );

    // Observable part: b minus its component along the vertical v̂ (body axes).
    let down = [-accel[0] / G, -accel[1] / G, -accel[2] / G];
    let along: f32 = bias.iter().zip(down.iter()).map(|(b, d)| b * d).sum();
    let estimated = ahrs.bias();
    for i in 0..3 {
        let observable = bias[i] - along * down[i];
        assert!(
            close(estimated[i], observable, 2e-4),
            "{estimated:?} vs observable part of {bias:?}"
        );
    }
    // The rates come out bias-corrected: what remains is the unobservable part.
    let e = ahrs.estimate();
    for (rate, d) in [e.p, e.q, e.r].iter().zip(down.iter()) {
        assert!(close(*rate, along * d, 2e-4));
    }
}

#[test]
fn the_bias_estimate_is_limited() {
    let mut ahrs = Mahony::new(MahonyConfig {
        bias_limit_rad_s: 0.01,
        ..gains(1.0, 1.0)
    })
    .unwrap();
    let accel = at_rest(0.0, 0.0);
    for _ in 0..20_000 {
        ahrs.update([0.05, 0.0, 0.0], accel);
    }
    assert_eq!(ahrs.bias()[0], 0.01);
    ahrs.set_bias([1.0, f32::NAN, -1.0]);
    assert_eq!(ahrs.bias(), [0.01, 0.0, -0.01]);
}

#[test]
fn the_accelerometer_is_gated_outside_its_band() {
    // K_i = 0: the bias stays 0, so gyro-only steps with zero rate must not turn.
    let mut ahrs = Mahony::new(gains(1.0, 0.0)).unwrap();
    let tilted = at_rest(0.2, 0.0);
    let scaled = |k: f32| tilted.map(|f| f * k);
    assert_eq!(ahrs.update([0.0; 3], scaled(1.09)), UpdateKind::Fused);
    let before = ahrs;
    for k in [1.11, 0.89, 2.0, 0.0, 1e30] {
        assert_eq!(ahrs.update([0.0; 3], scaled(k)), UpdateKind::AccelOutOfBand);
    }
    // Gyro-only with zero rate: nothing moves (beyond the renormalisation's last bit).
    let (now, then) = (
        ahrs.imu_attitude().to_array(),
        before.imu_attitude().to_array(),
    );
    assert!(now
        .iter()
        .zip(then.iter())
        .all(|(a, b)| close(*a, *b, 2e-7)));
    assert_eq!(ahrs.bias(), before.bias());
    assert_eq!(ahrs.counts().gyro_only, 5);
    assert_eq!(ahrs.counts().fused, 1);
}

#[test]
fn non_finite_input_does_not_poison_the_state() {
    let mut ahrs = Mahony::new(gains(1.0, 0.1)).unwrap();
    let accel = at_rest(0.1, 0.2);
    ahrs.initialise_from_accel(accel).unwrap();
    for _ in 0..100 {
        ahrs.update([0.01, 0.0, 0.0], accel);
    }
    let before = ahrs;
    for bad in [f32::NAN, f32::INFINITY, -f32::INFINITY, 101.0] {
        for axis in 0..3 {
            let mut gyro = [0.0; 3];
            gyro[axis] = bad;
            assert_eq!(ahrs.update(gyro, accel), UpdateKind::GyroRejected);
            assert_eq!(ahrs.update(gyro, [f32::NAN; 3]), UpdateKind::GyroRejected);
        }
    }
    assert_eq!(ahrs.imu_attitude(), before.imu_attitude());
    assert_eq!(ahrs.bias(), before.bias());
    assert_eq!(ahrs.estimate(), before.estimate());
    assert_eq!(ahrs.counts().rejected, 24);

    // A NaN accelerometer sample: gyro-only, identical to a gated one.
    let mut gated = ahrs;
    assert_eq!(
        ahrs.update([0.01, 0.0, 0.0], [0.0, f32::NAN, -G]),
        UpdateKind::AccelNotFinite
    );
    assert_eq!(
        gated.update([0.01, 0.0, 0.0], [0.0, 0.0, -5.0]),
        UpdateKind::AccelOutOfBand
    );
    assert_eq!(ahrs.imu_attitude(), gated.imu_attitude());
    assert_eq!(ahrs.bias(), gated.bias());
    // And it carries on normally.
    for _ in 0..10_000 {
        ahrs.update([0.0; 3], accel);
    }
    let e = ahrs.estimate();
    assert!(
        close(e.phi, 0.1, 1e-3) && close(e.theta, 0.2, 1e-3),
        "{e:?}"
    );
}

#[test]
fn initialise_from_accel_sets_roll_and_pitch_exactly() {
    for (phi, theta) in [(0.0f32, 0.0f32), (0.3, -0.2), (-1.2, 0.7), (3.0, -1.4)] {
        let mut ahrs = Mahony::new(MahonyConfig::helicopter(FS)).unwrap();
        ahrs.initialise_from_accel(at_rest(phi, theta)).unwrap();
        let e = ahrs.estimate();
        assert!(
            close(e.phi, phi, 2e-6) && close(e.theta, theta, 2e-6),
            "{e:?}"
        );
        assert!(close(e.psi, 0.0, 1e-6), "{e:?}");
    }
    let mut ahrs = Mahony::new(MahonyConfig::helicopter(FS)).unwrap();
    for bad in [
        [f32::NAN, 0.0, -G],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, -1.5 * G],
        [0.0, f32::INFINITY, -G],
    ] {
        assert_eq!(
            ahrs.initialise_from_accel(bad),
            Err(EstimatorError::AccelUnusable)
        );
    }
    assert_eq!(ahrs.imu_attitude(), Quaternion::IDENTITY);
}

#[test]
fn level_offsets_are_removed_as_a_rotation() {
    let offset = LevelOffset {
        roll_rad: 0.03,
        pitch_rad: -0.02,
    };
    let config = MahonyConfig {
        level_offset: offset,
        ..MahonyConfig::helicopter(FS)
    };
    let mount = Quaternion::from_euler(offset.roll_rad, offset.pitch_rad, 0.0);
    for (phi, theta) in [(0.0f32, 0.0f32), (0.2, 0.1), (-0.4, 0.3)] {
        // The IMU's attitude is the airframe's followed by the mount: q = q_b ⊗ q_m.
        let airframe = Quaternion::from_euler(phi, theta, 0.0);
        let imu = airframe * mount;
        let accel = imu.rotate_inverse([0.0, 0.0, -G]);
        // A body roll rate of 1 rad/s, as the tilted gyro sees it.
        let gyro = mount.rotate_inverse([1.0, 0.0, 0.0]);
        let mut ahrs = Mahony::new(config).unwrap();
        ahrs.initialise_from_accel(accel).unwrap();
        ahrs.update(gyro, accel);
        let e = ahrs.estimate();
        // One 1 ms step of 1 rad/s roll moves φ by 1 mrad (plus a little correction).
        assert!(close(e.phi, phi + 1e-3, 2e-5), "{e:?}");
        assert!(close(e.theta, theta, 2e-5), "{e:?}");
        assert!(close(e.p, 1.0, 1e-6) && close(e.q, 0.0, 1e-6) && close(e.r, 0.0, 1e-6));
    }
}

#[test]
fn the_configuration_is_validated() {
    let base = MahonyConfig::helicopter(FS);
    let cases = [
        (
            MahonyConfig {
                kp: f32::NAN,
                ..base
            },
            EstimatorError::NotFinite,
        ),
        (
            MahonyConfig {
                sample_rate_hz: 0.0,
                ..base
            },
            EstimatorError::SampleRateOutOfRange,
        ),
        (
            MahonyConfig { kp: -1.0, ..base },
            EstimatorError::GainOutOfRange,
        ),
        (
            MahonyConfig { ki: -1.0, ..base },
            EstimatorError::GainOutOfRange,
        ),
        (
            MahonyConfig { kp: 101.0, ..base },
            EstimatorError::GainOutOfRange,
        ),
        (
            MahonyConfig {
                accel_band: 1.0,
                ..base
            },
            EstimatorError::AccelBandInvalid,
        ),
        (
            MahonyConfig {
                gravity_m_s2: 0.0,
                ..base
            },
            EstimatorError::AccelBandInvalid,
        ),
        (
            MahonyConfig {
                bias_limit_rad_s: -0.1,
                ..base
            },
            EstimatorError::BiasLimitNegative,
        ),
        (
            MahonyConfig {
                level_offset: LevelOffset {
                    roll_rad: 0.0,
                    pitch_rad: 0.8,
                },
                ..base
            },
            EstimatorError::LevelOffsetOutOfRange,
        ),
    ];
    for (config, error) in cases {
        assert_eq!(Mahony::new(config), Err(error));
    }
    assert!(Mahony::new(base).is_ok());
}

#[test]
fn euler_angles_round_trip_through_the_quaternion() {
    use core::f32::consts::PI;
    for (phi, theta, psi) in [
        (0.0, 0.0, 0.0),
        (0.5, -0.4, 3.0),
        (-3.0, 1.2, -2.0),
        (1.0, 0.0, PI),
        (0.0, 0.0, -PI),
    ] {
        let (a, b, c) = Quaternion::from_euler(phi, theta, psi).to_euler();
        assert!(close(a, phi, 2e-6) && close(b, theta, 2e-6), "{a} {b} {c}");
        assert!(angle_between(c, psi) < 2e-6, "{c}");
        assert!(c > -PI && c <= PI);
    }
}

proptest! {
    #[test]
    fn the_quaternion_stays_normalised_and_finite(
        samples in proptest::collection::vec(
            (
                proptest::array::uniform3(-40.0f32..40.0),
                proptest::array::uniform3(-30.0f32..30.0),
            ),
            1..400,
        ),
        poison in proptest::collection::vec(proptest::num::f32::ANY, 6),
    ) {
        let mut ahrs = Mahony::new(gains(2.0, 0.5)).unwrap();
        for (n, (gyro, accel)) in samples.iter().enumerate() {
            let (mut gyro, mut accel) = (*gyro, *accel);
            if n % 50 == 7 {
                gyro = [poison[0], poison[1], poison[2]];
                accel = [poison[3], poison[4], poison[5]];
            }
            ahrs.update(gyro, accel);
            let q = ahrs.imu_attitude();
            prop_assert!(q.is_finite());
            prop_assert!((q.norm() - 1.0).abs() < 1e-6, "{:?}", q);
            let e = ahrs.estimate();
            for v in [e.phi, e.theta, e.psi, e.p, e.q, e.r] {
                prop_assert!(v.is_finite());
            }
            prop_assert!(e.psi > -core::f32::consts::PI && e.psi <= core::f32::consts::PI);
            prop_assert!(ahrs.bias().iter().all(|b| b.abs() <= 0.1));
        }
    }

    #[test]
    fn euler_round_trip(
        phi in -3.1f32..3.1,
        theta in -1.5f32..1.5,
        psi in -3.1f32..3.1,
    ) {
        let (a, b, c) = Quaternion::from_euler(phi, theta, psi).to_euler();
        prop_assert!(close(a, phi, 1e-4) && close(b, theta, 1e-4) && close(c, psi, 1e-4),
            "{} {} {} vs {} {} {}", a, b, c, phi, theta, psi);
        let q = Quaternion::from_euler(phi, theta, psi);
        prop_assert!((q.norm() - 1.0).abs() < 1e-6);
        // rotate and rotate_inverse undo each other.
        let v = [1.0, -2.0, 0.5];
        let back = q.rotate_inverse(q.rotate(v));
        for (x, y) in back.iter().zip(v.iter()) {
            prop_assert!(close(*x, *y, 1e-5));
        }
        // down_in_body is the closed form of rotate_inverse(e_z).
        let down = q.down_in_body();
        let rotated = q.rotate_inverse([0.0, 0.0, 1.0]);
        for (x, y) in down.iter().zip(rotated.iter()) {
            prop_assert!(close(*x, *y, 1e-6));
        }
    }
}

#[test]
fn propagate_is_update_with_the_accelerometer_gated() {
    let config = MahonyConfig::helicopter(1000.0);
    let mut gated = Mahony::new(config).unwrap();
    let mut by_nan = Mahony::new(config).unwrap();
    gated.set_bias([0.01, -0.02, 0.005]);
    by_nan.set_bias([0.01, -0.02, 0.005]);
    for k in 0..500 {
        let gyro = [0.3, -0.1 * (k as f32 * 0.01).sin(), 0.05];
        assert_eq!(gated.propagate(gyro), UpdateKind::AccelGated);
        assert_eq!(
            by_nan.update(gyro, [f32::NAN; 3]),
            UpdateKind::AccelNotFinite
        );
    }
    assert_eq!(gated.imu_attitude(), by_nan.imu_attitude());
    assert_eq!(gated.bias(), by_nan.bias());
    assert_eq!(gated.counts().gyro_only, 500);
    assert_eq!(
        gated.propagate([f32::NAN, 0.0, 0.0]),
        UpdateKind::GyroRejected
    );
}
