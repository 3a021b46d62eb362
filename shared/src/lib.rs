//! # sweephold-protocol
//!
//! The wire protocol between the sweephold flight-controller firmware and the host tool:
//! frame types ([`frames`]), their encoding — postcard, CRC-32, COBS, 0x00 delimiter —
//! ([`codec`]), and a streaming decoder that survives corrupt input ([`decoder`]).
//!
//! `no_std`, no allocation. Features: `std` (error trait impls for the host), `defmt`
//! (derive `defmt::Format` on every wire type, for firmware logging).
//!
//! **Its room and what it may import.** The wire format and nothing else (no flight
//! logic, no file format of the host). No workspace crate: it is the one crate both sides share
//! (the firmware imports it and nothing else of the workspace; the host crates read the
//! telemetry through it). Its dependencies are `no_std` serialization crates (serde,
//! postcard, heapless) and, optionally, defmt.
//!
//! ```
//! use sweephold_protocol::{codec, decoder::Decoder, frames::*};
//!
//! let event = Frame::Event(Event::Abort { tick: 7, reason: AbortReason::RateLimit });
//! let mut wire = [0u8; codec::MAX_FRAME_LEN];
//! let n = codec::encode(&event, &mut wire).unwrap();
//!
//! let mut decoder = Decoder::new();
//! let frames: Vec<_> = decoder.feed(&wire[..n]).collect();
//! assert_eq!(frames, vec![Ok(event)]);
//! ```
#![cfg_attr(not(any(test, feature = "std")), no_std)]

pub mod board_events;
pub mod cobs;
pub mod codec;
pub mod decoder;
pub mod frames;
pub mod param_frames;
pub mod servo_frames;
#[cfg(feature = "synthetic")]
pub mod synthetic;
pub mod vocabulary;

pub use codec::{encode, MAX_FRAME_LEN};
pub use decoder::{tick_step, DecodeStats, Decoder, FrameError, TickStep};
pub use frames::*;
