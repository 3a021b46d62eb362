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

/// CRC-32 (IEEE) of `bytes`: reflected, polynomial 0xEDB88320, init and xorout
/// 0xFFFFFFFF. On the host this is crc32fast (carry-less multiply: decoding is CRC-bound);
/// on the flight controller it is [`crc32_small`], whose table costs 1 KiB of flash
/// instead of crc32fast's 16 KiB.
#[cfg(not(target_os = "none"))]
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(bytes);
    hasher.finalize()
}

/// CRC-32 (IEEE) of `bytes`; see the host variant.
#[cfg(target_os = "none")]
pub fn crc32(bytes: &[u8]) -> u32 {
    crc32_small(bytes)
}

/// CRC-32 (IEEE), byte at a time with one 256-entry table built at compile time:
/// crc ← T[(crc ⊕ b) & 0xFF] ⊕ (crc ≫ 8).
pub fn crc32_small(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &byte in bytes {
        crc = CRC_TABLE[usize::from((crc as u8) ^ byte)] ^ (crc >> 8);
    }
    !crc
}

/// T[n] = the CRC register after shifting the byte n through eight rounds of the
/// reflected polynomial.
const CRC_TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut n = 0;
    while n < 256 {
        let mut c = n as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        table[n] = c;
        n += 1;
    }
    table
};

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

#[cfg(test)]
mod tests {
    use super::{crc32, crc32_small};

    /// The standard check value of CRC-32/ISO-HDLC and a known string, both variants.
    #[test]
    fn reference_values() {
        for crc in [crc32, crc32_small] {
            assert_eq!(crc(b"123456789"), 0xCBF4_3926);
            assert_eq!(crc(b""), 0);
            assert_eq!(
                crc(b"The quick brown fox jumps over the lazy dog"),
                0x414F_A339
            );
        }
    }

    /// The board's table CRC and the host's agree on every length and content.
    #[test]
    fn board_and_host_variants_agree() {
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        let bytes: Vec<u8> = (0..4096)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as u8
            })
            .collect();
        for len in 0..bytes.len() {
            assert_eq!(
                crc32(&bytes[..len]),
                crc32_small(&bytes[..len]),
                "length {len}"
            );
        }
    }
}
