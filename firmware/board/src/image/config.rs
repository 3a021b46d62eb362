//! What the image flies: one image for every aircraft and test. The board application
//! flies the typed view of the parameter table ([`crate::image::params`]), whose `FRAME`
//! names the vehicle preset under it; a host's Configure frame (protocol 1.1) sets the
//! in-the-loop flight logic.

use sweephold_firmware::params::Params;
use sweephold_firmware::Config;
use sweephold_protocol::{LinkConfig, VehicleId};

/// The airframe whose defaults a board without a valid stored set boots: the TREX 700L,
/// the aircraft the boards fly (`FRAME` 0).
pub const DEFAULT_FRAME: VehicleId = VehicleId::Trex700l;

/// The preset of `vehicle` flying the paper's test on `axis`.
fn preset(vehicle: VehicleId, axis: sweephold_protocol::Axis) -> Config {
    match vehicle {
        VehicleId::Bo105 => Config::bo105_default(axis),
        VehicleId::Trex700l => Config::trex700l_default(axis),
    }
}

/// The configuration a board flies when its table cannot give one (never expected:
/// the boot loads only sets the typed view accepts, and the defaults are the presets).
pub const fn fallback_params() -> Params {
    Params::preset(DEFAULT_FRAME)
}

/// The configuration a Configure frame asks for: the vehicle's preset for the test's
/// primary axis with the frame's rate and test.
pub fn link_config(request: &LinkConfig) -> Config {
    let mut config = preset(request.vehicle, request.test.primary);
    config.rate_hz = request.rate_hz;
    config.test = request.test;
    config
}
