//! The time-stepping simulator: RK4 at a fixed internal step, actuators (second-order
//! servo with rate limit and transport delay), sensors (noise, bias, latency, dropout,
//! spikes) and gusts. Everything random comes from one seeded PRNG, so a run is a pure
//! function of (vehicle, options, seed, control sequence). No allocation per step.
//!
//! The settings live beside it: [`SimOptions`] (in `options`), the servo's
//! [`ActuatorModel`] (in `actuator`) and the sensor set's [`SensorNoise`] and
//! [`SensorReading`] (in `sensors`).

mod actuator;
mod options;
mod sensors;

pub use actuator::ActuatorModel;
pub use options::SimOptions;
pub use sensors::{wrap_angle, SensorNoise, SensorReading};

use crate::integrator::rk4_step;
use crate::linear_plant::LinearPlant;
use crate::model::{self, Model, ModelFlags, State, STATE_LEN};
use crate::rng::Rng;
use crate::trim::Trim;
use crate::vehicle::Helicopter;
use sensors::truth;

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

    /// Simulation time \[s\].
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

    /// An external force \[N\] and moment [N·m] about the CG in body axes, held until
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
mod tests;
