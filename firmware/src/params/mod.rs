//! The board's parameters: one typed table of everything an aircraft owner sets up
//! (swash type and servos, receiver map, IMU mounting, head speed, hold gains and
//! thresholds, abort limits, the test, the pilot mode's loop gains), its defaults from the aircraft preset, and the
//! typed view the control code reads.
//!
//! * [`table`] — the definitions: name (≤ 16 characters, ArduPilot / Rotorflight
//!   style), unit, range, kind. `firmware/README.md` lists them all with their defaults.
//! * [`ParamTable`] — the values. Set by name or id with the range and kind checked
//!   (unknown names, NaN, infinities, out-of-range values, fractions where a whole
//!   number is needed and values outside a list are refused; the table is unchanged
//!   then). No allocation, no panic path.
//! * [`Params`] ([`typed`]) — the values as the configuration structs the control code
//!   already reads ([`StackConfig`](crate::board_stack::StackConfig) and the board's
//!   frame rates and mounting), built only when the whole set is consistent (servo
//!   limits around their centre, distinct receiver channels, the test valid, …); the
//!   defaults give the preset exactly.
//! * [`store`] — the set in flash, versioned, CRC-checked and wear-levelled.
//! * [`link`] — the host's parameter requests (protocol 1.5), obeyed only disarmed.
//! * [`no_flash`] — the flash type of a board that keeps its parameters in RAM only.
//! * `ram_flash` (host only) — a NOR flash in RAM and the bytes a store region holds
//!   after a save (the QEMU tests preload a board's store with them).
//!
//! Every value is an `f32`, as ArduPilot's parameters travel over MAVLink: whole
//! numbers up to 2²⁴ are exact, which covers every integer parameter here.

pub mod link;
#[cfg(test)]
pub(crate) mod mock_flash;
pub mod no_flash;
#[cfg(test)]
mod pilot_gains_tests;
#[cfg(any(test, feature = "std"))]
pub mod ram_flash;
pub mod store;
pub mod table;
#[cfg(test)]
mod test_list_tests;
#[cfg(test)]
mod tests;
pub mod typed;

pub use table::{
    frame_code, frame_vehicle, ParamDef, ParamId, ParamKind, COUNT, DEFS, MAX_NAME_LEN,
    TABLE_VERSION,
};
pub use typed::{Params, ParamsError};

use sweephold_protocol::VehicleId;

/// Why a value was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SetError {
    /// No parameter has that name.
    UnknownName,
    /// NaN or infinite.
    NotFinite,
    /// Below the minimum or above the maximum.
    OutOfRange,
    /// A whole number is needed.
    NotAnInteger,
    /// Not one of the accepted values.
    NotAChoice,
}

impl SetError {
    /// Human-readable explanation.
    pub const fn message(self) -> &'static str {
        match self {
            SetError::UnknownName => "unknown parameter name",
            SetError::NotFinite => "value is NaN or infinite",
            SetError::OutOfRange => "value outside the parameter's range",
            SetError::NotAnInteger => "value must be a whole number",
            SetError::NotAChoice => "value is not one of the parameter's choices",
        }
    }
}

impl ParamId {
    /// The parameter called `name` (exact, upper case).
    pub fn from_name(name: &str) -> Option<ParamId> {
        ParamId::ALL
            .iter()
            .zip(DEFS.iter())
            .find(|(_, def)| def.name == name)
            .map(|(id, _)| *id)
    }

    /// Its position in the table.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The parameter at `index`.
    pub fn from_index(index: usize) -> Option<ParamId> {
        ParamId::ALL.get(index).copied()
    }

    /// Its definition.
    pub fn def(self) -> &'static ParamDef {
        // `index` < COUNT by construction; the fallback only avoids a panic path.
        DEFS.get(self.index()).unwrap_or(&DEFS[0])
    }
}

impl ParamDef {
    /// Whether `value` is acceptable for this parameter.
    pub fn check(&self, value: f32) -> Result<(), SetError> {
        if !value.is_finite() {
            return Err(SetError::NotFinite);
        }
        if value < self.min || value > self.max {
            return Err(SetError::OutOfRange);
        }
        match self.kind {
            ParamKind::Real => Ok(()),
            ParamKind::Integer if libm::truncf(value) == value => Ok(()),
            ParamKind::Integer => Err(SetError::NotAnInteger),
            ParamKind::OneOf(choices) if choices.contains(&value) => Ok(()),
            ParamKind::OneOf(_) => Err(SetError::NotAChoice),
        }
    }
}

/// The values of every parameter, in table order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamTable {
    values: [f32; COUNT],
}

impl ParamTable {
    /// The defaults: the preset of `vehicle` ([`crate::board_stack::StackConfig`] with
    /// [`crate::app::AppConfig::preset`], test axis lat, the board's frame rates and
    /// mounting), `FRAME` naming it.
    pub fn defaults(vehicle: VehicleId) -> Self {
        ParamTable {
            values: typed::values_of(&Params::preset(vehicle)),
        }
    }

    /// A table holding `values` if every one is acceptable, else the first refused
    /// parameter and why.
    pub fn from_values(values: [f32; COUNT]) -> Result<Self, (ParamId, SetError)> {
        for (id, value) in ParamId::ALL.iter().zip(values) {
            id.def().check(value).map_err(|error| (*id, error))?;
        }
        Ok(ParamTable { values })
    }

    /// Every value, in table order.
    pub const fn values(&self) -> &[f32; COUNT] {
        &self.values
    }

    /// The value of `id`.
    pub fn get(&self, id: ParamId) -> f32 {
        self.values.get(id.index()).copied().unwrap_or(0.0)
    }

    /// The value of the parameter called `name`.
    pub fn get_by_name(&self, name: &str) -> Result<f32, SetError> {
        ParamId::from_name(name)
            .map(|id| self.get(id))
            .ok_or(SetError::UnknownName)
    }

    /// Set `id` to `value` after checking it; on a refusal nothing changes.
    pub fn set(&mut self, id: ParamId, value: f32) -> Result<(), SetError> {
        id.def().check(value)?;
        if let Some(slot) = self.values.get_mut(id.index()) {
            *slot = value;
        }
        Ok(())
    }

    /// Set the parameter called `name`; on a refusal nothing changes.
    pub fn set_by_name(&mut self, name: &str, value: f32) -> Result<(), SetError> {
        let id = ParamId::from_name(name).ok_or(SetError::UnknownName)?;
        self.set(id, value)
    }

    /// The typed view (on top of the preset `FRAME` names), if the whole set is
    /// consistent.
    pub fn params(&self) -> Result<Params, ParamsError> {
        Params::from_values(&self.values)
    }

    /// The vehicle whose preset `FRAME` names (TREX 700L for a value the table would
    /// refuse, which [`ParamTable::set`] never stores).
    pub fn frame(&self) -> VehicleId {
        table::frame_vehicle(self.get(ParamId::Frame)).unwrap_or(VehicleId::Trex700l)
    }
}
