//! Parameter frames (protocol 1.5): a host lists, reads, sets, saves and resets the
//! flight controller's parameters ([`Frame::ParamRequest`](crate::Frame::ParamRequest),
//! answered by [`Frame::ParamReply`](crate::Frame::ParamReply)).
//!
//! * `List` → one [`ParamReply::Value`] per parameter, in table order (`index` 0 …
//!   `count` − 1), then [`ParamReply::Done`].
//! * `Get { name }` → its [`ParamReply::Value`].
//! * `Set { name, value }` → the new [`ParamReply::Value`]; the value is checked
//!   against the parameter's range and kind, and the set in RAM changes, not the flash.
//! * `Save` → [`ParamReply::Done`] once the set is in flash (a set that is not
//!   consistent as a whole is refused and nothing is written).
//! * `Reset` → [`ParamReply::Done`]: the set in RAM goes back to the defaults (a
//!   `Save` makes that permanent).
//!
//! A request the flight controller cannot carry out is answered with
//! [`ParamReply::Refused`] and its [`ParamRefusal`]; every request is refused with
//! [`ParamRefusal::Armed`] while the aircraft is armed, and changes nothing.

use postcard::experimental::max_size::MaxSize;
use serde::{Deserialize, Serialize};

/// Longest parameter name.
pub const PARAM_NAME_LEN: usize = 16;

/// A parameter name: ASCII, at most [`PARAM_NAME_LEN`] bytes, zero-padded on the wire
/// (a fixed 16 bytes, so a frame's size does not depend on the name).
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParamName {
    bytes: [u8; PARAM_NAME_LEN],
}

impl ParamName {
    /// The empty name (replies that concern no single parameter).
    pub const EMPTY: ParamName = ParamName {
        bytes: [0; PARAM_NAME_LEN],
    };

    /// `name` if it is 1–16 printable ASCII characters.
    pub fn new(name: &str) -> Option<ParamName> {
        let source = name.as_bytes();
        if source.is_empty()
            || source.len() > PARAM_NAME_LEN
            || !source.iter().all(|b| b.is_ascii_graphic())
        {
            return None;
        }
        let mut bytes = [0u8; PARAM_NAME_LEN];
        for (slot, byte) in bytes.iter_mut().zip(source) {
            *slot = *byte;
        }
        Some(ParamName { bytes })
    }

    /// The name; `None` when the bytes received are not a name (non-ASCII, or a zero
    /// followed by more characters).
    pub fn as_str(&self) -> Option<&str> {
        let len = self
            .bytes
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(PARAM_NAME_LEN);
        let (name, padding) = self.bytes.split_at(len);
        if !name.iter().all(|b| b.is_ascii_graphic()) || padding.iter().any(|&b| b != 0) {
            return None;
        }
        core::str::from_utf8(name).ok()
    }
}

/// Host → flight controller: what to do with the parameters.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamRequest {
    /// Every parameter's value.
    List,
    /// One parameter's value.
    Get {
        /// Which.
        name: ParamName,
    },
    /// Change one parameter in RAM.
    Set {
        /// Which.
        name: ParamName,
        /// Its new value.
        value: f32,
    },
    /// Write the set in RAM to flash.
    Save,
    /// Put the defaults in RAM.
    Reset,
}

impl ParamRequest {
    /// The operation, without its arguments.
    pub const fn op(&self) -> ParamOp {
        match self {
            ParamRequest::List => ParamOp::List,
            ParamRequest::Get { .. } => ParamOp::Get,
            ParamRequest::Set { .. } => ParamOp::Set,
            ParamRequest::Save => ParamOp::Save,
            ParamRequest::Reset => ParamOp::Reset,
        }
    }
}

/// A parameter operation.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamOp {
    /// [`ParamRequest::List`].
    List,
    /// [`ParamRequest::Get`].
    Get,
    /// [`ParamRequest::Set`].
    Set,
    /// [`ParamRequest::Save`].
    Save,
    /// [`ParamRequest::Reset`].
    Reset,
}

/// Why a parameter request was refused.
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamRefusal {
    /// The aircraft is armed: parameters change only on the ground, disarmed.
    Armed,
    /// No parameter has that name (or the name is not ASCII).
    UnknownName,
    /// The value is NaN or infinite.
    NotFinite,
    /// The value is outside the parameter's range.
    OutOfRange,
    /// The parameter takes whole numbers only.
    NotAnInteger,
    /// The value is not one of the parameter's choices.
    NotAChoice,
    /// The set is not consistent as a whole (e.g. a servo's limits do not surround its
    /// centre, two functions on one receiver channel); nothing was saved.
    Inconsistent,
    /// The flash write failed; the stored set is the previous one.
    StoreFailed,
    /// This flight controller has no parameter store.
    NoStore,
}

impl ParamRefusal {
    /// Short snake_case name used in reports and logs.
    pub const fn name(self) -> &'static str {
        match self {
            ParamRefusal::Armed => "armed",
            ParamRefusal::UnknownName => "unknown_name",
            ParamRefusal::NotFinite => "not_finite",
            ParamRefusal::OutOfRange => "out_of_range",
            ParamRefusal::NotAnInteger => "not_an_integer",
            ParamRefusal::NotAChoice => "not_a_choice",
            ParamRefusal::Inconsistent => "inconsistent",
            ParamRefusal::StoreFailed => "store_failed",
            ParamRefusal::NoStore => "no_store",
        }
    }
}

/// Flight controller → host: the answer to a [`ParamRequest`].
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamReply {
    /// One parameter's value.
    Value {
        /// Its position in the table.
        index: u16,
        /// The number of parameters.
        count: u16,
        /// Its name.
        name: ParamName,
        /// Its value (in RAM).
        value: f32,
    },
    /// A `List`, `Save` or `Reset` finished.
    Done {
        /// Which.
        op: ParamOp,
    },
    /// The request was refused and changed nothing.
    Refused {
        /// Which operation.
        op: ParamOp,
        /// The parameter concerned ([`ParamName::EMPTY`] for `List`, `Save`, `Reset`).
        name: ParamName,
        /// Why.
        reason: ParamRefusal,
    },
}

/// What the flight controller found in its parameter store at boot, reported once in
/// an [`Event::ParamStore`](crate::Event::ParamStore).
#[derive(Serialize, Deserialize, MaxSize, Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamStoreStatus {
    /// The stored set is in use.
    Loaded,
    /// Nothing stored: defaults in use, arming refused until a set is saved.
    Empty,
    /// The store is damaged: defaults in use, arming refused.
    Corrupt,
    /// The stored set is of another table version: defaults in use, arming refused.
    OtherVersion,
    /// The stored set is refused by the table: defaults in use, arming refused.
    Invalid,
    /// The flash could not be read: defaults in use, arming refused.
    FlashError,
}

impl ParamStoreStatus {
    /// Short snake_case name used in reports and logs.
    pub const fn name(self) -> &'static str {
        match self {
            ParamStoreStatus::Loaded => "loaded",
            ParamStoreStatus::Empty => "empty",
            ParamStoreStatus::Corrupt => "corrupt",
            ParamStoreStatus::OtherVersion => "other_version",
            ParamStoreStatus::Invalid => "invalid",
            ParamStoreStatus::FlashError => "flash_error",
        }
    }
}
