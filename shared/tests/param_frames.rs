//! Protocol 1.5's parameter frames (and 1.6's and 1.7's additions): round trips, their place at the end of every
//! enum (so the older encodings stay as they were), and parameter names.

mod strategies;

use postcard::experimental::max_size::MaxSize;
use proptest::prelude::*;
use strategies::*;
use sweephold_protocol::*;

fn postcard_bytes<T: serde::Serialize>(value: &T) -> Vec<u8> {
    let mut buffer = [0u8; 256];
    postcard::to_slice(value, &mut buffer).unwrap().to_vec()
}

fn round_trip(frame: &Frame) -> Frame {
    let bytes = codec::encode_to_vec(frame).unwrap().to_vec();
    let mut decoder = Decoder::new();
    let frames: Vec<_> = decoder.feed(&bytes).collect();
    assert_eq!(frames.len(), 1);
    frames[0].expect("an intact frame decodes")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn requests_and_replies_round_trip(request in param_request(), reply in param_reply()) {
        let frame = Frame::ParamRequest(request);
        prop_assert_eq!(postcard_bytes(&round_trip(&frame)), postcard_bytes(&frame));
        let frame = Frame::ParamReply(reply);
        prop_assert_eq!(postcard_bytes(&round_trip(&frame)), postcard_bytes(&frame));
    }

    #[test]
    fn names_round_trip(name in "[A-Z0-9_]{1,16}") {
        let param = ParamName::new(&name).unwrap();
        prop_assert_eq!(param.as_str(), Some(name.as_str()));
        let back: ParamName = postcard::from_bytes(&postcard_bytes(&param)).unwrap();
        prop_assert_eq!(back, param);
    }
}

#[test]
fn parameter_frames_are_appended_and_keep_the_older_encodings() {
    // Frame: ConfigureResult stays variant 6, the new frames are 7 and 8.
    let result = Frame::ConfigureResult(ConfigureResult {
        accepted: true,
        refusal: 0,
    });
    assert_eq!(postcard_bytes(&result), [6, 1, 0]);
    let set = Frame::ParamRequest(ParamRequest::Set {
        name: ParamName::new("SWASH_TYPE").unwrap(),
        value: 140.0,
    });
    let mut expected = vec![7, 2];
    expected.extend_from_slice(b"SWASH_TYPE\0\0\0\0\0\0");
    expected.extend_from_slice(&140.0f32.to_le_bytes());
    assert_eq!(postcard_bytes(&set), expected);
    let refused = Frame::ParamReply(ParamReply::Refused {
        op: ParamOp::Save,
        name: ParamName::EMPTY,
        reason: ParamRefusal::Armed,
    });
    let mut expected = vec![8, 2, 3];
    expected.extend_from_slice(&[0; 16]);
    expected.push(0);
    assert_eq!(postcard_bytes(&refused), expected);
    // Event: HostLinkIgnored stays 8, ParamStore is 9.
    let store = Event::ParamStore {
        tick: 5,
        status: ParamStoreStatus::OtherVersion,
    };
    assert_eq!(postcard_bytes(&store), [9, 5, 3]);
    // RefusedCheck: SequencerBusy stays 6, the new checks are 7 and 8.
    assert_eq!(postcard_bytes(&RefusedCheck::SequencerBusy), [6]);
    assert_eq!(postcard_bytes(&RefusedCheck::ParamsInvalid), [7]);
    assert_eq!(postcard_bytes(&RefusedCheck::NotLevel), [8]);
}

#[test]
fn the_largest_frame_is_not_a_parameter_frame() {
    // The new variants do not raise the largest frame, so every buffer sized by
    // MAX_FRAME_LEN keeps its size.
    let older = [
        Header::POSTCARD_MAX_SIZE,
        Sample::POSTCARD_MAX_SIZE,
        Event::POSTCARD_MAX_SIZE,
        SensorIn::POSTCARD_MAX_SIZE,
        ActuatorOut::POSTCARD_MAX_SIZE,
        LinkConfig::POSTCARD_MAX_SIZE,
        ConfigureResult::POSTCARD_MAX_SIZE,
    ]
    .into_iter()
    .max()
    .unwrap();
    assert!(ParamRequest::POSTCARD_MAX_SIZE < older);
    assert!(ParamReply::POSTCARD_MAX_SIZE < older);
    assert_eq!(Frame::POSTCARD_MAX_SIZE, 1 + older);
}

#[test]
fn names_are_checked() {
    assert!(ParamName::new("ABCDEFGHIJKLMNOP").is_some());
    assert!(ParamName::new("ABCDEFGHIJKLMNOPQ").is_none());
    assert!(ParamName::new("").is_none());
    assert!(ParamName::new("SWASH TYPE").is_none());
    assert!(ParamName::new("SWASH_TYPÉ").is_none());
    assert_eq!(ParamName::EMPTY.as_str(), Some(""));
    // Bytes from the wire that are not a name: a gap, or a non-ASCII byte.
    let mut gap = [0u8; 16];
    gap[0] = b'A';
    gap[2] = b'B';
    let name: ParamName = postcard::from_bytes(&gap).unwrap();
    assert_eq!(name.as_str(), None);
    let mut high = [0u8; 16];
    high[0] = 0xC3;
    let name: ParamName = postcard::from_bytes(&high).unwrap();
    assert_eq!(name.as_str(), None);
    assert_eq!(ParamRefusal::NotAChoice.name(), "not_a_choice");
    assert_eq!(ParamStoreStatus::FlashError.name(), "flash_error");
    assert_eq!(RefusedCheck::ParamsInvalid.name(), "params_invalid");
}

#[test]
fn protocol_1_6_appends_landed_and_not_airborne() {
    // AbortReason: Disarmed stays 8, Landed is 9.
    assert_eq!(postcard_bytes(&AbortReason::Disarmed), [8]);
    assert_eq!(postcard_bytes(&AbortReason::Landed), [9]);
    assert_eq!(AbortReason::Landed.name(), "landed");
    // RefusedCheck: NotLevel stays 8, NotAirborne is 9.
    assert_eq!(postcard_bytes(&RefusedCheck::NotLevel), [8]);
    assert_eq!(postcard_bytes(&RefusedCheck::NotAirborne), [9]);
    assert_eq!(RefusedCheck::NotAirborne.name(), "not_airborne");
}

#[test]
fn protocol_1_7_appends_the_selection_and_no_test_selected() {
    // 1.7 or later: later minor versions only append.
    const { assert!(PROTOCOL_VERSION.major == 1 && PROTOCOL_VERSION.minor >= 7) };
    assert_eq!(
        ProtocolVersion::BOARD_APPLICATION,
        ProtocolVersion { major: 1, minor: 7 }
    );
    assert_eq!(postcard_bytes(&RefusedCheck::NoTestSelected), [10]);
    assert_eq!(RefusedCheck::NoTestSelected.name(), "no_test_selected");

    // A Header without a selection is the 1.6 layout, byte for byte: the fields up to
    // `test`, nothing after them.
    let old = synthetic::header();
    assert_eq!(old.selection, None);
    let fields = (
        old.protocol,
        old.firmware,
        old.vehicle,
        old.rate_hz,
        old.test,
    );
    let mut tagged = vec![0u8]; // Frame::Header's variant
    tagged.extend(postcard_bytes(&fields));
    assert_eq!(postcard_bytes(&Frame::Header(old)), tagged);
    assert_eq!(round_trip(&Frame::Header(old)), Frame::Header(old));

    // With one, the entry and the count follow as an Option: tag 1, u8, varint u16.
    let new = Header {
        selection: Some(TestSelection {
            entry: 7,
            engagement: 300,
        }),
        ..old
    };
    let mut expected = tagged.clone();
    expected.extend([1, 7, 0xAC, 0x02]);
    assert_eq!(postcard_bytes(&Frame::Header(new)), expected);
    assert_eq!(round_trip(&Frame::Header(new)), Frame::Header(new));
    // The frame's largest size counts the selection.
    assert!(Header::POSTCARD_MAX_SIZE >= postcard_bytes(&new).len());
}

#[test]
fn protocol_1_7_appends_the_measurement_filter_frame() {
    use sweephold_protocol::{Frame, MeasurementFilter};
    // 1.7 or later: later minor versions only append.
    const { assert!(PROTOCOL_VERSION.major == 1 && PROTOCOL_VERSION.minor >= 7) };
    let filter = MeasurementFilter {
        sample_rate_hz: 1000.0,
        sections: [[1.0, 0.0, 0.0, 0.0, 0.0]; 4],
    };
    // ParamReply stays variant 8; MeasurementFilter is 9, its f32s little-endian.
    let bytes = postcard_bytes(&Frame::MeasurementFilter(filter));
    assert_eq!(bytes[0], 9);
    assert_eq!(&bytes[1..5], &1000.0f32.to_le_bytes());
    assert_eq!(bytes.len(), 1 + 4 + 4 * 5 * 4);
    // It does not raise the largest frame.
    assert!(bytes.len() + 4 + 2 <= sweephold_protocol::MAX_FRAME_LEN);
}

#[test]
fn protocol_1_8_appends_the_servo_test_frames() {
    use sweephold_protocol::{
        codec, Decoder, Frame, ServoTarget, ServoTest, ServoTestEnd, ServoTestReply,
        ServoTestStatus,
    };
    const { assert!(PROTOCOL_VERSION.major == 1 && PROTOCOL_VERSION.minor >= 8) };
    let request = Frame::ServoTest(ServoTest {
        servo: 2,
        target: ServoTarget::PulseUs(1600),
        hold_ms: 500,
    });
    // MeasurementFilter stays variant 9; ServoTest is 10, ServoTestReply 11.
    let bytes = postcard_bytes(&request);
    // Variant, servo, target variant 3 and 1600 as a varint (0xC0 0x0C), hold 500 (0xF4 0x03).
    assert_eq!(bytes, [10, 2, 3, 0xC0, 0x0C, 0xF4, 0x03]);
    let reply = Frame::ServoTestReply(ServoTestReply {
        servo: 2,
        pulse_us: 0,
        status: ServoTestStatus::Ended(ServoTestEnd::TimedOut),
    });
    assert_eq!(postcard_bytes(&reply), [11, 2, 0, 1, 1]);
    for frame in [request, reply] {
        let mut wire = [0u8; sweephold_protocol::MAX_FRAME_LEN];
        let n = codec::encode(&frame, &mut wire).unwrap();
        let decoded: Vec<_> = Decoder::new().feed(&wire[..n]).collect();
        assert_eq!(decoded, vec![Ok(frame)]);
    }
}
