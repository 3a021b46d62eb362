//! Trim in steady flight by Newton iteration.
//!
//! Unknowns z = [θ0, θ1s, θ1c, θ0_TR, φ, θ, β1c, β1s]; equations: the eight accelerations
//! [u̇ v̇ ẇ ṗ q̇ ṙ β̇1c β̇1s] = 0 at heading north (ψ = 0). The flight condition is a
//! [`SteadyFlight`]: the velocity over the ground (north, east, down) and a turn rate ψ̇.
//! The body velocity is R_bn·(V_N, V_E, V_D) with the Euler rotation at (φ, θ, ψ = 0):
//!
//! ```text
//! u = cos θ·V_N − sin θ·V_D
//! v = sin φ sin θ·V_N + cos φ·V_E + sin φ cos θ·V_D
//! w = cos φ sin θ·V_N − sin φ·V_E + cos φ cos θ·V_D
//! ```
//!
//! and the body rates of a steady turn (φ̇ = θ̇ = 0) are p = −ψ̇ sin θ, q = ψ̇ sin φ cos θ,
//! r = ψ̇ cos φ cos θ. Both are constant in body axes, so the state is steady. Level flight
//! at V north, [`trim`], is the case (V, 0, 0), ψ̇ = 0. The inflow is solved inside every
//! evaluation (Glauert momentum), so it is trimmed too. Newton: J Δz = −r with a
//! central-difference Jacobian, steps limited to 0.1 rad per unknown.

use crate::model::{self, Model, ModelFlags, State, STATE_LEN};
use crate::vehicle::{BladePitch, Helicopter};

/// Metres per second in one knot.
pub const KNOT: f64 = 1852.0 / 3600.0;
/// The fastest speed \[kt\] `trim` accepts.
pub const MAX_TRIM_SPEED_KT: f64 = 120.0;

/// A steady flight condition: velocity over the ground and turn rate, heading north.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SteadyFlight {
    /// Velocity over the ground [m/s]: north, east, down (a climb has V_D < 0).
    pub velocity_ned: [f64; 3],
    /// Turn rate ψ̇ [rad/s] (positive to the right).
    pub turn_rate: f64,
}

impl SteadyFlight {
    /// Level flight at `speed_kt` knots north.
    pub fn level(speed_kt: f64) -> SteadyFlight {
        SteadyFlight {
            velocity_ned: [speed_kt * KNOT, 0.0, 0.0],
            turn_rate: 0.0,
        }
    }
}

/// The fastest turn [rad/s] `trim_steady` accepts (one turn in about 10 s).
pub const MAX_TURN_RATE: f64 = 0.6;

/// A trimmed flight condition.
#[derive(Clone, Debug, PartialEq)]
pub struct Trim {
    /// Forward speed \[kt\].
    pub speed_kt: f64,
    /// Stick fractions [lat, lon, ped, col].
    pub controls: [f64; 4],
    /// Blade pitches \[rad\].
    pub blade_pitch_rad: BladePitch,
    /// Roll attitude φ \[rad\].
    pub phi: f64,
    /// Pitch attitude θ \[rad\].
    pub theta: f64,
    /// Longitudinal tip-path-plane tilt β1c \[rad\] (forward positive, relative to the shaft).
    pub beta1c: f64,
    /// Lateral tip-path-plane tilt β1s \[rad\] (left positive).
    pub beta1s: f64,
    /// Main-rotor induced inflow λ_i (divided by ΩR).
    pub inflow: f64,
    /// Tail-rotor induced inflow λ_i.
    pub tail_inflow: f64,
    /// Main-rotor coning β0 \[rad\].
    pub coning: f64,
    /// Main-rotor thrust \[N\].
    pub main_thrust: f64,
    /// Tail-rotor thrust \[N\].
    pub tail_thrust: f64,
    /// Largest absolute residual acceleration at the solution (m/s², rad/s², rad/s).
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// The full trimmed state vector (position at the origin).
    pub state: State,
}

/// Why a trim failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrimError {
    /// The speed is negative, not finite or above [`MAX_TRIM_SPEED_KT`].
    #[error("invalid trim speed {0} kt (expected 0 to {max} kt)", max = MAX_TRIM_SPEED_KT)]
    InvalidSpeed(f64),
    /// The turn rate is not finite or above [`MAX_TURN_RATE`] in magnitude.
    #[error(
        "invalid turn rate {0} rad/s (expected at most {max} rad/s either way)",
        max = MAX_TURN_RATE
    )]
    InvalidTurnRate(f64),
    /// Newton did not bring the residual below the tolerance.
    #[error("trim did not converge: residual {residual:.3e} after {iterations} iterations")]
    NotConverged {
        /// Largest residual reached.
        residual: f64,
        /// Iterations spent.
        iterations: usize,
    },
    /// The Jacobian was singular.
    #[error("trim Jacobian is singular")]
    SingularJacobian,
    /// The solution needs a stick beyond ±1 (the gearing's range).
    #[error("trim needs {control} stick {value:.3}, beyond the range ±1")]
    ControlOutOfRange {
        /// Control name (lat, lon, ped, col).
        control: &'static str,
        /// Stick fraction needed.
        value: f64,
    },
}

/// Names of the stick channels in control order.
pub const CONTROL_NAMES: [&str; 4] = ["lat", "lon", "ped", "col"];

const UNKNOWNS: usize = 8;
const TOLERANCE: f64 = 1e-10;

/// The state vector of `flight` with attitude φ, θ and flapping β1c, β1s (module
/// documentation).
fn steady_state(
    flight: &SteadyFlight,
    phi: f64,
    theta: f64,
    beta: [f64; 2],
    inflow: f64,
) -> [f64; STATE_LEN] {
    let mut x = [0.0; STATE_LEN];
    let (sin_phi, cos_phi) = phi.sin_cos();
    let (sin_theta, cos_theta) = theta.sin_cos();
    let [north, east, down] = flight.velocity_ned;
    x[model::U] = cos_theta * north - sin_theta * down;
    x[model::V] = sin_phi * sin_theta * north + cos_phi * east + sin_phi * cos_theta * down;
    x[model::W] = cos_phi * sin_theta * north - sin_phi * east + cos_phi * cos_theta * down;
    x[model::P] = -flight.turn_rate * sin_theta;
    x[model::Q] = flight.turn_rate * sin_phi * cos_theta;
    x[model::R] = flight.turn_rate * cos_phi * cos_theta;
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
    flight: &SteadyFlight,
    z: &[f64; UNKNOWNS],
    warm: &mut [f64; 2],
) -> [f64; UNKNOWNS] {
    let x = steady_state(flight, z[4], z[5], [z[6], z[7]], warm[0]);
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
    trim_steady(heli, &SteadyFlight::level(speed_kt))
}

/// Trim `heli` in the steady flight `flight` (module documentation). `Trim::speed_kt` is
/// the horizontal ground speed.
pub fn trim_steady(heli: &Helicopter, flight: &SteadyFlight) -> Result<Trim, TrimError> {
    let [north, east, down] = flight.velocity_ned;
    let speed_kt = north.hypot(east) / KNOT;
    if !(north.is_finite() && east.is_finite() && down.is_finite())
        || north.hypot(east).hypot(down) / KNOT > MAX_TRIM_SPEED_KT
    {
        return Err(TrimError::InvalidSpeed(
            north.hypot(east).hypot(down) / KNOT,
        ));
    }
    if !flight.turn_rate.is_finite() || flight.turn_rate.abs() > MAX_TURN_RATE {
        return Err(TrimError::InvalidTurnRate(flight.turn_rate));
    }
    let model = Model::new(heli.clone());

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
    let mut r = residual(&model, flight, &z, &mut warm);
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
            let rp = residual(&model, flight, &plus, &mut warm);
            let rm = residual(&model, flight, &minus, &mut warm);
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
        r = residual(&model, flight, &z, &mut warm);
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
    let x = steady_state(flight, z[4], z[5], [z[6], z[7]], warm[0]);
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
    fn error_messages_name_the_limit_or_the_residual() {
        let messages = [
            (
                TrimError::InvalidSpeed(-1.0),
                "invalid trim speed -1 kt (expected 0 to 120 kt)",
            ),
            (
                TrimError::InvalidTurnRate(0.75),
                "invalid turn rate 0.75 rad/s (expected at most 0.6 rad/s either way)",
            ),
            (
                TrimError::NotConverged {
                    residual: 0.00123456,
                    iterations: 40,
                },
                "trim did not converge: residual 1.235e-3 after 40 iterations",
            ),
            (TrimError::SingularJacobian, "trim Jacobian is singular"),
            (
                TrimError::ControlOutOfRange {
                    control: "col",
                    value: 1.23456,
                },
                "trim needs col stick 1.235, beyond the range ±1",
            ),
        ];
        for (error, message) in messages {
            assert_eq!(error.to_string(), message);
            assert!(std::error::Error::source(&error).is_none());
        }
    }

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
    fn small_steady_flights_satisfy_the_hover_linearization() {
        // Trims a little off hover in each direction (forward, right, down, turning): the
        // linearization about hover must hold them in steady state, A·Δx + B·Δδ = 0, with
        // Δ the central difference of the two trims. The rows are the accelerations of the
        // linearization's states, ψ̇ aside. Not exact: the fuselage drag goes with u·|u|,
        // whose slope at hover is zero but whose central difference is the step, so the
        // residual shrinks only linearly with the step (Bo-105 u row: 16 % of the largest
        // term at 0.2 m/s, 4 % at 0.05 m/s); 5e-5 m/s² (rad/s²) is the floor of rows whose
        // terms are all that small.
        for heli in [Helicopter::bo105(), Helicopter::trex700l()] {
            let hover = trim(&heli, 0.0).unwrap();
            let lin = crate::linearize(&heli, &hover);
            let step = |sign: f64, k: usize| {
                let mut flight = SteadyFlight::default();
                match k {
                    3 => flight.turn_rate = 0.005 * sign,
                    _ => flight.velocity_ned[k] = 0.05 * sign,
                }
                trim_steady(&heli, &flight).unwrap()
            };
            for k in 0..4 {
                let (plus, minus) = (step(1.0, k), step(-1.0, k));
                let dx: Vec<f64> = (0..lin.states.len())
                    .map(|i| plus.state.0[i] - minus.state.0[i])
                    .collect();
                let du: Vec<f64> = (0..4)
                    .map(|j| plus.controls[j] - minus.controls[j])
                    .collect();
                for (row, name) in lin.states.iter().enumerate() {
                    if *name == "psi" {
                        continue;
                    }
                    let terms = lin.a[row]
                        .iter()
                        .zip(&dx)
                        .map(|(a, x)| a * x)
                        .chain(lin.b[row].iter().zip(&du).map(|(b, u)| b * u));
                    let (sum, scale) =
                        terms.fold((0.0, 0.0), |(s, m), t: f64| (s + t, f64::max(m, t.abs())));
                    assert!(
                        sum.abs() <= 0.05 * scale + 5e-5,
                        "{} case {k} row {name}: residual {sum:.3e} of terms up to {scale:.3e}",
                        heli.name
                    );
                }
            }
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
