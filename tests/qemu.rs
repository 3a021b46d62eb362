//! `sweephold fly --fc qemu`: the board image in QEMU flies the same record as the
//! firmware library in-process, byte for byte, and its defmt log comes back decoded.
//!
//! Needs `qemu-system-arm` and the image (`cargo fw`; or the path in `SWEEPHOLD_FC_ELF`),
//! built after the last change to `firmware/src`, `firmware/board/src` and `shared/src`.
//! Without them the test prints why and passes, so `cargo test --workspace` stays green on
//! machines without QEMU — unless `SWEEPHOLD_REQUIRE_QEMU=1` (CI) turns that into a failure.
//!
//! Why the bytes can be equal at all: the flight logic is the same source compiled for
//! x86-64 and for thumbv7em-none-eabihf; both do IEEE-754 single precision with
//! round-to-nearest for + − × ÷ and √ (Rust never fuses a multiply-add on its own), and
//! every transcendental function comes from the same pure-Rust `libm`, so every Sample
//! value is computed by the same sequence of correctly rounded operations.

use std::path::PathBuf;

use sweephold::fly::link_qemu::{self, QemuLink, QemuTransport};
use sweephold_protocol::{Decoder, Frame};
use sweephold_tests::{fly, fly_args, Scratch};

/// The image and QEMU, or why the test cannot run here.
fn qemu_and_image() -> Result<PathBuf, String> {
    link_qemu::qemu_available().map_err(|e| e.to_string())?;
    match std::env::var_os("SWEEPHOLD_FC_ELF") {
        Some(path) => {
            let path = PathBuf::from(path);
            if path.is_file() {
                Ok(path)
            } else {
                Err(format!("SWEEPHOLD_FC_ELF={} is not a file", path.display()))
            }
        }
        None => link_qemu::default_image().map_err(|e| e.to_string()),
    }
    .and_then(|image| {
        // An image built before the flight logic or the protocol last changed cannot be
        // expected to match (or to speak protocol 1.1): say so instead of failing on it.
        let built = modified(&image).ok_or_else(|| format!("cannot stat {}", image.display()))?;
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let newest = ["firmware/src", "firmware/board/src", "shared/src"]
            .iter()
            .filter_map(|dir| newest_in(&root.join(dir)))
            .max();
        match newest {
            Some(source) if source > built => Err(format!(
                "{} is older than the firmware or protocol sources: rebuild it with `cargo fw`",
                image.display()
            )),
            _ => Ok(image),
        }
    })
}

fn modified(path: &std::path::Path) -> Option<std::time::SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

/// The newest modification time of the files under `dir`.
fn newest_in(dir: &std::path::Path) -> Option<std::time::SystemTime> {
    let mut newest = None;
    for entry in std::fs::read_dir(dir).ok()?.flatten() {
        let path = entry.path();
        let time = if path.is_dir() {
            newest_in(&path)
        } else {
            modified(&path)
        };
        newest = newest.max(time);
    }
    newest
}

fn frames(bytes: &[u8]) -> Vec<Frame> {
    let mut decoder = Decoder::new();
    let frames: Vec<Frame> = decoder
        .feed(bytes)
        .map(|f| f.expect("a clean dump"))
        .collect();
    assert_eq!(decoder.finish(), None, "the dump ends on a frame boundary");
    frames
}

/// The image, or `None` (after printing why) when the test cannot run here.
fn image_or_skip(test: &str) -> Option<PathBuf> {
    match qemu_and_image() {
        Ok(image) => Some(image),
        Err(why) => {
            assert!(
                std::env::var_os("SWEEPHOLD_REQUIRE_QEMU").is_none(),
                "SWEEPHOLD_REQUIRE_QEMU is set but {test} cannot run: {why}"
            );
            eprintln!("SKIPPED {test}: {why}");
            None
        }
    }
}

/// The 10 s lateral sweep campaign (two records, 0.2–31.4 and 0.01–18.85 rad/s) over
/// semihosting, the transport `--fc qemu` uses.
#[test]
fn qemu_flies_the_same_bytes_as_in_process() {
    let Some(image) = image_or_skip("qemu_flies_the_same_bytes_as_in_process") else {
        return;
    };
    compare(
        &image,
        QemuTransport::Semihosting,
        &["--axes", "lat", "--t-rec", "10", "--seed", "5"],
    );
}

/// A lateral doublet (7 s of flight) over the emulated USART, the transport of the
/// board (`--fc qemu-usart`, ~200 ticks/s, hence the short record).
#[test]
fn qemu_over_the_usart_flies_the_same_bytes_as_in_process() {
    let Some(image) = image_or_skip("qemu_over_the_usart_flies_the_same_bytes_as_in_process")
    else {
        return;
    };
    compare(
        &image,
        QemuTransport::Usart,
        &["--axes", "lat", "--input", "doublet", "--seed", "6"],
    );
}

/// Fly `campaign` in QEMU over `transport` and in-process; every dump must be the same.
fn compare(image: &std::path::Path, transport: QemuTransport, campaign: &[&str]) {
    let name = transport.link_name();
    let (qemu_dir, local_dir) = (
        Scratch::new(&format!("{name}-q")),
        Scratch::new(&format!("{name}-p")),
    );
    let args = |dir: &Scratch, fc: &str| {
        let mut all = campaign.to_vec();
        all.extend(["--fc", fc, "--out", dir.path().to_str().unwrap()]);
        fly_args(&all)
    };
    let started = std::time::Instant::now();
    let flown = sweephold::fly::fly(&args(&qemu_dir, name), &|| {
        Box::new(QemuLink::new(image, transport, &[]).with_log_folder(qemu_dir.path()))
    })
    .expect("the campaign flies in QEMU");
    let wall_s = started.elapsed().as_secs_f64();
    let reference = fly(&args(&local_dir, "in-process"));
    assert_eq!(flown.summary.link, name);
    assert_eq!(reference.summary.link, "in-process");
    assert_eq!(flown.dumps.len(), reference.dumps.len());

    let mut ticks = 0.0;
    for (run, local) in flown.summary.runs.iter().zip(&reference.summary.runs) {
        assert!(!run.aborted, "{}: aborted in QEMU", run.file);
        assert_eq!(run.duration_s, local.duration_s, "{}", run.file);
        ticks += run.duration_s * f64::from(flown.summary.rate_hz);
    }
    for (dump, local) in flown.dumps.iter().zip(&reference.dumps) {
        let (bytes, local_bytes) = (std::fs::read(dump).unwrap(), std::fs::read(local).unwrap());
        let (frames, local_frames) = (frames(&bytes), frames(&local_bytes));
        let samples = frames
            .iter()
            .filter(|f| matches!(f, Frame::Sample(_)))
            .count();
        assert!(samples >= 1000, "{}: {samples} Samples", dump.display());
        assert_eq!(frames.len(), local_frames.len(), "{}", dump.display());
        for (i, (a, b)) in frames.iter().zip(&local_frames).enumerate() {
            assert_eq!(a, b, "{}: frame {i} differs", dump.display());
        }
        assert!(
            bytes == local_bytes,
            "{}: same frames, different bytes",
            dump.display()
        );
    }
    eprintln!(
        "{name}: {ticks:.0} ticks in {wall_s:.1} s ({:.0} ticks/s over all workers); \
         every dump byte-identical to the in-process one",
        ticks / wall_s
    );
    if transport == QemuTransport::Semihosting {
        check_logs(&flown.dumps);
    }
}

/// Over semihosting every record has its decoded defmt log beside its dump: the
/// Configure that set it up, each phase of the sequencer from arming to Done and the
/// hold engaging and releasing, each line stamped with the loop tick and the level.
fn check_logs(dumps: &[PathBuf]) {
    for dump in dumps {
        let path = dump.with_extension("log");
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: no log ({e})", path.display()));
        for expected in [
            "INFO  configured by the host: bo105, 200 Hz",
            "phase Idle -> Armed",
            "phase Armed -> TrimCapture",
            "trim captured",
            "phase TrimCapture -> FadeIn",
            "phase FadeIn -> Sweep",
            "phase Sweep -> FadeOut",
            "phase FadeOut -> Done",
            // Conditional attitude hold at work (deterministic: lockstep, fixed seed).
            "DEBUG tick ",
            "hold engaged on",
            "hold released on",
        ] {
            assert!(
                text.lines().any(|line| line.contains(expected)),
                "{}: no line with {expected:?} in\n{text}",
                path.display()
            );
        }
        assert!(!text.contains("malformed"), "{}:\n{text}", path.display());
        // The time stamp is the tick of the Sample the line belongs to.
        let done = text
            .lines()
            .find(|line| line.contains("-> Done"))
            .unwrap_or_default();
        let stamp: u32 = done
            .split_whitespace()
            .next()
            .unwrap_or("")
            .parse()
            .unwrap();
        assert!(done.contains(&format!("tick {stamp}:")), "{done}");
    }
}

/// An aborted record's log says why: the pilot moves the stick during the sweep.
#[test]
fn qemu_logs_an_abort() {
    let Some(image) = image_or_skip("qemu_logs_an_abort") else {
        return;
    };
    let dir = Scratch::new("qemu-abort");
    let args = fly_args(&[
        "--axes",
        "lat",
        "--t-rec",
        "10",
        "--seed",
        "7",
        "--pilot-override",
        "8",
        "--fc",
        "qemu",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let flown = sweephold::fly::fly(&args, &|| {
        Box::new(QemuLink::new(&image, QemuTransport::Semihosting, &[]).with_log_folder(dir.path()))
    })
    .expect("the campaign flies in QEMU");
    assert!(
        flown.summary.runs.iter().all(|run| run.aborted),
        "both records abort"
    );
    for dump in &flown.dumps {
        let path = dump.with_extension("log");
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.lines()
                .any(|line| line.contains("WARN") && line.contains("abort: PilotOverride")),
            "{}: no abort line in\n{text}",
            path.display()
        );
        assert!(text.contains("-> Aborted"), "{}:\n{text}", path.display());
    }
}

/// A configuration the flight logic refuses is refused by the image too, named by the
/// host, and the link flies the next, valid one.
#[test]
fn qemu_refuses_a_bad_configuration_and_keeps_flying() {
    let Some(image) = image_or_skip("qemu_refuses_a_bad_configuration_and_keeps_flying") else {
        return;
    };
    use sweephold::fly::link::FlightControllerLink;
    use sweephold::fly::VehicleArg;
    use sweephold_protocol::{Axis, SensorIn};

    let logs = Scratch::new("qemu-refusal");
    let mut link =
        QemuLink::new(&image, QemuTransport::Semihosting, &[]).with_log_folder(logs.path());
    let mut bad = VehicleArg::Bo105.firmware_config(Axis::Ped);
    bad.rate_hz = 20;
    let error = link.begin_record(&bad).expect_err("rate 20 Hz is refused");
    let text = error.to_string();
    assert!(
        text.contains("refused") && text.contains("tick rate outside 50-1000 Hz"),
        "{text}"
    );
    link.begin_record(&VehicleArg::Bo105.firmware_config(Axis::Ped))
        .expect("a valid configuration is accepted after a refusal");
    let mut telemetry = Vec::new();
    let input = SensorIn {
        seq: 41,
        ..SensorIn::default()
    };
    let out = link.exchange(&input, &mut telemetry).expect("one tick");
    assert_eq!((out.seq, out.tick), (41, 0), "answers seq 41 at tick 0");
    let frames = frames(&telemetry);
    assert!(
        matches!(frames.as_slice(), [Frame::Sample(sample)] if sample.tick == 0),
        "the first tick's telemetry is its Sample alone: {frames:?}"
    );
    link.end_record("ped-1.bin").expect("the log is written");
    let log = std::fs::read_to_string(logs.path().join("ped-1.log")).unwrap();
    for expected in [
        "WARN  configuration refused: tick rate outside 50-1000 Hz",
        "INFO  configured by the host: bo105, 200 Hz",
    ] {
        assert!(log.contains(expected), "no {expected:?} in\n{log}");
    }
}

/// The onboard log: standalone, the image sends the same frames to the logger's UART
/// (USART3, the third `-serial`) as to the host link (USART1), and the logger's file
/// decodes as a dump does.
#[test]
fn qemu_log_uart_carries_the_same_frames_as_the_link() {
    let Some(image) = image_or_skip("qemu_log_uart_carries_the_same_frames_as_the_link") else {
        return;
    };
    let dir = Scratch::new("qemu-log-uart");
    let (link, log) = (dir.path().join("usart1.bin"), dir.path().join("usart3.bin"));
    let mut qemu = std::process::Command::new("qemu-system-arm")
        .args([
            "-M",
            "netduinoplus2",
            "-nographic",
            "-monitor",
            "none",
            "-kernel",
        ])
        .arg(&image)
        .arg("-serial")
        .arg(format!("file:{}", link.display()))
        .args(["-serial", "null", "-serial"])
        .arg(format!("file:{}", log.display()))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("qemu-system-arm starts");
    std::thread::sleep(std::time::Duration::from_secs(2));
    qemu.kill().expect("QEMU stops");
    qemu.wait().expect("QEMU is reaped");
    let decode = |path: &std::path::Path| -> Vec<Frame> {
        let bytes = std::fs::read(path).unwrap();
        // The kill may cut the last frame: decode whole frames only.
        let end = bytes.iter().rposition(|&b| b == 0).map_or(0, |i| i + 1);
        frames(&bytes[..end])
    };
    let (link_frames, log_frames) = (decode(&link), decode(&log));
    assert!(
        matches!(log_frames.first(), Some(Frame::Header(_))),
        "the log starts with the boot Header: {:?}",
        log_frames.first()
    );
    let samples = log_frames
        .iter()
        .filter(|f| matches!(f, Frame::Sample(_)))
        .count();
    assert!(samples >= 20, "{samples} Samples in the log");
    let common = link_frames.len().min(log_frames.len());
    assert!(common + 2 >= link_frames.len().max(log_frames.len()));
    assert_eq!(link_frames[..common], log_frames[..common]);
}
