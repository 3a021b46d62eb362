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
        crc = crc32_byte(crc, byte);
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
///
/// One pass where the frame allows it: the postcard bytes are written at `out[1..]`
/// (by hand for the per-tick [`Frame::Sample`] and [`Frame::ActuatorOut`], see
/// [`serialize_tick_frame`]; by postcard for the rest), then a single loop computes the
/// CRC and COBS-encodes in place. In-place COBS needs no extra code byte inside the
/// payload, i.e. no run of 254 non-zero bytes: guaranteed for payloads of at most
/// [`MAX_IN_PLACE_PAYLOAD`] bytes (every frame but a large Header or Configure, which
/// take the copying path). The bytes are those of the two-step definition in the module
/// documentation in every case (tests below).
pub fn encode(frame: &Frame, out: &mut [u8]) -> Result<usize, EncodeError> {
    let (code, rest) = out.split_first_mut().ok_or(EncodeError::BufferTooSmall)?;
    let room = rest.len().min(MAX_POSTCARD_LEN);
    let body_len = match serialize_tick_frame(frame, rest.get_mut(..room).unwrap_or(&mut [])) {
        Some(len) => len,
        None => postcard::to_slice(frame, rest.get_mut(..room).unwrap_or(&mut []))
            .map_err(|error| match error {
                postcard::Error::SerializeBufferFull => EncodeError::BufferTooSmall,
                _ => EncodeError::Serialize,
            })?
            .len(),
    };
    let payload_len = body_len + CRC_LEN;
    if payload_len > MAX_IN_PLACE_PAYLOAD {
        return encode_by_copy(body_len, out);
    }
    // code byte, payload, delimiter.
    if rest.len() < payload_len + 1 {
        return Err(EncodeError::BufferTooSmall);
    }
    let (body, tail) = rest.split_at_mut(body_len);
    let (crc_bytes, delimiter) = tail.split_at_mut(CRC_LEN);
    // COBS in place: every 0x00 becomes the distance to the next 0x00 (or to the end),
    // and the code byte in front holds the distance to the first. `slot` is where the
    // pending distance goes; `distance` ≤ payload_len + 1 ≤ 254 fits the u8.
    // Two tight passes rather than one loop doing both (which spills registers on the
    // Cortex-M4). CRC: slicing-by-4 over whole words, then the tail bytes.
    let mut crc = 0xFFFF_FFFFu32;
    let mut words = body.chunks_exact(4);
    for word in &mut words {
        crc = crc32_word(
            crc,
            u32::from_le_bytes([word[0], word[1], word[2], word[3]]),
        );
    }
    for &byte in words.remainder() {
        crc = crc32_byte(crc, byte);
    }
    crc_bytes.copy_from_slice(&(!crc).to_le_bytes());
    // COBS in place: a word without a zero byte only moves the distance on. A word w has
    // a zero byte iff (w − 0x01010101) & !w & 0x80808080 ≠ 0 (the borrow of the lowest
    // zero byte sets its top bit, and no non-zero byte below it borrows).
    let mut slot: &mut u8 = code;
    let mut distance: u8 = 1;
    let mut words = body.chunks_exact_mut(4);
    for word in &mut words {
        let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
        if value.wrapping_sub(0x0101_0101) & !value & 0x8080_8080 == 0 {
            distance += 4;
        } else {
            cobs_in_place(word, &mut slot, &mut distance);
        }
    }
    cobs_in_place(words.into_remainder(), &mut slot, &mut distance);
    cobs_in_place(crc_bytes, &mut slot, &mut distance);
    *slot = distance;
    *delimiter.first_mut().ok_or(EncodeError::BufferTooSmall)? = DELIMITER;
    Ok(payload_len + 2)
}

/// Largest payload (postcard bytes + CRC) [`encode`] COBS-encodes in place: 253 bytes
/// hold at most 253 consecutive non-zero bytes, so every COBS code is at most 254 and no
/// code byte is inserted inside the payload.
pub const MAX_IN_PLACE_PAYLOAD: usize = 253;

/// The general path for long payloads: the postcard bytes at `out[1..=body_len]` are
/// copied out, the CRC appended, and the payload COBS-encoded back into `out`.
fn encode_by_copy(body_len: usize, out: &mut [u8]) -> Result<usize, EncodeError> {
    let mut payload = [0u8; MAX_PAYLOAD_LEN];
    let body = out.get(1..=body_len).ok_or(EncodeError::Serialize)?;
    payload
        .get_mut(..body_len)
        .ok_or(EncodeError::Serialize)?
        .copy_from_slice(body);
    let crc = crc32(body);
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

/// In-place COBS over `bytes`, continuing a block: each 0x00 receives nothing yet but
/// becomes the next `slot`, the previous slot receives the distance to it.
#[inline(always)]
fn cobs_in_place<'a>(bytes: &'a mut [u8], slot: &mut &'a mut u8, distance: &mut u8) {
    for byte in bytes.iter_mut() {
        if *byte == 0 {
            **slot = *distance;
            *slot = byte;
            *distance = 1;
        } else {
            *distance += 1;
        }
    }
}

/// Four bytes of the CRC at once (slicing-by-4, Intel 2006): with the little-endian
/// word w of the next four bytes, c = crc ⊕ w and
/// crc ← T₃[c₀] ⊕ T₂[c₁] ⊕ T₁[c₂] ⊕ T₀[c₃] (cₖ the k-th byte of c), where Tₖ shifts a
/// byte through k further zero bytes. Equal to four [`crc32_byte`] steps.
#[inline(always)]
fn crc32_word(crc: u32, word: u32) -> u32 {
    let c = crc ^ word;
    CRC_TABLES[3][(c & 0xFF) as usize]
        ^ CRC_TABLES[2][((c >> 8) & 0xFF) as usize]
        ^ CRC_TABLES[1][((c >> 16) & 0xFF) as usize]
        ^ CRC_TABLES[0][(c >> 24) as usize]
}

/// T₀ = [`CRC_TABLE`], Tₖ[n] = (Tₖ₋₁[n] ≫ 8) ⊕ T₀[Tₖ₋₁[n] & 0xFF]: 4 KiB of flash.
const CRC_TABLES: [[u32; 256]; 4] = {
    let mut tables = [CRC_TABLE; 4];
    let mut k = 1;
    while k < 4 {
        let mut n = 0;
        while n < 256 {
            let previous = tables[k - 1][n];
            tables[k][n] = (previous >> 8) ^ CRC_TABLE[(previous & 0xFF) as usize];
            n += 1;
        }
        k += 1;
    }
    tables
};

/// One byte of the table CRC: crc ← T[(crc ⊕ b) & 0xFF] ⊕ (crc ≫ 8) (register form,
/// before the final inversion).
#[inline(always)]
fn crc32_byte(crc: u32, byte: u8) -> u32 {
    CRC_TABLE[usize::from((crc as u8) ^ byte)] ^ (crc >> 8)
}

/// postcard's encoding of the frames the flight controller sends every tick, written
/// field by field: `None` for the other variants (and when `out` is too short), which
/// go through postcard itself. The bytes are postcard's (proved against it below):
///
/// ```text
/// variant index, u16, u32   varint (LEB128: 7 bits a byte, low first, high bit = more)
/// unit enum (Phase, Axis…)  varint of the variant index (< 128: one byte)
/// f32                       4 bytes, little-endian IEEE bits
/// struct, [T; N]            the fields / elements in order, no length
/// ```
pub fn serialize_tick_frame(frame: &Frame, out: &mut [u8]) -> Option<usize> {
    let mut writer = Writer { out, len: 0 };
    match frame {
        Frame::Sample(sample) => {
            writer.byte(1)?;
            writer.varint(sample.tick)?;
            writer.byte(sample.phase as u8)?;
            writer.byte(sample.primary as u8)?;
            writer.floats([sample.sweep_omega])?;
            for hold in sample.hold {
                writer.byte(hold as u8)?;
            }
            let (c, s, n, p) = (sample.command, sample.sweep, sample.noise, sample.pilot);
            writer.floats([
                c.lat, c.lon, c.ped, c.col, s.lat, s.lon, s.ped, s.col, n.lat, n.lon, n.ped, n.col,
                p.lat, p.lon, p.ped, p.col,
            ])?;
            let m = &sample.meas;
            writer.floats([
                m.p, m.q, m.r, m.phi, m.theta, m.psi, m.u, m.v, m.w, m.ax, m.ay, m.az,
            ])?;
        }
        Frame::ActuatorOut(answer) => {
            writer.byte(4)?;
            writer.varint(answer.tick)?;
            writer.varint(answer.seq)?;
            let c = answer.command;
            writer.floats([c.lat, c.lon, c.ped, c.col])?;
            for pulse in answer.servo_us {
                writer.varint(u32::from(pulse))?;
            }
        }
        _ => return None,
    }
    Some(writer.len)
}

/// Appends postcard primitives to a slice; `None` when it is full.
struct Writer<'a> {
    out: &'a mut [u8],
    len: usize,
}

impl Writer<'_> {
    fn byte(&mut self, value: u8) -> Option<()> {
        *self.out.get_mut(self.len)? = value;
        self.len += 1;
        Some(())
    }

    fn varint(&mut self, mut value: u32) -> Option<()> {
        while value >= 0x80 {
            self.byte(value as u8 | 0x80)?;
            value >>= 7;
        }
        self.byte(value as u8)
    }

    /// `N` floats with one bounds check.
    fn floats<const N: usize>(&mut self, values: [f32; N]) -> Option<()> {
        let end = self.len + 4 * N;
        let slots = self.out.get_mut(self.len..end)?;
        for (slot, value) in slots.chunks_exact_mut(4).zip(values) {
            slot.copy_from_slice(&value.to_le_bytes());
        }
        self.len = end;
        Some(())
    }
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

// The integration tests' strategies; they build values of the crate as a dependency (the
// dev-dependency on itself), carried over to this crate's types through postcard.
#[cfg(test)]
#[path = "../tests/strategies/mod.rs"]
mod test_strategies;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    use super::test_strategies as strategies;

    fn local<T: serde::Serialize, U: serde::de::DeserializeOwned>(value: &T) -> U {
        let mut buffer = [0u8; MAX_POSTCARD_LEN];
        postcard::from_bytes(postcard::to_slice(value, &mut buffer).unwrap()).unwrap()
    }

    /// The module's definition, step by step with copies: postcard into a buffer, the
    /// CRC appended, COBS into the output, the delimiter.
    fn encode_by_definition(frame: &Frame) -> Vec<u8> {
        let mut payload = [0u8; MAX_PAYLOAD_LEN];
        let body_len = postcard::to_slice(frame, &mut payload[..MAX_POSTCARD_LEN])
            .unwrap()
            .len();
        let crc = crc32_small(&payload[..body_len]);
        payload[body_len..body_len + CRC_LEN].copy_from_slice(&crc.to_le_bytes());
        let mut out = vec![0u8; MAX_FRAME_LEN];
        let n = cobs::encode(&payload[..body_len + CRC_LEN], &mut out).unwrap();
        out.truncate(n);
        out.push(DELIMITER);
        out
    }

    proptest! {
        /// Every frame kind, NaN and infinities included: the one-pass encoder writes
        /// the definition's bytes.
        #[test]
        fn one_pass_encoding_equals_the_definition(frame in strategies::frame()) {
            let frame: Frame = local(&frame);
            let mut out = [0u8; MAX_FRAME_LEN];
            let n = encode(&frame, &mut out).unwrap();
            prop_assert_eq!(&out[..n], &encode_by_definition(&frame)[..]);
        }

        /// The hand-written Sample and ActuatorOut serialization is postcard's, for any
        /// bit pattern of their floats.
        #[test]
        fn tick_frames_serialize_as_postcard(
            sample in strategies::sample(),
            answer in strategies::actuator_out(),
            bits in proptest::collection::vec(any::<u32>(), 4),
            tick in any::<u32>(),
        ) {
            let mut sample: crate::frames::Sample = local(&sample);
            sample.tick = tick;
            sample.sweep_omega = f32::from_bits(bits[0]);
            sample.meas.az = f32::from_bits(bits[1]);
            let mut answer: crate::frames::ActuatorOut = local(&answer);
            answer.command.col = f32::from_bits(bits[2]);
            answer.seq = bits[3];
            for frame in [Frame::Sample(sample), Frame::ActuatorOut(answer)] {
                let mut fast = [0u8; MAX_POSTCARD_LEN];
                let n = serialize_tick_frame(&frame, &mut fast).unwrap();
                let mut reference = [0u8; MAX_POSTCARD_LEN];
                let expected = postcard::to_slice(&frame, &mut reference).unwrap();
                prop_assert_eq!(&fast[..n], &*expected);
            }
        }
    }

    /// Payloads with long zero-free runs and many zeros around the in-place limit.
    #[test]
    fn in_place_cobs_handles_zero_runs_and_the_length_limit() {
        let mut sample = crate::synthetic::sample(0);
        for fill in [0.0f32, f32::from_bits(0x0101_0101), -1.5] {
            sample.command = crate::frames::Controls::from_array([fill; 4]);
            sample.sweep = sample.command;
            sample.noise = sample.command;
            sample.pilot = sample.command;
            for tick in [0, 1, 127, 128, 16_384, u32::MAX] {
                sample.tick = tick;
                let frame = Frame::Sample(sample);
                let mut out = [0u8; MAX_FRAME_LEN];
                let n = encode(&frame, &mut out).unwrap();
                assert_eq!(&out[..n], &encode_by_definition(&frame)[..]);
            }
        }
    }

    #[test]
    fn short_buffers_are_refused() {
        let frame = Frame::Sample(crate::synthetic::sample(3));
        let full = encode_by_definition(&frame);
        for len in [0, 1, 10, full.len() - 1] {
            let mut out = vec![0u8; len];
            assert_eq!(encode(&frame, &mut out), Err(EncodeError::BufferTooSmall));
        }
        let mut out = vec![0u8; full.len()];
        assert_eq!(encode(&frame, &mut out), Ok(full.len()));
    }

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
