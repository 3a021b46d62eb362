//! The image logic, the same on every board: the boot and the control loop
//! ([`runner`]: what the flight controller does each tick in either run mode), the frame
//! link to the host ([`link`]), the parameter table the board application flies and the
//! host's requests on it ([`params`]), the QEMU-only semihosting transport
//! ([`semihosting`]), the defmt logger ([`log`]) and the defaults and in-the-loop
//! configuration ([`config`]).
//!
//! **What it may import.** The flight logic (`sweephold-firmware`), the wire protocol,
//! the chip layer (`crate::chip`: drivers, taken and set up by `chip::devices`) and the
//! selected board's map (`crate::boards::BOARD`); never the PAC directly.

pub mod config;
pub mod link;
pub mod log;
pub mod params;
pub mod runner;
pub mod semihosting;
