//! The corruption suite: a long stream of frames with random bit flips, inserted garbage,
//! dropped bytes and a truncated tail. The decoder must not panic, must recover every
//! frame that no corruption touched exactly, and must account for every touched frame —
//! touched Samples show up as tick gaps, and every run of touched frames yields at least
//! one corrupt-frame count.

mod strategies;

use rand_core::{Rng as _, SeedableRng};
use rand_xoshiro::SplitMix64;
use sweephold_protocol::*;

/// SplitMix64 (`rand_xoshiro`'s, the host's generator) with the draws the suite needs,
/// so the suite is reproducible.
struct Rng(SplitMix64);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(SplitMix64::seed_from_u64(seed))
    }
    fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn sample(tick: u32, rng: &mut Rng) -> Frame {
    let x = |rng: &mut Rng| (rng.unit() * 2.0 - 1.0) as f32;
    let c = |rng: &mut Rng| Controls {
        lat: x(rng),
        lon: x(rng),
        ped: x(rng),
        col: x(rng),
    };
    Frame::Sample(Sample {
        tick,
        phase: Phase::Sweep,
        primary: Axis::Lat,
        sweep_omega: (rng.unit() * 31.4) as f32,
        hold: [HoldState::Released, HoldState::Engaged, HoldState::Released],
        command: c(rng),
        sweep: c(rng),
        noise: c(rng),
        pilot: c(rng),
        meas: Measurements {
            p: x(rng),
            q: x(rng),
            r: x(rng),
            phi: x(rng),
            theta: x(rng),
            psi: x(rng),
            u: x(rng),
            v: x(rng),
            w: x(rng),
            ax: x(rng),
            ay: x(rng),
            az: -9.81 + x(rng),
        },
    })
}

fn header() -> Frame {
    Frame::Header(synthetic::header())
}

struct Case {
    frames: Vec<Frame>,
    /// Encoded frames, delimiter included.
    encoded: Vec<Vec<u8>>,
}

fn build_stream(n: usize, rng: &mut Rng) -> Case {
    let mut frames = vec![header()];
    let mut tick = 1000;
    while frames.len() < n {
        frames.push(sample(tick, rng));
        tick += 1;
        if rng.below(50) == 0 {
            frames.push(Frame::Event(Event::HoldEngaged {
                tick,
                axis: Axis::Lon,
            }));
        }
    }
    let encoded = frames
        .iter()
        .map(|f| codec::encode_to_vec(f).unwrap().to_vec())
        .collect();
    Case { frames, encoded }
}

#[derive(Clone, Copy, Debug)]
enum Corruption {
    BitFlip,
    GarbageInside,
    GarbageBetween,
    DropBytes,
}

/// The suite's streams are the ones its own SplitMix64 drew before it used the crate's:
/// the first words of the seeds it uses.
#[test]
fn the_generator_draws_the_suites_streams() {
    let first = |seed| Rng::new(seed).next();
    assert_eq!(first(1), 0x910a_2dec_8902_5cc1);
    assert_eq!(first(2), 0x9758_35de_1c97_56ce);
    assert_eq!(first(3), 0x1d0b_14e4_db01_8fed);
}

#[test]
fn corrupted_stream_recovers_every_untouched_frame() {
    for seed in 1..=3u64 {
        let mut rng = Rng::new(seed);
        let case = build_stream(12_000, &mut rng);
        let n = case.frames.len();
        let mut touched = vec![false; n];
        let mut stream = Vec::new();
        let mut kinds_seen = [0usize; 4];
        for (k, bytes) in case.encoded.iter().enumerate() {
            let mut bytes = bytes.clone();
            // ~4 % of frames get one corruption.
            if k > 0 && k + 1 < n && rng.below(25) == 0 {
                let kind = match rng.below(4) {
                    0 => Corruption::BitFlip,
                    1 => Corruption::GarbageInside,
                    2 => Corruption::GarbageBetween,
                    _ => Corruption::DropBytes,
                };
                kinds_seen[kind as usize] += 1;
                match kind {
                    Corruption::BitFlip => {
                        let at = rng.below(bytes.len());
                        bytes[at] ^= 1 << rng.below(8);
                        touched[k] = true;
                        if at == bytes.len() - 1 {
                            touched[k + 1] = true; // lost delimiter: merges with the next
                        }
                    }
                    Corruption::GarbageInside => {
                        let at = rng.below(bytes.len() - 1);
                        let len = 1 + rng.below(40);
                        let garbage: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
                        bytes.splice(at..at, garbage);
                        touched[k] = true;
                    }
                    Corruption::GarbageBetween => {
                        // Line noise ending in a delimiter, between two frames: it must be
                        // counted and skipped without touching either neighbour.
                        let len = 1 + rng.below(300);
                        let mut garbage: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
                        garbage.push(0);
                        stream.extend_from_slice(&garbage);
                    }
                    Corruption::DropBytes => {
                        let at = rng.below(bytes.len());
                        let len = (1 + rng.below(8)).min(bytes.len() - at);
                        bytes.drain(at..at + len);
                        touched[k] = true;
                        if at + len == case.encoded[k].len() {
                            touched[k + 1] = true; // the delimiter went with them
                        }
                    }
                }
            }
            stream.extend_from_slice(&bytes);
        }
        // Truncated tail: the last frame loses its second half and its delimiter.
        let last_len = case.encoded[n - 1].len();
        stream.truncate(stream.len() - last_len / 2);
        touched[n - 1] = true;
        assert!(
            kinds_seen.iter().all(|&c| c > 20),
            "every corruption kind exercised: {kinds_seen:?}"
        );

        // Decode in random chunk sizes.
        let mut decoder = Decoder::new();
        let mut good = Vec::new();
        let mut at = 0;
        while at < stream.len() {
            let end = (at + 1 + rng.below(4096)).min(stream.len());
            good.extend(decoder.feed(&stream[at..end]).flatten());
            at = end;
        }
        assert_eq!(decoder.finish(), Some(FrameError::Truncated));
        let stats = decoder.stats();

        // 1. Exactly the untouched frames, in order, bit for bit.
        let want: Vec<&Vec<u8>> = case
            .encoded
            .iter()
            .zip(&touched)
            .filter(|(_, &t)| !t)
            .map(|(e, _)| e)
            .collect();
        assert_eq!(
            good.len(),
            want.len(),
            "seed {seed}: untouched frames recovered"
        );
        for (got, want) in good.iter().zip(&want) {
            assert_eq!(&codec::encode_to_vec(got).unwrap().to_vec(), *want);
        }

        // 2. Touched Samples between the first and last recovered Sample are tick gaps.
        let sample_touched: Vec<bool> = case
            .frames
            .iter()
            .zip(&touched)
            .filter(|(f, _)| matches!(f, Frame::Sample(_)))
            .map(|(_, &t)| t)
            .collect();
        let first_good = sample_touched.iter().position(|t| !t).unwrap();
        let last_good = sample_touched.iter().rposition(|t| !t).unwrap();
        let expected_gaps = sample_touched[first_good..=last_good]
            .iter()
            .filter(|&&t| t)
            .count();
        assert_eq!(
            stats.tick_gaps, expected_gaps as u64,
            "seed {seed}: tick gaps"
        );
        assert_eq!(
            stats.tick_steps_back, 0,
            "seed {seed}: lost frames are no steps back"
        );

        // 3. Every run of touched frames and every garbage burst is counted corrupt.
        let touched_runs =
            touched.windows(2).filter(|w| w[1] && !w[0]).count() + usize::from(touched[0]);
        let bursts = kinds_seen[Corruption::GarbageBetween as usize];
        assert!(
            stats.corrupt_frames >= (touched_runs + bursts) as u64,
            "seed {seed}: {} corrupt counted, {touched_runs} touched runs + {bursts} garbage bursts",
            stats.corrupt_frames
        );
        assert_eq!(stats.good_frames, good.len() as u64);
        assert_eq!(stats.bytes, stream.len() as u64);
    }
}

#[test]
fn oversized_garbage_is_counted_and_the_next_frame_survives() {
    let mut stream = vec![0x55u8; 5 * codec::MAX_FRAME_LEN];
    stream.push(0);
    let frame = header();
    stream.extend_from_slice(&codec::encode_to_vec(&frame).unwrap());
    let mut decoder = Decoder::new();
    let results: Vec<_> = stream
        .chunks(97)
        .flat_map(|c| decoder.feed(c).collect::<Vec<_>>())
        .collect();
    assert_eq!(results, vec![Err(FrameError::TooLong), Ok(frame)]);
}

#[test]
fn another_major_version_is_refused_naming_both() {
    let Frame::Header(mut h) = header() else {
        unreachable!()
    };
    h.protocol = ProtocolVersion {
        major: PROTOCOL_VERSION.major + 1,
        minor: 3,
    };
    let bytes = codec::encode_to_vec(&Frame::Header(h)).unwrap();
    let mut decoder = Decoder::new();
    let result = decoder.feed(&bytes).next().unwrap();
    let expected = FrameError::VersionMismatch {
        found: h.protocol,
        expected: PROTOCOL_VERSION,
    };
    assert_eq!(result, Err(expected));
    let text = expected.to_string();
    assert!(
        text.contains(&format!("{}.3", PROTOCOL_VERSION.major + 1)),
        "{text}"
    );
    assert!(text.contains(&PROTOCOL_VERSION.to_string()), "{text}");
}

#[test]
fn a_future_header_layout_is_still_recognised_by_its_version() {
    // A major-2 Header whose body no longer parses as ours: tag 0, version 2.0, junk.
    let body = [0u8, 2, 0, 0xFF, 0xFF, 0xFF];
    let mut payload = body.to_vec();
    payload.extend_from_slice(&codec::crc32(&body).to_le_bytes());
    let mut wire = vec![0u8; cobs::max_encoded_len(payload.len()) + 1];
    let n = cobs::encode(&payload, &mut wire).unwrap();
    let mut decoder = Decoder::new();
    let result = decoder.feed(&wire[..n + 1]).next().unwrap();
    assert!(
        matches!(
            result,
            Err(FrameError::VersionMismatch {
                found: ProtocolVersion { major: 2, minor: 0 },
                ..
            })
        ),
        "{result:?}"
    );
}
