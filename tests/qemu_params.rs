//! `sweephold fc params` against the board image in QEMU (protocol 1.5's parameter
//! frames on USART1): push then pull returns the same set, the board refuses unknown
//! names and out-of-range values, and while armed every request is refused and changes
//! nothing. Part of the `qemu` test (same image lookup and skipping rules).

use clap::Parser;
use sweephold::fc::client::{ParamBoard, ParamClient, ParamError};
use sweephold::fc::{params_file, push, FcWire};
use sweephold::fly::link_qemu::{self, QemuTransport};
use sweephold_firmware::params::ParamTable;
use sweephold_protocol::{
    Axis, Header, ParamName, ParamOp, ParamRefusal, ParamReply, ParamRequest, ParamStoreStatus,
    VehicleId,
};

use super::*;

/// A parameter client on a fresh QEMU running `image`, over its USART1.
fn client(image: &std::path::Path) -> ParamClient<FcWire> {
    let session = link_qemu::start_session(image, QemuTransport::Usart, &[]).expect("QEMU boots");
    ParamClient::new(session.map_wire(FcWire::Qemu))
}

/// Run `sweephold ARGS` in-process.
fn sweephold(args: &[&str]) -> Result<(), String> {
    let cli =
        sweephold::Cli::try_parse_from(std::iter::once("sweephold").chain(args.iter().copied()))
            .expect("a valid command line");
    sweephold::run(cli).map_err(|e| format!("{e:#}"))
}

/// The board's list starts at the TREX 700L's defaults (a fresh board: no stored set);
/// a pushed file, then a pull, give back exactly the file's values; a second push of
/// the pulled file changes nothing.
#[test]
fn qemu_params_push_then_pull_returns_the_same_set() {
    let Some(image) = image_or_skip("qemu_params_push_then_pull_returns_the_same_set") else {
        return;
    };
    let mut board = client(&image);
    let defaults = board.list().expect("the board lists its parameters");
    assert_eq!(defaults.len(), sweephold_firmware::params::COUNT);
    let expected = ParamTable::defaults(VehicleId::Trex700l);
    for (listed, held) in defaults.iter().zip(expected.values()) {
        assert_eq!(listed.value.to_bits(), held.to_bits(), "{}", listed.name);
    }

    let mut file = defaults.clone();
    let mut change = |name: &str, new: f32| {
        file.iter_mut().find(|v| v.name == name).expect(name).value = new;
    };
    change("SWASH_TYPE", 140.0);
    change("SWASH_PHASE", -12.5);
    change("SWASH_LEAD", 2.0);
    let text = params_file::write(
        &params_file::Source {
            fc: "qemu-usart".into(),
            image: None,
        },
        &file,
    );
    let file = params_file::parse(&text, "pushed").expect("a params file");
    let pushed = push::push(&mut board, &file).expect("the push");
    assert_eq!((pushed.changed, pushed.unchanged), (3, file.len() - 3));
    let pulled = board.list().expect("the board lists its parameters again");
    for entry in &file {
        let on_board = pulled
            .iter()
            .find(|v| v.name == entry.name)
            .expect("listed");
        assert_eq!(
            on_board.value.to_bits(),
            entry.value.to_bits(),
            "{}",
            entry.name
        );
    }
    let again = push::push(&mut board, &file).expect("the same push again");
    assert_eq!(again.changed, 0);

    // The command line end to end: pull writes the defaults of a fresh QEMU, diff against
    // the pushed set names the three changes.
    let scratch = Scratch::new("qemu-params-pull");
    let elf = image.display().to_string();
    let pulled_path = scratch.path().join("board.toml");
    let pulled_arg = pulled_path.display().to_string();
    sweephold(&[
        "fc",
        "params",
        "pull",
        &pulled_arg,
        "--fc",
        "qemu-usart",
        "--elf",
        &elf,
    ])
    .expect("pull");
    let pulled_text = std::fs::read_to_string(&pulled_path).unwrap();
    assert!(
        pulled_text.contains("[source]\nfc = \"qemu-usart\""),
        "{pulled_text}"
    );
    let from_cli = params_file::parse(&pulled_text, "pulled").unwrap();
    assert_eq!(from_cli.len(), defaults.len());
    for entry in &from_cli {
        let listed = defaults
            .iter()
            .find(|v| v.name == entry.name)
            .expect("listed");
        assert_eq!(
            listed.value.to_bits(),
            entry.value.to_bits(),
            "{}",
            entry.name
        );
    }
}

/// The board itself refuses an unknown name and an out-of-range value (asked directly,
/// past the host's own checks) and keeps its value; the command line refuses them too.
#[test]
fn qemu_params_unknown_name_and_out_of_range_value_are_refused() {
    let Some(image) = image_or_skip("qemu_params_unknown_name_and_out_of_range_value_are_refused")
    else {
        return;
    };
    let mut board = client(&image);
    let before = board.get("SWASH_PHASE").expect("get");
    let refusal = |result: Result<f32, ParamError>| match result {
        Err(ParamError::Refused { op, reason }) => (op, reason),
        other => panic!("expected a refusal, got {other:?}"),
    };
    assert_eq!(
        refusal(board.set("NO_SUCH", 1.0)),
        (ParamOp::Set, "unknown_name")
    );
    assert_eq!(
        refusal(board.set("SWASH_PHASE", 400.0)),
        (ParamOp::Set, "out_of_range")
    );
    assert_eq!(
        refusal(board.set("SWASH_TYPE", 121.0)),
        (ParamOp::Set, "not_a_choice")
    );
    assert_eq!(
        board.get("SWASH_PHASE").expect("get").to_bits(),
        before.to_bits()
    );
    // Save: QEMU's flash keeps nothing that is programmed, so the driver's read-back
    // refuses it (a reason, not a hang), and the board answers on.
    assert!(matches!(
        board.save(),
        Err(ParamError::Refused {
            op: ParamOp::Save,
            reason: "store_failed"
        })
    ));
    assert_eq!(
        board.get("SWASH_PHASE").expect("get").to_bits(),
        before.to_bits()
    );

    let elf = image.display().to_string();
    let error = sweephold(&[
        "fc",
        "params",
        "set",
        "SWASH_PHASE",
        "400",
        "--fc",
        "qemu-usart",
        "--elf",
        &elf,
    ])
    .expect_err("out of range");
    assert!(error.contains("outside the parameter's range"), "{error}");
    let error = sweephold(&[
        "fc",
        "params",
        "set",
        "NO_SUCH",
        "1",
        "--fc",
        "qemu-usart",
        "--elf",
        &elf,
    ])
    .expect_err("unknown");
    assert!(error.contains("unknown_name"), "{error}");
    let scratch = Scratch::new("qemu-params-unknown");
    let file = scratch.path().join("bad.toml");
    std::fs::write(&file, "[params]\nSWASH_TYPE = 140\nNO_SUCH = 3\n").unwrap();
    let error = sweephold(&[
        "fc",
        "params",
        "push",
        &file.display().to_string(),
        "--fc",
        "qemu-usart",
        "--elf",
        &elf,
    ])
    .expect_err("unknown name in the file");
    assert!(error.contains("nothing was written"), "{error}");
}

/// Armed (bench image, arm switch on over SBUS), every parameter request is refused as
/// armed — a List (a push's first step), a Set, a Reset — and disarmed again the board
/// holds what it held before.
#[test]
fn qemu_params_while_armed_a_push_changes_nothing() {
    let Some(image) = bench_image_or_skip("qemu_params_while_armed_a_push_changes_nothing") else {
        return;
    };
    let mut board = Board::boot_with_store(&image, Some(&default_store()));
    let mut rc = RcInput::NEUTRAL;
    wait_until_calibrated(&mut board, &rc);
    let replies = |board: &Board, from: usize| -> Vec<ParamReply> {
        board.frames[from..]
            .iter()
            .filter_map(|f| match f {
                Frame::ParamReply(reply) => Some(*reply),
                _ => None,
            })
            .collect()
    };
    let phase = ParamName::new("SWASH_PHASE").unwrap();
    let get_phase = |board: &mut Board, rc: &RcInput| {
        let from = board.frames.len();
        board.send(&Frame::ParamRequest(ParamRequest::Get { name: phase }));
        board.run(0.3, Some(rc));
        match replies(board, from).as_slice() {
            [ParamReply::Value { value, .. }] => *value,
            other => panic!("Get answered {other:?}"),
        }
    };
    let before = get_phase(&mut board, &rc);

    rc.arm = true;
    board.run(0.3, Some(&rc));
    let from = board.frames.len();
    for request in [
        ParamRequest::List,
        ParamRequest::Set {
            name: phase,
            value: before + 10.0,
        },
        ParamRequest::Reset,
    ] {
        board.send(&Frame::ParamRequest(request));
    }
    board.run(0.5, Some(&rc));
    let armed = replies(&board, from);
    assert_eq!(armed.len(), 3, "{armed:?}");
    assert!(
        armed.iter().all(|r| matches!(
            r,
            ParamReply::Refused {
                reason: ParamRefusal::Armed,
                ..
            }
        )),
        "{armed:?}"
    );

    rc.arm = false;
    board.run(0.3, Some(&rc));
    assert_eq!(get_phase(&mut board, &rc).to_bits(), before.to_bits());
    // Disarmed, the same Set is obeyed: the refusal above was the arming's.
    let from = board.frames.len();
    board.send(&Frame::ParamRequest(ParamRequest::Set {
        name: phase,
        value: before + 10.0,
    }));
    board.run(0.3, Some(&rc));
    assert!(
        matches!(replies(&board, from).as_slice(), [ParamReply::Value { value, .. }] if *value == before + 10.0),
        "{:?}",
        replies(&board, from)
    );
}

/// The status the board reported for its store at boot.
fn store_status(board: &Board) -> Option<ParamStoreStatus> {
    board.events().into_iter().find_map(|e| match e {
        Event::ParamStore { status, .. } => Some(status),
        _ => None,
    })
}

/// The mode changes the board reported.
fn mode_changes(board: &Board) -> Vec<(FlightMode, FlightMode)> {
    board
        .events()
        .into_iter()
        .filter_map(|e| match e {
            Event::ModeChange { from, to, .. } => Some((from, to)),
            _ => None,
        })
        .collect()
}

/// Flip the arm switch on (from off) and run 0.3 s.
fn flip_arm(board: &mut Board, rc: &mut RcInput) {
    rc.arm = false;
    board.run(0.3, Some(rc));
    rc.arm = true;
    board.run(0.3, Some(rc));
}

/// A corrupt store (its sectors hold bytes that are no store: pseudo-random, as a
/// region another program wrote) boots the defaults, says so, and arming is refused
/// naming the parameters; so is a fresh QEMU flash (zero-filled).
#[test]
fn qemu_params_a_corrupt_store_boots_the_defaults_and_refuses_to_arm() {
    let Some(image) =
        bench_image_or_skip("qemu_params_a_corrupt_store_boots_the_defaults_and_refuses_to_arm")
    else {
        return;
    };
    let garbage: Vec<u8> = (0..STORE_REGION.len() as u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    for store in [Some(garbage.as_slice()), None] {
        let mut board = Board::boot_with_store(&image, store);
        let mut rc = RcInput::NEUTRAL;
        wait_until_calibrated(&mut board, &rc);
        assert_eq!(store_status(&board), Some(ParamStoreStatus::Corrupt));
        flip_arm(&mut board, &mut rc);
        let refusals: Vec<RefusedCheck> = board
            .events()
            .into_iter()
            .filter_map(|e| match e {
                Event::Refused {
                    request: Request::Arm,
                    check,
                    ..
                } => Some(check),
                _ => None,
            })
            .collect();
        assert_eq!(refusals, [RefusedCheck::ParamsInvalid]);
        assert_eq!(mode_changes(&board), []);
        // The defaults are in use.
        let mut client = BoardParams(&mut board);
        let expected = ParamTable::defaults(VehicleId::Trex700l);
        assert_eq!(
            client.get("SWASH_PHASE").to_bits(),
            expected.get_by_name("SWASH_PHASE").unwrap().to_bits()
        );
    }
}

/// A valid store made on the host by the firmware library's own `ParamStore` (over a
/// RAM flash with the F405's word and sector sizes), holding a non-default swash phase
/// and tail centre, is loaded at boot (the values read back) and the board arms.
#[test]
fn qemu_params_a_stored_set_is_flown_and_the_board_arms() {
    let Some(image) = bench_image_or_skip("qemu_params_a_stored_set_is_flown_and_the_board_arms")
    else {
        return;
    };
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    table.set_by_name("SWASH_PHASE", -12.5).unwrap();
    table.set_by_name("SERVO_RATE", 200.0).unwrap();
    let mut board = Board::boot_with_store(&image, Some(&saved_store(&table)));
    let mut rc = RcInput::NEUTRAL;
    wait_until_calibrated(&mut board, &rc);
    assert_eq!(store_status(&board), Some(ParamStoreStatus::Loaded));
    {
        let mut client = BoardParams(&mut board);
        assert_eq!(client.get("SWASH_PHASE"), -12.5);
        assert_eq!(client.get("SERVO_RATE"), 200.0);
    }
    flip_arm(&mut board, &mut rc);
    assert_eq!(
        mode_changes(&board),
        [(FlightMode::Disarmed, FlightMode::Pilot)]
    );
}

/// Parameter requests on a [`Board`] (whose link the test reads itself).
struct BoardParams<'a>(&'a mut Board);

impl BoardParams<'_> {
    /// The value of `name` (a Get answered within 0.3 s).
    fn get(&mut self, name: &str) -> f32 {
        let board = &mut *self.0;
        let from = board.frames.len();
        board.send(&Frame::ParamRequest(ParamRequest::Get {
            name: ParamName::new(name).unwrap(),
        }));
        board.run(0.3, Some(&RcInput::NEUTRAL));
        let replies: Vec<ParamReply> = board.frames[from..]
            .iter()
            .filter_map(|f| match f {
                Frame::ParamReply(reply) => Some(*reply),
                _ => None,
            })
            .collect();
        match replies.as_slice() {
            [ParamReply::Value { value, .. }] => *value,
            other => panic!("Get {name} answered {other:?}"),
        }
    }
}

/// One image for every aircraft: on the ground a Set is flown from the next control
/// tick. FRAME 1 and TEST_AXIS 1 make the board application a Bo-105 flying a
/// longitudinal test, announced by its new Header; a set the typed view refuses as a
/// whole is not flown (no Header) until it is whole again.
#[test]
fn qemu_params_a_set_on_the_ground_is_flown_from_the_next_tick() {
    let Some(image) = image_or_skip("qemu_params_a_set_on_the_ground_is_flown_from_the_next_tick")
    else {
        return;
    };
    let mut board = Board::boot(&image);
    board.run(0.5, None);
    let headers = |board: &Board, from: usize| -> Vec<Header> {
        board.frames[from..]
            .iter()
            .filter_map(|f| match f {
                Frame::Header(header) => Some(*header),
                _ => None,
            })
            .collect()
    };
    let boot = headers(&board, 0);
    assert_eq!(boot.len(), 1, "{boot:?}");
    assert_eq!(boot[0].vehicle, VehicleId::Trex700l);
    assert_eq!(boot[0].test.primary, Axis::Lat);
    let set = |board: &mut Board, name: &str, value: f32| {
        board.send(&Frame::ParamRequest(ParamRequest::Set {
            name: ParamName::new(name).unwrap(),
            value,
        }));
        board.run(0.3, None);
    };
    let from = board.frames.len();
    set(&mut board, "FRAME", 1.0);
    let after_frame = headers(&board, from);
    assert_eq!(after_frame.len(), 1, "{after_frame:?}");
    assert_eq!(after_frame[0].vehicle, VehicleId::Bo105);
    let from = board.frames.len();
    set(&mut board, "TEST_AXIS", 1.0);
    let after_axis = headers(&board, from);
    assert_eq!(after_axis.len(), 1, "{after_axis:?}");
    assert_eq!(
        (after_axis[0].vehicle, after_axis[0].test.primary),
        (VehicleId::Bo105, Axis::Lon)
    );
    // Servo 1's lowest pulse above its centre: accepted by the table, refused by the
    // typed view, so nothing is flown until the centre follows.
    let from = board.frames.len();
    set(&mut board, "SERVO1_MIN", 1600.0);
    assert_eq!(headers(&board, from), []);
    set(&mut board, "SERVO1_MID", 1700.0);
    set(&mut board, "SERVO1_MAX", 1900.0);
    assert!(!headers(&board, from).is_empty());
}
