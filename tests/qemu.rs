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
use sweephold_firmware::receiver::{sbus, ChannelMap, RcInput};
use sweephold_protocol::{
    Controls, Decoder, Event, FlightMode, Frame, HostFrame, ImuHealth, Phase, ProtocolVersion,
    RefusedCheck, Request, Sample, SensorIn,
};
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
/// `qemu-system-arm` on the netduinoplus2 machine (an STM32F405) booting `image`, no
/// display or monitor; the caller adds the serial ports.
fn netduinoplus2(image: &std::path::Path) -> std::process::Command {
    let mut command = std::process::Command::new("qemu-system-arm");
    command
        .args([
            "-M",
            "netduinoplus2",
            "-nographic",
            "-monitor",
            "none",
            "-kernel",
        ])
        .arg(image);
    command
}

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
    use sweephold::vehicle::Vehicle;
    use sweephold_protocol::{Axis, SensorIn};

    let logs = Scratch::new("qemu-refusal");
    let mut link =
        QemuLink::new(&image, QemuTransport::Semihosting, &[]).with_log_folder(logs.path());
    let mut bad = Vehicle::shipped("bo105").firmware_config(Axis::Ped);
    bad.rate_hz = 20;
    let error = link.begin_record(&bad).expect_err("rate 20 Hz is refused");
    let text = error.to_string();
    assert!(
        text.contains("refused") && text.contains("tick rate outside 50-1000 Hz"),
        "{text}"
    );
    link.begin_record(&Vehicle::shipped("bo105").firmware_config(Axis::Ped))
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
    let mut qemu = netduinoplus2(&image)
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

/// The board image on its own in QEMU: USART1 (the host link) on a TCP connection the
/// test accepts, USART2 (the SBUS receiver) on a second one, USART3 (the log) nowhere.
struct Board {
    qemu: std::process::Child,
    link: std::net::TcpStream,
    sbus: std::net::TcpStream,
    decoder: Decoder,
    /// Every frame read from the link so far.
    frames: Vec<Frame>,
    /// Holds the preloaded store file while QEMU runs.
    _store: Option<Scratch>,
}

/// The parameter store's sectors (`memory.x`, `firmware/board/src/chip/flash.rs`):
/// sectors 10 and 11 of the STM32F405, 128 KiB each, from 0x080C_0000 to the end of
/// its 1 MiB flash; offsets into the flash as the board's driver counts them.
const STORE_REGION: std::ops::Range<u32> = 0xC_0000..0x10_0000;
/// Where the flash is mapped.
const FLASH_BASE: u32 = 0x0800_0000;
/// The F405 driver's write unit (a 32-bit word) and erase unit (a 128 KiB sector).
const FLASH_WORD: usize = 4;
const FLASH_SECTOR: usize = 128 * 1024;

/// The store sectors after the firmware library's own `ParamStore` saved `table` into
/// them (over a RAM flash with the F405 driver's word and sector sizes).
fn saved_store(table: &sweephold_firmware::params::ParamTable) -> Vec<u8> {
    sweephold_firmware::params::ram_flash::saved_region::<FLASH_WORD, FLASH_SECTOR>(
        table,
        STORE_REGION,
    )
    .expect("the store saves into a RAM flash")
}

/// The store holding the TREX 700L's defaults: a board that may arm.
fn default_store() -> Vec<u8> {
    saved_store(&sweephold_firmware::params::ParamTable::defaults(
        sweephold_protocol::VehicleId::Trex700l,
    ))
}

impl Board {
    /// The image on a flash whose store sectors are as QEMU leaves them (zero: not a
    /// valid store).
    fn boot(image: &std::path::Path) -> Board {
        Board::boot_with_store(image, None)
    }

    /// The image, with `store` (the bytes of the store's sectors) preloaded into the
    /// flash by QEMU's generic loader.
    fn boot_with_store(image: &std::path::Path, store: Option<&[u8]>) -> Board {
        use std::net::TcpListener;
        let listen = || {
            let listener = TcpListener::bind("127.0.0.1:0").expect("a local port");
            let port = listener.local_addr().unwrap().port();
            (listener, port)
        };
        let (link_listener, link_port) = listen();
        let (sbus_listener, sbus_port) = listen();
        let chardev =
            |id: &str, port: u16| format!("socket,id={id},host=127.0.0.1,port={port},server=off");
        static BOOTS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let scratch = store.map(|bytes| {
            let boot = BOOTS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let scratch = Scratch::new(&format!("qemu-store-{boot}"));
            std::fs::write(scratch.path().join("store.bin"), bytes).unwrap();
            scratch
        });
        let mut qemu = netduinoplus2(image);
        if let Some(scratch) = &scratch {
            qemu.args([
                "-device",
                &format!(
                    "loader,file={},addr={:#x},force-raw=on",
                    scratch.path().join("store.bin").display(),
                    FLASH_BASE + STORE_REGION.start
                ),
            ]);
        }
        let qemu = qemu
            .args(["-chardev", &chardev("usart1", link_port)])
            .args(["-chardev", &chardev("usart2", sbus_port)])
            .args(["-serial", "chardev:usart1", "-serial", "chardev:usart2"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("qemu-system-arm starts");
        let (link, _) = link_listener.accept().expect("QEMU connects USART1");
        let (sbus, _) = sbus_listener.accept().expect("QEMU connects USART2");
        link.set_read_timeout(Some(std::time::Duration::from_millis(20)))
            .unwrap();
        Board {
            qemu,
            link,
            sbus,
            decoder: Decoder::new(),
            frames: Vec::new(),
            _store: scratch,
        }
    }

    /// Read the link for `seconds`, sending the SBUS frame of `rc` every 10 ms (the
    /// receiver's frame rate) when given.
    fn run(&mut self, seconds: f64, rc: Option<&RcInput>) {
        use std::io::{Read, Write};
        let bytes = rc.map(|rc| sbus::encode(&ChannelMap::flybarless_default().encode(rc)));
        let until = std::time::Instant::now() + std::time::Duration::from_secs_f64(seconds);
        let mut chunk = [0u8; 4096];
        while std::time::Instant::now() < until {
            if let Some(bytes) = &bytes {
                self.sbus.write_all(bytes).expect("SBUS bytes to QEMU");
            }
            let deadline = std::time::Instant::now() + std::time::Duration::from_millis(10);
            while std::time::Instant::now() < deadline {
                match self.link.read(&mut chunk) {
                    Ok(0) => panic!("QEMU closed the link"),
                    Ok(n) => {
                        for frame in self.decoder.feed(&chunk[..n]) {
                            self.frames.push(frame.expect("a clean stream"));
                        }
                    }
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                        ) => {}
                    Err(e) => panic!("link: {e}"),
                }
            }
        }
    }

    /// Send one frame to the board over the link.
    fn send(&mut self, frame: &Frame) {
        use std::io::Write;
        let mut wire = [0u8; sweephold_protocol::MAX_FRAME_LEN];
        let n = sweephold_protocol::encode(frame, &mut wire).unwrap();
        self.link.write_all(&wire[..n]).expect("a frame to QEMU");
    }

    fn events(&self) -> Vec<Event> {
        self.frames
            .iter()
            .filter_map(|f| match f {
                Frame::Event(e) => Some(*e),
                _ => None,
            })
            .collect()
    }
}

impl Drop for Board {
    fn drop(&mut self) {
        let _ = self.qemu.kill();
        let _ = self.qemu.wait();
    }
}

/// The IMU: with nothing on QEMU's SPI1 the image boots into the board application,
/// streams its Header (protocol 1.4) and, on its first tick, an Event naming the missing
/// IMU, then a Sample per tick with the safe, disarmed command.
#[test]
fn qemu_imu_missing_is_reported_at_boot() {
    let Some(image) = image_or_skip("qemu_imu_missing_is_reported_at_boot") else {
        return;
    };
    let mut board = Board::boot(&image);
    board.run(1.0, None);
    let Some(Frame::Header(header)) = board.frames.first() else {
        panic!(
            "the stream starts with a Header: {:?}",
            board.frames.first()
        );
    };
    assert_eq!(header.protocol, ProtocolVersion::BOARD_APPLICATION);
    // Then what the parameter store held at boot, then the IMU's absence.
    assert!(
        matches!(
            board.frames.get(1),
            Some(Frame::Event(Event::ParamStore { tick: 0, .. }))
        ),
        "{:?}",
        board.frames.get(1)
    );
    assert_eq!(
        board.frames.get(2),
        Some(&Frame::Event(Event::ImuHealthChange {
            tick: 0,
            health: ImuHealth::Missing
        }))
    );
    let samples: Vec<&Sample> = board
        .frames
        .iter()
        .filter_map(|f| match f {
            Frame::Sample(s) => Some(s),
            _ => None,
        })
        .collect();
    assert!(samples.len() >= 50, "{} Samples in 1 s", samples.len());
    assert!(samples
        .iter()
        .all(|s| s.command == Controls::default() && s.phase == Phase::Idle));
    assert_eq!(board.events().len(), 2, "{:?}", board.events());
}

/// SBUS and arming: frames fed on the second `-serial` (USART2) reach the board
/// application; the arm switch going on is refused, naming the missing IMU, and the
/// board stays disarmed. A second flip is refused again.
#[test]
fn qemu_sbus_arm_switch_is_refused_without_an_imu() {
    let Some(image) = image_or_skip("qemu_sbus_arm_switch_is_refused_without_an_imu") else {
        return;
    };
    let mut board = Board::boot(&image);
    let mut rc = RcInput::NEUTRAL;
    board.run(0.5, Some(&rc));
    assert!(
        board
            .events()
            .iter()
            .all(|e| !matches!(e, Event::Refused { .. })),
        "nothing requested yet: {:?}",
        board.events()
    );
    let refusal = Event::Refused {
        tick: 0,
        request: Request::Arm,
        check: RefusedCheck::Imu(ImuHealth::Missing),
    };
    let refusals = |board: &Board| -> Vec<Event> {
        board
            .events()
            .into_iter()
            .filter_map(|e| match e {
                Event::Refused { request, check, .. } => Some(Event::Refused {
                    tick: 0,
                    request,
                    check,
                }),
                _ => None,
            })
            .collect()
    };
    rc.arm = true;
    board.run(0.5, Some(&rc));
    assert_eq!(refusals(&board), [refusal]);
    rc.arm = false;
    board.run(0.3, Some(&rc));
    rc.arm = true;
    board.run(0.3, Some(&rc));
    assert_eq!(refusals(&board), [refusal, refusal]);
    assert!(
        board
            .events()
            .iter()
            .all(|e| !matches!(e, Event::ModeChange { .. })),
        "the board never left Disarmed: {:?}",
        board.events()
    );
}

/// The bench image (`sweephold-board` feature `bench-imu`: the IMU is the emulated chip at
/// rest), from `SWEEPHOLD_FC_BENCH_ELF` or the workspace's `target/fw-bench`; `None` (after
/// printing why) when the test cannot run here.
fn bench_image_or_skip(test: &str) -> Option<PathBuf> {
    // QEMU itself and the sources' age are checked as for the board image.
    image_or_skip(test)?;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let path = std::env::var_os("SWEEPHOLD_FC_BENCH_ELF")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            root.join("target/fw-bench/thumbv7em-none-eabihf/firmware/sweephold-fc")
        });
    if path.is_file() {
        return Some(path);
    }
    assert!(
        std::env::var_os("SWEEPHOLD_REQUIRE_QEMU").is_none(),
        "SWEEPHOLD_REQUIRE_QEMU is set but {test} has no bench image at {}",
        path.display()
    );
    eprintln!(
        "SKIPPED {test}: no bench image at {} (build it with `cargo fw --features bench-imu --target-dir target/fw-bench`)",
        path.display()
    );
    None
}

/// Arming, and the host link while armed: on the bench image the gyro calibrates, the
/// SBUS arm switch arms the board (Disarmed → Pilot), and a SensorIn from the host is then
/// ignored (one `HostLinkIgnored` Event, no ActuatorOut, the Samples go on); disarmed
/// again, the next SensorIn takes the board into the loop and is answered.
#[test]
fn qemu_arm_by_sbus_then_a_host_sensor_in_is_ignored() {
    let Some(image) = bench_image_or_skip("qemu_arm_by_sbus_then_a_host_sensor_in_is_ignored")
    else {
        return;
    };
    // A fresh board refuses to arm: a stored set (the defaults) lets it.
    let mut board = Board::boot_with_store(&image, Some(&default_store()));
    let mut rc = RcInput::NEUTRAL;
    wait_until_calibrated(&mut board, &rc);
    rc.arm = true;
    board.run(0.3, Some(&rc));
    let modes = |board: &Board| -> Vec<(FlightMode, FlightMode)> {
        board
            .events()
            .into_iter()
            .filter_map(|e| match e {
                Event::ModeChange { from, to, .. } => Some((from, to)),
                _ => None,
            })
            .collect()
    };
    assert_eq!(modes(&board), [(FlightMode::Disarmed, FlightMode::Pilot)]);

    let sensor_in = |seq| {
        Frame::SensorIn(SensorIn {
            seq,
            ..SensorIn::default()
        })
    };
    let before = board.frames.len();
    board.send(&sensor_in(1));
    board.run(0.2, Some(&rc));
    board.send(&sensor_in(2));
    board.run(0.2, Some(&rc));
    let after = &board.frames[before..];
    assert!(
        after.iter().all(|f| !matches!(f, Frame::ActuatorOut(_))),
        "armed, the board answered the host"
    );
    let ignored: Vec<&Frame> = after
        .iter()
        .filter(|f| matches!(f, Frame::Event(Event::HostLinkIgnored { .. })))
        .collect();
    assert!(
        matches!(
            ignored.as_slice(),
            [Frame::Event(Event::HostLinkIgnored {
                frame: HostFrame::SensorIn,
                ..
            })]
        ),
        "one HostLinkIgnored per armed period: {ignored:?}"
    );
    let samples = after
        .iter()
        .filter(|f| matches!(f, Frame::Sample(_)))
        .count();
    assert!(
        samples >= 20,
        "the board application flew on: {samples} Samples"
    );

    rc.arm = false;
    board.run(0.3, Some(&rc));
    assert_eq!(
        modes(&board),
        [
            (FlightMode::Disarmed, FlightMode::Pilot),
            (FlightMode::Pilot, FlightMode::Disarmed)
        ]
    );
    let before = board.frames.len();
    board.send(&sensor_in(3));
    board.run(0.3, Some(&rc));
    assert!(
        board.frames[before..]
            .iter()
            .any(|f| matches!(f, Frame::ActuatorOut(out) if out.seq == 3)),
        "disarmed, the SensorIn is answered"
    );
}

/// Runs the bench board on neutral sticks (`rc`) until its gyro has calibrated (an
/// `ImuHealthChange` to `Ok`), at most 10 s of board time; fails the test otherwise.
fn wait_until_calibrated(board: &mut Board, rc: &RcInput) {
    let calibrated = |board: &Board| {
        board.events().iter().any(|e| {
            matches!(
                e,
                Event::ImuHealthChange {
                    health: ImuHealth::Ok,
                    ..
                }
            )
        })
    };
    for _ in 0..50 {
        if calibrated(board) {
            return;
        }
        board.run(0.2, Some(rc));
    }
    assert!(
        calibrated(board),
        "the gyro never calibrated: {:?}",
        board.events()
    );
}

#[path = "qemu_params.rs"]
mod qemu_params;

#[path = "qemu_bench_tools.rs"]
mod qemu_bench_tools;
