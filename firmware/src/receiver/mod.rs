//! The RC receiver: SBUS frames from the serial line ([`sbus`]) and the pilot's
//! functions read from their channels ([`channel_map`]).
//!
//! The path from the wire to the flight logic, one concept per step:
//!
//! ```text
//! UART bytes ──SbusDecoder──▶ SbusFrame ──Receiver──▶ Valid / Lost
//!                                 │
//!                                 └──ChannelMap::map──▶ RcInput { sticks, throttle, arm,
//!                                                                 test_switch, mode }
//! ```
//!
//! ```
//! use sweephold_firmware::receiver::{ChannelMap, LinkStatus, Receiver, SbusDecoder, SbusFrame};
//!
//! // A transmitter model: every channel centred, channel 7 (the test switch) high.
//! let mut sent = SbusFrame { channels: [992; 16], ..SbusFrame::default() };
//! sent.channels[6] = 1811;
//! let wire = sent.encode();
//!
//! let mut decoder = SbusDecoder::new();
//! let mut link = Receiver::default();
//! let now_us = 1_000;
//! if let Some(frame) = decoder.feed_slice(&wire) {
//!     link.on_frame(&frame, now_us);
//! }
//! assert_eq!(link.status(now_us), LinkStatus::Valid);
//! let input = ChannelMap::flybarless_default().map(&link.frame(now_us).unwrap());
//! assert!(input.test_switch && !input.arm);
//! assert_eq!(input.sticks.lat, 0.0);
//! ```

pub mod channel_map;
pub mod sbus;

pub use channel_map::{ChannelMap, ChannelMapError, ChannelSource, ModeSwitch, RawRange, RcInput};
pub use sbus::{
    decode, encode, LinkStatus, LossReason, Receiver, SbusDecoder, SbusError, SbusFrame, SbusStats,
};

#[cfg(test)]
mod tests;
