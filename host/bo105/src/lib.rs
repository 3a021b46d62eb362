//! Nonlinear helicopter simulation (Bo-105, TREX 700L class) with trim and linearization.
