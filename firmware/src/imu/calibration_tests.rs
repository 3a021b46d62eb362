//! Tests of `calibration`.
use super::*;

const DEG: f32 = core::f32::consts::PI / 180.0;

fn sample(gyro: [f32; 3], accel: [f32; 3]) -> ImuSample {
    ImuSample {
        gyro_rad_s: gyro,
        accel_m_s2: accel,
        temperature_c: 30.0,
        ..ImuSample::default()
    }
}

fn level() -> [f32; 3] {
    [0.0, 0.0, -GRAVITY_M_S2]
}

fn small(window: u32) -> CalibrationConfig {
    CalibrationConfig {
        window_samples: window,
        timeout_samples: 10 * window,
        ..CalibrationConfig::DEFAULT
    }
}

#[test]
fn still_constant_data_gives_the_exact_bias() {
    let bias = [0.0123_f32, -0.0045, 0.0078];
    let mut cal = GyroCalibration::default();
    for i in 1..1000 {
        assert_eq!(
            cal.feed(&sample(bias, level())),
            CalibrationStatus::Collecting,
            "sample {i}"
        );
    }
    let CalibrationStatus::Done(found) = cal.feed(&sample(bias, level())) else {
        panic!("not done after 1000 samples");
    };
    assert_eq!(found.gyro_rad_s, bias);
    assert_eq!(found.accel_mean_m_s2, level());
    assert_eq!(found.roll_rad, 0.0);
    assert_eq!(found.pitch_rad, 0.0);
    assert_eq!(found.temperature_c, 30.0);
    assert_eq!(found.correct_gyro(bias), [0.0; 3]);
    // Final: later samples change nothing.
    assert_eq!(
        cal.feed(&sample([1.0; 3], level())),
        CalibrationStatus::Done(found)
    );
    assert_eq!(cal.fed(), 1000);
}

#[test]
fn alternating_noise_averages_exactly() {
    // Dyadic values: the f64 sums and the mean are exact.
    let low = [0.0078125_f32, -0.00390625, 0.0];
    let high = [0.01171875_f32, 0.00390625, 0.001953125];
    let mut cal = GyroCalibration::new(small(100));
    let mut last = CalibrationStatus::Collecting;
    for i in 0..100 {
        let g = if i % 2 == 0 { low } else { high };
        last = cal.feed(&sample(g, level()));
    }
    let CalibrationStatus::Done(found) = last else {
        panic!("not done: {last:?}");
    };
    assert_eq!(found.gyro_rad_s, [0.009765625, 0.0, 0.0009765625]);
}

#[test]
fn movement_mid_window_restarts_and_only_the_new_window_counts() {
    let mut cal = GyroCalibration::new(small(100));
    let first = [0.01_f32, 0.0, 0.0];
    for _ in 0..60 {
        assert_eq!(
            cal.feed(&sample(first, level())),
            CalibrationStatus::Collecting
        );
    }
    // A 5 °/s roll: more than 1 °/s away from the mean.
    let status = cal.feed(&sample([first[0] + 5.0 * DEG, 0.0, 0.0], level()));
    assert_eq!(
        status,
        CalibrationStatus::Moved(Restart {
            count: 1,
            cause: Motion::Rotation
        })
    );
    assert_eq!(cal.collected(), 0);
    // Just inside the limit does not restart.
    let second = [-0.02_f32, 0.005, 0.0];
    assert_eq!(
        cal.feed(&sample(second, level())),
        CalibrationStatus::Collecting
    );
    assert_eq!(
        cal.feed(&sample([second[0] + 0.9 * DEG, 0.005, 0.0], level())),
        CalibrationStatus::Collecting
    );
    let mut last = CalibrationStatus::Collecting;
    for _ in 0..98 {
        last = cal.feed(&sample(second, level()));
    }
    let CalibrationStatus::Done(found) = last else {
        panic!("not done: {last:?}");
    };
    let expected_x =
        ((99.0 * f64::from(second[0]) + f64::from(second[0] + 0.9 * DEG)) / 100.0) as f32;
    assert_eq!(found.gyro_rad_s, [expected_x, 0.005, 0.0]);
    assert_eq!(cal.restarts(), 1);
    assert_eq!(cal.fed(), 161);
}

#[test]
fn a_steady_rotation_restarts_on_the_rate_limit() {
    let mut cal = GyroCalibration::new(small(100));
    // 6 °/s yaw, constant: every sample equals the window mean.
    let yaw = [0.0, 0.0, 6.0 * DEG];
    for i in 1..=5 {
        assert_eq!(
            cal.feed(&sample(yaw, level())),
            CalibrationStatus::Moved(Restart {
                count: i,
                cause: Motion::Rotation
            })
        );
    }
    // 4.9 °/s is inside the limit.
    assert_eq!(
        cal.feed(&sample([0.0, 0.0, 4.9 * DEG], level())),
        CalibrationStatus::Collecting
    );
}

#[test]
fn a_bump_restarts_on_the_accelerometer_norm() {
    let mut cal = GyroCalibration::new(small(100));
    for _ in 0..10 {
        cal.feed(&sample([0.0; 3], level()));
    }
    let bump = [0.0, 0.0, -GRAVITY_M_S2 - 0.3];
    assert_eq!(
        cal.feed(&sample([0.0; 3], bump)),
        CalibrationStatus::Moved(Restart {
            count: 1,
            cause: Motion::Acceleration
        })
    );
    for _ in 0..10 {
        assert_eq!(
            cal.feed(&sample([0.0; 3], level())),
            CalibrationStatus::Collecting
        );
    }
    // A lateral push that keeps the norm within 0.2 m/s² is not seen by the norm
    // check (the gyro check catches the rotation that comes with real pushes).
    assert_eq!(
        cal.feed(&sample([0.0; 3], [0.5, 0.0, -GRAVITY_M_S2])),
        CalibrationStatus::Collecting
    );
}

#[test]
fn not_gravity_and_not_finite_restart() {
    let mut cal = GyroCalibration::new(small(100));
    assert_eq!(
        cal.feed(&sample([0.0; 3], [0.0, 0.0, -8.5])),
        CalibrationStatus::Moved(Restart {
            count: 1,
            cause: Motion::NotGravity
        })
    );
    assert_eq!(
        cal.feed(&sample([f32::NAN, 0.0, 0.0], level())),
        CalibrationStatus::Moved(Restart {
            count: 2,
            cause: Motion::NotFinite
        })
    );
    let mut hot = sample([0.0; 3], level());
    hot.temperature_c = f32::INFINITY;
    assert_eq!(
        cal.feed(&hot),
        CalibrationStatus::Moved(Restart {
            count: 3,
            cause: Motion::NotFinite
        })
    );
}

#[test]
fn level_offsets_are_exact_for_a_tilted_still_accelerometer() {
    let g = f64::from(GRAVITY_M_S2);
    for (roll_deg, pitch_deg) in [(10.0_f64, -5.0_f64), (-3.0, 7.5), (0.0, 20.0)] {
        let (phi, theta) = (roll_deg.to_radians(), pitch_deg.to_radians());
        // f = (g sin θ, −g sin φ cos θ, −g cos φ cos θ).
        let f = [
            g * theta.sin(),
            -g * phi.sin() * theta.cos(),
            -g * phi.cos() * theta.cos(),
        ]
        .map(|v| v as f32);
        let mut cal = GyroCalibration::new(small(50));
        let mut last = CalibrationStatus::Collecting;
        for _ in 0..50 {
            last = cal.feed(&sample([0.0; 3], f));
        }
        let CalibrationStatus::Done(found) = last else {
            panic!("not done: {last:?}");
        };
        // Reference from the same f32 inputs, in f64.
        let [fx, fy, fz] = f.map(f64::from);
        assert_eq!(found.roll_rad, libm::atan2(-fy, -fz) as f32);
        assert_eq!(
            found.pitch_rad,
            libm::atan2(fx, libm::sqrt(fy * fy + fz * fz)) as f32
        );
        // And the angles themselves to f32 precision.
        assert!((f64::from(found.roll_rad) - phi).abs() < 1e-6, "{found:?}");
        assert!(
            (f64::from(found.pitch_rad) - theta).abs() < 1e-6,
            "{found:?}"
        );
    }
}

#[test]
fn times_out_when_never_still() {
    let config = CalibrationConfig {
        window_samples: 10,
        timeout_samples: 25,
        ..CalibrationConfig::DEFAULT
    };
    assert!(config.is_valid());
    let mut cal = GyroCalibration::new(config);
    let mut statuses = 0;
    for i in 0..25 {
        // Alternating ±5 °/s: every other sample moves.
        let w = if i % 2 == 0 { 5.0 * DEG } else { -5.0 * DEG };
        let status = cal.feed(&sample([w, 0.0, 0.0], level()));
        statuses += 1;
        if i < 24 {
            assert_ne!(status, CalibrationStatus::TimedOut, "sample {i}");
        } else {
            assert_eq!(status, CalibrationStatus::TimedOut);
        }
    }
    assert_eq!(statuses, 25);
    assert_eq!(
        cal.feed(&sample([0.0; 3], level())),
        CalibrationStatus::TimedOut
    );
    assert_eq!(cal.result(), Some(CalibrationStatus::TimedOut));
    cal.reset();
    assert_eq!(cal.fed(), 0);
    assert_eq!(cal.result(), None);
}

#[test]
fn nan_limits_are_safe_and_time_out() {
    let config = CalibrationConfig {
        max_gyro_deviation_rad_s: f32::NAN,
        max_gravity_error_m_s2: f32::NAN,
        window_samples: 5,
        timeout_samples: 8,
        ..CalibrationConfig::DEFAULT
    };
    assert!(!config.is_valid());
    let mut cal = GyroCalibration::new(config);
    let statuses: [CalibrationStatus; 8] =
        core::array::from_fn(|_| cal.feed(&sample([0.0; 3], level())));
    assert!(matches!(statuses[0], CalibrationStatus::Moved(_)));
    assert_eq!(statuses[7], CalibrationStatus::TimedOut);
    assert!(!CalibrationConfig {
        window_samples: 0,
        ..CalibrationConfig::DEFAULT
    }
    .is_valid());
    assert!(CalibrationConfig::DEFAULT.is_valid());
}
