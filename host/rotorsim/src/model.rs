//! The nonlinear six-degree-of-freedom model: state layout, loads of every component and
//! the state derivative ẋ = f(x, u, wind).
//!
//! Rigid body (body axes, x forward, y right, z down, origin at the CG):
//!
//! ```text
//! u̇ = r v − q w + X/m − g sin θ
//! v̇ = p w − r u + Y/m + g sin φ cos θ
//! ẇ = q u − p v + Z/m + g cos φ cos θ
//! I ω̇ = M − ω × (I ω),   I = [[Ixx, 0, −Ixz], [0, Iyy, 0], [−Ixz, 0, Izz]]
//! φ̇ = p + (q sin φ + r cos φ) tan θ,  θ̇ = q cos φ − r sin φ,  ψ̇ = (q sin φ + r cos φ)/cos θ
//! ṗ_NED = R_nb(φ, θ, ψ) · [u v w]
//! ```
//!
//! X, Y, Z, L, M, N are the aerodynamic loads: main rotor (thrust along the tip-path-plane
//! normal at the hub, hub spring moment, shaft torque), tail rotor (same thrust routine),
//! quadratic fuselage drag, vertical fin and horizontal tailplane. Loads at a point r act
//! through the moment r × F, which yields Heffley's (N_b K_β/2 + T h)·β hub moment.

use crate::rotor::{self, InflowSource, RotorConstants};
use crate::trig::sin_cos;
use crate::vehicle::{BladePitch, Helicopter, Surface};

/// Number of entries of the full state vector.
pub const STATE_LEN: usize = 15;
/// Forward body velocity u [m/s].
pub const U: usize = 0;
/// Lateral body velocity v [m/s].
pub const V: usize = 1;
/// Vertical body velocity w [m/s] (down positive).
pub const W: usize = 2;
/// Roll rate p [rad/s].
pub const P: usize = 3;
/// Pitch rate q [rad/s].
pub const Q: usize = 4;
/// Yaw rate r [rad/s].
pub const R: usize = 5;
/// Roll angle φ \[rad\].
pub const PHI: usize = 6;
/// Pitch angle θ \[rad\].
pub const THETA: usize = 7;
/// Heading ψ \[rad\] (integrated freely; wrapped only in the sensor reading).
pub const PSI: usize = 8;
/// Longitudinal tip-path-plane tilt β1c \[rad\] (forward positive).
pub const BETA1C: usize = 9;
/// Lateral tip-path-plane tilt β1s \[rad\] (left positive).
pub const BETA1S: usize = 10;
/// Main-rotor uniform induced inflow λ_i (a state only with dynamic inflow).
pub const LAMBDA: usize = 11;
/// North position \[m\].
pub const NORTH: usize = 12;
/// East position \[m\].
pub const EAST: usize = 13;
/// Down position \[m\].
pub const DOWN: usize = 14;

/// The full state vector, indexed by the constants of this module.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State(pub [f64; STATE_LEN]);

impl State {
    /// Body velocity [u, v, w] [m/s].
    pub fn velocity(&self) -> [f64; 3] {
        [self.0[U], self.0[V], self.0[W]]
    }
    /// Body rates [p, q, r] [rad/s].
    pub fn rates(&self) -> [f64; 3] {
        [self.0[P], self.0[Q], self.0[R]]
    }
    /// Euler angles [φ, θ, ψ] \[rad\].
    pub fn attitude(&self) -> [f64; 3] {
        [self.0[PHI], self.0[THETA], self.0[PSI]]
    }
    /// Tip-path-plane tilts [β1c, β1s] \[rad\].
    pub fn flapping(&self) -> [f64; 2] {
        [self.0[BETA1C], self.0[BETA1S]]
    }
    /// Position north, east, down \[m\].
    pub fn position(&self) -> [f64; 3] {
        [self.0[NORTH], self.0[EAST], self.0[DOWN]]
    }
    /// Main-rotor induced inflow λ_i.
    pub fn inflow(&self) -> f64 {
        self.0[LAMBDA]
    }
}

/// Aerodynamic loads and the derived quantities of one evaluation.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Loads {
    /// Total aerodynamic force, body axes [N].
    pub force: [f64; 3],
    /// Total aerodynamic moment about the CG, body axes [N·m].
    pub moment: [f64; 3],
    /// Main-rotor thrust [N].
    pub main_thrust: f64,
    /// Tail-rotor thrust [N].
    pub tail_thrust: f64,
    /// Main-rotor induced inflow λ_i.
    pub main_inflow: f64,
    /// Tail-rotor induced inflow λ_i.
    pub tail_inflow: f64,
    /// Main-rotor coning β0 [rad].
    pub coning: f64,
}

/// Switches that change the model's equations, and external loads.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub(crate) struct ModelFlags {
    /// Main-rotor inflow is the state `LAMBDA` (Pitt–Peters) instead of being iterated.
    pub dynamic_inflow: bool,
    /// Rotors, fuselage and surfaces produce no loads (physics tests).
    pub no_aero: bool,
    /// Newton steps on the momentum inflow per evaluation, starting from the previous
    /// evaluation's solution; 0 = iterate to convergence (trim, linearization).
    pub inflow_steps: u32,
    /// External force [N] and moment [N·m] about the CG, body axes (disturbance hook).
    pub external_load: [f64; 6],
}

/// Precomputed constants of a helicopter for fast evaluation.
#[derive(Clone, Debug)]
pub(crate) struct Model {
    pub heli: Helicopter,
    pub main: RotorConstants,
    pub tail: RotorConstants,
    /// Shaft x axis in body axes (x_s = (cos i_s, 0, sin i_s)).
    shaft_x: [f64; 3],
    /// Shaft z axis (down along the shaft) in body axes (z_s = (−sin i_s, 0, cos i_s)).
    shaft_z: [f64; 3],
    /// 1 / (Ixx Izz − Ixz²).
    inv_det_xz: f64,
    /// 1 / m.
    inv_mass: f64,
    /// 1 / Iyy.
    inv_iyy: f64,
}

#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Normal force of a lifting surface per unit of the normal velocity convention:
/// `0.5 ρ S a |u| · clamp(|u| i + v_n, ±α_stall |u|)` (linear lift on the angle
/// i + v_n/|u|, capped at the stall angle).
#[inline]
fn surface_force(rho: f64, surface: &Surface, along: f64, normal: f64) -> f64 {
    let speed = along.abs();
    let limit = surface.stall_angle * speed;
    // max/min rather than clamp: clamp asserts min ≤ max at run time.
    let angle_times_speed = (speed * surface.incidence + normal).max(-limit).min(limit);
    0.5 * rho * surface.area * surface.lift_slope * speed * angle_times_speed
}

impl Model {
    pub(crate) fn new(heli: Helicopter) -> Model {
        let main = RotorConstants::new(&heli.main_rotor, heli.air_density);
        let tail = RotorConstants::new(&heli.tail_rotor, heli.air_density);
        let (sin_is, cos_is) = heli.shaft_tilt.sin_cos();
        let inv_det_xz = 1.0 / (heli.ixx * heli.izz - heli.ixz * heli.ixz);
        Model {
            main,
            tail,
            shaft_x: [cos_is, 0.0, sin_is],
            shaft_z: [-sin_is, 0.0, cos_is],
            inv_det_xz,
            inv_mass: 1.0 / heli.mass,
            inv_iyy: 1.0 / heli.iyy,
            heli,
        }
    }

    /// Aerodynamic loads at state `x` with blade pitches `pitch` and wind `wind` (air
    /// velocity relative to the ground, body axes). `warm` holds the last main and tail
    /// inflow solutions (Newton starts there); it is updated.
    #[inline(always)]
    pub(crate) fn loads(
        &self,
        x: &[f64; STATE_LEN],
        pitch: &BladePitch,
        wind: [f64; 3],
        flags: ModelFlags,
        warm: &mut [f64; 2],
    ) -> (Loads, [f64; 2], f64) {
        let external = flags.external_load;
        if flags.no_aero {
            let loads = Loads {
                force: [external[0], external[1], external[2]],
                moment: [external[3], external[4], external[5]],
                ..Loads::default()
            };
            return (loads, [0.0; 2], 0.0);
        }
        let heli = &self.heli;
        let rho = heli.air_density;
        let air = [x[U] - wind[0], x[V] - wind[1], x[W] - wind[2]];
        let omega = [x[P], x[Q], x[R]];

        // Main rotor, in shaft axes.
        let hub = heli.main_rotor.hub;
        let hub_velocity = add(air, cross(omega, hub));
        let shaft_velocity = [
            dot(hub_velocity, self.shaft_x),
            hub_velocity[1],
            dot(hub_velocity, self.shaft_z),
        ];
        let shaft_rates = [dot(omega, self.shaft_x), omega[1]];
        let inflow = if flags.dynamic_inflow {
            InflowSource::State(x[LAMBDA])
        } else {
            InflowSource::Iterate {
                guess: warm[0],
                max_steps: flags.inflow_steps,
            }
        };
        let main = rotor::main_rotor(
            &self.main,
            shaft_velocity,
            shaft_rates,
            [pitch.theta0, pitch.theta1s, pitch.theta1c],
            [x[BETA1C], x[BETA1S]],
            inflow,
        );
        warm[0] = main.solution.induced;
        let to_body = |s: [f64; 3]| {
            [
                s[0] * self.shaft_x[0] + s[2] * self.shaft_z[0],
                s[1],
                s[0] * self.shaft_x[2] + s[2] * self.shaft_z[2],
            ]
        };
        let main_force = to_body(main.force);
        let mut force = main_force;
        let mut moment = add(to_body(main.moment), cross(hub, main_force));

        // Tail rotor: thrust along +y, air pushed toward −y (its "down" axis).
        let tail_hub = heli.tail_rotor.hub;
        let tail_velocity = add(air, cross(omega, tail_hub));
        let inv_tip = self.tail.inv_tip_speed;
        let mu2 = (tail_velocity[0] * tail_velocity[0] + tail_velocity[2] * tail_velocity[2])
            * inv_tip
            * inv_tip;
        let mu_z = -tail_velocity[1] * inv_tip;
        let tail = rotor::thrust(
            &self.tail,
            mu2,
            mu_z,
            pitch.theta0_tr,
            0.0,
            InflowSource::Iterate {
                guess: warm[1],
                max_steps: flags.inflow_steps,
            },
        );
        warm[1] = tail.induced;
        let tail_thrust = tail.thrust_coefficient * self.tail.thrust_scale;
        // r × (0, Y, 0) = (−r_z Y, 0, r_x Y).
        force[1] += tail_thrust;
        moment[0] -= tail_hub[2] * tail_thrust;
        moment[2] += tail_hub[0] * tail_thrust;

        // Fuselage: quadratic drag −½ρ|V|·(f_x u, f_y v, f_z w) at the CG.
        let speed = dot(air, air).sqrt();
        let drag = heli.fuselage_drag_area;
        let q_half = 0.5 * rho * speed;
        force = add(
            force,
            [
                -q_half * drag[0] * air[0],
                -q_half * drag[1] * air[1],
                -q_half * drag[2] * air[2],
            ],
        );

        // Fin: side force from the sideslip at the fin (positive incidence pushes +y).
        // Local velocity u + (ω × r)_x, v + (ω × r)_y.
        let fin = &heli.fin;
        let fp = fin.position;
        let fin_u = air[0] + omega[1] * fp[2] - omega[2] * fp[1];
        let fin_v = air[1] + omega[2] * fp[0] - omega[0] * fp[2];
        let fin_side = surface_force(rho, fin, fin_u, -fin_v);
        force[1] += fin_side;
        moment[0] -= fp[2] * fin_side;
        moment[2] += fp[0] * fin_side;

        // Tailplane: lift (−z) from incidence plus the local angle of attack w/|u|.
        // Local u + (ω × r)_x, w + (ω × r)_z; r × (0, 0, Z) = (r_y Z, −r_x Z, 0).
        let plane = &heli.tailplane;
        let tp = plane.position;
        let plane_u = air[0] + omega[1] * tp[2] - omega[2] * tp[1];
        let plane_w = air[2] + omega[0] * tp[1] - omega[1] * tp[0];
        let plane_lift = -surface_force(rho, plane, plane_u, plane_w);
        force[2] += plane_lift;
        moment[0] += tp[1] * plane_lift;
        moment[1] -= tp[0] * plane_lift;

        force = add(force, [external[0], external[1], external[2]]);
        moment = add(moment, [external[3], external[4], external[5]]);
        let loads = Loads {
            force,
            moment,
            main_thrust: main.thrust,
            tail_thrust,
            main_inflow: main.solution.induced,
            tail_inflow: tail.induced,
            coning: main.coning,
        };
        (loads, main.flap_rate, main.solution.induced_rate)
    }

    /// The state derivative ẋ = f(x, pitch, wind); also returns the loads.
    #[inline(always)]
    pub(crate) fn derivative(
        &self,
        x: &[f64; STATE_LEN],
        pitch: &BladePitch,
        wind: [f64; 3],
        flags: ModelFlags,
        warm: &mut [f64; 2],
    ) -> ([f64; STATE_LEN], Loads) {
        let heli = &self.heli;
        let (loads, flap_rate, inflow_rate) = self.loads(x, pitch, wind, flags, warm);
        let g = heli.gravity;
        let inv_mass = self.inv_mass;
        let (u, v, w) = (x[U], x[V], x[W]);
        let (p, q, r) = (x[P], x[Q], x[R]);
        let (sin_phi, cos_phi) = sin_cos(x[PHI]);
        let (sin_theta, cos_theta) = sin_cos(x[THETA]);
        let (sin_psi, cos_psi) = sin_cos(x[PSI]);
        let mut dx = [0.0; STATE_LEN];
        let f = loads.force;
        dx[U] = r * v - q * w + f[0] * inv_mass - g * sin_theta;
        dx[V] = p * w - r * u + f[1] * inv_mass + g * sin_phi * cos_theta;
        dx[W] = q * u - p * v + f[2] * inv_mass + g * cos_phi * cos_theta;

        // Euler's equations with the xz product of inertia: H = I ω,
        // [Ixx −Ixz; −Ixz Izz][ṗ ṙ]ᵀ = [L − (ω×H)_x, N − (ω×H)_z], Iyy q̇ = M − (ω×H)_y.
        let (ixx, iyy, izz, ixz) = (heli.ixx, heli.iyy, heli.izz, heli.ixz);
        let h = [ixx * p - ixz * r, iyy * q, izz * r - ixz * p];
        let gyro = cross([p, q, r], h);
        let roll = loads.moment[0] - gyro[0];
        let pitch_moment = loads.moment[1] - gyro[1];
        let yaw = loads.moment[2] - gyro[2];
        dx[P] = (izz * roll + ixz * yaw) * self.inv_det_xz;
        dx[Q] = pitch_moment * self.inv_iyy;
        dx[R] = (ixz * roll + ixx * yaw) * self.inv_det_xz;

        let inv_cos_theta = 1.0 / cos_theta;
        let q_sin_r_cos = q * sin_phi + r * cos_phi;
        dx[PHI] = p + q_sin_r_cos * sin_theta * inv_cos_theta;
        dx[THETA] = q * cos_phi - r * sin_phi;
        dx[PSI] = q_sin_r_cos * inv_cos_theta;
        dx[BETA1C] = flap_rate[0];
        dx[BETA1S] = flap_rate[1];
        dx[LAMBDA] = inflow_rate;

        // Position: NED = R_nb · body velocity.
        let (st_cp, st_sp) = (sin_theta * cos_psi, sin_theta * sin_psi);
        dx[NORTH] = cos_theta * cos_psi * u
            + (sin_phi * st_cp - cos_phi * sin_psi) * v
            + (cos_phi * st_cp + sin_phi * sin_psi) * w;
        dx[EAST] = cos_theta * sin_psi * u
            + (sin_phi * st_sp + cos_phi * cos_psi) * v
            + (cos_phi * st_sp - sin_phi * cos_psi) * w;
        dx[DOWN] = -sin_theta * u + sin_phi * cos_theta * v + cos_phi * cos_theta * w;
        (dx, loads)
    }
}
