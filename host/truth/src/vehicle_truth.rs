//! The simulator's linear truth: a vehicle trimmed in hover and linearized, its servos'
//! equivalent delay, and the simulator's names for the body states and controls.

use aircraft::Aircraft;
use rotorsim::{linearize, trim, ActuatorModel, Helicopter, Linearization};
use sysid::fit::Model;

use crate::Error;

/// The simulator's rigid-body velocity and rate states, in the order of its state vector.
pub(crate) const BODY_STATES: [&str; 6] = ["u", "v", "w", "p", "q", "r"];
/// The simulator's controls (stick fractions), in the order of its control vector.
pub(crate) const CONTROLS: [&str; 4] = ["lat", "lon", "ped", "col"];

/// The simulator's linear truth at hover trim.
#[derive(Clone, Debug)]
pub struct VehicleTruth {
    /// Which vehicle.
    pub aircraft: Aircraft,
    /// Linearization at hover trim (flapping states included, quasi-static derivatives).
    pub linearization: Linearization,
    /// Equivalent delay of the aircraft's servos: 2ζ/ω_n + transport delay \[s\].
    pub actuator_delay_s: f64,
    /// The aircraft's servos themselves (a structure with `[actuators]` models their lag,
    /// and its delays are the transport delay alone).
    pub actuator: ActuatorModel,
}

impl VehicleTruth {
    /// Trim `vehicle` at hover and linearize it; the servos are its aircraft file's, the
    /// ones `sweephold fly` flies with.
    pub fn at_hover(aircraft: &Aircraft) -> Result<VehicleTruth, Error> {
        let heli = Helicopter::from_aircraft(aircraft);
        let trimmed = trim(&heli, 0.0).map_err(|source| Error::Trim {
            vehicle: aircraft.name.clone(),
            source,
        })?;
        let linearization = linearize(&heli, &trimmed);
        let actuator = ActuatorModel::from_aircraft(aircraft);
        let servo_lag = if actuator.natural_frequency_rad_s.is_finite()
            && actuator.natural_frequency_rad_s > 0.0
        {
            2.0 * actuator.damping / actuator.natural_frequency_rad_s
        } else {
            0.0
        };
        Ok(VehicleTruth {
            aircraft: aircraft.clone(),
            linearization,
            actuator_delay_s: servo_lag + actuator.transport_delay_s,
            actuator,
        })
    }

    pub(crate) fn state(&self, name: &str) -> Option<usize> {
        self.linearization.states.iter().position(|s| *s == name)
    }

    pub(crate) fn control(&self, name: &str) -> Option<usize> {
        self.linearization.controls.iter().position(|c| *c == name)
    }

    pub(crate) fn a(&self, row: &str, column: &str) -> Option<f64> {
        Some(self.linearization.a[self.state(row)?][self.state(column)?])
    }

    pub(crate) fn b(&self, row: &str, control: &str) -> Option<f64> {
        Some(self.linearization.b[self.state(row)?][self.control(control)?])
    }

    /// The full linearization as a [`Model`] on the simulator's outputs
    /// `u v w p q r ax ay az phi theta`, with `delays` per control: the reference the truth
    /// mapping is checked against. `y = C x + D u` is written as `H0 x + H1 ẋ`: the
    /// specific forces are `ẋ_u + (C[ax,·] − A[u,·]) x` (and likewise for ay, az), which
    /// carries D = B[u,·] without a feed-through matrix.
    pub fn linear_model(&self, delays: &[f64]) -> Model {
        let lin = &self.linearization;
        let states: Vec<String> = lin.states.iter().map(|s| s.to_string()).collect();
        let controls: Vec<String> = lin.controls.iter().map(|s| s.to_string()).collect();
        let outputs: Vec<String> = lin.outputs.iter().map(|s| s.to_string()).collect();
        let n = lin.states.len();
        let mut model = Model::zeros(states, controls, outputs);
        for i in 0..n {
            model.m[(i, i)] = 1.0;
            for j in 0..n {
                model.f[(i, j)] = lin.a[i][j];
            }
            for j in 0..lin.controls.len() {
                model.g[(i, j)] = lin.b[i][j];
            }
        }
        for (row, name) in lin.outputs.iter().enumerate() {
            let velocity = match *name {
                "ax" => self.state("u"),
                "ay" => self.state("v"),
                "az" => self.state("w"),
                _ => None,
            };
            for j in 0..n {
                model.h0[(row, j)] = lin.c[row][j] - velocity.map_or(0.0, |v| lin.a[v][j]);
            }
            if let Some(v) = velocity {
                model.h1[(row, v)] = 1.0;
            }
        }
        for (k, delay) in delays.iter().enumerate().take(model.delays.len()) {
            model.delays[k] = *delay;
        }
        model
    }
}
