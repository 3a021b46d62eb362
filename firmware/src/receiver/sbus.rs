//! SBUS: frame codec, a resynchronising stream decoder, a non-blocking reader and the
//! link monitor.
//!
//! # The wire
//!
//! 100 000 Bd, 8 data bits, even parity, 2 stop bits, with the line *inverted* (idle
//! low). The inversion is undone in hardware (an inverter, or the UART's RX-invert bit
//! where it has one) before the bytes reach this module. One byte takes
//! 12 bit times = 120 µs, a 25-byte frame 3 ms; the receiver sends a frame every 14 ms
//! (analogue-servo mode) or every 7 ms (high-speed mode), so consecutive frames are
//! separated by at least 4 ms of idle line while the bytes inside a frame follow each
//! other back to back.
//!
//! ```text
//! byte  0      0x0F                 header
//! bytes 1..=22 d₀ … d₂₁             16 channels × 11 bits, LSB first
//! byte  23     flags                bit0 ch17, bit1 ch18, bit2 frame lost, bit3 failsafe
//! byte  24     end                  0x00 (SBUS2 telemetry slots: 0x04, 0x14, 0x24, 0x34)
//! ```
//!
//! The 22 data bytes form one little-endian 176-bit integer `D = Σᵢ dᵢ·2⁸ⁱ`, and channel
//! `k` (0-based, `k = 0` is "channel 1" on the radio) is its bits 11k … 11k + 10:
//!
//! ```text
//! cₖ = ⌊D / 2¹¹ᵏ⌋ mod 2¹¹,        D = Σₖ cₖ·2¹¹ᵏ
//! ```
//!
//! The codec runs this as a bit accumulator: bytes are shifted in at the top and
//! 11-bit channels taken from the bottom (decoding), or channels shifted in and bytes
//! taken out (encoding). The upper nibble of the flags byte is unused; the decoder
//! ignores it and the encoder writes zeros there.
//!
//! # Finding frames in a byte stream
//!
//! [`SbusDecoder`] collects bytes from a 0x0F header on. When 25 bytes are in, the end
//! byte decides: one of the five end values yields the frame; anything else means the
//! 0x0F was not a header (0x0F occurs in channel data), and the buffered bytes after it
//! are *rescanned* for the next 0x0F, which becomes the new candidate header. Discarding
//! all 25 bytes instead could throw away a real header that arrived inside the false
//! candidate, and with a steady stream of frames it would do so every time.
//!
//! The scan is equivalent to: candidate `s` = the next 0x0F at or after position `p`;
//! accept if byte `s + 24` is an end byte (then `p = s + 25`), else `p = s + 1`. It
//! recovers every frame that is not overlapped by an *accepted false candidate*: a 0x0F
//! outside any frame with an end value 24 bytes later. Timing alone can rule those out:
//! [`SbusDecoder::feed_at`] drops a partial frame when more than
//! [`INTER_FRAME_GAP_US`] passes between two bytes, because a real frame never contains
//! such a gap while every real frame is preceded by one. Without timestamps a stream
//! whose channels hold still can keep a false alignment indefinitely (for example flags
//! 0x0F followed by an end value at byte 22): use `feed_at` where the byte arrival time
//! is known.

use embedded_io::{Read, ReadReady};

/// Bytes in a frame.
pub const FRAME_LEN: usize = 25;
/// The header byte.
pub const HEADER: u8 = 0x0F;
/// The accepted end bytes: SBUS (0x00) and the four SBUS2 telemetry-slot markers.
pub const END_BYTES: [u8; 5] = [0x00, 0x04, 0x14, 0x24, 0x34];
/// Proportional channels in a frame.
pub const CHANNELS: usize = 16;
/// The largest 11-bit channel value.
pub const CHANNEL_MAX: u16 = 0x07FF;
/// Line rate \[Bd\].
pub const BAUD: u32 = 100_000;
/// A silence longer than this between two bytes ends any partial frame \[µs\]: more than
/// the 120 µs of one byte (with ample margin for interrupt latency), less than the 4 ms
/// that separate two frames at the fastest (7 ms) frame rate.
pub const INTER_FRAME_GAP_US: u32 = 3_000;

/// Data bytes (between header and flags).
const DATA_LEN: usize = 22;
/// Bits per channel.
const CHANNEL_BITS: u32 = 11;

const FLAG_CH17: u8 = 1 << 0;
const FLAG_CH18: u8 = 1 << 1;
const FLAG_FRAME_LOST: u8 = 1 << 2;
const FLAG_FAILSAFE: u8 = 1 << 3;

/// One decoded SBUS frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SbusFrame {
    /// The 16 proportional channels, 11 bits each (0 … 2047); index 0 is channel 1.
    pub channels: [u16; CHANNELS],
    /// Digital channel 17 (flags bit 0).
    pub ch17: bool,
    /// Digital channel 18 (flags bit 1).
    pub ch18: bool,
    /// The receiver missed this frame from the transmitter and repeats old values (flags
    /// bit 2). Isolated lost frames are normal.
    pub frame_lost: bool,
    /// The receiver has lost the transmitter for its own failsafe time and outputs its
    /// failsafe values (flags bit 3).
    pub failsafe: bool,
}

/// Why 25 bytes are not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SbusError {
    /// Byte 0 is not 0x0F.
    Header,
    /// Byte 24 is none of [`END_BYTES`].
    End,
}

impl SbusFrame {
    /// Decode 25 bytes, checking the header and end bytes (the only redundancy SBUS
    /// has: it carries no checksum).
    pub fn decode(bytes: &[u8; FRAME_LEN]) -> Result<SbusFrame, SbusError> {
        let [header, rest @ ..] = bytes;
        let [data @ .., flags, end] = rest;
        if *header != HEADER {
            return Err(SbusError::Header);
        }
        if !END_BYTES.contains(end) {
            return Err(SbusError::End);
        }
        // Bit accumulator: bytes enter above the `bits` valid bits, channels leave from
        // the bottom. At most 7 + 8 = 15 bits are ever held.
        let mut channels = [0u16; CHANNELS];
        let mut slots = channels.iter_mut();
        let mut accumulator: u32 = 0;
        let mut bits: u32 = 0;
        for &byte in data.iter() {
            accumulator |= u32::from(byte) << bits;
            bits += 8;
            if bits >= CHANNEL_BITS {
                if let Some(slot) = slots.next() {
                    *slot = (accumulator & u32::from(CHANNEL_MAX)) as u16;
                }
                accumulator >>= CHANNEL_BITS;
                bits -= CHANNEL_BITS;
            }
        }
        Ok(SbusFrame {
            channels,
            ch17: flags & FLAG_CH17 != 0,
            ch18: flags & FLAG_CH18 != 0,
            frame_lost: flags & FLAG_FRAME_LOST != 0,
            failsafe: flags & FLAG_FAILSAFE != 0,
        })
    }

    /// The 25 bytes of this frame with end byte 0x00. Channel values above 2047 are
    /// truncated to their low 11 bits (the field width).
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        let mut data = [0u8; DATA_LEN];
        let mut out = data.iter_mut();
        let mut accumulator: u32 = 0;
        let mut bits: u32 = 0;
        for &channel in self.channels.iter() {
            accumulator |= u32::from(channel & CHANNEL_MAX) << bits;
            bits += CHANNEL_BITS;
            while bits >= 8 {
                if let Some(byte) = out.next() {
                    *byte = (accumulator & 0xFF) as u8;
                }
                accumulator >>= 8;
                bits -= 8;
            }
        }
        // 16 × 11 = 176 = 22 × 8 bits: nothing is left over.
        let flags = [
            (self.ch17, FLAG_CH17),
            (self.ch18, FLAG_CH18),
            (self.frame_lost, FLAG_FRAME_LOST),
            (self.failsafe, FLAG_FAILSAFE),
        ]
        .iter()
        .filter(|(set, _)| *set)
        .fold(0u8, |flags, (_, bit)| flags | bit);
        let mut frame = [0u8; FRAME_LEN];
        let (first, rest) = frame.split_at_mut(1);
        if let Some(header) = first.first_mut() {
            *header = HEADER;
        }
        for (slot, byte) in rest.iter_mut().zip(data.iter().chain([flags, 0x00].iter())) {
            *slot = *byte;
        }
        frame
    }

    /// Whether the frame carries live stick data: neither the frame-lost nor the
    /// failsafe flag is set.
    pub const fn is_intact(&self) -> bool {
        !self.frame_lost && !self.failsafe
    }
}

/// The 25 bytes of `frame` (see [`SbusFrame::encode`]).
pub fn encode(frame: &SbusFrame) -> [u8; FRAME_LEN] {
    frame.encode()
}

/// Decode 25 bytes (see [`SbusFrame::decode`]).
pub fn decode(bytes: &[u8; FRAME_LEN]) -> Result<SbusFrame, SbusError> {
    SbusFrame::decode(bytes)
}

/// Running totals of an [`SbusDecoder`]. Every counter saturates at `u32::MAX`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SbusStats {
    /// Frames decoded.
    pub frames: u32,
    /// Decoded frames with the frame-lost flag set.
    pub lost_flags: u32,
    /// Decoded frames with the failsafe flag set.
    pub failsafe_flags: u32,
    /// Candidate frames rejected for their end byte (a 0x0F that was not a header).
    pub bad_end_bytes: u32,
    /// Partial frames dropped because of an inter-byte gap ([`SbusDecoder::feed_at`]).
    pub gap_drops: u32,
    /// Bytes that ended up in no frame.
    pub discarded_bytes: u32,
}

/// The stream decoder: bytes in, frames out. A 25-byte buffer, no allocation, at most
/// 25 byte moves per byte fed.
#[derive(Clone, Debug, Default)]
pub struct SbusDecoder {
    buffer: [u8; FRAME_LEN],
    /// Bytes of the current candidate in `buffer` (0 = waiting for a header).
    len: usize,
    /// Arrival time of the previous byte given to [`SbusDecoder::feed_at`].
    last_byte_us: Option<u32>,
    stats: SbusStats,
}

/// Largest number of bytes [`SbusDecoder::poll`] takes from its reader in one call:
/// five frames, so a poll at 200 Hz drains the 8 333 B/s of the line with room to spare
/// while its run time stays bounded.
pub const MAX_POLL_BYTES: usize = 5 * FRAME_LEN;

impl SbusDecoder {
    /// A decoder waiting for a header.
    pub const fn new() -> Self {
        SbusDecoder {
            buffer: [0; FRAME_LEN],
            len: 0,
            last_byte_us: None,
            stats: SbusStats {
                frames: 0,
                lost_flags: 0,
                failsafe_flags: 0,
                bad_end_bytes: 0,
                gap_drops: 0,
                discarded_bytes: 0,
            },
        }
    }

    /// The running totals.
    pub const fn stats(&self) -> &SbusStats {
        &self.stats
    }

    /// Bytes of a partial frame currently held.
    pub const fn pending(&self) -> usize {
        self.len
    }

    /// Forget any partial frame (counted as discarded).
    pub fn clear(&mut self) {
        self.discard(self.len);
        self.len = 0;
    }

    /// Feed one byte; returns the frame it completes, if any.
    pub fn feed(&mut self, byte: u8) -> Option<SbusFrame> {
        if self.len == 0 {
            if byte == HEADER {
                if let Some(first) = self.buffer.first_mut() {
                    *first = byte;
                }
                self.len = 1;
            } else {
                self.discard(1);
            }
            return None;
        }
        if let Some(slot) = self.buffer.get_mut(self.len) {
            *slot = byte;
            self.len += 1;
        }
        if self.len < FRAME_LEN {
            return None;
        }
        match SbusFrame::decode(&self.buffer) {
            Ok(frame) => {
                self.len = 0;
                let stats = &mut self.stats;
                stats.frames = stats.frames.saturating_add(1);
                stats.lost_flags = stats.lost_flags.saturating_add(u32::from(frame.frame_lost));
                stats.failsafe_flags = stats
                    .failsafe_flags
                    .saturating_add(u32::from(frame.failsafe));
                Some(frame)
            }
            Err(_) => {
                self.stats.bad_end_bytes = self.stats.bad_end_bytes.saturating_add(1);
                self.rescan();
                None
            }
        }
    }

    /// Feed one byte that arrived at `now_us` (a free-running µs counter; wrapping
    /// arithmetic). If more than [`INTER_FRAME_GAP_US`] passed since the previous byte,
    /// the partial frame is dropped first, so the byte after a gap can only be a header.
    ///
    /// `now_us` must be the byte's arrival time (stamped in the receive interrupt): a
    /// batch drained from a buffer later carries no gap information, so feed it with
    /// [`SbusDecoder::feed`]. A time earlier than the previous byte's reads as a long gap.
    pub fn feed_at(&mut self, byte: u8, now_us: u32) -> Option<SbusFrame> {
        if let Some(previous) = self.last_byte_us {
            if self.len > 0 && now_us.wrapping_sub(previous) > INTER_FRAME_GAP_US {
                self.stats.gap_drops = self.stats.gap_drops.saturating_add(1);
                self.clear();
            }
        }
        self.last_byte_us = Some(now_us);
        self.feed(byte)
    }

    /// Feed every byte of `bytes`; returns the newest frame they complete. Older frames
    /// completed in the same slice are counted in [`SbusStats::frames`] but not returned
    /// (feed byte by byte to see each one).
    pub fn feed_slice(&mut self, bytes: &[u8]) -> Option<SbusFrame> {
        bytes
            .iter()
            .fold(None, |newest, &byte| self.feed(byte).or(newest))
    }

    /// Drain the bytes `reader` has ready, without blocking: reads only while
    /// [`ReadReady::read_ready`] says a read will not block, at most [`MAX_POLL_BYTES`]
    /// per call (the rest stays in the reader for the next call), and stops at a read
    /// of 0 bytes (end of stream). Returns the newest frame completed.
    pub fn poll<R: Read + ReadReady>(
        &mut self,
        reader: &mut R,
    ) -> Result<Option<SbusFrame>, R::Error> {
        let mut chunk = [0u8; FRAME_LEN];
        let mut budget = MAX_POLL_BYTES;
        let mut newest = None;
        while budget > 0 && reader.read_ready()? {
            let Some(window) = chunk.get_mut(..budget.min(FRAME_LEN)) else {
                break;
            };
            let window_len = window.len();
            let count = reader.read(window)?.min(window_len);
            if count == 0 {
                break;
            }
            if let Some(read) = window.get(..count) {
                newest = self.feed_slice(read).or(newest);
            }
            budget = budget.saturating_sub(count);
        }
        Ok(newest)
    }

    /// After a bad end byte: the candidate header was data. Move the candidate to the
    /// next 0x0F among the buffered bytes after it, or empty the buffer if none.
    fn rescan(&mut self) {
        let held = self.len.min(FRAME_LEN);
        let next_header = self
            .buffer
            .iter()
            .take(held)
            .skip(1)
            .position(|&b| b == HEADER)
            .map(|i| i + 1);
        match next_header {
            Some(start) => {
                self.buffer.copy_within(start..held, 0);
                self.len = held - start;
                self.discard(start);
            }
            None => {
                self.len = 0;
                self.discard(held);
            }
        }
    }

    fn discard(&mut self, count: usize) {
        let count = u32::try_from(count).unwrap_or(u32::MAX);
        self.stats.discarded_bytes = self.stats.discarded_bytes.saturating_add(count);
    }
}

/// Default link timeout \[µs\]: 100 ms, about seven frames at the slow 14 ms rate and
/// fourteen at 7 ms, so a few lost frames are not a loss of link, while a dead line is
/// noticed within 20 ticks at 200 Hz (the receiver's own, usually slower, verdict
/// arrives as the failsafe flag).
pub const LINK_TIMEOUT_US: u32 = 100_000;

/// What the link monitor concludes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LinkStatus {
    /// An intact frame arrived within the timeout and the receiver is not in failsafe.
    Valid,
    /// The stick data must not be used.
    Lost(LossReason),
}

/// Why the link is lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LossReason {
    /// No intact frame has arrived yet.
    NoFrame,
    /// No intact frame for longer than the timeout.
    Timeout,
    /// The newest frame carries the failsafe flag.
    Failsafe,
}

/// Freshness of the last intact frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Freshness {
    NoFrame,
    Heard { at_us: u32 },
    TimedOut,
}

/// The link monitor: is the newest stick data fresh and real?
///
/// ```text
/// failsafe flag in the newest frame            → Lost(Failsafe)
/// no intact frame yet                          → Lost(NoFrame)
/// now − t_last_intact > timeout                → Lost(Timeout)   (latched until the next
///                                                                 intact frame)
/// otherwise                                    → Valid
/// ```
///
/// An *intact* frame has neither the frame-lost nor the failsafe flag. A frame-lost
/// frame repeats old values: it is counted, and it does not refresh the time, so a run
/// of them ends in a timeout but a single one changes nothing.
///
/// Times are a free-running `u32` µs counter (it wraps after 71.6 min). The age
/// `now − t` is taken with wrapping subtraction read as signed, so a frame stamped a
/// little after `now` (an interrupt's timestamp against a tick's) counts as fresh. The
/// timeout is latched when [`Receiver::status`] sees it, so calling `status` at least
/// once every 2³¹ µs (35 min) — every tick in practice — keeps a long-dead link from
/// looking fresh again after the counter wraps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Receiver {
    timeout_us: u32,
    freshness: Freshness,
    failsafe: bool,
    last_intact: SbusFrame,
    intact_frames: u32,
    lost_frames: u32,
    consecutive_lost: u32,
}

impl Default for Receiver {
    fn default() -> Self {
        Receiver::new(LINK_TIMEOUT_US)
    }
}

impl Receiver {
    /// A monitor that has heard nothing yet, with link timeout `timeout_us` (values
    /// above 2³¹ − 1 are taken as 2³¹ − 1).
    pub const fn new(timeout_us: u32) -> Self {
        Receiver {
            timeout_us: if timeout_us > i32::MAX as u32 {
                i32::MAX as u32
            } else {
                timeout_us
            },
            freshness: Freshness::NoFrame,
            failsafe: false,
            last_intact: SbusFrame {
                channels: [0; CHANNELS],
                ch17: false,
                ch18: false,
                frame_lost: false,
                failsafe: false,
            },
            intact_frames: 0,
            lost_frames: 0,
            consecutive_lost: 0,
        }
    }

    /// Take a decoded frame that arrived at `now_us`.
    pub fn on_frame(&mut self, frame: &SbusFrame, now_us: u32) {
        self.failsafe = frame.failsafe;
        if frame.frame_lost {
            self.lost_frames = self.lost_frames.saturating_add(1);
            self.consecutive_lost = self.consecutive_lost.saturating_add(1);
        }
        if frame.is_intact() {
            self.consecutive_lost = 0;
            self.intact_frames = self.intact_frames.saturating_add(1);
            self.last_intact = *frame;
            self.freshness = Freshness::Heard { at_us: now_us };
        }
    }

    /// The link status at `now_us` (latches a timeout, hence `&mut`).
    pub fn status(&mut self, now_us: u32) -> LinkStatus {
        if self.failsafe {
            return LinkStatus::Lost(LossReason::Failsafe);
        }
        match self.freshness {
            Freshness::NoFrame => LinkStatus::Lost(LossReason::NoFrame),
            Freshness::TimedOut => LinkStatus::Lost(LossReason::Timeout),
            Freshness::Heard { at_us } => {
                // Wrapping difference read as signed: (−2³¹, 2³¹) µs.
                let age = now_us.wrapping_sub(at_us) as i32;
                if i64::from(age) > i64::from(self.timeout_us) {
                    self.freshness = Freshness::TimedOut;
                    LinkStatus::Lost(LossReason::Timeout)
                } else {
                    LinkStatus::Valid
                }
            }
        }
    }

    /// The newest intact frame if the link is [`LinkStatus::Valid`] at `now_us`.
    pub fn frame(&mut self, now_us: u32) -> Option<SbusFrame> {
        match self.status(now_us) {
            LinkStatus::Valid => Some(self.last_intact),
            LinkStatus::Lost(_) => None,
        }
    }

    /// The configured timeout \[µs\].
    pub const fn timeout_us(&self) -> u32 {
        self.timeout_us
    }

    /// Intact frames taken so far.
    pub const fn intact_frames(&self) -> u32 {
        self.intact_frames
    }

    /// Frames with the frame-lost flag taken so far.
    pub const fn lost_frames(&self) -> u32 {
        self.lost_frames
    }

    /// Frame-lost frames since the last intact frame.
    pub const fn consecutive_lost_frames(&self) -> u32 {
        self.consecutive_lost
    }
}
