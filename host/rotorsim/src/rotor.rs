//! Rotor aerodynamics: blade-element thrust with Glauert momentum inflow (iterated, or a
//! Pitt–Peters uniform dynamic-inflow state), first-order tip-path-plane flapping of a
//! centre-spring rotor, and the rotor's forces and moments in shaft axes.
//!
//! Conventions (Padfield): azimuth ψ from the tail, anticlockwise seen from above; blade
//! pitch θ = θ0 + x·θ_tw + θ1c cos ψ + θ1s sin ψ; flapping β = β0 + β1c cos ψ + β1s sin ψ,
//! so β1c > 0 tilts the disc forward and β1s > 0 tilts it to the left. Non-dimensional
//! velocities are divided by the tip speed ΩR, rates by Ω.
//!
//! Flapping derivation (uniform inflow plus Pitt–Peters longitudinal inflow λ1c, no reverse
//! flow): the blade flap equation
//!
//! ```text
//! β'' + λ_β² β = (γ/2) ∫₀¹ x (U_T² θ − U_T U_P) dx,
//! U_T = x + μ sin ψ,  U_P = λ + λ1c x cos ψ + x (β' − q̄ cos ψ − p̄ sin ψ) + μ β cos ψ
//! ```
//!
//! in hub-wind axes (free stream from the front), plus the gyroscopic terms 2p̄ (cos ψ
//! harmonic) and −2q̄ (sin ψ harmonic) that keep a free rotor fixed in inertial space.
//! Its first harmonics, second derivatives dropped (the first-order tip-path-plane model of
//! Heffley & Mnich and Chen), give with g = γ/8 and s = λ_β² − 1:
//!
//! ```text
//! [ g  2][β1c']   [F_c]   F_c = −s β1c + 2p̄ + (γ/2)[θ1c(1/4 + μ²/8) − (β1s − q̄)/4
//! [−2  g][β1s'] = [F_s]                             − μβ0/3 − μ²β1s/8 − λ1c/4]
//!                         F_s = −s β1s − 2q̄ + (γ/2)[2μθ0/3 + μθ_tw/2 + θ1s(1/4 + 3μ²/8)
//!                                                  + (β1c + p̄)/4 − μλ/2 − μ²β1c/8]
//! ```
//!
//! The steady state of these equations is Padfield's quasi-steady centre-spring flapping;
//! their eigenvalues give τ_f (see [`crate::Rotor::flap_time_constant`]).

use crate::vehicle::Rotor;

/// 1/3 and 1/6 as multiplications (a division by a constant that is not a power of two is
/// compiled as a real division).
const THIRD: f64 = 1.0 / 3.0;
const SIXTH: f64 = 1.0 / 6.0;
/// Pitt–Peters apparent-mass coefficient of the uniform inflow, 8/(3π).
const PITT_PETERS_MASS: f64 = 8.0 / (3.0 * std::f64::consts::PI);
/// Pitt–Peters skewed-wake coefficient, λ1c = (15π/32)·tan(χ/2)·λ0.
const SKEW_COEFFICIENT: f64 = 15.0 * std::f64::consts::PI / 32.0;

/// Constants of a rotor derived once from its data.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RotorConstants {
    /// Ω [rad/s].
    pub omega: f64,
    /// a·σ.
    pub a_sigma: f64,
    /// σ.
    pub solidity: f64,
    /// Lock number γ.
    pub lock: f64,
    /// λ_β² − 1.
    pub stiffness_excess: f64,
    /// Blade twist θ_tw [rad].
    pub twist: f64,
    /// ρ·πR²·(ΩR)² [N]: thrust per unit C_T.
    pub thrust_scale: f64,
    /// ρ·πR²·(ΩR)²·R [N·m]: torque per unit C_Q.
    pub torque_scale: f64,
    /// Profile drag δ0, δ2.
    pub profile_drag: [f64; 2],
    /// Hub spring moment per rad of disc tilt, N_b·K_β/2 [N·m/rad].
    pub hub_spring: f64,
    /// 1/(ΩR).
    pub inv_tip_speed: f64,
    /// 1/Ω.
    pub inv_omega: f64,
    /// Ω/(g² + 4), g = γ/8: scale of the inverted flap "mass" matrix.
    pub flap_scale: f64,
    /// 1/λ_β².
    pub inv_flap_frequency2: f64,
}

impl RotorConstants {
    pub(crate) fn new(rotor: &Rotor, air_density: f64) -> RotorConstants {
        let area = rotor.disc_area();
        let tip = rotor.tip_speed();
        RotorConstants {
            omega: rotor.omega,
            a_sigma: rotor.lift_slope * rotor.solidity(),
            solidity: rotor.solidity(),
            lock: rotor.lock_number(air_density),
            stiffness_excess: rotor.stiffness_excess(),
            twist: rotor.twist,
            thrust_scale: air_density * area * tip * tip,
            torque_scale: air_density * area * tip * tip * rotor.radius,
            profile_drag: rotor.profile_drag,
            hub_spring: rotor.blades * rotor.hub_stiffness / 2.0,
            inv_tip_speed: 1.0 / tip,
            inv_omega: 1.0 / rotor.omega,
            flap_scale: {
                let g = rotor.lock_number(air_density) / 8.0;
                rotor.omega / (g * g + 4.0)
            },
            inv_flap_frequency2: 1.0 / (1.0 + rotor.stiffness_excess()),
        }
    }
}

/// How the uniform induced inflow λ_i is obtained.
#[derive(Clone, Copy, Debug)]
pub(crate) enum InflowSource {
    /// Solve Glauert's momentum equation by Newton iteration from `guess`: to convergence
    /// when `max_steps` is 0, else at most `max_steps` Newton steps.
    Iterate {
        /// Starting value (the previous solution); 0 or non-finite = a hover estimate.
        guess: f64,
        /// Newton-step budget (0 = until converged).
        max_steps: u32,
    },
    /// Take this value (a dynamic-inflow state) and return its time derivative.
    State(f64),
}

/// Thrust coefficient and inflow of one rotor.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ThrustSolution {
    /// C_T.
    pub thrust_coefficient: f64,
    /// Induced inflow λ_i (positive down through the disc).
    pub induced: f64,
    /// Total inflow through the hub plane λ = λ_i − μ_z.
    pub total: f64,
    /// Resultant velocity √(μ² + λ²).
    pub resultant: f64,
    /// dλ_i/dt [1/s] (dynamic inflow; 0 when iterated).
    pub induced_rate: f64,
}

/// Blade-element thrust with uniform momentum inflow.
///
/// ```text
/// C_T = K0 − (aσ/4)·λ,   λ = λ_i − μ_z,
/// K0  = (aσ/2)[θ0(1/3 + μ²/2) + θ_tw(1 + μ²)/4 + (μ/2)(θ1sw + p̄w/2)]   (`cyclic_term`
///        carries the last bracket),
/// Glauert:  C_T = 2 λ_i √(μ² + λ²).
/// ```
///
/// Newton on `G(λ_i) = 2λ_i V − C_T(λ_i)`, `G' = 2V + 2λ_iλ/V + aσ/4`, until a step is
/// below 1e-8 (remaining error ~1e-15 by quadratic convergence).
#[inline(always)]
pub(crate) fn thrust(
    rotor: &RotorConstants,
    mu2: f64,
    mu_z: f64,
    theta0: f64,
    cyclic_term: f64,
    inflow: InflowSource,
) -> ThrustSolution {
    let half = 0.5 * rotor.a_sigma;
    let k0 = half
        * (theta0 * (1.0 / 3.0 + 0.5 * mu2) + rotor.twist * (1.0 + mu2) * 0.25 + 0.5 * cyclic_term);
    let quarter = 0.25 * rotor.a_sigma;
    match inflow {
        InflowSource::State(induced) => {
            let total = induced - mu_z;
            let resultant = (mu2 + total * total).sqrt();
            let ct = k0 - quarter * total;
            // Pitt–Peters uniform inflow: (8/3π) dλ_i/dψ = C_T − 2 λ_i V.
            let induced_rate = rotor.omega * (ct - 2.0 * induced * resultant) / PITT_PETERS_MASS;
            ThrustSolution {
                thrust_coefficient: ct,
                induced,
                total,
                resultant,
                induced_rate,
            }
        }
        InflowSource::Iterate { guess, max_steps } => {
            let budget = if max_steps == 0 {
                60
            } else {
                max_steps.min(60)
            };
            let mut induced = if guess.is_finite() && guess != 0.0 {
                guess
            } else {
                (k0.abs().max(1e-6) * 0.5).sqrt().copysign(k0) + 0.0
            };
            let mut total = induced - mu_z;
            let mut resultant = (mu2 + total * total).sqrt().max(1e-9);
            for iteration in 0..budget {
                // Newton step s = G/G' with one division:
                // G/G' = (2λ_i V − C_T)·V / (2V² + 2λ_iλ + (aσ/4)V).
                let residual = 2.0 * induced * resultant - (k0 - quarter * total);
                let slope_times_v =
                    2.0 * resultant * resultant + 2.0 * induced * total + quarter * resultant;
                // Keep the iterate from jumping across the whole envelope (descent).
                let step = (residual * resultant / slope_times_v).clamp(-0.05, 0.05);
                induced -= step;
                let new_total = induced - mu_z;
                // Newton converges quadratically (error after a step s is ~ s²/λ), so a
                // step below 1e-8 leaves an error near 1e-15; on the last step of a budget
                // the O(s²) error of the update below is of the order already accepted.
                if step.abs() < 1e-8 || iteration + 1 == budget {
                    // V(λ − s) = V − s·λ/V + O(s²/V): saves a square root on exit.
                    resultant -= step * total / resultant;
                    total = new_total;
                    break;
                }
                total = new_total;
                resultant = (mu2 + total * total).sqrt().max(1e-9);
            }
            let ct = k0 - quarter * total;
            ThrustSolution {
                thrust_coefficient: ct,
                induced,
                total,
                resultant,
                induced_rate: 0.0,
            }
        }
    }
}

/// What the main rotor does at one instant.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MainRotorOutput {
    /// Thrust [N] along the tip-path-plane normal.
    pub thrust: f64,
    /// Force in shaft axes [N].
    pub force: [f64; 3],
    /// Hub spring moment in shaft axes [N·m]; about z the shaft torque Q, whose reaction
    /// on the fuselage is +Q for an anticlockwise rotor (nose right).
    pub moment: [f64; 3],
    /// dβ1c/dt, dβ1s/dt [rad/s].
    pub flap_rate: [f64; 2],
    /// Thrust/inflow solution.
    pub solution: ThrustSolution,
    /// Coning β0 [rad] (quasi-steady).
    pub coning: f64,
}

/// The main rotor: thrust, inflow, flapping and the shaft-axis loads.
///
/// `velocity`: hub velocity relative to the air in shaft axes [m/s]; `rates`: body p, q
/// in shaft axes [rad/s]; `pitch`: θ0, θ1s, θ1c [rad]; `flap`: β1c, β1s [rad].
#[inline(always)]
pub(crate) fn main_rotor(
    rotor: &RotorConstants,
    velocity: [f64; 3],
    rates: [f64; 2],
    pitch: [f64; 3],
    flap: [f64; 2],
    inflow: InflowSource,
) -> MainRotorOutput {
    let inv_tip = rotor.inv_tip_speed;
    let mu_x = velocity[0] * inv_tip;
    let mu_y = velocity[1] * inv_tip;
    let mu_z = velocity[2] * inv_tip;
    let mu2 = mu_x * mu_x + mu_y * mu_y;
    let [theta0, theta1s, theta1c] = pitch;
    let [beta1c, beta1s] = flap;
    let inv_omega = rotor.inv_omega;
    let p_bar = rates[0] * inv_omega;
    let q_bar = rates[1] * inv_omega;

    // The flap equations are written in hub-wind axes (free stream from the front) and
    // rotated back by the sideslip angle χ of the in-plane velocity. Every term is done
    // here directly in hub axes, which needs neither μ = √μ² nor 1/μ:
    // * rotation-invariant terms keep their form;
    // * a wind-axis term linear in μ, (a μ, b μ), becomes (a μ_x + b μ_y, −a μ_y + b μ_x);
    // * μ² diag(d1, d2) in wind axes becomes μ²(d1+d2)/2 I + (d1−d2)/2 [[D, −E], [−E, −D]]
    //   with D = μ_x² − μ_y² (= μ² cos 2χ), E = 2μ_xμ_y (= μ² sin 2χ), and the swap
    //   (β1sw, β1cw) becomes [[E, D], [D, −E]]·(β1c, β1s).
    // μ(θ1sw + p̄w/2) = θ1c μ_y + θ1s μ_x + (q̄ μ_y + p̄ μ_x)/2.
    let cyclic_term = theta1c * mu_y + theta1s * mu_x + 0.5 * (q_bar * mu_y + p_bar * mu_x);
    let solution = thrust(rotor, mu2, mu_z, theta0, cyclic_term, inflow);
    let lambda = solution.total;
    let twist = rotor.twist;
    let gamma = rotor.lock;
    let half_gamma = 0.5 * gamma;
    let g = gamma / 8.0;
    let s = rotor.stiffness_excess;

    // Coning, quasi-steady: λ_β² β0 = (γ/2)[θ0(1+μ²)/4 + θ_tw(1/5 + μ²/6)
    //                                      + μ(θ1sw + p̄w/2)/3 − λ/3].
    let coning = half_gamma
        * (theta0 * (1.0 + mu2) * 0.25
            + twist * (0.2 + mu2 * SIXTH)
            + (cyclic_term - lambda) * THIRD)
        * rotor.inv_flap_frequency2;

    // Skewed-wake longitudinal inflow λ1cw = (15π/32) tan(χ_w/2) λ_i, wake skew
    // χ_w = atan(μ/λ), tan(χ_w/2) = μ/(V + λ); in hub axes (λ1c, λ1s) = λ1cw/μ·(μ_x, −μ_y).
    let skew_den = solution.resultant + lambda;
    let skew = if skew_den > 1e-9 {
        SKEW_COEFFICIENT * solution.induced / skew_den
    } else {
        0.0
    };
    let (lambda1c, lambda1s) = (skew * mu_x, -skew * mu_y);

    // Rotation-invariant (hover) part: spring, gyroscopic, cyclic, flap and rate damping,
    // skewed inflow.
    let mut f_c = -s * beta1c + 2.0 * p_bar + g * (theta1c - beta1s + q_bar - lambda1c);
    let mut f_s = -s * beta1s - 2.0 * q_bar + g * (theta1s + beta1c + p_bar - lambda1s);
    // Terms linear in μ: wind-axis (a μ, b μ) with a = −(γ/2)β0/3 (coning → lateral
    // flapping) and b = (γ/2)(2θ0/3 + θ_tw/2 − λ/2) (blow-back).
    let a = -half_gamma * coning * THIRD;
    let b = half_gamma * (2.0 * THIRD * theta0 + 0.5 * twist - 0.5 * lambda);
    f_c += a * mu_x + b * mu_y;
    f_s += -a * mu_y + b * mu_x;
    // Terms in μ²: (γ/2)(μ²/8)·[(θ1cw, 3θ1sw) − (β1sw, β1cw)].
    let d = mu_x * mu_x - mu_y * mu_y;
    let e = 2.0 * mu_x * mu_y;
    let quad = half_gamma * 0.125;
    f_c += quad * (2.0 * mu2 * theta1c - d * theta1c + e * theta1s - (e * beta1c + d * beta1s));
    f_s += quad * (2.0 * mu2 * theta1s + e * theta1c + d * theta1s - (d * beta1c - e * beta1s));
    // M⁻¹ = [[g, −2], [2, g]] / (g² + 4); d/dt = Ω d/dψ.
    let scale = rotor.flap_scale;
    let flap_rate = [scale * (g * f_c - 2.0 * f_s), scale * (2.0 * f_c + g * f_s)];

    let ct = solution.thrust_coefficient;
    let thrust = ct * rotor.thrust_scale;
    // C_Q = C_T(λ + μβ1cw) + σδ(1 + 3μ²)/8: induced + climb + propulsive power (inflow
    // through the tip-path plane) plus profile power.
    let delta = rotor.profile_drag[0] + rotor.profile_drag[1] * ct * ct;
    // μβ1cw = β1c μ_x − β1s μ_y.
    let cq = ct * (lambda + beta1c * mu_x - beta1s * mu_y)
        + rotor.solidity * delta * (1.0 + 3.0 * mu2) * 0.125;
    let torque = cq * rotor.torque_scale;
    // Thrust along the tip-path-plane normal (small angles): forward tilt β1c gives +x,
    // left tilt β1s gives −y.
    let force = [thrust * flap[0], -thrust * flap[1], -thrust];
    // Hub spring: a forward tilt pitches the nose down, a left tilt rolls left.
    let moment = [
        -rotor.hub_spring * flap[1],
        -rotor.hub_spring * flap[0],
        torque,
    ];
    MainRotorOutput {
        thrust,
        force,
        moment,
        flap_rate,
        solution,
        coning,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::Helicopter;

    fn constants() -> RotorConstants {
        let heli = Helicopter::bo105();
        RotorConstants::new(&heli.main_rotor, heli.air_density)
    }

    #[test]
    fn iterated_inflow_satisfies_momentum_and_blade_element() {
        let rotor = constants();
        for &(mu2, mu_z) in &[(0.0, 0.0), (0.0049, 0.01), (0.01, -0.02)] {
            let sol = thrust(
                &rotor,
                mu2,
                mu_z,
                0.24,
                0.0,
                InflowSource::Iterate {
                    guess: 0.0,
                    max_steps: 0,
                },
            );
            let glauert = 2.0 * sol.induced * (mu2 + sol.total * sol.total).sqrt();
            assert!((glauert - sol.thrust_coefficient).abs() < 1e-12);
        }
    }

    #[test]
    fn hover_flap_steady_state_matches_padfield_quasi_steady_cyclic_response() {
        // Hover, centre spring (Sβ = s/g): a pure θ1s input gives
        // β1c = −θ1s/(1+Sβ²) (aft tilt) and β1s = +Sβ θ1s/(1+Sβ²) (left tilt).
        let rotor = constants();
        let s_beta = 8.0 * rotor.stiffness_excess / rotor.lock;
        let theta1s = 0.02;
        let expect_c = -theta1s / (1.0 + s_beta * s_beta);
        let expect_s = s_beta * theta1s / (1.0 + s_beta * s_beta);
        let out = main_rotor(
            &rotor,
            [0.0; 3],
            [0.0; 2],
            [0.24, theta1s, 0.0],
            [expect_c, expect_s],
            InflowSource::Iterate {
                guess: 0.05,
                max_steps: 0,
            },
        );
        assert!(
            out.flap_rate[0].abs() < 1e-9 && out.flap_rate[1].abs() < 1e-9,
            "{:?}",
            out.flap_rate
        );
    }
}
