//! The bench tools against the board image in QEMU: `sweephold fc watch` (the live view
//! of the telemetry) and `sweephold fc servo` (a servo moved while disarmed, refused
//! armed, back to centre when the link goes quiet). Part of the `qemu` test (same image
//! lookup and skipping rules).

use clap::Parser;
use sweephold::fc::client::ParamClient;
use sweephold::fc::watch::{self, Limits, Watcher};
use sweephold::fc::{board_mixer, FcWire};

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
