//! Frame encoding: `postcard(frame) ‖ crc32(postcard bytes) as u32 LE`, COBS-encoded,
//! followed by one 0x00 delimiter.
//!
//! The CRC is the IEEE 802.3 CRC-32 (reflected, polynomial 0xEDB88320, init and xorout
//! 0xFFFFFFFF — the zlib/PNG one). It catches every error COBS resynchronisation cannot:
//! flipped bits inside a frame, and frames spliced together by a lost delimiter.

use postcard::experimental::max_size::MaxSize;

use crate::cobs;
use crate::frames::Frame;

/// Bytes of CRC appended to each postcard payload.
pub const CRC_LEN: usize = 4;

/// Largest postcard encoding of any [`Frame`].
pub const MAX_POSTCARD_LEN: usize = Frame::POSTCARD_MAX_SIZE;

/// Largest payload before COBS: postcard bytes plus the CRC.
pub const MAX_PAYLOAD_LEN: usize = MAX_POSTCARD_LEN + CRC_LEN;

/// Largest frame on the wire: COBS-encoded payload plus the 0x00 delimiter. A buffer of
/// this size holds any frame [`encode`] writes.
pub const MAX_FRAME_LEN: usize = cobs::max_encoded_len(MAX_PAYLOAD_LEN) + 1;

/// The frame delimiter.
pub const DELIMITER: u8 = 0x00;

/// Why a frame could not be encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The output buffer is shorter than the frame; [`MAX_FRAME_LEN`] always suffices.
    BufferTooSmall,
    /// postcard refused the value (cannot happen for the types of this crate).
    Serialize,
}

/// CRC-32 (IEEE) of `bytes`.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(bytes);
    hasher.finalize()
}

/// Encode `frame` into `out` as it goes on the wire, delimiter included; returns the
/// number of bytes written. No allocation; bounded time.
pub fn encode(frame: &Frame, out: &mut [u8]) -> Result<usize, EncodeError> {
    let mut payload = [0u8; MAX_PAYLOAD_LEN];
    let body_len = postcard::to_slice(frame, &mut payload[..MAX_POSTCARD_LEN])
        .map_err(|_| EncodeError::Serialize)?
        .len();
    let crc = crc32(payload.get(..body_len).ok_or(EncodeError::Serialize)?);
    let payload_len = body_len + CRC_LEN;
    payload
        .get_mut(body_len..payload_len)
        .ok_or(EncodeError::Serialize)?
        .copy_from_slice(&crc.to_le_bytes());
    let payload = payload.get(..payload_len).ok_or(EncodeError::Serialize)?;
    let cobs_len = cobs::encode(payload, out).ok_or(EncodeError::BufferTooSmall)?;
    *out.get_mut(cobs_len).ok_or(EncodeError::BufferTooSmall)? = DELIMITER;
    Ok(cobs_len + 1)
}

/// Encode `frame` into a fixed buffer; convenient where a heapless frame is wanted.
pub fn encode_to_vec(frame: &Frame) -> Result<FrameBytes, EncodeError> {
    let mut bytes = FrameBytes {
        buf: [0; MAX_FRAME_LEN],
        len: 0,
    };
    bytes.len = encode(frame, &mut bytes.buf)?;
    Ok(bytes)
}

/// One encoded frame in a stack buffer.
#[derive(Clone, Copy)]
pub struct FrameBytes {
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
}

impl FrameBytes {
    /// The encoded bytes, delimiter included.
    pub fn as_bytes(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&[])
    }
}

impl core::ops::Deref for FrameBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        self.as_bytes()
    }
}
