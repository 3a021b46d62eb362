//! Consistent Overhead Byte Stuffing (Cheshire & Baker, 1999).
//!
//! COBS removes every 0x00 from a payload so that 0x00 can delimit frames on the wire: a
//! receiver that loses bytes resynchronises at the next 0x00. The payload is split at its
//! zeros into blocks; each block is written as a code byte `n` (1..=255) followed by its
//! `n − 1` non-zero bytes, and every block but a full one (`n = 255`) and the last stands
//! for a zero that followed it. Worst-case growth is one byte per 254 plus one.

/// Largest COBS encoding of a payload of `n` bytes (without the 0x00 delimiter).
pub const fn max_encoded_len(n: usize) -> usize {
    n + n / 254 + 1
}

/// Why a COBS block could not be decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CobsError {
    /// A code byte was 0x00 (a delimiter inside a frame).
    ZeroCode,
    /// A code byte promised more bytes than the frame holds.
    ShortBlock,
    /// The decoded payload does not fit the destination buffer.
    TooLong,
}

/// Encode `src` into `dst`; returns the encoded length, or `None` if `dst` is shorter than
/// [`max_encoded_len`]`(src.len())`. Appends no delimiter.
pub fn encode(src: &[u8], dst: &mut [u8]) -> Option<usize> {
    if dst.len() < max_encoded_len(src.len()) {
        return None;
    }
    // `dst` has room for the worst case, so the writes below stay in bounds.
    let mut code_at = 0;
    let mut out = 1;
    let mut code: u8 = 1;
    for &byte in src {
        if byte == 0 {
            dst[code_at] = code;
            code_at = out;
            out += 1;
            code = 1;
        } else {
            dst[out] = byte;
            out += 1;
            code += 1;
            if code == 0xFF {
                dst[code_at] = code;
                code_at = out;
                out += 1;
                code = 1;
            }
        }
    }
    dst[code_at] = code;
    Some(out)
}

/// Decode one COBS frame `src` (without its delimiter) into `dst`; returns the payload
/// length.
pub fn decode(src: &[u8], dst: &mut [u8]) -> Result<usize, CobsError> {
    let mut rest = src;
    let mut out = 0;
    while let Some((&code, tail)) = rest.split_first() {
        if code == 0 {
            return Err(CobsError::ZeroCode);
        }
        let run = usize::from(code) - 1;
        if tail.len() < run {
            return Err(CobsError::ShortBlock);
        }
        let (block, after) = tail.split_at(run);
        if block.contains(&0) {
            return Err(CobsError::ZeroCode);
        }
        dst.get_mut(out..out + run)
            .ok_or(CobsError::TooLong)?
            .copy_from_slice(block);
        out += run;
        rest = after;
        if code != 0xFF && !rest.is_empty() {
            *dst.get_mut(out).ok_or(CobsError::TooLong)? = 0;
            out += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Examples from the COBS paper and the Wikipedia table.
    #[test]
    fn reference_vectors() {
        let cases: &[(&[u8], &[u8])] = &[
            (&[0x00], &[0x01, 0x01]),
            (&[0x00, 0x00], &[0x01, 0x01, 0x01]),
            (&[0x00, 0x11, 0x00], &[0x01, 0x02, 0x11, 0x01]),
            (&[0x11, 0x22, 0x00, 0x33], &[0x03, 0x11, 0x22, 0x02, 0x33]),
            (&[0x11, 0x22, 0x33, 0x44], &[0x05, 0x11, 0x22, 0x33, 0x44]),
            (&[0x11, 0x00, 0x00, 0x00], &[0x02, 0x11, 0x01, 0x01, 0x01]),
        ];
        for (raw, cobs) in cases {
            let mut enc = [0u8; 16];
            let n = encode(raw, &mut enc).unwrap();
            assert_eq!(&enc[..n], *cobs, "encode {raw:02x?}");
            let mut dec = [0u8; 16];
            let m = decode(cobs, &mut dec).unwrap();
            assert_eq!(&dec[..m], *raw, "decode {cobs:02x?}");
        }
    }

    /// 254 non-zero bytes make exactly one full block; 255 spill into a second.
    #[test]
    fn full_blocks() {
        for n in [253usize, 254, 255, 508, 509, 600] {
            let raw: Vec<u8> = (0..n).map(|i| (i % 255 + 1) as u8).collect();
            let mut enc = vec![0u8; max_encoded_len(n)];
            let len = encode(&raw, &mut enc).unwrap();
            assert!(!enc[..len].contains(&0));
            let mut dec = vec![0u8; n];
            let m = decode(&enc[..len], &mut dec).unwrap();
            assert_eq!(&dec[..m], &raw[..]);
        }
    }

    #[test]
    fn refuses_bad_input() {
        let mut dec = [0u8; 4];
        assert_eq!(decode(&[0x05, 1, 2], &mut dec), Err(CobsError::ShortBlock));
        assert_eq!(decode(&[0x00], &mut dec), Err(CobsError::ZeroCode));
        assert_eq!(
            decode(&[0x07, 1, 2, 3, 4, 5, 6], &mut dec),
            Err(CobsError::TooLong)
        );
        let mut small = [0u8; 2];
        assert_eq!(encode(&[1, 2, 3], &mut small), None);
    }
}
