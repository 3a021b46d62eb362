//! # sweephold-firmware — flight logic
//!
//! The host-testable, `no_std`, allocation-free flight logic of the sweephold flight
//! controller: Tischler's exponential frequency sweep (and doublet / 3-2-1-1 inputs)
//! flown under the *conditional attitude hold* of Jung, Shim & Kim, with off-axis noise,
//! abort safety, swashplate mixing (120°, 135°, 140° CCPM, H1) and postcard telemetry.
//!
//! The entry point is [`FlightController`]: build it from a [`Config`] (presets
//! [`Config::bo105_default`] and [`Config::trex700l_default`]), then call
//! [`FlightController::step`] once per tick with the sensor frame; it returns the
//! [`Output`] (commands and servo pulse widths) and writes the telemetry frames (Header,
//! Events, one Sample per tick) into a [`FrameSink`].
//!
//! ```
//! use sweephold_firmware::{Config, FlightController};
//! use sweephold_protocol::{Axis, Phase, SensorIn};
//!
//! let mut fc = FlightController::new(Config::bo105_default(Axis::Lat)).unwrap();
//! let mut telemetry: heapless::Vec<u8, 1024> = heapless::Vec::new();
//! let mut sensor = SensorIn::default();
//! sensor.pilot.test_switch = true;
//! let out = fc.step(&sensor, &mut telemetry);
//! assert_eq!(fc.phase(), Phase::Armed);
//! assert!(out.command.lat.abs() <= 1.0);
//! ```
//!
//! The tick path has no `unwrap`, `expect`, panicking index or `unsafe`, runs in bounded
//! time and turns NaN or infinite inputs into an abort and finite, clamped outputs.
//!
//! **Its room and what it may import.** The flight logic and the board application,
//! written against traits and plain data: no register, pin or peripheral of a board
//! (those are the image's, `firmware/board`). Of the workspace, only the wire protocol
//! (`sweephold-protocol`); otherwise `no_std` crates that allocate nothing (heapless,
//! libm, micromath, embedded-hal, embedded-io, rand_pcg, defmt, and for the parameter
//! store sequential-storage, embedded-storage and embassy-futures). It never imports the
//! host crates: they drive it (in-process, in QEMU or over a serial port).
//!
//! Modules, one concept each: [`sweep`] (the sweep, its closed-form phase and its
//! `f64`-free tick evaluation), [`turns`] (angles as fixed-point fractions of a turn and
//! their `f32` sine),
//! [`pulse`] (multisteps), [`excitation`] (both behind one interface; what each yields
//! per instant is an [`excitation_sample`]), [`amplitude`] (the
//! adaptive sweep amplitude), [`noise`] (PRNG,
//! filtered noise), [`hold`] (the hysteresis), [`attitude_hold`] (the PID),
//! [`safety`] (abort checks), [`trim`] (trim capture), [`slew`] (the commands' slew
//! limit), [`mixer`] (swash and tail mixing), [`servo_test`] (the bench servo test), [`swash`] (the swash types, phase angle
//! and cyclic ring),
//! [`sink`] (telemetry output), [`config`] and [`controller`] (the sequencer); for the
//! board's inputs: [`imu`] (the ICM-42688-P driver, its health monitor, boot calibration
//! and, on the host, a register-level emulator of the chip), [`receiver`] (SBUS decoding,
//! link monitoring, the channel map), [`filters`] (biquads and the IMU filter bank) and
//! [`estimator`] (the attitude estimator); [`app`] (the board application: arming, the
//! stabilised pilot mode, failsafes and the throttle around the sequencer); and
//! [`board_stack`] (all of these wired together: the IMU polled at 1 kHz through the
//! monitor, calibration, filters and estimator, the receiver bytes through the SBUS
//! decoder and channel map, and the application's control tick); [`params`] (the
//! board's parameter table, its typed view and its flash store).
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

#[macro_use]
mod fmt;

pub mod amplitude;
pub mod app;
pub mod attitude_hold;
pub mod board_stack;
pub mod config;
pub mod controller;
pub mod estimator;
pub mod excitation;
pub mod excitation_sample;
pub mod excitation_scale;
pub mod filters;
pub mod hold;
pub mod imu;
pub mod mixer;
pub mod noise;
pub mod params;
pub mod pulse;
pub mod receiver;
pub mod safety;
pub mod servo_test;
pub mod sink;
pub mod slew;
pub mod swash;
pub mod sweep;
pub mod trim;
pub mod turns;

pub use attitude_hold::{AxisGains, Gains};
pub use config::{paper_test, CollectiveSource, Config, ConfigError, HoldReference};
pub use controller::{FlightController, Output, FIRMWARE_VERSION};
pub use mixer::{mix, MixerConfig, ServoConfig};
pub use safety::SafetyLimits;
pub use sink::{FrameSink, IoSink};
