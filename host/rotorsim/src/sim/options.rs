//! What a [`Sim`](super::Sim) is built with: step, sensors, actuators, turbulence, faults,
//! seed, and which plant it flies.

use super::actuator::ActuatorModel;
use super::sensors::SensorNoise;

/// Simulation options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Fixed RK4 step \[s\].
    pub internal_step_s: f64,
    /// Sensor imperfections.
    pub sensor_noise: SensorNoise,
    /// PRNG seed (noise, gusts, faults).
    pub seed: u64,
    /// Turbulence intensity, 1σ per body axis [m/s] (0 = still air).
    pub gust_level: f64,
    /// Correlation time of the first-order (Gauss–Markov) gust filter \[s\].
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
    /// the estimator's. Takes effect in [`Sim::at_trim`](super::Sim::at_trim); still air only (wind, gusts and
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
