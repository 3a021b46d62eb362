//! The time-stepping simulator: RK4 at a fixed internal step, actuators (second-order
//! servo with rate limit and transport delay), sensors (noise, bias, latency, dropout,
//! spikes) and gusts. Everything random comes from one seeded PRNG, so a run is a pure
//! function of (vehicle, options, seed, control sequence). No allocation per step.

use crate::linear_plant::LinearPlant;
use crate::model::{self, Loads, Model, ModelFlags, State, STATE_LEN};
use crate::rng::Rng;
use crate::trim::Trim;
use crate::vehicle::Helicopter;

/// White noise, bias and latency of the sensor set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorNoise {
    /// Gyro noise, 1σ [rad/s].
    pub gyro_rad_s: f64,
    /// Attitude noise, 1σ [rad].
    pub attitude_rad: f64,
    /// Velocity noise, 1σ [m/s].
    pub velocity_m_s: f64,
    /// Accelerometer noise, 1σ [m/s²].
    pub accel_m_s2: f64,
    /// Constant bias per channel, order [p q r φ θ ψ u v w ax ay az] (SI units).
    pub bias: [f64; 12],
    /// Latency [s] (rounded to internal steps): the reading shows the aircraft this long ago.
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

/// Control actuators: second-order servo with a rate limit, after a transport delay,
/// acting on the stick fractions (so their units are stick fractions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorModel {
    /// Natural frequency ω_n [rad/s]; infinite (or ≤ 0) = the actuator follows instantly.
    pub natural_frequency_rad_s: f64,
    /// Damping ratio ζ.
    pub damping: f64,
    /// Rate limit [stick fraction per second].
    pub rate_limit_per_s: f64,
    /// Transport delay [s] (rounded to internal steps).
    pub transport_delay_s: f64,
}

impl ActuatorModel {
    /// Instant actuators, no delay.
    pub fn ideal() -> ActuatorModel {
        ActuatorModel {
            natural_frequency_rad_s: f64::INFINITY,
            damping: 1.0,
            rate_limit_per_s: f64::INFINITY,
            transport_delay_s: 0.0,
        }
    }

    fn is_instant(&self) -> bool {
        !(self.natural_frequency_rad_s.is_finite() && self.natural_frequency_rad_s > 0.0)
    }
}

impl Default for ActuatorModel {
    /// ω_n = 60 rad/s, ζ = 0.7, full travel (2) in 0.5 s (4 per second), no delay.
    fn default() -> ActuatorModel {
        ActuatorModel {
            natural_frequency_rad_s: 60.0,
            damping: 0.7,
            rate_limit_per_s: 4.0,
            transport_delay_s: 0.0,
        }
    }
}

/// Simulation options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Fixed RK4 step [s].
    pub internal_step_s: f64,
    /// Sensor imperfections.
    pub sensor_noise: SensorNoise,
    /// PRNG seed (noise, gusts, faults).
    pub seed: u64,
    /// Turbulence intensity, 1σ per body axis [m/s] (0 = still air).
    pub gust_level: f64,
    /// Correlation time of the first-order (Gauss–Markov) gust filter [s].
    pub gust_time_constant_s: f64,
    /// Probability per `step` that the sensor sample is not updated (dropout).
    pub dropout_probability: f64,
    /// Probability per `step` that one channel carries a large outlier (spike).
    pub spike_probability: f64,
    /// Size of a spike, multiplying [1 rad/s, 0.2 rad, 5 m/s, 20 m/s²] by channel group.
    pub spike_scale: f64,
    /// Actuator model.
    pub actuator: ActuatorModel,
    /// Pitt–Peters dynamic inflow for the main rotor instead of iterated momentum inflow.
    pub dynamic_inflow: bool,
    /// Fly the model's first-order expansion about the trim instead of the model itself
    /// (see `linear_plant`): the aircraft is then exactly the linearization the
    /// identification is scored against, so what remains in an identification error is
    /// the estimator's. Takes effect in [`Sim::at_trim`]; still air only (wind, gusts and
    /// external loads do not act on it). Sensors and actuators are unchanged.
    pub linearized_plant: bool,
}

impl Default for SimOptions {
    fn default() -> SimOptions {
        SimOptions {
            internal_step_s: 1e-3,
            sensor_noise: SensorNoise::default(),
            seed: 0,
            gust_level: 0.0,
            gust_time_constant_s: 1.0,
            dropout_probability: 0.0,
            spike_probability: 0.0,
            spike_scale: 1.0,
            actuator: ActuatorModel::default(),
            dynamic_inflow: false,
            linearized_plant: false,
        }
    }
}

impl SimOptions {
    /// Perfect sensors, ideal actuators, still air: the truth model alone.
    pub fn perfect() -> SimOptions {
        SimOptions {
            sensor_noise: SensorNoise::perfect(),
            actuator: ActuatorModel::ideal(),
            ..SimOptions::default()
        }
    }
}

/// What the flight controller reads: rates [rad/s], Euler angles [rad] (ψ wrapped to
/// (−π, π]), body velocity [m/s] and specific force [m/s²] (≈ (0, 0, −g) in hover).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SensorReading {
    /// Sequence number: increments on every fresh sample, repeats on a dropout.
    pub seq: u32,
    /// Time of the sample [s] (the simulation time when it was taken).
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
    fn channels(&self) -> [f64; 12] {
        [
            self.p, self.q, self.r, self.phi, self.theta, self.psi, self.u, self.v, self.w,
            self.ax, self.ay, self.az,
        ]
    }

    fn with_channels(seq: u32, time_s: f64, c: [f64; 12]) -> SensorReading {
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
fn truth(x: &[f64; STATE_LEN], force: [f64; 3], mass: f64, time_s: f64) -> SensorReading {
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

/// One classical RK4 step of size h with fixed blade pitch and wind; returns k1's loads.
#[inline]
pub(crate) fn rk4_step(
    model: &Model,
    x: &mut [f64; STATE_LEN],
    pitch: &crate::vehicle::BladePitch,
    wind: [f64; 3],
    flags: ModelFlags,
    warm: &mut [f64; 2],
    h: f64,
) -> Loads {
    let (k1, loads) = model.derivative(x, pitch, wind, flags, warm);
    rk4_from(x, h, k1, |stage| {
        model.derivative(stage, pitch, wind, flags, warm).0
    });
    loads
}

/// One classical RK4 step of ẋ = f(x) from `x`, given k1 = f(x) (the caller evaluates it,
/// to keep what comes with it, e.g. the loads):
/// x_{n+1} = x_n + h/6 (k1 + 2k2 + 2k3 + k4). The linearized plant steps with it too.
#[inline]
pub(crate) fn rk4_from<const N: usize>(
    x: &mut [f64; N],
    h: f64,
    k1: [f64; N],
    mut f: impl FnMut(&[f64; N]) -> [f64; N],
) {
    let mut stage = [0.0; N];
    for i in 0..N {
        stage[i] = x[i] + 0.5 * h * k1[i];
    }
    let k2 = f(&stage);
    for i in 0..N {
        stage[i] = x[i] + 0.5 * h * k2[i];
    }
    let k3 = f(&stage);
    for i in 0..N {
        stage[i] = x[i] + h * k3[i];
    }
    let k4 = f(&stage);
    let sixth_h = h * (1.0 / 6.0);
    for i in 0..N {
        x[i] += sixth_h * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
    }
}

/// The simulator of one helicopter.
#[derive(Clone, Debug)]
pub struct Sim {
    model: Model,
    options: SimOptions,
    flags: ModelFlags,
    x: [f64; STATE_LEN],
    time: f64,
    warm: [f64; 2],
    /// Last accepted command (used when a command is not finite).
    command: [f64; 4],
    actuator_position: [f64; 4],
    actuator_rate: [f64; 4],
    /// Ring buffer of commands, one per internal step (transport delay).
    delay_line: Vec<[f64; 4]>,
    delay_head: usize,
    /// Ring buffer of true sensor samples, one per internal step (latency).
    latency_line: Vec<SensorReading>,
    latency_head: usize,
    rng: Rng,
    gust: [f64; 3],
    wind: [f64; 3],
    last_reading: SensorReading,
    seq: u32,
    /// The expansion flown instead of `model` (`SimOptions::linearized_plant`).
    linear_plant: Option<Box<LinearPlant>>,
}

impl Sim {
    /// A simulator at rest on the ground frame origin (level, zero velocity, controls
    /// centred) — not trimmed: use [`Sim::at_trim`] to start flying.
    pub fn new(heli: Helicopter, options: SimOptions) -> Sim {
        let mut x = [0.0; STATE_LEN];
        let model = Model::new(heli);
        // A plausible inflow to start the iteration or the dynamic-inflow state.
        x[model::LAMBDA] = 0.05;
        let step = Self::sanitised_step(options.internal_step_s);
        // Non-finite settings fall back to the defaults instead of poisoning the state.
        let mut options = options;
        if !(options.actuator.damping.is_finite() && options.actuator.damping >= 0.0) {
            options.actuator.damping = ActuatorModel::default().damping;
        }
        if !options.spike_scale.is_finite() {
            options.spike_scale = 1.0;
        }
        let delay_steps = Self::steps_for(options.actuator.transport_delay_s, step);
        let latency_steps = Self::steps_for(options.sensor_noise.latency_s, step);
        // One Newton step on the momentum inflow per evaluation, from the previous
        // evaluation's value: consecutive evaluations are 0.5 ms apart, the inflow moves
        // by Δλ ≲ 1e-5 between them and Newton's quadratic convergence leaves an error of
        // order Δλ²/λ ≈ 1e-9 (relative thrust error ~1e-8) at a third of the cost.
        let flags = ModelFlags {
            dynamic_inflow: options.dynamic_inflow,
            inflow_steps: 1,
            ..ModelFlags::default()
        };
        let mut sim = Sim {
            model,
            options: SimOptions {
                internal_step_s: step,
                ..options
            },
            flags,
            x,
            time: 0.0,
            warm: [0.05, 0.05],
            command: [0.0; 4],
            actuator_position: [0.0; 4],
            actuator_rate: [0.0; 4],
            delay_line: vec![[0.0; 4]; delay_steps.max(1)],
            delay_head: 0,
            latency_line: vec![SensorReading::default(); latency_steps.max(1)],
            latency_head: 0,
            rng: Rng::new(options.seed),
            gust: [0.0; 3],
            wind: [0.0; 3],
            last_reading: SensorReading::default(),
            seq: 0,
            linear_plant: None,
        };
        sim.reset_lines();
        sim
    }

    /// A simulator in the trimmed state, actuators and delay line at the trim controls.
    pub fn at_trim(heli: Helicopter, trim: &Trim, options: SimOptions) -> Sim {
        let mut sim = Sim::new(heli, options);
        sim.x = trim.state.0;
        sim.warm = [trim.inflow, trim.tail_inflow];
        sim.command = trim.controls;
        sim.actuator_position = trim.controls;
        sim.reset_lines();
        if sim.options.linearized_plant {
            let plant = LinearPlant::about(&sim.model, trim, sim.flags);
            sim.linear_plant = Some(Box::new(plant));
        }
        sim
    }

    fn sanitised_step(step: f64) -> f64 {
        if step.is_finite() && step > 0.0 {
            step.clamp(1e-5, 0.02)
        } else {
            1e-3
        }
    }

    fn steps_for(seconds: f64, step: f64) -> usize {
        if seconds.is_finite() && seconds > 0.0 {
            ((seconds / step).round() as usize).min(100_000)
        } else {
            0
        }
    }

    /// Fill the delay line with the current command and the latency line with the
    /// current truth.
    fn reset_lines(&mut self) {
        for slot in self.delay_line.iter_mut() {
            *slot = self.command;
        }
        let pitch = self.model.heli.blade_pitch(self.actuator_position);
        let (_, loads) = self.model.derivative(
            &self.x,
            &pitch,
            self.total_wind(),
            self.flags,
            &mut self.warm,
        );
        let now = truth(&self.x, loads.force, self.model.heli.mass, self.time);
        for slot in self.latency_line.iter_mut() {
            *slot = now;
        }
        self.last_reading = now;
    }

    fn total_wind(&self) -> [f64; 3] {
        [
            self.wind[0] + self.gust[0],
            self.wind[1] + self.gust[1],
            self.wind[2] + self.gust[2],
        ]
    }

    /// Advance by `dt` seconds (the loop period; rounded to whole internal steps, at least
    /// one) with stick fractions `controls` = [lat, lon, ped, col] (clamped to ±1; a
    /// non-finite entry keeps the previous command), and return the sensor reading.
    pub fn step(&mut self, dt: f64, controls: [f64; 4]) -> SensorReading {
        for (held, new) in self.command.iter_mut().zip(controls) {
            if new.is_finite() {
                *held = new.clamp(-1.0, 1.0);
            }
        }
        let h_nominal = self.options.internal_step_s;
        let steps = if dt.is_finite() && dt > 0.0 {
            ((dt / h_nominal).round() as usize).max(1)
        } else {
            1
        };
        let h = if dt.is_finite() && dt > 0.0 {
            dt / steps as f64
        } else {
            h_nominal
        };
        self.update_gust(h * steps as f64);
        let wind = self.total_wind();
        let mass = self.model.heli.mass;
        let latency = self.latency_line.len() > 1 || self.options.sensor_noise.latency_s >= 0.5 * h;
        for _ in 0..steps {
            // Transport delay: the command written now comes out `len` steps later.
            let delayed = if self.delay_line.len() > 1
                || self.options.actuator.transport_delay_s >= 0.5 * h
            {
                let out = self.delay_line[self.delay_head];
                self.delay_line[self.delay_head] = self.command;
                self.delay_head = (self.delay_head + 1) % self.delay_line.len();
                out
            } else {
                self.command
            };
            self.update_actuators(delayed, h);
            let start = self.x;
            let force = if let Some(plant) = &self.linear_plant {
                plant.rk4_step(&mut self.x, &self.actuator_position, h);
                plant.force(&start, &self.actuator_position)
            } else {
                let pitch = self.model.heli.blade_pitch(self.actuator_position);
                let loads = rk4_step(
                    &self.model,
                    &mut self.x,
                    &pitch,
                    wind,
                    self.flags,
                    &mut self.warm,
                    h,
                );
                if !self.flags.dynamic_inflow {
                    self.x[model::LAMBDA] = self.warm[0];
                }
                loads.force
            };
            if latency {
                // Truth at the start of this internal step (RK4's k1 is evaluated there).
                self.latency_line[self.latency_head] = truth(&start, force, mass, self.time);
                self.latency_head = (self.latency_head + 1) % self.latency_line.len();
            }
            self.time += h;
        }
        let sample = if latency {
            self.latency_line[self.latency_head]
        } else {
            let force = if let Some(plant) = &self.linear_plant {
                plant.force(&self.x, &self.actuator_position)
            } else {
                // Loads only (no rigid-body derivative) for the accelerometer.
                let pitch = self.model.heli.blade_pitch(self.actuator_position);
                let (loads, _, _) =
                    self.model
                        .loads(&self.x, &pitch, wind, self.flags, &mut self.warm);
                loads.force
            };
            truth(&self.x, force, mass, self.time)
        };
        self.measure(sample)
    }

    /// Advance the Gauss–Markov gust over one loop period:
    /// g ← a·g + σ√(1 − a²)·n,  a = e^{−Δt/τ}, n ~ N(0, 1) per axis.
    fn update_gust(&mut self, period: f64) {
        let sigma = self.options.gust_level;
        if !(sigma.is_finite() && sigma > 0.0) {
            return;
        }
        let tau = self.options.gust_time_constant_s.max(1e-3);
        let a = (-period / tau).exp();
        let drive = sigma * (1.0 - a * a).sqrt();
        for g in self.gust.iter_mut() {
            *g = a * *g + drive * self.rng.normal();
        }
    }

    /// Second-order servo with rate limit, semi-implicit Euler at the internal step:
    /// ẍ = ω_n²(c − x) − 2ζω_n ẋ, |ẋ| ≤ rate limit, x ∈ [−1, 1].
    fn update_actuators(&mut self, command: [f64; 4], h: f64) {
        let act = self.options.actuator;
        if act.is_instant() {
            self.actuator_position = command;
            self.actuator_rate = [0.0; 4];
            return;
        }
        let wn = act.natural_frequency_rad_s;
        let limit = if act.rate_limit_per_s > 0.0 {
            act.rate_limit_per_s
        } else {
            f64::INFINITY
        };
        let channels = command
            .iter()
            .zip(self.actuator_position.iter_mut())
            .zip(self.actuator_rate.iter_mut());
        for ((&target, position), rate) in channels {
            let accel = wn * wn * (target - *position) - 2.0 * act.damping * wn * *rate;
            *rate = (*rate + h * accel).clamp(-limit, limit);
            *position = (*position + h * *rate).clamp(-1.0, 1.0);
        }
    }

    /// Apply noise, bias, dropout and spikes to a true sample.
    fn measure(&mut self, sample: SensorReading) -> SensorReading {
        let noise = self.options.sensor_noise;
        let dropout = self.options.dropout_probability;
        if dropout > 0.0 && self.rng.uniform() < dropout && self.seq > 0 {
            return self.last_reading;
        }
        let sigma = [
            noise.gyro_rad_s,
            noise.gyro_rad_s,
            noise.gyro_rad_s,
            noise.attitude_rad,
            noise.attitude_rad,
            noise.attitude_rad,
            noise.velocity_m_s,
            noise.velocity_m_s,
            noise.velocity_m_s,
            noise.accel_m_s2,
            noise.accel_m_s2,
            noise.accel_m_s2,
        ];
        let mut channels = sample.channels();
        for i in 0..12 {
            channels[i] += noise.bias[i];
            if sigma[i] > 0.0 {
                channels[i] += sigma[i] * self.rng.normal();
            }
        }
        let spike = self.options.spike_probability;
        if spike > 0.0 && self.rng.uniform() < spike {
            const SIZE: [f64; 4] = [1.0, 0.2, 5.0, 20.0];
            let channel = (self.rng.uniform() * 12.0) as usize % 12;
            let sign = if self.rng.uniform() < 0.5 { -1.0 } else { 1.0 };
            channels[channel] += sign * SIZE[channel / 3] * self.options.spike_scale;
        }
        channels[5] = wrap_angle(channels[5]);
        self.seq = self.seq.wrapping_add(1);
        let reading = SensorReading::with_channels(self.seq, sample.time_s, channels);
        self.last_reading = reading;
        reading
    }

    /// The full state (see [`crate::model`] for the layout).
    pub fn state(&self) -> State {
        State(self.x)
    }

    /// Replace the state (e.g. to start from a perturbed trim).
    pub fn set_state(&mut self, state: State) {
        if state.0.iter().all(|v| v.is_finite()) {
            self.x = state.0;
        }
    }

    /// Simulation time [s].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The actuator outputs (stick fractions actually applied) [lat, lon, ped, col].
    pub fn actuator_position(&self) -> [f64; 4] {
        self.actuator_position
    }

    /// The helicopter being simulated.
    pub fn helicopter(&self) -> &Helicopter {
        &self.model.heli
    }

    /// The options in force (internal step sanitised).
    pub fn options(&self) -> &SimOptions {
        &self.options
    }

    /// A steady wind, air velocity relative to the ground in body axes [m/s], added to the
    /// turbulence (disturbance hook).
    pub fn set_wind(&mut self, body_wind: [f64; 3]) {
        if body_wind.iter().all(|v| v.is_finite()) {
            self.wind = body_wind;
        }
    }

    /// The current turbulence velocity, body axes [m/s].
    pub fn gust(&self) -> [f64; 3] {
        self.gust
    }

    /// An external force [N] and moment [N·m] about the CG in body axes, held until
    /// changed (disturbance hook; the accelerometer feels the force).
    pub fn set_external_load(&mut self, force: [f64; 3], moment: [f64; 3]) {
        if force.iter().chain(moment.iter()).all(|v| v.is_finite()) {
            self.flags.external_load = [
                force[0], force[1], force[2], moment[0], moment[1], moment[2],
            ];
        }
    }

    /// Switch all aerodynamic loads (rotors, fuselage, surfaces) on or off; off leaves a
    /// rigid body under gravity and external loads (physics checks).
    pub fn set_aerodynamics(&mut self, enabled: bool) {
        self.flags.no_aero = !enabled;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trim::trim;
    use nalgebra::{Matrix3, Vector3};

    #[test]
    fn free_fall_at_g_with_rotors_off() {
        let heli = Helicopter::bo105();
        let g = heli.gravity;
        let mut sim = Sim::new(heli, SimOptions::perfect());
        sim.set_aerodynamics(false);
        let mut reading = SensorReading::default();
        for _ in 0..200 {
            reading = sim.step(0.005, [0.0; 4]);
        }
        let t = sim.time();
        assert!((t - 1.0).abs() < 1e-9);
        let x = sim.state();
        assert!((x.0[model::W] - g * t).abs() < 1e-9, "w {}", x.0[model::W]);
        assert!((x.0[model::DOWN] - 0.5 * g * t * t).abs() < 1e-9);
        // An accelerometer in free fall reads zero specific force.
        assert!(reading.az.abs() < 1e-12 && reading.ax.abs() < 1e-12);
    }

    #[test]
    fn applied_moment_gives_inverse_inertia_times_moment() {
        let heli = Helicopter::bo105();
        let inertia = Matrix3::new(
            heli.ixx, 0.0, -heli.ixz, 0.0, heli.iyy, 0.0, -heli.ixz, 0.0, heli.izz,
        );
        let model = Model::new(heli);
        let moment = Vector3::new(500.0, -300.0, 200.0);
        let mut flags = ModelFlags {
            no_aero: true,
            ..ModelFlags::default()
        };
        flags.external_load[3..].copy_from_slice(moment.as_slice());
        // From rest: ω̇ = I⁻¹ M exactly.
        let x = [0.0; STATE_LEN];
        let pitch = model.heli.blade_pitch([0.0; 4]);
        let (dx, _) = model.derivative(&x, &pitch, [0.0; 3], flags, &mut [0.05; 2]);
        let expected = inertia.try_inverse().unwrap() * moment;
        for i in 0..3 {
            assert!((dx[model::P + i] - expected[i]).abs() < 1e-12 * expected.norm());
        }
        // Spinning: ω̇ = I⁻¹ (M − ω × Iω).
        let mut spinning = x;
        spinning[model::P] = 0.3;
        spinning[model::Q] = -0.2;
        spinning[model::R] = 0.5;
        let omega = Vector3::new(0.3, -0.2, 0.5);
        let expected = inertia.try_inverse().unwrap() * (moment - omega.cross(&(inertia * omega)));
        let (dx, _) = model.derivative(&spinning, &pitch, [0.0; 3], flags, &mut [0.05; 2]);
        for i in 0..3 {
            assert!((dx[model::P + i] - expected[i]).abs() < 1e-12 * expected.norm());
        }
    }

    #[test]
    fn rk4_error_shrinks_sixteenfold_when_the_step_halves() {
        let heli = Helicopter::bo105();
        let t = trim(&heli, 20.0).unwrap();
        let model = Model::new(heli);
        let pitch = t.blade_pitch_rad;
        let mut start = t.state.0;
        start[model::P] += 0.2;
        start[model::Q] -= 0.1;
        start[model::BETA1C] += 0.01;
        let run = |h: f64| {
            let mut x = start;
            let mut warm = [t.inflow, t.tail_inflow];
            let steps = (0.4 / h).round() as usize;
            for _ in 0..steps {
                rk4_step(
                    &model,
                    &mut x,
                    &pitch,
                    [0.0; 3],
                    ModelFlags::default(),
                    &mut warm,
                    h,
                );
            }
            x
        };
        let coarse = run(0.008);
        let medium = run(0.004);
        let fine = run(0.002);
        let error = |a: &[f64; STATE_LEN], b: &[f64; STATE_LEN]| {
            (0..11).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
        };
        let ratio = error(&coarse, &medium) / error(&medium, &fine);
        eprintln!("RK4 error ratio on halving the step: {ratio:.2}");
        assert!((13.0..19.0).contains(&ratio), "error ratio {ratio}");
    }

    #[test]
    fn hover_trim_holds_and_accelerometer_reads_minus_g() {
        let heli = Helicopter::bo105();
        let g = heli.gravity;
        let t = trim(&heli, 0.0).unwrap();
        let mut sim = Sim::at_trim(heli, &t, SimOptions::perfect());
        let mut reading = SensorReading::default();
        for _ in 0..40 {
            reading = sim.step(0.005, t.controls);
        }
        // 0.2 s after release the trimmed state has not drifted (unstable modes are slow).
        assert!(
            reading.p.abs() < 1e-5 && reading.q.abs() < 1e-5,
            "{reading:?}"
        );
        assert!((reading.az + g * t.phi.cos() * t.theta.cos()).abs() < 1e-3 && reading.seq == 40);
    }

    #[test]
    fn seeded_runs_repeat_and_faults_behave() {
        let heli = Helicopter::bo105();
        let t = trim(&heli, 0.0).unwrap();
        let options = SimOptions {
            seed: 99,
            gust_level: 1.0,
            dropout_probability: 0.2,
            spike_probability: 0.05,
            ..SimOptions::default()
        };
        let run = || {
            let mut sim = Sim::at_trim(heli.clone(), &t, options);
            (0..200)
                .map(|_| sim.step(0.005, t.controls))
                .collect::<Vec<_>>()
        };
        let a = run();
        let b = run();
        assert_eq!(a, b);
        // Dropouts repeat the previous sample with its sequence number.
        let repeats = a.windows(2).filter(|w| w[0] == w[1]).count();
        assert!((20..70).contains(&repeats), "repeats {repeats}");
        let last = a.last().unwrap();
        assert_eq!(last.seq as usize, 200 - repeats);
        assert!(a
            .iter()
            .all(|r| r.psi > -std::f64::consts::PI && r.psi <= std::f64::consts::PI));
    }

    /// Stick sign convention: a positive stick gives a positive response (lat → roll right,
    /// lon → nose up, ped → nose right, col → climb), for both vehicles.
    #[test]
    fn positive_sticks_give_positive_moments_on_both_vehicles() {
        for heli in [Helicopter::bo105(), Helicopter::trex700l()] {
            let t = trim(&heli, 0.0).unwrap();
            for axis in 0..4 {
                let mut sim = Sim::at_trim(heli.clone(), &t, SimOptions::perfect());
                let mut controls = t.controls;
                controls[axis] += 0.05;
                let mut reading = SensorReading::default();
                for _ in 0..20 {
                    reading = sim.step(0.005, controls);
                }
                let response = [reading.p, reading.q, reading.r, -reading.w][axis];
                assert!(response > 0.0, "{} axis {axis}: {reading:?}", heli.name);
            }
        }
    }

    /// A plain PD attitude hold (what the firmware's hold does) keeps the Bo-105 in hover
    /// while a 5 %-of-stick lateral sweep (0.3 → 12 rad/s over 30 s) runs.
    #[test]
    fn pd_attitude_hold_keeps_bo105_hovering_through_a_five_percent_sweep() {
        let heli = Helicopter::bo105();
        let t = trim(&heli, 0.0).unwrap();
        let mut sim = Sim::at_trim(
            heli,
            &t,
            SimOptions {
                seed: 3,
                ..SimOptions::default()
            },
        );
        let dt = 0.005;
        let (duration, w_min, w_max) = (30.0, 0.3, 12.0);
        let mut reading = sim.step(dt, t.controls);
        let mut worst: f64 = 0.0;
        for tick in 1..(duration / dt) as usize {
            let time = tick as f64 * dt;
            // Linear chirp phase θ(t) = w_min t + (w_max − w_min) t² / (2T).
            let phase = w_min * time + (w_max - w_min) * time * time / (2.0 * duration);
            let sweep = 0.05 * phase.sin();
            let lat = t.controls[0] - 0.4 * (reading.phi - t.phi) - 0.1 * reading.p + sweep;
            let lon = t.controls[1] - 1.1 * (reading.theta - t.theta) - 0.5 * reading.q;
            let ped = t.controls[2] - 0.9 * reading.psi - 0.3 * reading.r;
            let col = t.controls[3] + 0.1 * reading.w;
            reading = sim.step(dt, [lat, lon, ped, col]);
            worst = worst
                .max((reading.phi - t.phi).abs())
                .max((reading.theta - t.theta).abs());
        }
        eprintln!(
            "PD hold through a 5 % lateral sweep: largest attitude excursion {:.2} deg",
            worst.to_degrees()
        );
        assert!(
            worst < 6f64.to_radians(),
            "largest attitude excursion {} deg",
            worst.to_degrees()
        );
    }

    /// Largest |r| difference between the linearized plant and the model over 3 s of a
    /// pedal pulse of `size` (1 s long), relative to the model's largest |r|.
    fn linearized_plant_relative_error(size: f64) -> f64 {
        let heli = Helicopter::bo105();
        let t = crate::trim(&heli, 0.0).expect("hover trims");
        let fly = |linearized_plant: bool| {
            let options = SimOptions {
                linearized_plant,
                ..SimOptions::perfect()
            };
            let mut sim = Sim::at_trim(heli.clone(), &t, options);
            let dt = 0.005;
            (0..600)
                .map(|tick| {
                    let mut controls = t.controls;
                    if tick < 200 {
                        controls[2] += size;
                    }
                    sim.step(dt, controls).r
                })
                .collect::<Vec<f64>>()
        };
        let (model, linear) = (fly(false), fly(true));
        let peak = model.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        let worst = model
            .iter()
            .zip(&linear)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(peak > 0.0, "the pulse must yaw the aircraft");
        worst / peak
    }

    #[test]
    fn the_linearized_plant_is_the_model_for_small_inputs_only() {
        let small = linearized_plant_relative_error(0.001);
        let large = linearized_plant_relative_error(0.1);
        eprintln!("linearized vs model, r over 3 s: {small:.2e} (0.001 pulse), {large:.2e} (0.1)");
        // First order: the error of the expansion shrinks with the input (∝ size²/size).
        assert!(small < 2e-3, "small pulse: relative error {small}");
        assert!(large > 10.0 * small, "large {large} vs small {small}");
    }

    #[test]
    fn sensor_latency_and_transport_delay_shift_the_signals() {
        let heli = Helicopter::bo105();
        let g = heli.gravity;
        let noise = SensorNoise {
            latency_s: 0.010,
            ..SensorNoise::perfect()
        };
        let mut sim = Sim::new(
            heli.clone(),
            SimOptions {
                sensor_noise: noise,
                ..SimOptions::perfect()
            },
        );
        sim.set_aerodynamics(false);
        let mut reading = SensorReading::default();
        for _ in 0..100 {
            reading = sim.step(0.005, [0.0; 4]);
        }
        // Free fall read 10 ms late: w = g (t − 0.010).
        assert!((reading.w - g * 0.490).abs() < 1e-9, "{}", reading.w);
        assert!((reading.time_s - 0.490).abs() < 1e-9);

        let actuator = ActuatorModel {
            transport_delay_s: 0.020,
            ..ActuatorModel::ideal()
        };
        let mut sim = Sim::new(
            heli,
            SimOptions {
                actuator,
                ..SimOptions::perfect()
            },
        );
        for _ in 0..3 {
            sim.step(0.005, [0.5; 4]);
        }
        assert_eq!(sim.actuator_position(), [0.0; 4]);
        for _ in 0..2 {
            sim.step(0.005, [0.5; 4]);
        }
        assert_eq!(sim.actuator_position(), [0.5; 4]);
    }

    #[test]
    fn dynamic_inflow_trim_is_an_equilibrium() {
        let heli = Helicopter::bo105();
        let t = trim(&heli, 20.0).unwrap();
        let options = SimOptions {
            dynamic_inflow: true,
            ..SimOptions::perfect()
        };
        let mut sim = Sim::at_trim(heli, &t, options);
        let mut reading = SensorReading::default();
        for _ in 0..40 {
            reading = sim.step(0.005, t.controls);
        }
        assert!(reading.p.abs() < 1e-5 && reading.q.abs() < 1e-5 && reading.r.abs() < 1e-5);
        assert!((sim.state().inflow() - t.inflow).abs() < 1e-6);
    }

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

        /// Any stick input, even non-finite or out of range, leaves a finite state.
        #[test]
        fn bad_controls_never_poison_the_state(
            sticks in proptest::collection::vec(
                proptest::prop_oneof![
                    -3.0f64..3.0,
                    proptest::strategy::Just(f64::NAN),
                    proptest::strategy::Just(f64::INFINITY),
                ],
                40,
            ),
            dt in proptest::prop_oneof![0.001f64..0.02, proptest::strategy::Just(f64::NAN), proptest::strategy::Just(-1.0)],
        ) {
            let heli = Helicopter::bo105();
            let t = trim(&heli, 0.0).unwrap();
            let mut sim = Sim::at_trim(heli, &t, SimOptions::default());
            for chunk in sticks.chunks(4) {
                let reading = sim.step(dt, [chunk[0], chunk[1], chunk[2], chunk[3]]);
                proptest::prop_assert!(reading.p.is_finite() && reading.az.is_finite());
            }
            proptest::prop_assert!(sim.state().0.iter().all(|v| v.is_finite()));
            proptest::prop_assert!(sim.actuator_position().iter().all(|v| v.abs() <= 1.0));
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
