//! A streaming frame decoder that survives any input.
//!
//! Feed it byte chunks of any size, split anywhere. It yields every good frame; a frame
//! that fails COBS, CRC or postcard decoding is counted and skipped, and decoding
//! resynchronises at the next 0x00. Missing Sample tick numbers are counted as gaps, and
//! a Sample whose tick does not move forward (a step back or a repeat) as a backward step
//! (see [`tick_step`] for how a counter wrap at 2³² is told from a step back).
//! No allocation: a partial frame that straddles two chunks is kept in a fixed buffer of
//! [`MAX_FRAME_LEN`] bytes.

use crate::cobs::{self, CobsError};
use crate::codec::{crc32, CRC_LEN, DELIMITER, MAX_FRAME_LEN, MAX_PAYLOAD_LEN};
use crate::frames::{Frame, ProtocolVersion, PROTOCOL_VERSION};

/// Why a frame was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// The bytes between two delimiters are not valid COBS.
    Cobs(CobsError),
    /// More bytes than any frame can have arrived without a delimiter.
    TooLong,
    /// The payload is shorter than a CRC.
    TooShort,
    /// The CRC does not match the payload.
    Crc,
    /// The CRC matched but postcard could not decode a known frame (a newer minor
    /// version's frame, or a bug).
    Postcard,
    /// The stream ended inside a frame.
    Truncated,
    /// A Header announced another protocol major version. The dump must be refused.
    VersionMismatch {
        /// Version in the Header.
        found: ProtocolVersion,
        /// Version this decoder speaks.
        expected: ProtocolVersion,
    },
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FrameError::Cobs(e) => write!(f, "bad COBS framing ({e:?})"),
            FrameError::TooLong => write!(f, "frame longer than {MAX_FRAME_LEN} bytes"),
            FrameError::TooShort => write!(f, "frame shorter than its CRC"),
            FrameError::Crc => write!(f, "CRC mismatch"),
            FrameError::Postcard => write!(f, "CRC good but the frame does not decode"),
            FrameError::Truncated => write!(f, "stream ends inside a frame"),
            FrameError::VersionMismatch { found, expected } => write!(
                f,
                "dump uses protocol version {found}, this tool speaks {expected} (major versions differ)"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for FrameError {}

/// Running totals of a decode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DecodeStats {
    /// Bytes fed so far.
    pub bytes: u64,
    /// Frames decoded.
    pub good_frames: u64,
    /// Frames rejected (COBS, CRC, postcard, too long, truncated tail, version).
    pub corrupt_frames: u64,
    /// Sample ticks missing between consecutive good Samples that move forward.
    pub tick_gaps: u64,
    /// Good Samples whose tick does not move forward from the previous good Sample's: a
    /// step back or a repeat (a restarted counter, spliced or reordered data). Not gaps.
    pub tick_steps_back: u64,
}

/// How a Sample's tick relates to the previous Sample's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TickStep {
    /// The tick moves forward by this many (≥ 1; 1 is the next tick, more means gaps).
    Forward(u32),
    /// The tick is the same as or before the previous one.
    Back,
}

/// Classify the step from tick `previous` to tick `next` of a u32 counter that wraps at
/// 2³²: the forward distance `next − previous` (mod 2³²) is a step forward when it is
/// in 1..2³¹ — across a wrap too, so 4 294 967 295 → 0 is the next tick — and a step back
/// otherwise: 0 is a repeat, 2³¹ or more is read as `next` lying before `previous`
/// (102 → 50 is a step back of 52, not 4 294 967 244 ticks forward).
pub const fn tick_step(previous: u32, next: u32) -> TickStep {
    let forward = next.wrapping_sub(previous);
    if forward == 0 || forward >= 1 << 31 {
        TickStep::Back
    } else {
        TickStep::Forward(forward)
    }
}

/// Streaming decoder; see the module documentation.
pub struct Decoder {
    /// COBS bytes of a frame that started in an earlier chunk.
    partial: [u8; MAX_FRAME_LEN],
    partial_len: usize,
    /// The current frame overflowed `partial`; discard up to the next delimiter.
    overflowed: bool,
    last_tick: Option<u32>,
    stats: DecodeStats,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// A decoder at the start of a stream.
    pub const fn new() -> Self {
        Decoder {
            partial: [0; MAX_FRAME_LEN],
            partial_len: 0,
            overflowed: false,
            last_tick: None,
            stats: DecodeStats {
                bytes: 0,
                good_frames: 0,
                corrupt_frames: 0,
                tick_gaps: 0,
                tick_steps_back: 0,
            },
        }
    }

    /// Totals so far.
    pub fn stats(&self) -> DecodeStats {
        self.stats
    }

    /// Decode the frames completed by `chunk`. The iterator must be drained for the
    /// whole chunk to be consumed; bytes of a frame still open at its end are kept.
    pub fn feed<'d, 'c>(&'d mut self, chunk: &'c [u8]) -> Frames<'d, 'c> {
        self.stats.bytes += chunk.len() as u64;
        Frames {
            decoder: self,
            rest: chunk,
        }
    }

    /// Decode every frame completed by `chunk`, handing each result to `sink`.
    pub fn feed_with(&mut self, chunk: &[u8], mut sink: impl FnMut(Result<Frame, FrameError>)) {
        for result in self.feed(chunk) {
            sink(result);
        }
    }

    /// End of stream: reports a frame left open by the last chunk, if any.
    pub fn finish(&mut self) -> Option<FrameError> {
        let open = self.partial_len > 0 || self.overflowed;
        self.partial_len = 0;
        self.overflowed = false;
        if open {
            self.stats.corrupt_frames += 1;
            Some(FrameError::Truncated)
        } else {
            None
        }
    }

    fn decode_complete(&mut self, cobs_bytes: &[u8]) -> Result<Frame, FrameError> {
        let result = decode_frame(cobs_bytes);
        match &result {
            Ok(frame) => {
                self.stats.good_frames += 1;
                if let Frame::Sample(sample) = frame {
                    if let Some(last) = self.last_tick {
                        match tick_step(last, sample.tick) {
                            TickStep::Forward(step) => {
                                self.stats.tick_gaps += u64::from(step.saturating_sub(1));
                            }
                            TickStep::Back => self.stats.tick_steps_back += 1,
                        }
                    }
                    self.last_tick = Some(sample.tick);
                }
            }
            Err(_) => self.stats.corrupt_frames += 1,
        }
        result
    }
}

/// Decode the COBS bytes of one frame (delimiter removed).
pub fn decode_frame(cobs_bytes: &[u8]) -> Result<Frame, FrameError> {
    let mut payload = [0u8; MAX_PAYLOAD_LEN];
    let len = cobs::decode(cobs_bytes, &mut payload).map_err(|e| match e {
        CobsError::TooLong => FrameError::TooLong,
        other => FrameError::Cobs(other),
    })?;
    let payload = payload.get(..len).ok_or(FrameError::TooLong)?;
    if len < CRC_LEN + 1 {
        return Err(FrameError::TooShort);
    }
    let (body, crc_bytes) = payload.split_at(len - CRC_LEN);
    let mut crc = [0u8; CRC_LEN];
    crc.copy_from_slice(crc_bytes);
    if crc32(body) != u32::from_le_bytes(crc) {
        return Err(FrameError::Crc);
    }
    match postcard::take_from_bytes::<Frame>(body) {
        Ok((Frame::Header(header), [])) if header.protocol.major != PROTOCOL_VERSION.major => {
            Err(FrameError::VersionMismatch {
                found: header.protocol,
                expected: PROTOCOL_VERSION,
            })
        }
        Ok((frame, [])) => Ok(frame),
        // A Header of another major version may not decode at all: peek at its version.
        _ => match peek_header_version(body) {
            Some(found) if found.major != PROTOCOL_VERSION.major => {
                Err(FrameError::VersionMismatch {
                    found,
                    expected: PROTOCOL_VERSION,
                })
            }
            _ => Err(FrameError::Postcard),
        },
    }
}

/// The protocol version of a Header frame body: variant tag 0 followed by two varint u16.
fn peek_header_version(body: &[u8]) -> Option<ProtocolVersion> {
    let (&tag, rest) = body.split_first()?;
    if tag != 0 {
        return None;
    }
    let ((major, minor), _) = postcard::take_from_bytes::<(u16, u16)>(rest).ok()?;
    Some(ProtocolVersion { major, minor })
}

/// Iterator over the frames completed by one chunk; see [`Decoder::feed`].
pub struct Frames<'d, 'c> {
    decoder: &'d mut Decoder,
    rest: &'c [u8],
}

impl Iterator for Frames<'_, '_> {
    type Item = Result<Frame, FrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if self.rest.is_empty() {
                return None;
            }
            let Some(end) = self.rest.iter().position(|&b| b == DELIMITER) else {
                // No delimiter: the whole rest belongs to a frame still open.
                let rest = core::mem::take(&mut self.rest);
                self.decoder.keep_partial(rest);
                return None;
            };
            let (segment, after) = self.rest.split_at(end);
            self.rest = after.get(1..).unwrap_or(&[]);
            let dec = &mut *self.decoder;
            if dec.overflowed {
                dec.overflowed = false;
                dec.partial_len = 0;
                dec.stats.corrupt_frames += 1;
                return Some(Err(FrameError::TooLong));
            }
            if dec.partial_len == 0 {
                if segment.is_empty() {
                    continue; // back-to-back delimiters carry no frame
                }
                return Some(dec.decode_complete(segment));
            }
            dec.keep_partial(segment);
            if dec.overflowed {
                dec.overflowed = false;
                dec.partial_len = 0;
                dec.stats.corrupt_frames += 1;
                return Some(Err(FrameError::TooLong));
            }
            // Copy out so the frame can be decoded while the decoder is borrowed mutably.
            let joined = dec.partial;
            let len = dec.partial_len;
            dec.partial_len = 0;
            return Some(dec.decode_complete(joined.get(..len).unwrap_or(&[])));
        }
    }
}

impl Decoder {
    fn keep_partial(&mut self, bytes: &[u8]) {
        if self.overflowed {
            return;
        }
        let end = self.partial_len + bytes.len();
        match self.partial.get_mut(self.partial_len..end) {
            Some(dst) => {
                dst.copy_from_slice(bytes);
                self.partial_len = end;
            }
            None => {
                self.overflowed = true;
                self.partial_len = 0;
            }
        }
    }
}
