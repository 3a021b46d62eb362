//! What the image flies, chosen when it is built (`SWEEPHOLD_VEHICLE`, `SWEEPHOLD_AXIS`),
//! and what a host's Configure frame turns it into.

use sweephold_firmware::board_stack::StackConfig;
use sweephold_firmware::Config;
use sweephold_protocol::{Axis, LinkConfig, VehicleId};

/// Vehicle preset of the image, chosen when it is built: `SWEEPHOLD_VEHICLE=trex700l`
/// (the default: the aircraft this board flies) or `bo105` (QEMU in the loop with the
/// Bo-105 simulator).
const VEHICLE: VehicleId = match option_env!("SWEEPHOLD_VEHICLE") {
    None => VehicleId::Trex700l,
    Some(name) => match parse_vehicle(name) {
        Some(vehicle) => vehicle,
        None => panic!("SWEEPHOLD_VEHICLE must be trex700l or bo105"),
    },
};

/// Primary axis of the image's test, chosen when it is built: `SWEEPHOLD_AXIS=lat`
/// (default), `lon`, `ped` or `col`.
const PRIMARY_AXIS: Axis = match option_env!("SWEEPHOLD_AXIS") {
    None => Axis::Lat,
    Some(name) => match parse_axis(name) {
        Some(axis) => axis,
        None => panic!("SWEEPHOLD_AXIS must be lat, lon, ped or col"),
    },
};

/// `a == b` for strings, usable in a constant.
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const fn parse_vehicle(name: &str) -> Option<VehicleId> {
    if same(name, VehicleId::Trex700l.name()) {
        Some(VehicleId::Trex700l)
    } else if same(name, VehicleId::Bo105.name()) {
        Some(VehicleId::Bo105)
    } else {
        None
    }
}

const fn parse_axis(name: &str) -> Option<Axis> {
    let mut i = 0;
    while i < Axis::ALL.len() {
        if same(name, Axis::ALL[i].name()) {
            return Some(Axis::ALL[i]);
        }
        i += 1;
    }
    None
}

/// The preset of `vehicle` flying the paper's test on `axis`.
fn preset(vehicle: VehicleId, axis: Axis) -> Config {
    match vehicle {
        VehicleId::Bo105 => Config::bo105_default(axis),
        VehicleId::Trex700l => Config::trex700l_default(axis),
    }
}

/// The flight-logic configuration the image boots with: the preset of [`VEHICLE`]
/// flying the paper's test on [`PRIMARY_AXIS`]. A host changes it at run time with a
/// Configure frame (protocol 1.1).
pub fn image_config() -> Config {
    preset(VEHICLE, PRIMARY_AXIS)
}

/// The board application's configuration: the vehicle's board settings (pilot mode,
/// throttle, failsafes, IMU, filters, estimator, receiver) around [`image_config`].
pub fn stack_config() -> StackConfig {
    match VEHICLE {
        VehicleId::Bo105 => StackConfig::bo105(PRIMARY_AXIS),
        VehicleId::Trex700l => StackConfig::trex700l(PRIMARY_AXIS),
    }
}

/// The configuration a Configure frame asks for: the vehicle's preset for the test's
/// primary axis with the frame's rate and test.
pub fn link_config(request: &LinkConfig) -> Config {
    let mut config = preset(request.vehicle, request.test.primary);
    config.rate_hz = request.rate_hz;
    config.test = request.test;
    config
}
