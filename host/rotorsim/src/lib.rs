//! Nonlinear single-main-rotor helicopter simulation of any aircraft file (the shipped
//! Bo-105, TREX 700L and fbl700) with trim and linearization.
//!
//! A minimum-complexity model after Heffley & Mnich (NASA CR-177476) with Padfield's Bo-105
//! data: six-degree-of-freedom rigid body with Euler angles and position, first-order
//! tip-path-plane flapping (β1c, β1s) whose time constant follows from the blade data,
//! blade-element thrust with iterated Glauert momentum inflow (optionally Pitt–Peters
//! dynamic inflow), hub spring and thrust-offset moments, tail rotor, fuselage drag, fin
//! and tailplane. See `README.md` for the validation against Padfield's Helisim.
//!
//! **Its room and what it may import.** This crate is the aircraft only. Of the
//! workspace it imports `aircraft` alone (the aircraft file is its input); otherwise
//! general-purpose crates (nalgebra, rand_core and rand_xoshiro, thiserror). It never
//! imports the identification library (`sysid`), the mapping of its linearization onto a
//! model structure (`truth`) or the command-line tool, which build on it.

mod integrator;
mod linear_plant;
pub mod linearize;
pub mod model;
mod rng;
mod rotor;
pub mod sim;
mod trig;
pub mod trim;
pub mod vehicle;

pub use linearize::{linearize, linearize_with, Linearization};
pub use model::State;
pub use sim::{ActuatorModel, SensorNoise, SensorReading, Sim, SimOptions};
pub use trim::{trim, trim_steady, SteadyFlight, Trim, TrimError, KNOT};
pub use vehicle::{BladePitch, Gearing, Helicopter, Rotor, Surface};
