//! Trim in level flight by Newton iteration.
//!
//! Unknowns z = [θ0, θ1s, θ1c, θ0_TR, φ, θ, β1c, β1s]; equations: the eight accelerations
//! [u̇ v̇ ẇ ṗ q̇ ṙ β̇1c β̇1s] = 0 with zero body rates, heading north (ψ = 0) and the ground
//! velocity (V, 0, 0) north, i.e. body velocity R_bn·(V, 0, 0) = V(cos θ, sin φ sin θ,
//! cos φ sin θ). The inflow is solved inside every evaluation (Glauert momentum), so it is
//! trimmed too. Newton: J Δz = −r with a central-difference Jacobian, steps limited to
//! 0.1 rad per unknown.

use std::fmt;

use crate::model::{self, Model, ModelFlags, State, STATE_LEN};
use crate::vehicle::{BladePitch, Helicopter};

/// Metres per second in one knot.
pub const KNOT: f64 = 1852.0 / 3600.0;
/// The fastest speed [kt] `trim` accepts.
pub const MAX_TRIM_SPEED_KT: f64 = 120.0;

/// A trimmed flight condition.
#[derive(Clone, Debug, PartialEq)]
pub struct Trim {
    /// Forward speed [kt].
    pub speed_kt: f64,
    /// Stick fractions [lat, lon, ped, col].
    pub controls: [f64; 4],
    /// Blade pitches [rad].
    pub blade_pitch_rad: BladePitch,
    /// Roll attitude φ [rad].
    pub phi: f64,
    /// Pitch attitude θ [rad].
    pub theta: f64,
    /// Longitudinal tip-path-plane tilt β1c [rad] (forward positive, relative to the shaft).
    pub beta1c: f64,
    /// Lateral tip-path-plane tilt β1s [rad] (left positive).
    pub beta1s: f64,
    /// Main-rotor induced inflow λ_i (divided by ΩR).
    pub inflow: f64,
    /// Tail-rotor induced inflow λ_i.
    pub tail_inflow: f64,
    /// Main-rotor coning β0 [rad].
    pub coning: f64,
    /// Main-rotor thrust [N].
    pub main_thrust: f64,
    /// Tail-rotor thrust [N].
    pub tail_thrust: f64,
    /// Largest absolute residual acceleration at the solution (m/s², rad/s², rad/s).
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// The full trimmed state vector (position at the origin).
    pub state: State,
}

/// Why a trim failed.
#[derive(Clone, Debug, PartialEq)]
pub enum TrimError {
    /// The speed is negative, not finite or above [`MAX_TRIM_SPEED_KT`].
    InvalidSpeed(f64),
    /// Newton did not bring the residual below the tolerance.
    NotConverged {
        /// Largest residual reached.
        residual: f64,
        /// Iterations spent.
        iterations: usize,
    },
    /// The Jacobian was singular.
    SingularJacobian,
    /// The solution needs a stick beyond ±1 (the gearing's range).
    ControlOutOfRange {
        /// Control name (lat, lon, ped, col).
        control: &'static str,
        /// Stick fraction needed.
        value: f64,
    },
}

impl fmt::Display for TrimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TrimError::InvalidSpeed(v) => {
                write!(
                    f,
                    "invalid trim speed {v} kt (expected 0 to {MAX_TRIM_SPEED_KT} kt)"
                )
            }
            TrimError::NotConverged {
                residual,
                iterations,
            } => write!(
                f,
                "trim did not converge: residual {residual:.3e} after {iterations} iterations"
            ),
            TrimError::SingularJacobian => write!(f, "trim Jacobian is singular"),
            TrimError::ControlOutOfRange { control, value } => {
                write!(
                    f,
                    "trim needs {control} stick {value:.3}, beyond the range ±1"
                )
            }
        }
    }
}

impl std::error::Error for TrimError {}

/// Names of the stick channels in control order.
pub const CONTROL_NAMES: [&str; 4] = ["lat", "lon", "ped", "col"];

const UNKNOWNS: usize = 8;
const TOLERANCE: f64 = 1e-10;

/// The state vector of level flight at `speed` [m/s] north with attitude φ, θ and
/// flapping β1c, β1s.
fn level_state(speed: f64, phi: f64, theta: f64, beta: [f64; 2], inflow: f64) -> [f64; STATE_LEN] {
    let mut x = [0.0; STATE_LEN];
    let (sin_phi, cos_phi) = phi.sin_cos();
    let (sin_theta, cos_theta) = theta.sin_cos();
    x[model::U] = speed * cos_theta;
    x[model::V] = speed * sin_phi * sin_theta;
    x[model::W] = speed * cos_phi * sin_theta;
    x[model::PHI] = phi;
    x[model::THETA] = theta;
    x[model::BETA1C] = beta[0];
    x[model::BETA1S] = beta[1];
    x[model::LAMBDA] = inflow;
    x
}

fn pitch_of(z: &[f64; UNKNOWNS]) -> BladePitch {
    BladePitch {
        theta0: z[0],
        theta1s: z[1],
        theta1c: z[2],
        theta0_tr: z[3],
    }
}

/// Residual accelerations for the unknowns z.
fn residual(
    model: &Model,
    speed: f64,
    z: &[f64; UNKNOWNS],
    warm: &mut [f64; 2],
) -> [f64; UNKNOWNS] {
    let x = level_state(speed, z[4], z[5], [z[6], z[7]], warm[0]);
    let (dx, _) = model.derivative(&x, &pitch_of(z), [0.0; 3], ModelFlags::default(), warm);
    [
        dx[model::U],
        dx[model::V],
        dx[model::W],
        dx[model::P],
        dx[model::Q],
        dx[model::R],
        dx[model::BETA1C],
        dx[model::BETA1S],
    ]
}

/// Solve the dense system `a·x = b` in place by Gaussian elimination with partial
/// pivoting; `None` when a pivot vanishes.
pub(crate) fn solve_dense<const N: usize>(
    mut a: [[f64; N]; N],
    mut b: [f64; N],
) -> Option<[f64; N]> {
    for col in 0..N {
        let pivot = (col..N).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 || !a[pivot][col].is_finite() {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..N {
            let factor = a[row][col] / a[col][col];
            if factor != 0.0 {
                let pivot_row = a[col];
                for (target, source) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                    *target -= factor * source;
                }
                b[row] -= factor * b[col];
            }
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let mut sum = b[row];
        for k in row + 1..N {
            sum -= a[row][k] * x[k];
        }
        x[row] = sum / a[row][row];
    }
    Some(x)
}

fn max_abs(values: &[f64]) -> f64 {
    values.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

/// Trim `heli` in level flight at `speed_kt` knots (0 = hover), heading north.
pub fn trim(heli: &Helicopter, speed_kt: f64) -> Result<Trim, TrimError> {
    if !speed_kt.is_finite() || !(0.0..=MAX_TRIM_SPEED_KT).contains(&speed_kt) {
        return Err(TrimError::InvalidSpeed(speed_kt));
    }
    let model = Model::new(heli.clone());
    let speed = speed_kt * KNOT;

    // Start: hover momentum theory for the collective, C_T = W/(ρA(ΩR)²),
    // θ0 = 3[2C_T/(aσ) − θ_tw/4 + λ/2], λ = √(C_T/2); level attitude, no flapping.
    let ct = heli.mass * heli.gravity / model.main.thrust_scale;
    let lambda = (ct / 2.0).sqrt();
    let theta0 = 3.0 * (2.0 * ct / model.main.a_sigma - model.main.twist / 4.0 + lambda / 2.0);
    let mut z = [
        theta0,
        0.0,
        0.0,
        heli.gearing[2].centre,
        0.0,
        heli.shaft_tilt,
        0.0,
        0.0,
    ];
    let mut warm = [lambda, 0.0];
    let mut r = residual(&model, speed, &z, &mut warm);
    let mut iterations = 0;
    while max_abs(&r) > TOLERANCE && iterations < 60 {
        iterations += 1;
        let mut jacobian = [[0.0; UNKNOWNS]; UNKNOWNS];
        for j in 0..UNKNOWNS {
            let h = 1e-6;
            let mut plus = z;
            plus[j] += h;
            let mut minus = z;
            minus[j] -= h;
            let rp = residual(&model, speed, &plus, &mut warm);
            let rm = residual(&model, speed, &minus, &mut warm);
            for i in 0..UNKNOWNS {
                jacobian[i][j] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let step = solve_dense(jacobian, r.map(|v| -v)).ok_or(TrimError::SingularJacobian)?;
        // Limit the step so a poor start cannot throw the attitude around.
        let largest = max_abs(&step);
        let scale = if largest > 0.1 { 0.1 / largest } else { 1.0 };
        for (zi, si) in z.iter_mut().zip(step) {
            *zi += scale * si;
        }
        r = residual(&model, speed, &z, &mut warm);
    }
    let residual_max = max_abs(&r);
    // Written so that a NaN residual also fails.
    if residual_max.is_nan() || residual_max > TOLERANCE * 100.0 {
        return Err(TrimError::NotConverged {
            residual: residual_max,
            iterations,
        });
    }
    let pitch = pitch_of(&z);
    let controls = heli.controls_for(&pitch);
    for (value, control) in controls.iter().zip(CONTROL_NAMES) {
        if value.abs() > 1.0 {
            return Err(TrimError::ControlOutOfRange {
                control,
                value: *value,
            });
        }
    }
    let x = level_state(speed, z[4], z[5], [z[6], z[7]], warm[0]);
    let (_, loads) = model.derivative(&x, &pitch, [0.0; 3], ModelFlags::default(), &mut warm);
    let mut state = x;
    state[model::LAMBDA] = loads.main_inflow;
    Ok(Trim {
        speed_kt,
        controls,
        blade_pitch_rad: pitch,
        phi: z[4],
        theta: z[5],
        beta1c: z[6],
        beta1s: z[7],
        inflow: loads.main_inflow,
        tail_inflow: loads.tail_inflow,
        coning: loads.coning,
        main_thrust: loads.main_thrust,
        tail_thrust: loads.tail_thrust,
        residual: residual_max,
        iterations,
        state: State(state),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bo105_trims_in_hover_and_at_20_and_40_kt() {
        let heli = Helicopter::bo105();
        for speed in [0.0, 20.0, 40.0] {
            let t = trim(&heli, speed).unwrap();
            assert!(t.residual < 1e-6, "{speed} kt residual {}", t.residual);
            assert!(
                t.controls.iter().all(|c| c.abs() < 0.9),
                "{speed} kt margin {:?}",
                t.controls
            );
        }
    }

    #[test]
    fn trex_trims_in_hover() {
        let t = trim(&Helicopter::trex700l(), 0.0).unwrap();
        assert!(t.residual < 1e-6, "residual {}", t.residual);
    }

    #[test]
    fn bad_speeds_are_rejected() {
        let heli = Helicopter::bo105();
        assert_eq!(trim(&heli, -1.0), Err(TrimError::InvalidSpeed(-1.0)));
        assert!(matches!(
            trim(&heli, f64::NAN),
            Err(TrimError::InvalidSpeed(_))
        ));
    }

    #[test]
    fn bo105_hover_trim_is_near_padfield_flight_test() {
        // Padfield, flight test: θ0 ≈ 14°, θ1s ≈ 2.0°, θ1c ≈ 1.1°, θ0tr ≈ 10.6°, θ ≈ 2.7°.
        let t = trim(&Helicopter::bo105(), 0.0).unwrap();
        let deg = 180.0 / std::f64::consts::PI;
        let p = t.blade_pitch_rad;
        assert!(
            (p.theta0 * deg - 14.0).abs() < 2.0,
            "theta0 {}",
            p.theta0 * deg
        );
        assert!(
            (p.theta0_tr * deg - 10.6).abs() < 3.0,
            "theta0tr {}",
            p.theta0_tr * deg
        );
        assert!((t.theta * deg - 2.7).abs() < 1.5, "theta {}", t.theta * deg);
        assert!(
            (p.theta1s * deg - 2.0).abs() < 2.0,
            "theta1s {}",
            p.theta1s * deg
        );
        assert!(
            (p.theta1c * deg - 1.1).abs() < 2.0,
            "theta1c {}",
            p.theta1c * deg
        );
    }
}
