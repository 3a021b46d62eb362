//! Property round-trips of every frame type through encode → decode.

mod strategies;

use proptest::prelude::*;
use strategies::*;
use sweephold_protocol::{codec, Decoder, Frame};

/// Frames compare by their wire bytes: postcard writes f32 bit-exactly, so equal bytes
/// mean bit-identical values (NaN payloads included, which `PartialEq` cannot check).
fn wire(frame: &Frame) -> Vec<u8> {
    codec::encode_to_vec(frame)
        .expect("every frame fits MAX_FRAME_LEN")
        .to_vec()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_frame_round_trips(frame in frame()) {
        let bytes = wire(&frame);
        prop_assert!(bytes.len() <= codec::MAX_FRAME_LEN);
        prop_assert_eq!(bytes.last(), Some(&0u8));
        prop_assert!(!bytes[..bytes.len() - 1].contains(&0), "COBS leaves no zero inside");
        let mut decoder = Decoder::new();
        let decoded: Vec<_> = decoder.feed(&bytes).collect();
        prop_assert_eq!(decoded.len(), 1);
        let back = decoded[0].expect("an intact frame decodes");
        prop_assert_eq!(wire(&back), bytes);
        prop_assert_eq!(decoder.finish(), None);
        prop_assert_eq!(decoder.stats().good_frames, 1);
    }

    /// A stream split into arbitrary chunks decodes to the same frames.
    #[test]
    fn chunking_does_not_matter(frames in proptest::collection::vec(frame(), 1..40),
                                cuts in proptest::collection::vec(1usize..300, 1..50)) {
        let stream: Vec<u8> = frames.iter().flat_map(wire).collect();
        let mut decoder = Decoder::new();
        let mut out = Vec::new();
        let mut at = 0;
        for cut in cuts.iter().cycle() {
            if at >= stream.len() { break; }
            let end = (at + cut).min(stream.len());
            out.extend(decoder.feed(&stream[at..end]));
            at = end;
        }
        prop_assert_eq!(decoder.finish(), None);
        prop_assert_eq!(out.len(), frames.len());
        for (got, want) in out.iter().zip(&frames) {
            prop_assert_eq!(wire(got.as_ref().expect("intact")), wire(want));
        }
    }

    /// Arbitrary bytes never panic the decoder, and every byte is accounted for.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let mut decoder = Decoder::new();
        let n = decoder.feed(&bytes).count();
        decoder.finish();
        let stats = decoder.stats();
        prop_assert_eq!(stats.bytes, bytes.len() as u64);
        prop_assert!(stats.good_frames + stats.corrupt_frames >= n as u64);
    }
}

/// Protocol 1.3 appended `InputKind::AdaptiveSweep`: the older variants keep their
/// encoding, the new one is the next index, and a test without it announces 1.2 so its
/// dumps stay those of a 1.2 flight controller.
#[test]
fn adaptive_sweep_is_appended_and_announced_only_when_used() {
    use sweephold_protocol::{InputKind, ProtocolVersion};
    let encoded = |kind: InputKind| {
        let mut buffer = [0u8; 4];
        postcard::to_slice(&kind, &mut buffer).unwrap().to_vec()
    };
    assert_eq!(encoded(InputKind::Sweep), [0]);
    assert_eq!(encoded(InputKind::ThreeTwoOneOne), [2]);
    assert_eq!(encoded(InputKind::AdaptiveSweep), [3]);
    let mut test = sweephold_protocol::synthetic::header().test;
    for kind in [
        InputKind::Sweep,
        InputKind::Doublet,
        InputKind::ThreeTwoOneOne,
    ] {
        test.input = kind;
        assert_eq!(
            ProtocolVersion::for_test(&test),
            ProtocolVersion { major: 1, minor: 2 }
        );
        assert!(kind.is_sweep() == (kind == InputKind::Sweep));
    }
    test.input = InputKind::AdaptiveSweep;
    assert_eq!(
        ProtocolVersion::for_test(&test),
        ProtocolVersion { major: 1, minor: 3 }
    );
    assert!(test.input.is_sweep());
}

/// Protocol 1.9 appended the loop test's input kind (index 4): a Header of a loop test
/// announces 1.9, every other test's announcement stays as it was.
#[test]
fn protocol_1_9_appends_the_loop_sweep() {
    use sweephold_protocol::{InputKind, ProtocolVersion};
    let encoded = |kind: InputKind| {
        let mut buffer = [0u8; 4];
        postcard::to_slice(&kind, &mut buffer).unwrap().to_vec()
    };
    assert_eq!(encoded(InputKind::LoopSweep), [4]);
    let mut test = sweephold_protocol::synthetic::header().test;
    test.input = InputKind::LoopSweep;
    assert_eq!(
        ProtocolVersion::for_test(&test),
        ProtocolVersion { major: 1, minor: 9 }
    );
    assert!(test.input.is_sweep() && test.input.is_loop());
    assert!(!InputKind::Sweep.is_loop());
}

/// Protocol 1.4 appended the board application's events after `Abort` (variant 4): the
/// older events keep their encoding, the new ones take indices 5–8, and a board
/// application announces 1.4 whatever its test.
#[test]
fn board_events_are_appended_after_abort() {
    use sweephold_protocol::{
        AbortReason, Event, FlightMode, HostFrame, ImuHealth, ProtocolVersion, RefusedCheck,
        Request,
    };
    let encoded = |event: Event| {
        let mut buffer = [0u8; 32];
        postcard::to_slice(&event, &mut buffer).unwrap().to_vec()
    };
    let abort = Event::Abort {
        tick: 1,
        reason: AbortReason::Disarmed,
    };
    assert_eq!(encoded(abort), [4, 1, 8]);
    let mode = Event::ModeChange {
        tick: 2,
        from: FlightMode::Disarmed,
        to: FlightMode::ImuFailsafe,
    };
    assert_eq!(encoded(mode), [5, 2, 0, 4]);
    let health = Event::ImuHealthChange {
        tick: 3,
        health: ImuHealth::Stale,
    };
    assert_eq!(encoded(health), [6, 3, 7]);
    let refused = Event::Refused {
        tick: 4,
        request: Request::Test,
        check: RefusedCheck::Imu(ImuHealth::Missing),
    };
    assert_eq!(encoded(refused), [7, 4, 1, 0, 2]);
    let ignored = Event::HostLinkIgnored {
        tick: 5,
        frame: HostFrame::Configure,
    };
    assert_eq!(encoded(ignored), [8, 5, 1]);
    let v = |minor| ProtocolVersion { major: 1, minor };
    assert_eq!(v(2).max(v(4)), v(4));
    assert_eq!(v(4).max(v(3)), v(4));
}
