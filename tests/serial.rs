//! `sweephold fly --fc serial:PATH`: a pseudo-terminal stands in for the board's serial
//! port. A thread on the master side plays the board with the firmware library, as the
//! board image does (`firmware/board/src/image/runner.rs`): a Configure builds the vehicle's
//! preset with the received rate and test and is answered by Header + ConfigureResult;
//! each SensorIn steps the flight logic, whose Events and Sample go out, then the
//! ActuatorOut answering its `seq`; a ParamRequest is answered by the firmware's
//! `ParamLink` (`sweephold fc params`). The host opens the slave side as the board's tty.

use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

use clap::Parser;
use sweephold_firmware::params::link::ParamLink;
use sweephold_firmware::params::no_flash::NoFlash;
use sweephold_firmware::{Config, FlightController};
use sweephold_protocol::codec::encode_to_vec;
use sweephold_protocol::{
    ConfigureResult, Decoder, Frame, LinkConfig, ParamRequest, ProtocolVersion, VehicleId,
};
use sweephold_tests::{fly, fly_args, Scratch};

/// How the fake board answers.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Board {
    /// The firmware library, as the board image runs it.
    Firmware,
    /// Reads everything, answers nothing.
    Silent,
    /// Answers a Configure with a Header of protocol major 2.
    ProtocolMajor2,
    /// The firmware library, but its third parameter Set is refused as armed (an arm
    /// switch flipped in the middle of a push).
    ArmsAtThirdSet,
}

/// A pseudo-terminal whose master side a thread drives as a board.
struct FakeBoard {
    slave_path: PathBuf,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    /// Kept open so the master never reads end of file between the host's opens.
    _slave: OwnedFd,
}

impl FakeBoard {
    fn start(behaviour: Board) -> FakeBoard {
        let (mut master, mut slave) = (0, 0);
        // SAFETY: out-pointers to two ints; name, termios and winsize may be null.
        let status = unsafe {
            libc::openpty(
                &mut master,
                &mut slave,
                std::ptr::null_mut(),
                std::ptr::null(),
                std::ptr::null(),
            )
        };
        assert_eq!(status, 0, "openpty: {}", std::io::Error::last_os_error());
        // SAFETY: openpty returned two fresh descriptors that nothing else owns.
        let (master, slave) = unsafe { (File::from_raw_fd(master), OwnedFd::from_raw_fd(slave)) };
        let slave_path = std::fs::read_link(format!("/proc/self/fd/{}", slave.as_raw_fd()))
            .expect("the slave's path");
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let stop = Arc::clone(&stop);
            std::thread::spawn(move || play_board(master, behaviour, &stop))
        };
        FakeBoard {
            slave_path,
            stop,
            thread: Some(thread),
            _slave: slave,
        }
    }

    fn fc_arg(&self) -> String {
        format!("serial:{}", self.slave_path.display())
    }
}

impl Drop for FakeBoard {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// What the board image builds from a Configure (`runner.rs`'s `link_config`).
fn board_config(request: &LinkConfig) -> Config {
    let mut config = match request.vehicle {
        VehicleId::Bo105 => Config::bo105_default(request.test.primary),
        VehicleId::Trex700l => Config::trex700l_default(request.test.primary),
    };
    config.rate_hz = request.rate_hz;
    config.test = request.test;
    config
}

fn put(out: &mut Vec<u8>, frame: &Frame) {
    out.extend_from_slice(encode_to_vec(frame).expect("encodes").as_bytes());
}

/// The board's main loop on the master side of the pty, until `stop`.
fn play_board(mut master: File, behaviour: Board, stop: &AtomicBool) {
    let mut decoder = Decoder::new();
    let mut fc: Option<FlightController> = None;
    // The parameters in RAM, answered as the board image does (`image/params.rs`), but a
    // List all at once.
    let mut params: ParamLink<NoFlash> = ParamLink::boot(None, VehicleId::Trex700l);
    let mut sets = 0;
    let mut chunk = [0u8; 4096];
    while !stop.load(Ordering::Relaxed) {
        let mut poll = libc::pollfd {
            fd: master.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd for the duration of the call.
        let ready = unsafe { libc::poll(&mut poll, 1, 20) };
        if ready <= 0 || poll.revents & libc::POLLIN == 0 {
            // Nothing (or only a hang-up while the host has the port closed).
            std::thread::sleep(std::time::Duration::from_millis(1));
            continue;
        }
        let count = match master.read(&mut chunk) {
            Ok(n) => n,
            Err(_) => continue,
        };
        let mut answer = Vec::new();
        decoder.feed_with(chunk.get(..count).unwrap_or(&[]), |frame| {
            match (behaviour, frame) {
                (Board::Silent, _) => {}
                (Board::Firmware, Ok(Frame::Configure(request))) => {
                    let result = match FlightController::new(board_config(&request)) {
                        Ok(controller) => {
                            put(&mut answer, &Frame::Header(controller.header()));
                            fc = Some(controller);
                            ConfigureResult {
                                accepted: true,
                                refusal: 0,
                            }
                        }
                        Err(error) => ConfigureResult {
                            accepted: false,
                            refusal: error as u8,
                        },
                    };
                    put(&mut answer, &Frame::ConfigureResult(result));
                }
                (Board::Firmware, Ok(Frame::SensorIn(input))) => {
                    if let Some(controller) = fc.as_mut() {
                        let tick = controller.tick();
                        let output = controller.step(&input, &mut answer);
                        put(
                            &mut answer,
                            &Frame::ActuatorOut(output.actuator_out(tick, input.seq)),
                        );
                    }
                }
                (Board::Firmware | Board::ArmsAtThirdSet, Ok(Frame::ParamRequest(request))) => {
                    if matches!(request, ParamRequest::Set { .. }) {
                        sets += 1;
                    }
                    let disarmed = behaviour == Board::Firmware || sets != 3;
                    params.handle(&request, disarmed, |reply| {
                        put(&mut answer, &Frame::ParamReply(reply))
                    });
                }
                (Board::ProtocolMajor2, Ok(Frame::Configure(request))) => {
                    let controller =
                        FlightController::new(board_config(&request)).expect("valid request");
                    let mut header = controller.header();
                    header.protocol = ProtocolVersion { major: 2, minor: 0 };
                    put(&mut answer, &Frame::Header(header));
                    put(
                        &mut answer,
                        &Frame::ConfigureResult(ConfigureResult {
                            accepted: true,
                            refusal: 0,
                        }),
                    );
                }
                _ => {}
            }
        });
        if !answer.is_empty() && master.write_all(&answer).is_err() {
            return;
        }
    }
}

/// The `*.bin` dumps in `dir`, sorted by name.
fn dumps(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("output folder")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "bin"))
        .collect();
    files.sort();
    files
}

/// Fly `campaign` with `--fc serial:` on `board`'s pty through the command's `run`;
/// return the error message, if any.
fn fly_serial(board: &FakeBoard, campaign: &[&str], out: &Scratch) -> Result<(), String> {
    let fc = board.fc_arg();
    let mut all = campaign.to_vec();
    all.extend(["--fc", &fc, "--out", out.path().to_str().unwrap()]);
    sweephold::fly::run(&fly_args(&all)).map_err(|e| format!("{e:#}"))
}

#[test]
fn a_board_on_a_serial_port_flies_the_same_bytes_as_in_process() {
    let board = FakeBoard::start(Board::Firmware);
    let campaign = ["--axes", "lat", "--t-rec", "5", "--seed", "9"];
    let (serial_dir, local_dir) = (Scratch::new("serial-s"), Scratch::new("serial-p"));
    fly_serial(&board, &campaign, &serial_dir).expect("the campaign flies over the pty");
    let mut local = campaign.to_vec();
    local.extend(["--out", local_dir.path().to_str().unwrap()]);
    let reference = fly(&fly_args(&local));

    let summary: serde_json::Value = serde_json::from_slice(
        &std::fs::read(serial_dir.path().join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    assert_eq!(
        summary["link"].as_str(),
        Some(format!("{}@460800", board.fc_arg()).as_str())
    );
    let flown = dumps(serial_dir.path());
    assert_eq!(flown.len(), reference.dumps.len());
    assert!(!flown.is_empty());
    for (dump, local) in flown.iter().zip(&reference.dumps) {
        assert_eq!(dump.file_name(), local.file_name());
        let (bytes, local_bytes) = (std::fs::read(dump).unwrap(), std::fs::read(local).unwrap());
        let samples = Decoder::new()
            .feed(&bytes)
            .filter(|f| matches!(f, Ok(Frame::Sample(_))))
            .count();
        assert!(samples >= 1000, "{}: {samples} Samples", dump.display());
        assert!(
            bytes == local_bytes,
            "{}: differs from the in-process dump",
            dump.display()
        );
    }
}

#[test]
fn a_silent_board_times_out_naming_the_port() {
    let board = FakeBoard::start(Board::Silent);
    let out = Scratch::new("serial-silent");
    let error = fly_serial(&board, &["--axes", "lat", "--input", "doublet"], &out)
        .expect_err("nothing answers");
    let port = board.slave_path.display().to_string();
    assert!(
        error.contains(&port)
            && error.contains("no ConfigureResult")
            && error.contains("within 2 s"),
        "{error}"
    );
    assert_eq!(error.lines().count(), 1, "{error}");
}

#[test]
fn a_board_of_another_protocol_major_version_is_refused() {
    let board = FakeBoard::start(Board::ProtocolMajor2);
    let out = Scratch::new("serial-major2");
    let error = fly_serial(&board, &["--axes", "lat", "--input", "doublet"], &out)
        .expect_err("protocol 2 is refused");
    assert!(
        error.contains("protocol 2.0") && error.contains("major versions differ"),
        "{error}"
    );
}

#[test]
fn a_missing_port_cannot_be_opened() {
    let out = Scratch::new("serial-missing");
    let fc = "serial:/dev/sweephold-no-such-port";
    let error = sweephold::fly::run(&fly_args(&[
        "--axes",
        "lat",
        "--input",
        "doublet",
        "--fc",
        fc,
        "--out",
        out.path().to_str().unwrap(),
    ]))
    .map(|_| ())
    .map_err(|e| format!("{e:#}"))
    .expect_err("no such port");
    assert!(
        error.contains("cannot open serial port /dev/sweephold-no-such-port"),
        "{error}"
    );
}

#[test]
fn a_malformed_fc_value_is_a_usage_error() {
    for fc in [
        "serial:",
        "serial:/dev/ttyUSB0@fast",
        "serial:/dev/ttyUSB0@123",
        "uart",
    ] {
        let error = sweephold::Cli::try_parse_from(["sweephold", "fly", "--fc", fc])
            .expect_err(fc)
            .to_string();
        assert!(error.contains("--fc"), "{fc}: {error}");
    }
}

/// `sweephold fc params` as separate commands on one board (its RAM outlives each
/// connection): a pushed file comes back from `pull` value for value, `diff` then finds
/// no difference, and `get` reads one value.
#[test]
fn params_push_then_pull_over_a_serial_port() {
    let board = FakeBoard::start(Board::Firmware);
    let fc = board.fc_arg();
    let scratch = Scratch::new("serial-params");
    let path = |name: &str| scratch.path().join(name).display().to_string();
    run_cli(&["fc", "params", "pull", &path("before.toml"), "--fc", &fc]).expect("pull");
    let before = std::fs::read_to_string(path("before.toml")).unwrap();
    let changed = before
        .replace("SWASH_TYPE = 120\n", "SWASH_TYPE = 140\n")
        .replace("SWASH_PHASE = 0\n", "SWASH_PHASE = -12.5\n");
    assert_ne!(changed, before, "the defaults are as expected");
    std::fs::write(path("pushed.toml"), &changed).unwrap();
    run_cli(&["fc", "params", "push", &path("pushed.toml"), "--fc", &fc]).expect("push");
    run_cli(&["fc", "params", "pull", &path("after.toml"), "--fc", &fc]).expect("pull");
    let after = std::fs::read_to_string(path("after.toml")).unwrap();
    assert_eq!(after, changed, "pull gives back the pushed set");
    run_cli(&["fc", "params", "diff", &path("pushed.toml"), "--fc", &fc]).expect("diff");
    // The pushed file is an input: not modified.
    assert_eq!(
        std::fs::read_to_string(path("pushed.toml")).unwrap(),
        changed
    );
}

/// A push whose third set is refused (the board armed mid-way) puts back the two values
/// it had changed: the board holds what it held before, and the error says so.
#[test]
fn a_push_refused_mid_way_restores_the_board() {
    let board = FakeBoard::start(Board::ArmsAtThirdSet);
    let fc = board.fc_arg();
    let scratch = Scratch::new("serial-params-midway");
    let path = |name: &str| scratch.path().join(name).display().to_string();
    run_cli(&["fc", "params", "pull", &path("before.toml"), "--fc", &fc]).expect("pull");
    let before = std::fs::read_to_string(path("before.toml")).unwrap();
    let changed = before
        .replace("SWASH_TYPE = 120\n", "SWASH_TYPE = 140\n")
        .replace("SWASH_PHASE = 0\n", "SWASH_PHASE = -12.5\n")
        .replace("SWASH_LEAD = 1\n", "SWASH_LEAD = 2\n");
    std::fs::write(path("pushed.toml"), &changed).unwrap();
    let error = run_cli(&["fc", "params", "push", &path("pushed.toml"), "--fc", &fc])
        .expect_err("the third set is refused");
    assert!(
        error.contains("setting SWASH_LEAD failed")
            && error.contains("armed")
            && error.contains("restored"),
        "{error}"
    );
    run_cli(&["fc", "params", "pull", &path("after.toml"), "--fc", &fc]).expect("pull");
    assert_eq!(std::fs::read_to_string(path("after.toml")).unwrap(), before);
}

/// Run `sweephold ARGS` in-process; the error as its one line.
fn run_cli(args: &[&str]) -> Result<(), String> {
    let cli =
        sweephold::Cli::try_parse_from(std::iter::once("sweephold").chain(args.iter().copied()))
            .map_err(|e| e.to_string())?;
    sweephold::run(cli).map_err(|e| format!("{e:#}"))
}
