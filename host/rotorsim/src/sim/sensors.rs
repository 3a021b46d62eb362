//! The sensor set: what the flight controller reads ([`SensorReading`]), the
//! imperfections [`Sim`](super::Sim) puts on it ([`SensorNoise`]), and the true channels of
//! a state.

use crate::model::{self, STATE_LEN};

/// White noise, bias and latency of the sensor set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorNoise {
    /// Gyro noise, 1σ [rad/s].
    pub gyro_rad_s: f64,
    /// Attitude noise, 1σ \[rad\].
    pub attitude_rad: f64,
    /// Velocity noise, 1σ [m/s].
    pub velocity_m_s: f64,
    /// Accelerometer noise, 1σ [m/s²].
    pub accel_m_s2: f64,
    /// Constant bias per channel, order [p q r φ θ ψ u v w ax ay az] (SI units).
    pub bias: [f64; 12],
    /// Latency \[s\] (rounded to internal steps): the reading shows the aircraft this long ago.
    pub latency_s: f64,
}

impl SensorNoise {
    /// No noise, no bias, no latency.
    pub fn perfect() -> SensorNoise {
        SensorNoise {
            gyro_rad_s: 0.0,
            attitude_rad: 0.0,
            velocity_m_s: 0.0,
            accel_m_s2: 0.0,
            bias: [0.0; 12],
            latency_s: 0.0,
        }
    }
}

impl Default for SensorNoise {
    /// A realistic MEMS/INS set: 0.5 °/s gyro, 0.1° attitude, 0.05 m/s velocity,
    /// 0.05 m/s² accelerometer, no bias, no latency.
    fn default() -> SensorNoise {
        let deg = std::f64::consts::PI / 180.0;
        SensorNoise {
            gyro_rad_s: 0.5 * deg,
            attitude_rad: 0.1 * deg,
            velocity_m_s: 0.05,
            accel_m_s2: 0.05,
            bias: [0.0; 12],
            latency_s: 0.0,
        }
    }
}

/// What the flight controller reads: rates [rad/s], Euler angles \[rad\] (ψ wrapped to
/// (−π, π]), body velocity [m/s] and specific force [m/s²] (≈ (0, 0, −g) in hover).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SensorReading {
    /// Sequence number: increments on every fresh sample, repeats on a dropout.
    pub seq: u32,
    /// Time of the sample \[s\] (the simulation time when it was taken).
    pub time_s: f64,
    /// Roll rate.
    pub p: f64,
    /// Pitch rate.
    pub q: f64,
    /// Yaw rate.
    pub r: f64,
    /// Roll angle.
    pub phi: f64,
    /// Pitch angle.
    pub theta: f64,
    /// Heading, wrapped to (−π, π].
    pub psi: f64,
    /// Forward velocity, body axes.
    pub u: f64,
    /// Lateral velocity, body axes.
    pub v: f64,
    /// Vertical velocity, body axes (down positive).
    pub w: f64,
    /// Specific force along x.
    pub ax: f64,
    /// Specific force along y.
    pub ay: f64,
    /// Specific force along z.
    pub az: f64,
}

impl SensorReading {
    pub(super) fn channels(&self) -> [f64; 12] {
        [
            self.p, self.q, self.r, self.phi, self.theta, self.psi, self.u, self.v, self.w,
            self.ax, self.ay, self.az,
        ]
    }

    pub(super) fn with_channels(seq: u32, time_s: f64, c: [f64; 12]) -> SensorReading {
        SensorReading {
            seq,
            time_s,
            p: c[0],
            q: c[1],
            r: c[2],
            phi: c[3],
            theta: c[4],
            psi: c[5],
            u: c[6],
            v: c[7],
            w: c[8],
            ax: c[9],
            ay: c[10],
            az: c[11],
        }
    }
}

/// Wrap an angle to (−π, π].
pub fn wrap_angle(angle: f64) -> f64 {
    use std::f64::consts::PI;
    let wrapped = (angle + PI).rem_euclid(2.0 * PI) - PI;
    if wrapped <= -PI {
        wrapped + 2.0 * PI
    } else {
        wrapped
    }
}

/// True sensor channels of a state and the body force acting on it.
pub(super) fn truth(
    x: &[f64; STATE_LEN],
    force: [f64; 3],
    mass: f64,
    time_s: f64,
) -> SensorReading {
    SensorReading {
        seq: 0,
        time_s,
        p: x[model::P],
        q: x[model::Q],
        r: x[model::R],
        phi: x[model::PHI],
        theta: x[model::THETA],
        psi: wrap_angle(x[model::PSI]),
        u: x[model::U],
        v: x[model::V],
        w: x[model::W],
        ax: force[0] / mass,
        ay: force[1] / mass,
        az: force[2] / mass,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

        #[test]
        fn wrapped_angles_are_in_range_and_equivalent(angle in -1.0e4f64..1.0e4) {
            let wrapped = wrap_angle(angle);
            let pi = std::f64::consts::PI;
            proptest::prop_assert!(wrapped > -pi && wrapped <= pi);
            proptest::prop_assert!((wrapped.sin() - angle.sin()).abs() < 1e-9);
            proptest::prop_assert!((wrapped.cos() - angle.cos()).abs() < 1e-9);
        }
    }

    #[test]
    fn wrap_angle_stays_in_half_open_interval() {
        use std::f64::consts::PI;
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
    }
}
