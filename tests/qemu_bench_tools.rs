//! The bench tools against the board image in QEMU: `sweephold fc watch` (the live view
//! of the telemetry) and `sweephold fc servo` (a servo moved while disarmed, refused
//! armed, back to centre when the link goes quiet). Part of the `qemu` test (same image
//! lookup and skipping rules).

use clap::Parser;
use sweephold::fc::client::ParamClient;
use sweephold::fc::watch::{self, Limits, Watcher};
use sweephold::fc::{board_mixer, FcWire};

use sweephold_protocol::{
    ServoTarget, ServoTest, ServoTestEnd, ServoTestRefusal, ServoTestReply, ServoTestStatus,
};

use super::*;

/// A fresh QEMU running `image`, its USART1 as a parameter client.
fn client(image: &std::path::Path) -> ParamClient<FcWire> {
    let session = link_qemu::start_session(image, QemuTransport::Usart, &[]).expect("QEMU boots");
    ParamClient::new(session.map_wire(FcWire::Qemu))
}

/// The status lines of `text` (those starting with the board time).
fn status_lines(text: &str) -> Vec<&str> {
    text.lines().filter(|l| l.starts_with("t ")).collect()
}

/// The board time of a status line \[s\].
fn board_time(line: &str) -> f64 {
    line.split_whitespace()
        .nth(1)
        .and_then(|t| t.parse().ok())
        .expect("a time")
}

/// `fc watch` on a fresh image: the events of its boot (the IMU missing, the store not
/// valid) from the telemetry read during the parameter List, then exactly `--count`
/// status lines `--every` board seconds apart, disarmed and idle, with the servo pulses
/// of the board's default mixer (every servo at its 1520 µs centre).
#[test]
fn qemu_fc_watch_shows_the_disarmed_board() {
    let Some(image) = image_or_skip("qemu_fc_watch_shows_the_disarmed_board") else {
        return;
    };
    let mut board = client(&image);
    let mixer = board_mixer(&mut board).expect("the disarmed board lists its parameters");
    let (mut channel, passed) = board.into_channel();
    let mut watcher = Watcher::new(0.1, Some(mixer));
    let mut text = Vec::new();
    watch::replay(&passed, &mut watcher, &mut text).unwrap();
    let limits = Limits {
        count: Some(5),
        seconds: None,
    };
    let lines =
        watch::watch(&mut channel, &mut watcher, limits, &mut text, || false).expect("the watch");
    assert_eq!(lines, 5);
    let text = String::from_utf8(text).unwrap();
    assert!(text.contains("event tick 0: IMU missing"), "{text}");
    assert!(text.contains("parameter store corrupt"), "{text}");
    let status = status_lines(&text);
    assert_eq!(status.len(), 5, "{text}");
    for line in &status {
        assert!(line.contains("disarmed disarmed"), "{line}");
        assert!(line.contains("phase idle"), "{line}");
        assert!(line.contains("servos 1520 1520 1520 1520 us"), "{line}");
    }
    for pair in status.windows(2) {
        let step = board_time(pair[1]) - board_time(pair[0]);
        assert!((step - 0.1).abs() < 1e-6, "{pair:?}");
    }

    // The command line ends by itself on --count and on --seconds.
    let elf = image.display().to_string();
    for limit in [["--count", "2"], ["--seconds", "1"]] {
        let args = [
            "fc",
            "watch",
            "--fc",
            "qemu-usart",
            "--elf",
            &elf,
            limit[0],
            limit[1],
        ];
        let cli = sweephold::Cli::try_parse_from(std::iter::once("sweephold").chain(args))
            .expect("a valid command line");
        sweephold::run(cli).expect("fc watch ends by itself");
    }
}

/// The watcher on an armed board's telemetry (the bench image armed over SBUS): the
/// mode change is an event line and the status lines say armed, pilot.
#[test]
fn qemu_fc_watch_follows_the_board_armed() {
    let Some(image) = bench_image_or_skip("qemu_fc_watch_follows_the_board_armed") else {
        return;
    };
    let mut board = Board::boot_with_store(&image, Some(&default_store()));
    let mut rc = RcInput::NEUTRAL;
    wait_until_calibrated(&mut board, &rc);
    rc.arm = true;
    board.run(0.5, Some(&rc));
    let mut watcher = Watcher::new(0.1, None);
    let mut lines = Vec::new();
    for frame in &board.frames {
        lines.extend(watcher.feed(frame).0);
    }
    let text = lines.join("\n");
    assert!(text.contains("mode disarmed -> pilot"), "{text}");
    let last = status_lines(&text).last().copied().expect("status lines");
    assert!(last.contains("armed pilot"), "{last}");
    assert!(last.contains("servos ? (parameters not read)"), "{last}");
    let calibrated = status_lines(&text)
        .iter()
        .position(|l| l.contains("armed pilot"))
        .expect("armed");
    assert!(calibrated > 0, "disarmed lines before the arming: {text}");
}

/// The servo test replies the board sent from frame `from` on.
fn servo_replies(board: &Board, from: usize) -> Vec<ServoTestReply> {
    board.frames[from..]
        .iter()
        .filter_map(|f| match f {
            Frame::ServoTestReply(reply) => Some(*reply),
            _ => None,
        })
        .collect()
}

/// Run `board` (on `rc`) until `count` servo test replies arrived from frame `from` on,
/// at most 10 s (QEMU takes a host frame in slowly when the machine is loaded).
fn run_for_replies(board: &mut Board, from: usize, count: usize, rc: Option<&RcInput>) {
    for _ in 0..50 {
        if servo_replies(board, from).len() >= count {
            return;
        }
        board.run(0.2, rc);
    }
}

/// A byte wire on the test board's link socket, for the host's own servo client.
struct LinkWire<'a>(&'a mut std::net::TcpStream);

impl sweephold::fly::frame_channel::ByteWire for LinkWire<'_> {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        use std::io::Write;
        self.0.write_all(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: std::time::Duration) -> std::io::Result<usize> {
        use std::io::Read;
        self.0
            .set_read_timeout(Some(timeout.max(std::time::Duration::from_millis(1))))?;
        self.0.read(buf)
    }

    fn failure(&mut self, what: &str) -> anyhow::Error {
        anyhow::anyhow!("{what}")
    }
}

/// Disarmed with a valid parameter set (the image, no IMU under QEMU: the servo test
/// does not need one), a servo test is accepted: the pulse the board applies is the
/// target within the servo's limits; a single request with a 500 ms hold times out
/// after 100 control ticks (200 Hz) without another request; the host's client holds a
/// servo over 1 s of repeated requests and stops it. A fresh board (no valid set)
/// refuses, and so does the command line.
#[test]
fn qemu_fc_servo_is_accepted_disarmed_and_times_out() {
    let Some(image) = image_or_skip("qemu_fc_servo_is_accepted_disarmed_and_times_out") else {
        return;
    };
    let mut board = Board::boot_with_store(&image, Some(&default_store()));
    board.run(0.5, None);
    let from = board.frames.len();
    board.send(&Frame::ServoTest(ServoTest {
        servo: 2,
        target: ServoTarget::PulseUs(1600),
        hold_ms: 500,
    }));
    run_for_replies(&mut board, from, 2, None);
    let after = &board.frames[from..];
    let moving = after
        .iter()
        .position(|f| matches!(f, Frame::ServoTestReply(r) if r.status == ServoTestStatus::Moving))
        .expect("the request is answered");
    let ended = after
        .iter()
        .position(|f| {
            matches!(f, Frame::ServoTestReply(r)
            if r.status == ServoTestStatus::Ended(ServoTestEnd::TimedOut))
        })
        .expect("the servo test times out");
    let replies = servo_replies(&board, from);
    assert_eq!(replies.len(), 2, "{replies:?}");
    assert_eq!((replies[0].servo, replies[0].pulse_us), (2, 1600));
    assert_eq!(replies[1].servo, 2);
    let ticks_held = after[moving..ended]
        .iter()
        .filter(|f| matches!(f, Frame::Sample(_)))
        .count();
    // The hold is counted in control ticks: 500 ms at 200 Hz.
    assert!((100..=101).contains(&ticks_held), "{ticks_held} ticks");

    // Beyond the servo's limits: clamped to its maximum (TREX 700L defaults).
    let from = board.frames.len();
    board.send(&Frame::ServoTest(ServoTest {
        servo: 4,
        target: ServoTarget::PulseUs(2500),
        hold_ms: 100,
    }));
    run_for_replies(&mut board, from, 1, None);
    let defaults =
        sweephold_firmware::params::ParamTable::defaults(sweephold_protocol::VehicleId::Trex700l);
    let tail_max = defaults.get_by_name("TAIL_MAX").expect("TAIL_MAX") as u16;
    let replies = servo_replies(&board, from);
    assert_eq!(replies[0].pulse_us, tail_max, "{replies:?}");

    // The host's client over the same link: held for 1 s, then stopped.
    let held = {
        let mut channel =
            sweephold::fly::frame_channel::FrameChannel::new(LinkWire(&mut board.link));
        sweephold::fc::servo::hold_servo(
            &mut channel,
            1,
            ServoTarget::Max,
            std::time::Duration::from_secs(1),
        )
        .expect("the servo test")
    };
    let servo1_max = defaults.get_by_name("SERVO1_MAX").expect("SERVO1_MAX") as u16;
    assert_eq!(held.pulse_us, servo1_max);
    assert!(held.requests >= 5, "{held:?}");

    // A fresh board has no valid set: refused, by the board and on the command line.
    let mut fresh = Board::boot(&image);
    fresh.run(0.3, None);
    fresh.send(&Frame::ServoTest(ServoTest {
        servo: 1,
        target: ServoTarget::Centre,
        hold_ms: 100,
    }));
    run_for_replies(&mut fresh, 0, 1, None);
    assert_eq!(
        servo_replies(&fresh, 0)
            .iter()
            .map(|r| r.status)
            .collect::<Vec<_>>(),
        [ServoTestStatus::Refused(ServoTestRefusal::ParamsInvalid)]
    );
    let elf = image.display().to_string();
    let args = [
        "fc",
        "servo",
        "2",
        "1600us",
        "--hold",
        "0.3s",
        "--fc",
        "qemu-usart",
        "--elf",
        &elf,
    ];
    let cli = sweephold::Cli::try_parse_from(std::iter::once("sweephold").chain(args))
        .expect("a valid command line");
    let error = format!("{:#}", sweephold::run(cli).expect_err("refused"));
    assert!(
        error.contains("refused the servo test: params_invalid"),
        "{error}"
    );
}

/// Armed (bench image, arm switch on over SBUS), a servo test is refused; a test running
/// when the board arms ends on that tick (`armed`), and disarmed again a request is
/// accepted.
#[test]
fn qemu_fc_servo_is_refused_armed() {
    let Some(image) = bench_image_or_skip("qemu_fc_servo_is_refused_armed") else {
        return;
    };
    let mut board = Board::boot_with_store(&image, Some(&default_store()));
    let mut rc = RcInput::NEUTRAL;
    wait_until_calibrated(&mut board, &rc);
    let request = Frame::ServoTest(ServoTest {
        servo: 1,
        target: ServoTarget::Max,
        hold_ms: 2000,
    });
    let from = board.frames.len();
    board.send(&request);
    run_for_replies(&mut board, from, 1, Some(&rc));
    rc.arm = true;
    run_for_replies(&mut board, from, 2, Some(&rc));
    board.send(&request);
    run_for_replies(&mut board, from, 3, Some(&rc));
    let statuses: Vec<ServoTestStatus> = servo_replies(&board, from)
        .iter()
        .map(|r| r.status)
        .collect();
    assert_eq!(
        statuses,
        [
            ServoTestStatus::Moving,
            ServoTestStatus::Ended(ServoTestEnd::Armed),
            ServoTestStatus::Refused(ServoTestRefusal::Armed)
        ]
    );
    rc.arm = false;
    board.run(0.3, Some(&rc));
    let from = board.frames.len();
    board.send(&request);
    run_for_replies(&mut board, from, 1, Some(&rc));
    assert_eq!(
        servo_replies(&board, from)
            .iter()
            .map(|r| r.status)
            .collect::<Vec<_>>(),
        [ServoTestStatus::Moving]
    );
}
