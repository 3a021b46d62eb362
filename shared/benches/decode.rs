//! Frame decoding throughput (COBS + CRC-32 + postcard) on one core.
//!
//! `cargo bench -p sweephold-protocol --bench decode`. Target: ≥ 300 MB/s of dump.
//! Prints the median of several passes over a ~64 MB stream of Sample frames.

use std::hint::black_box;
use std::time::Instant;

use sweephold_protocol::{codec, synthetic, Decoder, Frame};

fn main() {
    let mut stream = Vec::new();
    stream.extend_from_slice(&codec::encode_to_vec(&Frame::Header(synthetic::header())).unwrap());
    let mut tick = 0;
    while stream.len() < 64 << 20 {
        let frame = Frame::Sample(synthetic::sample(tick));
        stream.extend_from_slice(&codec::encode_to_vec(&frame).unwrap());
        tick += 1;
    }
    let frame_len = stream.len() as f64 / f64::from(tick);
    let mut rates = Vec::new();
    for _ in 0..9 {
        let start = Instant::now();
        let mut decoder = Decoder::new();
        let mut good = 0u64;
        for chunk in stream.chunks(256 * 1024) {
            for frame in decoder.feed(chunk) {
                good += u64::from(black_box(frame).is_ok());
            }
        }
        let secs = start.elapsed().as_secs_f64();
        assert_eq!(good, u64::from(tick) + 1);
        rates.push(stream.len() as f64 / secs / 1e6);
    }
    rates.sort_by(f64::total_cmp);
    let median = rates[rates.len() / 2];
    println!(
        "decode: {:.1} MB stream, {} frames of {:.1} B: median {:.0} MB/s ({:.2} M frames/s), {:.1}x the 300 MB/s target",
        stream.len() as f64 / 1e6,
        tick + 1,
        frame_len,
        median,
        median / frame_len,
        median / 300.0
    );
}
