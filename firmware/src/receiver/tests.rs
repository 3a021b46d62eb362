//! Receiver tests: the SBUS codec against a bit-by-bit reference, the stream decoder's
//! resynchronisation, the reader, the link monitor and the channel map.

use super::channel_map::*;
use super::sbus::*;
use proptest::prelude::*;

// ---------------------------------------------------------------------------------
// Reference codec: the definition cₖ = bits 11k … 11k+10 of D = Σ dᵢ·2⁸ⁱ, bit by bit.
// ---------------------------------------------------------------------------------

fn reference_channels(data: &[u8]) -> [u16; 16] {
    let mut channels = [0u16; 16];
    for bit in 0..176 {
        let data_bit = (data[bit / 8] >> (bit % 8)) & 1;
        channels[bit / 11] |= u16::from(data_bit) << (bit % 11);
    }
    channels
}

fn reference_data(channels: &[u16; 16]) -> [u8; 22] {
    let mut data = [0u8; 22];
    for bit in 0..176 {
        let channel_bit = (channels[bit / 11] >> (bit % 11)) & 1;
        data[bit / 8] |= (channel_bit as u8) << (bit % 8);
    }
    data
}

fn arb_frame() -> impl Strategy<Value = SbusFrame> {
    (
        proptest::array::uniform16(0u16..=CHANNEL_MAX),
        any::<[bool; 4]>(),
    )
        .prop_map(|(channels, [ch17, ch18, frame_lost, failsafe])| SbusFrame {
            channels,
            ch17,
            ch18,
            frame_lost,
            failsafe,
        })
}

fn centred() -> SbusFrame {
    SbusFrame {
        channels: [992; 16],
        ..SbusFrame::default()
    }
}

#[test]
fn one_full_channel_fills_its_eleven_bits_lsb_first() {
    let mut frame = SbusFrame::default();
    frame.channels[0] = 0x7FF;
    let bytes = frame.encode();
    assert_eq!(bytes[0], 0x0F);
    assert_eq!(&bytes[1..4], &[0xFF, 0x07, 0x00]);
    assert!(bytes[4..25].iter().all(|&b| b == 0));

    let mut frame = SbusFrame::default();
    frame.channels[1] = 0x7FF;
    // Channel 2 occupies bits 11..21: the top five bits of byte 2, all of byte 3 is
    // bits 16..23 of which 16..21 belong to it (six bits: 0x3F).
    assert_eq!(&frame.encode()[1..5], &[0x00, 0xF8, 0x3F, 0x00]);

    let mut frame = SbusFrame::default();
    frame.channels[15] = 0x7FF;
    // Channel 16 is bits 165..175: the top three bits of byte 21 and all of byte 22.
    assert_eq!(&frame.encode()[20..25], &[0x00, 0xE0, 0xFF, 0x00, 0x00]);
}

#[test]
fn all_channels_at_maximum_give_all_ones() {
    let frame = SbusFrame {
        channels: [CHANNEL_MAX; 16],
        ..SbusFrame::default()
    };
    let bytes = frame.encode();
    assert!(bytes[1..23].iter().all(|&b| b == 0xFF));
    assert_eq!(SbusFrame::decode(&bytes), Ok(frame));
}

#[test]
fn the_centred_frame_matches_the_reference_packing() {
    let bytes = centred().encode();
    assert_eq!(bytes[1..23], reference_data(&[992; 16]));
    assert_eq!(SbusFrame::decode(&bytes), Ok(centred()));
}

#[test]
fn each_flag_has_its_bit() {
    let cases = [
        (0x01, [true, false, false, false]),
        (0x02, [false, true, false, false]),
        (0x04, [false, false, true, false]),
        (0x08, [false, false, false, true]),
        (0x0C, [false, false, true, true]),
    ];
    for (flags, [ch17, ch18, frame_lost, failsafe]) in cases {
        let frame = SbusFrame {
            ch17,
            ch18,
            frame_lost,
            failsafe,
            ..centred()
        };
        let bytes = frame.encode();
        assert_eq!(bytes[23], flags);
        assert_eq!(SbusFrame::decode(&bytes), Ok(frame));
        assert_eq!(frame.is_intact(), !frame_lost && !failsafe);
    }
}

#[test]
fn the_upper_flag_nibble_is_ignored() {
    let mut bytes = centred().encode();
    bytes[23] = 0xF2;
    let frame = SbusFrame::decode(&bytes).unwrap();
    assert!(frame.ch18 && !frame.ch17 && !frame.frame_lost && !frame.failsafe);
}

#[test]
fn sbus2_end_bytes_are_accepted_and_others_refused() {
    for end in 0..=255u8 {
        let mut bytes = centred().encode();
        bytes[24] = end;
        let expected = if END_BYTES.contains(&end) {
            Ok(centred())
        } else {
            Err(SbusError::End)
        };
        assert_eq!(decode(&bytes), expected, "end byte {end:#04x}");
    }
    let mut bytes = centred().encode();
    bytes[0] = 0x0E;
    assert_eq!(decode(&bytes), Err(SbusError::Header));
}

#[test]
fn channel_values_above_eleven_bits_are_truncated_by_the_encoder() {
    let mut frame = centred();
    frame.channels[3] = 0x0800 | 5;
    let decoded = decode(&encode(&frame)).unwrap();
    assert_eq!(decoded.channels[3], 5);
    assert_eq!(decoded.channels[2], 992);
    assert_eq!(decoded.channels[4], 992);
}

proptest! {
    #[test]
    fn encode_then_decode_is_the_identity(frame in arb_frame()) {
        let bytes = encode(&frame);
        prop_assert_eq!(bytes[0], HEADER);
        prop_assert_eq!(bytes[24], 0x00);
        prop_assert_eq!(&bytes[1..23], &reference_data(&frame.channels)[..]);
        prop_assert_eq!(decode(&bytes), Ok(frame));
        // Byte by byte through the stream decoder too.
        let mut decoder = SbusDecoder::new();
        let out: Vec<_> = bytes.iter().filter_map(|&b| decoder.feed(b)).collect();
        prop_assert_eq!(out, vec![frame]);
    }

    #[test]
    fn decode_matches_the_bit_by_bit_reference(
        data in any::<[u8; 22]>(),
        flags in 0u8..16,
        end in proptest::sample::select(END_BYTES.to_vec()),
    ) {
        let mut bytes = [0u8; FRAME_LEN];
        bytes[0] = HEADER;
        bytes[1..23].copy_from_slice(&data);
        bytes[23] = flags;
        bytes[24] = end;
        let frame = decode(&bytes).unwrap();
        prop_assert_eq!(frame.channels, reference_channels(&data));
        // Re-encoding restores the bytes up to the end marker.
        let again = encode(&frame);
        prop_assert_eq!(&again[..24], &bytes[..24]);
    }

    #[test]
    fn arbitrary_bytes_never_panic(
        bytes in proptest::collection::vec(any::<u8>(), 0..600),
        times in proptest::collection::vec(any::<u32>(), 0..600),
    ) {
        let mut decoder = SbusDecoder::new();
        for &b in &bytes {
            let _ = decoder.feed(b);
            prop_assert!(decoder.pending() < FRAME_LEN);
        }
        let _ = decoder.feed_slice(&bytes);
        let mut timed = SbusDecoder::new();
        for (&b, &t) in bytes.iter().zip(times.iter()) {
            let _ = timed.feed_at(b, t);
            prop_assert!(timed.pending() < FRAME_LEN);
        }
        let mut reader: &[u8] = &bytes;
        let mut polled = SbusDecoder::new();
        while !reader.is_empty() {
            let before = reader.len();
            let _ = polled.poll(&mut reader).unwrap();
            prop_assert!(before - reader.len() <= MAX_POLL_BYTES);
        }
        // Every byte fed is accounted for: in a frame, discarded, or pending.
        let stats = decoder.stats();
        let total = 2 * bytes.len() as u64;
        let accounted = u64::from(stats.frames) * FRAME_LEN as u64
            + u64::from(stats.discarded_bytes)
            + decoder.pending() as u64;
        prop_assert_eq!(accounted, total);
    }
}

// ---------------------------------------------------------------------------------
// Frames between garbage.
//
// The decoder accepts a candidate starting at a 0x0F whose byte 24 places later is an
// end byte. A 0x0F in the garbage with an end byte 24 places later (in garbage or in a
// frame) would be a valid alignment that is not a frame: an ambiguity no decoder without
// timing can resolve. The property: if the garbage contains no such position, the
// decoder yields exactly the embedded frames, in order. Garbage is drawn heavy in 0x0F
// and end bytes, so false candidates overlapping real headers are frequent (a decoder
// that skipped all 25 bytes of a rejected candidate instead of rescanning them would
// lose those frames); ambiguous positions are then defused by turning their 0x0F into
// 0x0E, which cannot create a new one.
// ---------------------------------------------------------------------------------

fn garbage_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        3 => Just(HEADER),
        2 => proptest::sample::select(END_BYTES.to_vec()),
        5 => any::<u8>(),
    ]
}

/// The stream and, per byte, whether it is garbage.
fn embed(frames: &[SbusFrame], garbage: &[Vec<u8>]) -> (Vec<u8>, Vec<bool>) {
    let mut stream = Vec::new();
    let mut is_garbage = Vec::new();
    for (i, gap) in garbage.iter().enumerate() {
        stream.extend_from_slice(gap);
        is_garbage.extend(gap.iter().map(|_| true));
        if let Some(frame) = frames.get(i) {
            stream.extend_from_slice(&frame.encode());
            is_garbage.extend([false; FRAME_LEN]);
        }
    }
    for s in 0..stream.len() {
        let ambiguous = is_garbage[s]
            && stream[s] == HEADER
            && stream
                .get(s + FRAME_LEN - 1)
                .is_some_and(|end| END_BYTES.contains(end));
        if ambiguous {
            stream[s] = 0x0E;
        }
    }
    (stream, is_garbage)
}

proptest! {
    #[test]
    fn every_frame_between_unambiguous_garbage_is_recovered(
        frames in proptest::collection::vec(arb_frame(), 1..8),
        garbage in proptest::collection::vec(
            proptest::collection::vec(garbage_byte(), 0..60), 9),
        chunk in 1usize..40,
    ) {
        let (stream, _) = embed(&frames, &garbage);

        let mut decoder = SbusDecoder::new();
        let bytewise: Vec<_> = stream.iter().filter_map(|&b| decoder.feed(b)).collect();
        prop_assert_eq!(&bytewise, &frames);

        // Chunked, through the reader, polling until the stream is drained.
        let mut reader: &[u8] = &stream;
        let mut polled = SbusDecoder::new();
        let mut newest = Vec::new();
        while !reader.is_empty() {
            let mut limited = Chunked { bytes: &mut reader, chunk };
            if let Some(frame) = polled.poll(&mut limited).unwrap() {
                newest.push(frame);
            }
        }
        prop_assert_eq!(polled.stats().frames as usize, frames.len());
        prop_assert_eq!(newest.last(), frames.last());
    }
}

/// A reader that hands out at most `chunk` bytes per read.
struct Chunked<'a, 'b> {
    bytes: &'a mut &'b [u8],
    chunk: usize,
}

impl embedded_io::ErrorType for Chunked<'_, '_> {
    type Error = core::convert::Infallible;
}

impl embedded_io::ReadReady for Chunked<'_, '_> {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        Ok(!self.bytes.is_empty())
    }
}

impl embedded_io::Read for Chunked<'_, '_> {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        let n = buf.len().min(self.chunk).min(self.bytes.len());
        buf[..n].copy_from_slice(&self.bytes[..n]);
        *self.bytes = &self.bytes[n..];
        Ok(n)
    }
}

#[test]
fn a_false_header_overlapping_a_real_one_is_rescanned() {
    // 0x0F, then 10 bytes, then a real frame: the false candidate's byte 24 is inside
    // the real frame (data, not an end byte), and the real header lies inside the
    // false candidate.
    let mut frame = centred();
    frame.channels[0] = 1234;
    let mut stream = vec![HEADER, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10];
    stream.extend_from_slice(&frame.encode());
    assert!(!END_BYTES.contains(&stream[24]));
    let mut decoder = SbusDecoder::new();
    let out: Vec<_> = stream.iter().filter_map(|&b| decoder.feed(b)).collect();
    assert_eq!(out, vec![frame]);
    assert_eq!(decoder.stats().bad_end_bytes, 1);
    assert_eq!(decoder.stats().discarded_bytes, 11);
}

#[test]
fn starting_mid_stream_with_header_values_in_the_data_it_locks_on_within_two_frames() {
    // Channel 1 = 0x70F puts 0x0F into byte 1; every frame is the same.
    let mut frame = centred();
    frame.channels[0] = 0x70F;
    let bytes = frame.encode();
    assert_eq!(bytes[1], HEADER);
    let stream: Vec<u8> = bytes.iter().copied().cycle().take(10 * FRAME_LEN).collect();
    for start in 0..FRAME_LEN {
        let mut decoder = SbusDecoder::new();
        let out: Vec<_> = stream[start..]
            .iter()
            .enumerate()
            .filter_map(|(i, &b)| decoder.feed(b).map(|f| (i, f)))
            .collect();
        assert!(out.iter().all(|(_, f)| *f == frame), "start {start}");
        // The first complete frame after `start` is the one that begins at the next
        // multiple of 25: it must be the first one yielded.
        let first_header = (FRAME_LEN - start) % FRAME_LEN;
        assert_eq!(out[0].0, first_header + FRAME_LEN - 1, "start {start}");
        assert_eq!(out.len(), (stream.len() - start - first_header) / FRAME_LEN);
    }
}

/// A frame whose flags byte is 0x0F and whose byte 22 is 0x00: with back-to-back frames,
/// the alignment that starts at byte 23 also ends on an end byte (byte 22 of the next
/// frame), so an untimed decoder that starts there stays there.
fn trap_frame() -> SbusFrame {
    let mut frame = SbusFrame {
        ch17: true,
        ch18: true,
        frame_lost: true,
        failsafe: true,
        ..centred()
    };
    frame.channels[15] = 3; // byte 22 holds channel 16's bits 3..10: zero.
    frame
}

#[test]
fn without_timing_a_steady_stream_can_hold_a_false_alignment() {
    let bytes = trap_frame().encode();
    assert_eq!((bytes[22], bytes[23]), (0x00, 0x0F));
    let stream: Vec<u8> = bytes.iter().copied().cycle().take(12 * FRAME_LEN).collect();
    let mut decoder = SbusDecoder::new();
    let out: Vec<_> = stream[23..]
        .iter()
        .filter_map(|&b| decoder.feed(b))
        .collect();
    assert!(!out.is_empty());
    assert!(out.iter().all(|f| *f != trap_frame()));
}

#[test]
fn feed_at_breaks_a_false_alignment_at_the_inter_frame_gap() {
    let bytes = trap_frame().encode();
    let mut decoder = SbusDecoder::new();
    let mut out = Vec::new();
    // 7 ms frames, 120 µs per byte; start listening at byte 23 of the first frame.
    for n in 0..12u32 {
        for (i, &b) in bytes.iter().enumerate() {
            if n == 0 && i < 23 {
                continue;
            }
            let t = n * 7_000 + i as u32 * 120;
            out.extend(decoder.feed_at(b, t));
        }
    }
    assert_eq!(out, vec![trap_frame(); 11]);
    assert_eq!(decoder.stats().gap_drops, 1);
    assert_eq!(decoder.stats().discarded_bytes, 2);
}

#[test]
fn feed_at_keeps_frames_whose_bytes_are_close_and_the_clock_wraps() {
    let bytes = centred().encode();
    let mut decoder = SbusDecoder::new();
    let start = u32::MAX - 1_000;
    let out: Vec<_> = bytes
        .iter()
        .enumerate()
        .filter_map(|(i, &b)| decoder.feed_at(b, start.wrapping_add(i as u32 * 120)))
        .collect();
    assert_eq!(out, vec![centred()]);
    assert_eq!(decoder.stats().gap_drops, 0);
}

#[test]
fn a_gap_inside_a_frame_drops_it_and_the_next_frame_decodes() {
    let bytes = centred().encode();
    let mut decoder = SbusDecoder::new();
    for (i, &b) in bytes[..10].iter().enumerate() {
        assert_eq!(decoder.feed_at(b, i as u32 * 120), None);
    }
    // 3 ms exactly is not a gap; 3 ms + 1 µs is.
    assert_eq!(
        decoder.feed_at(bytes[10], 9 * 120 + INTER_FRAME_GAP_US),
        None
    );
    assert_eq!(decoder.pending(), 11);
    let t = 10 * 120 + INTER_FRAME_GAP_US + 1 + INTER_FRAME_GAP_US;
    assert_eq!(decoder.feed_at(bytes[11], t), None);
    assert_eq!(decoder.pending(), 0);
    let out: Vec<_> = bytes
        .iter()
        .enumerate()
        .filter_map(|(i, &b)| decoder.feed_at(b, t + 5_000 + i as u32 * 120))
        .collect();
    assert_eq!(out, vec![centred()]);
    assert_eq!(decoder.stats().gap_drops, 1);
}

/// A reader that is never ready: reading it would be a blocking read.
struct NeverReady;

impl embedded_io::ErrorType for NeverReady {
    type Error = core::convert::Infallible;
}

impl embedded_io::ReadReady for NeverReady {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        Ok(false)
    }
}

impl embedded_io::Read for NeverReady {
    fn read(&mut self, _buf: &mut [u8]) -> Result<usize, Self::Error> {
        panic!("read called although not ready: it would block");
    }
}

#[test]
fn poll_reads_only_what_is_ready_and_at_most_its_budget() {
    assert_eq!(SbusDecoder::new().poll(&mut NeverReady), Ok(None));

    let frames: Vec<SbusFrame> = (0..8u16)
        .map(|k| SbusFrame {
            channels: [200 + k; 16],
            ..SbusFrame::default()
        })
        .collect();
    let stream: Vec<u8> = frames.iter().flat_map(|f| f.encode()).collect();
    let mut reader: &[u8] = &stream;
    let mut decoder = SbusDecoder::new();
    assert_eq!(decoder.poll(&mut reader), Ok(Some(frames[4])));
    assert_eq!(reader.len(), 3 * FRAME_LEN);
    assert_eq!(decoder.poll(&mut reader), Ok(Some(frames[7])));
    assert_eq!(decoder.poll(&mut reader), Ok(None));
    assert_eq!(decoder.stats().frames, 8);
}

// ---------------------------------------------------------------------------------
// Link monitor.
// ---------------------------------------------------------------------------------

#[test]
fn no_frame_means_lost() {
    let mut link = Receiver::default();
    assert_eq!(link.status(0), LinkStatus::Lost(LossReason::NoFrame));
    assert_eq!(link.frame(0), None);
}

#[test]
fn an_intact_frame_is_valid_until_the_timeout_then_lost_until_the_next() {
    let mut link = Receiver::new(100_000);
    link.on_frame(&centred(), 5_000);
    assert_eq!(link.status(5_000), LinkStatus::Valid);
    assert_eq!(link.frame(105_000), Some(centred()));
    assert_eq!(link.status(105_001), LinkStatus::Lost(LossReason::Timeout));
    // Latched: even a time that would look fresh again stays lost.
    assert_eq!(link.status(5_000), LinkStatus::Lost(LossReason::Timeout));
    link.on_frame(&centred(), 200_000);
    assert_eq!(link.status(200_000), LinkStatus::Valid);
}

#[test]
fn the_timeout_spans_the_counter_wrap() {
    let mut link = Receiver::new(100_000);
    let t = u32::MAX - 20_000;
    link.on_frame(&centred(), t);
    assert_eq!(link.status(t.wrapping_add(100_000)), LinkStatus::Valid);
    assert_eq!(
        link.status(t.wrapping_add(100_001)),
        LinkStatus::Lost(LossReason::Timeout)
    );
}

#[test]
fn a_frame_stamped_just_after_now_is_fresh() {
    let mut link = Receiver::default();
    link.on_frame(&centred(), 1_000);
    assert_eq!(link.status(900), LinkStatus::Valid);
}

#[test]
fn single_lost_frames_are_counted_but_keep_the_link() {
    let mut link = Receiver::default();
    let lost = SbusFrame {
        frame_lost: true,
        ..centred()
    };
    let mut t = 0u32;
    for n in 0..100 {
        let frame = if n % 3 == 1 { lost } else { centred() };
        link.on_frame(&frame, t);
        assert_eq!(link.status(t), LinkStatus::Valid);
        t += 14_000;
    }
    assert_eq!(link.lost_frames(), 33);
    assert_eq!(link.intact_frames(), 67);
}

#[test]
fn a_run_of_lost_frames_longer_than_the_timeout_loses_the_link() {
    let mut link = Receiver::default();
    link.on_frame(&centred(), 0);
    let lost = SbusFrame {
        frame_lost: true,
        ..centred()
    };
    let mut t = 0;
    for _ in 0..7 {
        t += 14_000;
        link.on_frame(&lost, t);
        assert_eq!(link.status(t), LinkStatus::Valid, "t = {t}");
    }
    t += 14_000; // 112 ms since the last intact frame
    link.on_frame(&lost, t);
    assert_eq!(link.status(t), LinkStatus::Lost(LossReason::Timeout));
    assert_eq!(link.consecutive_lost_frames(), 8);
    link.on_frame(&centred(), t + 7_000);
    assert_eq!(link.consecutive_lost_frames(), 0);
    assert_eq!(link.status(t + 7_000), LinkStatus::Valid);
}

#[test]
fn the_failsafe_flag_loses_the_link_at_once() {
    let mut link = Receiver::default();
    link.on_frame(&centred(), 0);
    let failsafe = SbusFrame {
        failsafe: true,
        frame_lost: true,
        ..centred()
    };
    link.on_frame(&failsafe, 7_000);
    assert_eq!(link.status(7_000), LinkStatus::Lost(LossReason::Failsafe));
    assert_eq!(link.frame(7_000), None);
    link.on_frame(&centred(), 14_000);
    assert_eq!(link.status(14_000), LinkStatus::Valid);
}

// ---------------------------------------------------------------------------------
// Channel map.
// ---------------------------------------------------------------------------------

fn with_channel(index: usize, raw: u16) -> SbusFrame {
    let mut frame = centred();
    frame.channels[index] = raw;
    frame
}

#[test]
fn the_default_map_is_valid_and_centred_sticks_read_zero() {
    let map = ChannelMap::flybarless_default();
    assert_eq!(map.validate(), Ok(()));
    let input = map.map(&centred());
    assert_eq!(input.sticks, sweephold_protocol::Controls::default());
    assert_eq!(input.throttle, 820.0 / 1639.0);
    assert!(!input.arm && !input.test_switch);
    assert_eq!(input.mode, ModeSwitch::Middle);
}

#[test]
fn stick_endpoints_and_centre_are_exact() {
    let range = RawRange::SBUS;
    assert_eq!(range.stick(172), -1.0);
    assert_eq!(range.stick(992), 0.0);
    assert_eq!(range.stick(1811), 1.0);
    assert_eq!(range.stick(582), -0.5);
    assert_eq!(range.unipolar(172), 0.0);
    assert_eq!(range.unipolar(1811), 1.0);
    let map = ChannelMap::flybarless_default();
    for (index, get) in [
        (0usize, (|i: &RcInput| i.sticks.lat) as fn(&RcInput) -> f32),
        (1, |i| i.sticks.lon),
        (3, |i| i.sticks.ped),
        (5, |i| i.sticks.col),
    ] {
        assert_eq!(get(&map.map(&with_channel(index, 172))), -1.0);
        assert_eq!(get(&map.map(&with_channel(index, 1811))), 1.0);
        assert_eq!(get(&map.map(&with_channel(index, 992))), 0.0);
        assert_eq!(get(&map.map(&with_channel(index, 1401))), 409.0 / 819.0);
    }
    assert_eq!(map.map(&with_channel(2, 172)).throttle, 0.0);
    assert_eq!(map.map(&with_channel(2, 1811)).throttle, 1.0);
}

#[test]
fn values_beyond_the_range_clamp() {
    let map = ChannelMap::flybarless_default();
    assert_eq!(map.map(&with_channel(0, 0)).sticks.lat, -1.0);
    assert_eq!(map.map(&with_channel(0, 2047)).sticks.lat, 1.0);
    assert_eq!(map.map(&with_channel(2, 0)).throttle, 0.0);
    assert_eq!(map.map(&with_channel(2, 2047)).throttle, 1.0);
}

#[test]
fn reversal_inverts_each_kind() {
    let mut map = ChannelMap::flybarless_default();
    map.lateral.reversed = true;
    map.throttle.reversed = true;
    map.arm.reversed = true;
    map.mode.reversed = true;
    assert_eq!(map.map(&with_channel(0, 172)).sticks.lat, 1.0);
    assert_eq!(map.map(&with_channel(0, 1811)).sticks.lat, -1.0);
    assert_eq!(map.map(&with_channel(0, 1401)).sticks.lat, -409.0 / 819.0);
    assert_eq!(map.map(&with_channel(2, 172)).throttle, 1.0);
    assert_eq!(map.map(&with_channel(2, 1811)).throttle, 0.0);
    assert!(map.map(&with_channel(4, 172)).arm);
    assert!(!map.map(&with_channel(4, 1811)).arm);
    assert_eq!(map.map(&with_channel(7, 172)).mode, ModeSwitch::High);
    assert_eq!(map.map(&with_channel(7, 1811)).mode, ModeSwitch::Low);
}

#[test]
fn switch_thresholds_sit_half_way_and_the_threshold_itself_is_off() {
    let map = ChannelMap::flybarless_default();
    // s > ½ ⇔ r − 992 > 409.5 ⇔ r ≥ 1402.
    assert!(!map.map(&with_channel(4, 1401)).arm);
    assert!(map.map(&with_channel(4, 1402)).arm);
    assert!(!map.map(&with_channel(6, 1401)).test_switch);
    assert!(map.map(&with_channel(6, 1402)).test_switch);
    // s < −½ ⇔ r − 992 < −410 ⇔ r ≤ 581; r = 582 is exactly −½: Middle.
    assert_eq!(map.map(&with_channel(7, 581)).mode, ModeSwitch::Low);
    assert_eq!(map.map(&with_channel(7, 582)).mode, ModeSwitch::Middle);
    assert_eq!(map.map(&with_channel(7, 1401)).mode, ModeSwitch::Middle);
    assert_eq!(map.map(&with_channel(7, 1402)).mode, ModeSwitch::High);
    // Nominal positions.
    for (raw, mode) in [
        (172, ModeSwitch::Low),
        (992, ModeSwitch::Middle),
        (1811, ModeSwitch::High),
    ] {
        assert_eq!(map.map(&with_channel(7, raw)).mode, mode);
    }
}

#[test]
fn channels_can_be_reassigned() {
    let mut map = ChannelMap::flybarless_default();
    map.arm = ChannelSource::normal(9);
    map.test = ChannelSource::normal(5);
    assert_eq!(map.validate(), Ok(()));
    let input = map.map(&with_channel(8, 1811));
    assert!(input.arm && !input.test_switch);
    let input = map.map(&with_channel(4, 1811));
    assert!(!input.arm && input.test_switch);
    let pilot = input.pilot_input();
    assert!(pilot.test_switch);
    assert_eq!(pilot.sticks, input.sticks);
}

#[test]
fn invalid_maps_are_refused_and_still_map_to_neutral() {
    let mut map = ChannelMap::flybarless_default();
    map.arm.channel = 0;
    assert_eq!(map.validate(), Err(ChannelMapError::ChannelOutOfRange));
    assert!(
        !map.map(&SbusFrame {
            channels: [1811; 16],
            ..SbusFrame::default()
        })
        .arm
    );
    map.arm.channel = 17;
    assert_eq!(map.validate(), Err(ChannelMapError::ChannelOutOfRange));

    let mut map = ChannelMap::flybarless_default();
    map.mode.channel = 5;
    assert_eq!(map.validate(), Err(ChannelMapError::DuplicateChannel));

    let mut map = ChannelMap::flybarless_default();
    map.lateral.channel = 20;
    map.throttle.channel = 0;
    map.mode.channel = 99;
    let input = map.map(&SbusFrame {
        channels: [1811; 16],
        ..SbusFrame::default()
    });
    assert_eq!(input.sticks.lat, 0.0);
    assert_eq!(input.throttle, 0.0);
    assert_eq!(input.mode, ModeSwitch::Middle);

    for range in [
        RawRange {
            min: 992,
            centre: 992,
            max: 1811,
        },
        RawRange {
            min: 172,
            centre: 1811,
            max: 1811,
        },
        RawRange {
            min: 172,
            centre: 992,
            max: 2048,
        },
        RawRange {
            min: 1811,
            centre: 992,
            max: 172,
        },
    ] {
        let mut map = ChannelMap::flybarless_default();
        map.range = range;
        assert_eq!(map.validate(), Err(ChannelMapError::RangeInvalid));
        for raw in [0, 172, 992, 1811, 2047] {
            let input = map.map(&with_channel(0, raw));
            assert!(input.sticks.lat.is_finite() && input.throttle.is_finite());
        }
    }

    for tau in [0.0, 1.0, -0.2, f32::NAN, f32::INFINITY] {
        let mut map = ChannelMap::flybarless_default();
        map.switch_threshold = tau;
        assert_eq!(map.validate(), Err(ChannelMapError::ThresholdInvalid));
    }
    let mut map = ChannelMap::flybarless_default();
    map.switch_threshold = f32::NAN;
    let input = map.map(&with_channel(4, 1811));
    assert!(!input.arm);
    assert_eq!(input.mode, ModeSwitch::Middle);
}

#[test]
fn every_raw_value_maps_to_a_finite_in_range_monotone_output() {
    let map = ChannelMap::flybarless_default();
    let mut previous = (-1.0f32, 0.0f32);
    for raw in 0..=CHANNEL_MAX {
        let frame = SbusFrame {
            channels: [raw; 16],
            ..SbusFrame::default()
        };
        let input = map.map(&frame);
        for s in input.sticks.to_array() {
            assert!(s.is_finite() && (-1.0..=1.0).contains(&s), "raw {raw}");
        }
        assert!((0.0..=1.0).contains(&input.throttle), "raw {raw}");
        assert!(input.sticks.lat >= previous.0 && input.throttle >= previous.1);
        previous = (input.sticks.lat, input.throttle);
    }
}

// ---------------------------------------------------------------------------------
// The transmitter model: ChannelMap::encode is map's inverse up to one raw count.
// ---------------------------------------------------------------------------------

fn arb_mode() -> impl Strategy<Value = ModeSwitch> {
    prop_oneof![
        Just(ModeSwitch::Low),
        Just(ModeSwitch::Middle),
        Just(ModeSwitch::High)
    ]
}

proptest! {
    #[test]
    fn encode_then_map_returns_the_input(
        sticks in proptest::array::uniform4(-1.0f32..=1.0),
        throttle in 0.0f32..=1.0,
        arm in any::<bool>(),
        test_switch in any::<bool>(),
        mode in arb_mode(),
        reversed in any::<[bool; 8]>(),
    ) {
        let mut map = ChannelMap::flybarless_default();
        map.lateral.reversed = reversed[0];
        map.longitudinal.reversed = reversed[1];
        map.throttle.reversed = reversed[2];
        map.pedal.reversed = reversed[3];
        map.arm.reversed = reversed[4];
        map.collective.reversed = reversed[5];
        map.test.reversed = reversed[6];
        map.mode.reversed = reversed[7];
        let [lat, lon, ped, col] = sticks;
        let input = RcInput {
            sticks: sweephold_protocol::Controls { lat, lon, ped, col },
            throttle,
            arm,
            test_switch,
            mode,
            selector: None,
        };
        let frame = map.encode(&input);
        prop_assert!(frame.is_intact());
        let back = map.map(&frame);
        // One raw count: 1/819 of a half travel, 1/1639 of the throttle's.
        for (a, b) in input.sticks.to_array().iter().zip(back.sticks.to_array()) {
            prop_assert!((a - b).abs() <= 0.5 / 819.0 + 1e-6, "{a} -> {b}");
        }
        prop_assert!((input.throttle - back.throttle).abs() <= 0.5 / 1639.0 + 1e-6);
        prop_assert_eq!(back.arm, arm);
        prop_assert_eq!(back.test_switch, test_switch);
        prop_assert_eq!(back.mode, mode);
    }
}

#[test]
fn encode_writes_the_centre_for_non_finite_sticks_and_the_minimum_throttle() {
    let map = ChannelMap::flybarless_default();
    let input = RcInput {
        sticks: sweephold_protocol::Controls {
            lat: f32::NAN,
            lon: f32::INFINITY,
            ped: f32::NEG_INFINITY,
            col: 0.5,
        },
        throttle: f32::NAN,
        arm: false,
        test_switch: false,
        mode: ModeSwitch::Middle,
        selector: None,
    };
    let frame = map.encode(&input);
    assert_eq!(&frame.channels[..4], &[992, 992, 172, 992]);
    assert_eq!(frame.channels[4], 172, "arm off: full negative travel");
    assert_eq!(
        frame.channels[5],
        992 + 410,
        "collective 0.5: 992 + round(409.5)"
    );
    assert_eq!(frame.channels[7], 992, "mode Middle: centre");
    assert_eq!(frame.channels[8..], [992; 8]);
}

#[test]
fn the_test_selector_reads_its_channel_only_when_it_has_one() {
    let mut map = ChannelMap::flybarless_default();
    let mut frame = SbusFrame {
        channels: [992; 16],
        ..SbusFrame::default()
    };
    frame.channels[8] = 172;
    // No channel (the default): no selector, whatever the frame holds.
    assert_eq!(map.selector.channel, 0);
    assert_eq!(map.map(&frame).selector, None);
    // Channel 9: read like a stick, both ends and the centre exact.
    map.selector = ChannelSource::normal(9);
    assert_eq!(map.validate(), Ok(()));
    assert_eq!(map.map(&frame).selector, Some(-1.0));
    frame.channels[8] = 1811;
    assert_eq!(map.map(&frame).selector, Some(1.0));
    frame.channels[8] = 992;
    assert_eq!(map.map(&frame).selector, Some(0.0));
    // The transmitter's side writes it back.
    let input = RcInput {
        selector: Some(0.5),
        ..RcInput::NEUTRAL
    };
    let back = map.map(&map.encode(&input)).selector.unwrap();
    assert!((back - 0.5).abs() <= 0.5 / 819.0 + 1e-6, "{back}");
    // A channel another function reads, or beyond 16, is refused.
    map.selector = ChannelSource::normal(7);
    assert_eq!(map.validate(), Err(ChannelMapError::DuplicateChannel));
    map.selector = ChannelSource::normal(17);
    assert_eq!(map.validate(), Err(ChannelMapError::ChannelOutOfRange));
}
