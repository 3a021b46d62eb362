//! The hand-written frame encoder writes postcard's own bytes.
//!
//! A frame on the wire is `COBS(postcard(frame) ‖ CRC-32/ISO-HDLC(postcard bytes) LE)`
//! followed by a 0x00 (`shared/src/codec.rs`). postcard builds the same thing from its
//! flavors: `CrcModifier` digests every serialized byte and appends the CRC little-endian,
//! and `Cobs` below it COBS-encodes what it is given and ends it with the 0x00 sentinel.
//! The firmware keeps its own encoder (one pass, COBS in place, a 1 KiB CRC table),
//! which must therefore equal that stack byte for byte — proved here for every frame
//! kind, and part by part: COBS against postcard's `Cobs` flavor on any bytes (runs of
//! 254 non-zero bytes included), the CRC against the `crc` crate's algorithm.

#[path = "../shared/tests/strategies/mod.rs"]
mod strategies;

use crc::{Algorithm, Crc, CRC_32_BZIP2, CRC_32_ISO_HDLC};
use postcard::ser_flavors::crc::CrcModifier;
use postcard::ser_flavors::{Cobs, Flavor, Slice};
use proptest::prelude::*;
use sweephold_protocol::codec::{self, MAX_FRAME_LEN};
use sweephold_protocol::{cobs, Frame};

/// `frame` through postcard's flavor stack with the CRC `algorithm`: CRC over the
/// postcard bytes, appended little-endian, all COBS-encoded, then the 0x00 sentinel.
fn postcard_stack(frame: &Frame, algorithm: &'static Algorithm<u32>) -> Vec<u8> {
    let crc = Crc::<u32>::new(algorithm);
    let mut buf = vec![0u8; 2 * MAX_FRAME_LEN];
    let cobs = Cobs::try_new(Slice::new(&mut buf)).expect("room for the code byte");
    let bytes = postcard::serialize_with_flavor(frame, CrcModifier::new(cobs, crc.digest()))
        .expect("postcard encodes every frame");
    bytes.to_vec()
}

fn ours(frame: &Frame) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME_LEN];
    let n = codec::encode(frame, &mut out).expect("encodes");
    out[..n].to_vec()
}

/// `bytes` through postcard's `Cobs` flavor alone: the COBS encoding and the sentinel.
fn postcard_cobs(bytes: &[u8]) -> Vec<u8> {
    let mut buf = vec![0u8; cobs::max_encoded_len(bytes.len()) + 1];
    let mut flavor = Cobs::try_new(Slice::new(&mut buf)).expect("room for the code byte");
    for &byte in bytes {
        flavor.try_push(byte).expect("room");
    }
    flavor.finalize().expect("room for the sentinel").to_vec()
}

/// Bytes with long zero-free runs: mostly non-zero, so runs of 254 and more occur.
fn sparse_zeros() -> impl Strategy<Value = Vec<u8>> {
    proptest::collection::vec(prop_oneof![1 => Just(0u8), 200 => 1u8..=255], 0..1200)
}

proptest! {
    /// Every frame kind, NaN and infinities included: our bytes are postcard's.
    #[test]
    fn frames_equal_postcards_crc_and_cobs_flavors(frame in strategies::frame()) {
        prop_assert_eq!(ours(&frame), postcard_stack(&frame, &CRC_32_ISO_HDLC));
    }

    /// Another CRC in the same stack gives other bytes: the comparison above sees the
    /// CRC, not only the postcard and COBS bytes.
    #[test]
    fn another_crc_is_told_apart(frame in strategies::frame()) {
        prop_assert_ne!(ours(&frame), postcard_stack(&frame, &CRC_32_BZIP2));
    }

    /// Our COBS is postcard's `Cobs` flavor on any bytes.
    #[test]
    fn cobs_equals_postcards_flavor(bytes in sparse_zeros()) {
        let mut out = vec![0u8; cobs::max_encoded_len(bytes.len())];
        let n = cobs::encode(&bytes, &mut out).expect("room");
        out.truncate(n);
        out.push(codec::DELIMITER);
        prop_assert_eq!(out, postcard_cobs(&bytes));
    }

    /// Both of our CRC-32s are the `crc` crate's CRC-32/ISO-HDLC.
    #[test]
    fn crc_equals_the_crc_crates_iso_hdlc(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        let reference = Crc::<u32>::new(&CRC_32_ISO_HDLC).checksum(&bytes);
        prop_assert_eq!(codec::crc32(&bytes), reference);
        prop_assert_eq!(codec::crc32_small(&bytes), reference);
    }
}

/// Runs of exactly 253, 254 and 255 non-zero bytes, and at the end of the input: where
/// COBS implementations differ if they differ at all.
#[test]
fn cobs_block_boundaries_equal_postcards_flavor() {
    for run in [252usize, 253, 254, 255, 508, 509] {
        for tail in [&[][..], &[0][..], &[0, 7][..], &[7][..]] {
            let mut bytes: Vec<u8> = (0..run).map(|i| (i % 255 + 1) as u8).collect();
            bytes.extend_from_slice(tail);
            let mut out = vec![0u8; cobs::max_encoded_len(bytes.len())];
            let n = cobs::encode(&bytes, &mut out).expect("room");
            out.truncate(n);
            out.push(codec::DELIMITER);
            assert_eq!(out, postcard_cobs(&bytes), "run {run}, tail {tail:?}");
        }
    }
}
