//! The IMU mounting as a parameter: the 24 axis-aligned rotations, named and numbered as
//! ArduPilot's `enum Rotation` (`libraries/AP_Math/rotations.h`, the `ROTATION_*`
//! values of `AHRS_ORIENTATION` and of a hwdef's IMU line), and the pre-arm attitude
//! check.
//!
//! # Meaning
//!
//! A rotation named `ROLL_r_PITCH_p_YAW_y` maps a vector in the IMU's axes (as the
//! driver reports them with the identity [`Orientation`]: chip top face down, chip x
//! forward) to body axes (x forward, y right, z down) by
//!
//! ```text
//! v_body = R_z(y) · R_y(p) · R_x(r) · v_imu
//! ```
//!
//! (roll first, then pitch, then yaw, each a right-handed rotation about the body
//! axis), which is what ArduPilot's `Vector3::rotate` computes case by case; the tests
//! compare all 26 of its axis-aligned cases (two are aliases) with this product.
//! [`ImuRotation::None`] is the identity, the mounting the board has always assumed.
//! ArduPilot's driver frames are not this crate's chip frame, so a hwdef value is not
//! to be copied without checking the board (the tilt test of the pre-flight checklist).
//!
//! Betaflight's `CW0 … CW270FLIP` names cover only the 8 rotations that keep the board
//! flat; ArduPilot's names cover all 24, hence the choice.
//!
//! # Pre-arm attitude check
//!
//! [`check_level`] takes the accelerometer averaged at rest (the IMU's axes), rotates
//! it into body axes with the configured rotation and refuses when the body's tilt from
//! level, `acos(−f_z / |f|)` (the angle between the specific force and body "up"), is
//! above [`MAX_ARM_TILT_DEG`], or when the reading is not gravity (not finite, or its
//! norm more than [`MAX_GRAVITY_ERROR`] from g). A mounting that is wrong by 90° or
//! 180° about the body's x or y axis puts gravity on another axis (90°) or reverses it
//! (180°) and is refused. A mounting wrong only about the vertical axis (a yaw error)
//! leaves gravity on z and cannot be seen by an accelerometer at rest: the gyro's axes
//! are then swapped, which the checklist's tilt test finds.

use super::{Orientation, SignedAxis, GRAVITY_M_S2};

/// The largest tilt from level at which the board arms \[°\].
pub const MAX_ARM_TILT_DEG: f32 = 25.0;

/// The largest relative error of the averaged specific force's norm from g at rest.
pub const MAX_GRAVITY_ERROR: f32 = 0.2;

/// The 24 axis-aligned IMU mountings, ArduPilot's names and numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(non_camel_case_types, missing_docs)]
#[repr(u8)]
pub enum ImuRotation {
    None = 0,
    Yaw90 = 2,
    Yaw180 = 4,
    Yaw270 = 6,
    Roll180 = 8,
    Roll180Yaw90 = 10,
    Pitch180 = 12,
    Roll180Yaw270 = 14,
    Roll90 = 16,
    Roll90Yaw90 = 18,
    Roll270 = 20,
    Roll270Yaw90 = 22,
    Pitch90 = 24,
    Pitch270 = 25,
    Roll90Pitch90 = 28,
    Roll180Pitch90 = 29,
    Roll270Pitch90 = 30,
    Roll90Pitch180 = 31,
    Roll270Pitch180 = 32,
    Roll90Pitch270 = 33,
    Roll180Pitch270 = 34,
    Roll270Pitch270 = 35,
    Roll90Pitch180Yaw90 = 36,
    Roll90Yaw270 = 37,
}

/// ArduPilot's `ROTATION_PITCH_180_YAW_90`, the same rotation as [`ImuRotation::Roll180Yaw270`].
pub const ARDUPILOT_PITCH_180_YAW_90: u8 = 26;
/// ArduPilot's `ROTATION_PITCH_180_YAW_270`, the same rotation as [`ImuRotation::Roll180Yaw90`].
pub const ARDUPILOT_PITCH_180_YAW_270: u8 = 27;

impl ImuRotation {
    /// All 24, in ArduPilot's order.
    pub const ALL: [ImuRotation; 24] = [
        ImuRotation::None,
        ImuRotation::Yaw90,
        ImuRotation::Yaw180,
        ImuRotation::Yaw270,
        ImuRotation::Roll180,
        ImuRotation::Roll180Yaw90,
        ImuRotation::Pitch180,
        ImuRotation::Roll180Yaw270,
        ImuRotation::Roll90,
        ImuRotation::Roll90Yaw90,
        ImuRotation::Roll270,
        ImuRotation::Roll270Yaw90,
        ImuRotation::Pitch90,
        ImuRotation::Pitch270,
        ImuRotation::Roll90Pitch90,
        ImuRotation::Roll180Pitch90,
        ImuRotation::Roll270Pitch90,
        ImuRotation::Roll90Pitch180,
        ImuRotation::Roll270Pitch180,
        ImuRotation::Roll90Pitch270,
        ImuRotation::Roll180Pitch270,
        ImuRotation::Roll270Pitch270,
        ImuRotation::Roll90Pitch180Yaw90,
        ImuRotation::Roll90Yaw270,
    ];

    /// ArduPilot's number.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The rotation of ArduPilot's number `code` (26 and 27 are the aliases of 14 and
    /// 10); `None` for a number that is not an axis-aligned rotation.
    pub fn from_code(code: u8) -> Option<ImuRotation> {
        match code {
            ARDUPILOT_PITCH_180_YAW_90 => Some(ImuRotation::Roll180Yaw270),
            ARDUPILOT_PITCH_180_YAW_270 => Some(ImuRotation::Roll180Yaw90),
            _ => Self::ALL.iter().copied().find(|r| r.code() == code),
        }
    }

    /// (roll, pitch, yaw) in quarter turns.
    const fn quarter_turns(self) -> (u8, u8, u8) {
        use ImuRotation::*;
        match self {
            None => (0, 0, 0),
            Yaw90 => (0, 0, 1),
            Yaw180 => (0, 0, 2),
            Yaw270 => (0, 0, 3),
            Roll180 => (2, 0, 0),
            Roll180Yaw90 => (2, 0, 1),
            Pitch180 => (0, 2, 0),
            Roll180Yaw270 => (2, 0, 3),
            Roll90 => (1, 0, 0),
            Roll90Yaw90 => (1, 0, 1),
            Roll270 => (3, 0, 0),
            Roll270Yaw90 => (3, 0, 1),
            Pitch90 => (0, 1, 0),
            Pitch270 => (0, 3, 0),
            Roll90Pitch90 => (1, 1, 0),
            Roll180Pitch90 => (2, 1, 0),
            Roll270Pitch90 => (3, 1, 0),
            Roll90Pitch180 => (1, 2, 0),
            Roll270Pitch180 => (3, 2, 0),
            Roll90Pitch270 => (1, 3, 0),
            Roll180Pitch270 => (2, 3, 0),
            Roll270Pitch270 => (3, 3, 0),
            Roll90Pitch180Yaw90 => (1, 2, 1),
            Roll90Yaw270 => (1, 0, 3),
        }
    }

    /// The rotation matrix `R_z(yaw)·R_y(pitch)·R_x(roll)` (integer entries).
    pub fn matrix(self) -> [[i8; 3]; 3] {
        let (roll, pitch, yaw) = self.quarter_turns();
        let rx = axis_rotation(0, roll);
        let ry = axis_rotation(1, pitch);
        let rz = axis_rotation(2, yaw);
        multiply(&rz, &multiply(&ry, &rx))
    }

    /// The [`Orientation`] (signed axis map) the driver applies for this mounting.
    pub fn orientation(self) -> Orientation {
        let rows = self.matrix();
        let axes = rows.map(|row| {
            let mut picked = SignedAxis::PosX;
            for (column, &entry) in row.iter().enumerate() {
                picked = match (column, entry) {
                    (0, 1) => SignedAxis::PosX,
                    (0, -1) => SignedAxis::NegX,
                    (1, 1) => SignedAxis::PosY,
                    (1, -1) => SignedAxis::NegY,
                    (2, 1) => SignedAxis::PosZ,
                    (2, -1) => SignedAxis::NegZ,
                    _ => picked,
                };
            }
            picked
        });
        // A product of axis rotations is a proper signed permutation: never the
        // fallback, which is there only so that no path can panic.
        Orientation::new(axes).unwrap_or(Orientation::IDENTITY)
    }
}

/// cos and sin of `quarters` quarter turns.
const fn cos_sin(quarters: u8) -> (i8, i8) {
    match quarters % 4 {
        0 => (1, 0),
        1 => (0, 1),
        2 => (-1, 0),
        _ => (0, -1),
    }
}

/// The right-handed rotation by `quarters` quarter turns about axis `axis` (0 x, 1 y,
/// 2 z).
fn axis_rotation(axis: usize, quarters: u8) -> [[i8; 3]; 3] {
    let (c, s) = cos_sin(quarters);
    match axis {
        0 => [[1, 0, 0], [0, c, -s], [0, s, c]],
        1 => [[c, 0, s], [0, 1, 0], [-s, 0, c]],
        _ => [[c, -s, 0], [s, c, 0], [0, 0, 1]],
    }
}

fn multiply(a: &[[i8; 3]; 3], b: &[[i8; 3]; 3]) -> [[i8; 3]; 3] {
    let mut out = [[0i8; 3]; 3];
    for (out_row, a_row) in out.iter_mut().zip(a) {
        for (column, slot) in out_row.iter_mut().enumerate() {
            *slot = a_row
                .iter()
                .zip(b)
                .map(|(&x, b_row)| x * b_row.get(column).copied().unwrap_or(0))
                .sum();
        }
    }
    out
}

/// Why the pre-arm attitude check refused.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LevelError {
    /// A component is NaN or infinite.
    NotFinite,
    /// The norm is more than [`MAX_GRAVITY_ERROR`] from g: not at rest, or not gravity.
    NotGravity,
    /// The body is tilted from level by this many degrees, more than
    /// [`MAX_ARM_TILT_DEG`] (180 for upside down).
    Tilted(f32),
}

/// The body's tilt from level \[°\] for `accel_imu_m_s2`, the accelerometer averaged
/// at rest in the IMU's axes, mounted as `rotation`; refused as described in the
/// module documentation.
pub fn check_level(accel_imu_m_s2: [f32; 3], rotation: ImuRotation) -> Result<f32, LevelError> {
    if !accel_imu_m_s2.iter().all(|v| v.is_finite()) {
        return Err(LevelError::NotFinite);
    }
    let [x, y, z] = rotation.orientation().to_body(accel_imu_m_s2);
    let norm = libm::sqrtf(x * x + y * y + z * z);
    // The components are finite, so the norm is not NaN.
    if libm::fabsf(norm - GRAVITY_M_S2) > MAX_GRAVITY_ERROR * GRAVITY_M_S2 {
        return Err(LevelError::NotGravity);
    }
    // At rest and level the specific force is (0, 0, −g): "up" is −z.
    let cos_tilt = (-z / norm).clamp(-1.0, 1.0);
    let tilt_deg = libm::acosf(cos_tilt).to_degrees();
    if tilt_deg > MAX_ARM_TILT_DEG {
        return Err(LevelError::Tilted(tilt_deg));
    }
    Ok(tilt_deg)
}
