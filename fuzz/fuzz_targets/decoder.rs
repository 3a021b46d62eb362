//! Fuzz the streaming decoder: arbitrary bytes, fed in arbitrary chunk sizes, must never
//! panic, and every frame it accepts must re-encode to bytes that decode to itself.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sweephold_protocol::{codec, Decoder};

fuzz_target!(|data: &[u8]| {
    // The first byte picks the chunk size so the fuzzer explores split frames too.
    let Some((&split, bytes)) = data.split_first() else { return };
    let chunk = usize::from(split).max(1);
    let mut decoder = Decoder::new();
    for piece in bytes.chunks(chunk) {
        for frame in decoder.feed(piece).flatten() {
            let wire = codec::encode_to_vec(&frame).expect("a decoded frame re-encodes");
            let mut again = Decoder::new();
            let back: Vec<_> = again.feed(&wire).collect();
            assert_eq!(back.len(), 1);
            assert_eq!(codec::encode_to_vec(&back[0].expect("re-decodes")).unwrap().as_bytes(), wire.as_bytes());
        }
    }
    decoder.finish();
    assert_eq!(decoder.stats().bytes, bytes.len() as u64);
});
