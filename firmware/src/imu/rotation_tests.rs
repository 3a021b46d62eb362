//! The 24 mountings against ArduPilot's `Vector3::rotate`, and the pre-arm level check
//! over every pair of configured and actual mounting.

use super::rotation::*;
use super::{Orientation, GRAVITY_M_S2};

/// ArduPilot's `Vector3<T>::rotate` (`libraries/AP_Math/vector3.cpp`), its
/// axis-aligned cases transcribed statement by statement.
fn ardupilot_rotate(code: u8, v: [f32; 3]) -> [f32; 3] {
    let [mut x, mut y, mut z] = v;
    let mut tmp;
    match code {
        0 => {}
        2 => {
            tmp = x;
            x = -y;
            y = tmp;
        }
        4 => {
            x = -x;
            y = -y;
        }
        6 => {
            tmp = x;
            x = y;
            y = -tmp;
        }
        8 => {
            y = -y;
            z = -z;
        }
        10 => {
            tmp = x;
            x = y;
            y = tmp;
            z = -z;
        }
        12 => {
            x = -x;
            z = -z;
        }
        14 => {
            tmp = x;
            x = -y;
            y = -tmp;
            z = -z;
        }
        16 => {
            tmp = z;
            z = y;
            y = -tmp;
        }
        18 => {
            tmp = z;
            z = y;
            y = -tmp;
            tmp = x;
            x = -y;
            y = tmp;
        }
        20 => {
            tmp = z;
            z = -y;
            y = tmp;
        }
        22 => {
            tmp = z;
            z = -y;
            y = tmp;
            tmp = x;
            x = -y;
            y = tmp;
        }
        24 => {
            tmp = z;
            z = -x;
            x = tmp;
        }
        25 => {
            tmp = z;
            z = x;
            x = -tmp;
        }
        26 => {
            z = -z;
            tmp = -x;
            x = -y;
            y = tmp;
        }
        27 => {
            x = -x;
            z = -z;
            tmp = x;
            x = y;
            y = -tmp;
        }
        28 => {
            tmp = z;
            z = y;
            y = -tmp;
            tmp = z;
            z = -x;
            x = tmp;
        }
        29 => {
            y = -y;
            z = -z;
            tmp = z;
            z = -x;
            x = tmp;
        }
        30 => {
            tmp = z;
            z = -y;
            y = tmp;
            tmp = z;
            z = -x;
            x = tmp;
        }
        31 => {
            tmp = z;
            z = y;
            y = -tmp;
            x = -x;
            z = -z;
        }
        32 => {
            tmp = z;
            z = -y;
            y = tmp;
            x = -x;
            z = -z;
        }
        33 => {
            tmp = z;
            z = y;
            y = -tmp;
            tmp = z;
            z = x;
            x = -tmp;
        }
        34 => {
            y = -y;
            z = -z;
            tmp = z;
            z = x;
            x = -tmp;
        }
        35 => {
            tmp = z;
            z = -y;
            y = tmp;
            tmp = z;
            z = x;
            x = -tmp;
        }
        36 => {
            tmp = z;
            z = y;
            y = -tmp;
            x = -x;
            z = -z;
            tmp = x;
            x = -y;
            y = tmp;
        }
        37 => {
            tmp = z;
            z = y;
            y = -tmp;
            tmp = x;
            x = y;
            y = -tmp;
        }
        _ => panic!("not an axis-aligned ArduPilot rotation: {code}"),
    }
    [x, y, z]
}

#[test]
fn every_rotation_maps_vectors_as_ardupilot_rotates_them() {
    let probes = [[1.0, 2.0, 3.0], [-0.5, 7.0, -11.0], [0.0, -4.0, 0.25]];
    let codes = ImuRotation::ALL
        .iter()
        .map(|r| r.code())
        .chain([ARDUPILOT_PITCH_180_YAW_90, ARDUPILOT_PITCH_180_YAW_270]);
    for code in codes {
        let rotation = ImuRotation::from_code(code).unwrap();
        for v in probes {
            assert_eq!(
                rotation.orientation().to_body(v),
                ardupilot_rotate(code, v),
                "ArduPilot rotation {code} ({rotation:?}) on {v:?}"
            );
        }
    }
}

#[test]
fn the_24_rotations_are_distinct_and_none_is_the_old_default() {
    assert_eq!(ImuRotation::None.orientation(), Orientation::IDENTITY);
    for (i, a) in ImuRotation::ALL.iter().enumerate() {
        for b in ImuRotation::ALL.iter().skip(i + 1) {
            assert_ne!(a.orientation(), b.orientation(), "{a:?} = {b:?}");
        }
    }
}

#[test]
fn codes_round_trip_and_others_are_refused() {
    for rotation in ImuRotation::ALL {
        assert_eq!(ImuRotation::from_code(rotation.code()), Some(rotation));
    }
    // 45° rotations, the odd ArduPilot ones and out-of-range numbers.
    for code in [1, 3, 38, 39, 40, 41, 42, 43, 44, 100, 255] {
        assert_eq!(ImuRotation::from_code(code), None, "{code}");
    }
}

/// What the IMU reads at rest with the body tilted by `roll_deg` about x, mounted as
/// `actual`.
fn reading_at_rest(actual: ImuRotation, roll_deg: f32) -> [f32; 3] {
    let phi = roll_deg.to_radians();
    // f = (0, −g·sin φ, −g·cos φ) for a roll φ (calibration.rs's level-offset formulas).
    let body = [0.0, -GRAVITY_M_S2 * phi.sin(), -GRAVITY_M_S2 * phi.cos()];
    actual.orientation().to_chip(body)
}

/// Whether `configured` differs from `actual` only by a turn about body z.
fn differs_only_in_yaw(configured: ImuRotation, actual: ImuRotation) -> bool {
    let down = actual.orientation().to_chip([0.0, 0.0, 1.0]);
    configured.orientation().to_body(down) == [0.0, 0.0, 1.0]
}

#[test]
fn the_right_mounting_arms_and_a_wrong_one_is_refused_over_all_pairs() {
    let mut refused_pairs = 0;
    for actual in ImuRotation::ALL {
        let reading = reading_at_rest(actual, 0.0);
        let mut accepted = 0;
        for configured in ImuRotation::ALL {
            let result = check_level(reading, configured);
            if configured == actual {
                assert_eq!(result, Ok(0.0), "{actual:?} configured right");
            }
            if differs_only_in_yaw(configured, actual) {
                // Invisible to an accelerometer at rest (module documentation).
                assert!(result.is_ok(), "{actual:?} as {configured:?}");
                accepted += 1;
            } else {
                // 90° or 180° off about a horizontal axis: gravity on x or y (90°
                // tilt) or reversed (180°).
                match result {
                    Err(LevelError::Tilted(tilt)) => {
                        assert!(tilt == 90.0 || tilt == 180.0, "{tilt}");
                        refused_pairs += 1;
                    }
                    other => panic!("{actual:?} as {configured:?}: {other:?}"),
                }
            }
        }
        // The right one and its three yaw twins.
        assert_eq!(accepted, 4, "{actual:?}");
    }
    assert_eq!(refused_pairs, 24 * 20);
}

#[test]
fn the_tilt_limit_is_25_degrees() {
    for rotation in ImuRotation::ALL {
        let tilt = check_level(reading_at_rest(rotation, 20.0), rotation).unwrap();
        assert!((tilt - 20.0).abs() < 1e-3, "{tilt}");
        assert!(matches!(
            check_level(reading_at_rest(rotation, 26.0), rotation),
            Err(LevelError::Tilted(t)) if (t - 26.0).abs() < 1e-3
        ));
    }
}

#[test]
fn a_reading_that_is_not_gravity_is_refused() {
    let rotation = ImuRotation::None;
    assert_eq!(
        check_level([0.0, 0.0, -0.7 * GRAVITY_M_S2], rotation),
        Err(LevelError::NotGravity)
    );
    assert_eq!(
        check_level([0.0, 0.0, 0.0], rotation),
        Err(LevelError::NotGravity)
    );
    assert_eq!(
        check_level([f32::NAN, 0.0, -GRAVITY_M_S2], rotation),
        Err(LevelError::NotFinite)
    );
    assert_eq!(
        check_level([0.0, f32::INFINITY, -GRAVITY_M_S2], rotation),
        Err(LevelError::NotFinite)
    );
}

#[test]
fn a_mounting_after_another_rotates_as_the_two_in_turn() {
    // Every pair of the 24 mountings, on a vector with three distinct components.
    let v = [0.3, -1.7, 2.9];
    for outer in ImuRotation::ALL {
        for inner in ImuRotation::ALL {
            let composed = outer.orientation().after(inner.orientation());
            let in_turn = outer.orientation().to_body(inner.orientation().to_body(v));
            assert_eq!(composed.to_body(v), in_turn, "{outer:?} after {inner:?}");
            // And it is still a proper rotation the driver accepts.
            assert_eq!(Orientation::new(composed.axes()), Some(composed));
        }
    }
    assert_eq!(
        Orientation::IDENTITY.after(Orientation::TOP_UP_X_FORWARD),
        Orientation::TOP_UP_X_FORWARD
    );
}
