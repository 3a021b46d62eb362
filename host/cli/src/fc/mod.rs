//! `sweephold fc`: set up the flight controller over its link. `fc params` lists, reads,
//! sets, saves and resets the board's parameters (protocol 1.5's parameter frames),
//! pulls them into a params file, pushes such a file (all or nothing) and compares one
//! with the board, over `--fc qemu-usart` (the board image in QEMU, its USART1 on a
//! socket), `--fc serial:PATH[@BAUD]` (a board on a serial port) or `--fc
//! board-sim:FLASH` (the simulated board, its parameter sectors in a file: [`board_sim`]).
//!
//! Its parts: [`client`] (the frames), [`params_file`] (the file format) and [`push`]
//! (checking a file against the board, then writing it all or nothing). `fc watch`
//! ([`watch`]) shows the board's telemetry live; `fc servo` ([`servo`]) moves one servo
//! on the bench.

pub mod aircraft_params;
pub mod board_sim;
pub mod client;
pub mod params_file;
pub mod push;
pub mod servo;
pub mod watch;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::{Args, Subcommand};

use crate::fly::frame_channel::{ByteWire, FrameChannel};
use crate::fly::link_qemu::{self, QemuProcess, QemuTransport};
use crate::fly::link_serial::{SerialPort, SerialWire};
use crate::output;
use client::{BoardValue, ParamBoard, ParamClient};
use params_file::Source;

/// `sweephold fc`.
#[derive(Args, Debug)]
pub struct FcArgs {
    /// What to set up.
    #[command(subcommand)]
    pub command: FcCommand,
}

/// The parts of the flight controller `sweephold fc` sets up.
#[derive(Subcommand, Debug)]
pub enum FcCommand {
    /// The board's parameters (list, get, set, save, reset, pull, push, diff).
    Params(ParamsArgs),
    /// A live view of the board: mode, phase, test, attitude, rates, command, servo
    /// pulses and events, one line per update, until Ctrl-C (or --count / --seconds).
    Watch(WatchArgs),
    /// Bench servo test: one servo to its centre, min, max or a pulse for --hold, while
    /// disarmed; back to the disarmed output afterwards.
    Servo(ServoArgs),
}

/// `sweephold fc servo`.
#[derive(Args, Debug)]
#[command(
    after_help = "The board obeys only while disarmed and with a valid parameter set \
saved; armed, the request is refused and nothing moves, and a test running when the board \
arms ends at once. The pulse is clamped to the servo's own limits (SERVOn_MIN/MAX, \
TAIL_MIN/MAX). The host repeats the request every 0.2 s with a 0.5 s hold: if it stops \
asking (Ctrl-C, a pulled cable) the servo is back at the disarmed output within 0.5 s."
)]
pub struct ServoArgs {
    /// The servo: 1, 2, 3 (swash servos) or 4 (tail).
    #[arg(value_parser = clap::value_parser!(u8).range(1..=4))]
    pub servo: u8,
    /// Where to put it: centre, min, max, or a pulse such as 1600us.
    #[arg(value_parser = servo::parse_target)]
    pub target: sweephold_protocol::ServoTarget,
    /// How long to hold it (2s, 500ms, 1.5).
    #[arg(long, value_name = "DURATION", default_value = "2s", value_parser = servo::parse_duration)]
    pub hold: std::time::Duration,
    /// The flight controller: `qemu-usart` or `serial:PATH[@BAUD]` (as for `fc params`).
    #[arg(long, value_name = "FC", value_parser = parse_fc)]
    pub fc: Option<FcLink>,
    /// Board image for `--fc qemu-usart` (as for `fc params`).
    #[arg(long, value_name = "PATH")]
    pub elf: Option<PathBuf>,
}

/// `sweephold fc watch`.
#[derive(Args, Debug)]
#[command(
    after_help = "Status line: board time, armed or disarmed and the mode, the \
sequencer's phase, the test list entry and engagement of the last Header, the hold states \
(lat lon ped: - released, H engaged, F frozen), attitude phi theta psi, rates p q r, the \
command (lat lon ped col) and the servo pulses that command makes through the board's \
mixer (from the parameters listed at the start; `?` when the board refused the list, i.e. \
armed). Events are lines of their own. Ctrl-C ends the watch with exit status 0."
)]
pub struct WatchArgs {
    /// The flight controller: `qemu-usart` or `serial:PATH[@BAUD]` (as for `fc params`).
    #[arg(long, value_name = "FC", value_parser = parse_fc)]
    pub fc: Option<FcLink>,
    /// Board image for `--fc qemu-usart` (as for `fc params`).
    #[arg(long, value_name = "PATH")]
    pub elf: Option<PathBuf>,
    /// Board seconds between two status lines.
    #[arg(long, value_name = "S", default_value_t = 0.2)]
    pub every: f64,
    /// Stop after N status lines.
    #[arg(long, value_name = "N")]
    pub count: Option<u64>,
    /// Stop after S seconds (wall time).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
}

/// `sweephold fc params`.
#[derive(Args, Debug)]
#[command(
    after_help = "Parameters change only while the board is disarmed (every request is \
refused while armed) and only in its RAM until `save`. `push` reads the board's list first, \
refuses unknown names and out-of-range values before writing anything, sets only the values \
that differ, and puts the old values back if a set fails mid-way. `push` takes a params file \
or an aircraft file (its [flight_controller] and [swash] tables as parameters). With --fc \
board-sim:FLASH every command is a power cycle of the simulated board: `set`, `push` and \
`reset` without `save` in the same board's life are lost when the command ends, as on a \
board switched off; `save` writes FLASH, so change and save in one command with --save \
(e.g. `fc params push fbl700.toml --save --fc board-sim:F`)."
)]
pub struct ParamsArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: ParamsAction,
    /// The flight controller: `qemu-usart` (the board image in qemu-system-arm, frames
    /// over its USART1; its parameters live as long as that QEMU, i.e. this command) or
    /// `serial:PATH[@BAUD]` (a board on a serial port, default 460800 Bd) or
    /// `board-sim:FLASH` (the simulated board; FLASH, a file holding its parameter
    /// sectors, created erased if absent; one power cycle per command).
    #[arg(long, value_name = "FC", global = true, value_parser = parse_fc)]
    pub fc: Option<FcLink>,
    /// Board image for `--fc qemu-usart` [default: $SWEEPHOLD_FC_ELF, else
    /// target/thumbv7em-none-eabihf/firmware/sweephold-fc of the workspace this binary
    /// was built in, else of the current folder].
    #[arg(long, value_name = "PATH", global = true)]
    pub elf: Option<PathBuf>,
    /// After `set`, `push` or `reset`: save the set to the board's flash in the same
    /// connection (a board whose RAM does not outlive the command — QEMU, board-sim —
    /// keeps a change only so).
    #[arg(long, global = true)]
    pub save: bool,
}

/// What `fc params` does.
#[derive(Subcommand, Debug)]
pub enum ParamsAction {
    /// Print every parameter as `NAME = value`, in the board's order.
    List,
    /// Print one parameter's value.
    Get {
        /// The parameter's name (upper case, e.g. SWASH_TYPE).
        name: String,
    },
    /// Set one parameter in the board's RAM and print the value it now holds.
    Set {
        /// The parameter's name.
        name: String,
        /// Its new value.
        #[arg(allow_hyphen_values = true)]
        value: f32,
    },
    /// Write the set in the board's RAM to its flash.
    Save,
    /// Put the defaults in the board's RAM (`save` makes that permanent).
    Reset,
    /// Write every parameter into a params file (TOML, docs/formats.md).
    Pull {
        /// The params file to write (replaced atomically).
        file: PathBuf,
    },
    /// Set the board's RAM to a params file's values, or to an aircraft file's (its
    /// `[flight_controller]` and `[swash]` tables), all or nothing.
    Push {
        /// The params file or aircraft file to read.
        file: PathBuf,
    },
    /// Show where the board and a params file differ.
    Diff {
        /// The params file to compare with.
        file: PathBuf,
    },
}

/// A flight controller `fc` reaches.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FcLink {
    /// The board image in QEMU over its USART1.
    QemuUsart,
    /// A board on a serial port.
    Serial(SerialPort),
    /// The simulated board, its parameter sectors in a file.
    BoardSim(PathBuf),
}

impl FcLink {
    fn name(&self) -> String {
        match self {
            FcLink::QemuUsart => "qemu-usart".to_string(),
            FcLink::Serial(port) => format!("serial:{port}"),
            FcLink::BoardSim(path) => format!("board-sim:{}", path.display()),
        }
    }
}

/// Parse `--fc` of `fc`: `qemu-usart` or `serial:PATH[@BAUD]`.
pub fn parse_fc(text: &str) -> Result<FcLink, String> {
    if text == "qemu-usart" {
        return Ok(FcLink::QemuUsart);
    }
    if let Some(path) = text.strip_prefix("board-sim:") {
        if path.is_empty() {
            return Err("board-sim:FLASH needs the path of the flash file".to_string());
        }
        return Ok(FcLink::BoardSim(PathBuf::from(path)));
    }
    match text.strip_prefix("serial:") {
        Some(port) => SerialPort::parse(port)
            .map(FcLink::Serial)
            .map_err(|e| e.to_string()),
        None => Err(format!(
            "unknown flight controller `{text}` (expected qemu-usart, serial:PATH[@BAUD] or \
             board-sim:FLASH)"
        )),
    }
}

/// The byte stream to the board: either link.
pub enum FcWire {
    /// QEMU running the image.
    Qemu(QemuProcess),
    /// A serial port.
    Serial(SerialWire),
    /// The simulated board.
    BoardSim(Box<board_sim::BoardSimWire>),
}

impl ByteWire for FcWire {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        match self {
            FcWire::Qemu(wire) => wire.send(bytes),
            FcWire::Serial(wire) => wire.send(bytes),
            FcWire::BoardSim(wire) => wire.send(bytes),
        }
    }

    fn recv(&mut self, buf: &mut [u8], timeout: std::time::Duration) -> std::io::Result<usize> {
        match self {
            FcWire::Qemu(wire) => wire.recv(buf, timeout),
            FcWire::Serial(wire) => wire.recv(buf, timeout),
            FcWire::BoardSim(wire) => wire.recv(buf, timeout),
        }
    }

    fn failure(&mut self, what: &str) -> anyhow::Error {
        match self {
            FcWire::Qemu(wire) => wire.failure(what),
            FcWire::Serial(wire) => wire.failure(what),
            FcWire::BoardSim(wire) => wire.failure(what),
        }
    }
}

/// `sweephold fc`.
pub fn run(args: &FcArgs) -> anyhow::Result<()> {
    match &args.command {
        FcCommand::Params(params) => run_params(params),
        FcCommand::Watch(watch) => run_watch(watch),
        FcCommand::Servo(args) => run_servo(args),
    }
}

fn run_servo(args: &ServoArgs) -> anyhow::Result<()> {
    let Some(fc) = &args.fc else {
        bail!("--fc is required (qemu-usart or serial:PATH[@BAUD])");
    };
    if let FcLink::BoardSim(_) = fc {
        bail!("fc servo needs a board with servos: qemu-usart or serial:PATH");
    }
    let (client, _) = connect(fc, args.elf.as_deref())?;
    let (mut channel, _) = client.into_channel();
    let held = servo::hold_servo(&mut channel, args.servo, args.target, args.hold)?;
    output::print(&format!(
        "servo {} at {} us for {:.1} s, then back to the disarmed output\n",
        args.servo,
        held.pulse_us,
        args.hold.as_secs_f64()
    ))
}

fn run_watch(args: &WatchArgs) -> anyhow::Result<()> {
    let Some(fc) = &args.fc else {
        bail!("--fc is required (qemu-usart or serial:PATH[@BAUD])");
    };
    if let FcLink::BoardSim(_) = fc {
        bail!("fc watch needs a board that streams telemetry: qemu-usart or serial:PATH");
    }
    if !(args.every.is_finite() && args.every > 0.0) {
        bail!("--every must be a positive number of seconds");
    }
    if args.seconds.is_some_and(|s| !(s.is_finite() && s > 0.0)) {
        bail!("--seconds must be a positive number of seconds");
    }
    let (mut client, _) = connect(fc, args.elf.as_deref())?;
    let (mixer, note) = match board_mixer(&mut client) {
        Ok(mixer) => (Some(mixer), None),
        Err(error) => (None, Some(format!("servo pulses not shown: {error:#}"))),
    };
    let (mut channel, passed) = client.into_channel();
    let mut watcher = watch::Watcher::new(args.every, mixer);
    let mut out = output::StdoutWriter::lock();
    if let Some(note) = note {
        use std::io::Write;
        writeln!(out, "{note}")?;
    }
    // What the board sent before and during the List (its boot Header and Events).
    watch::replay(&passed, &mut watcher, &mut out)?;
    let limits = watch::Limits {
        count: args.count,
        seconds: args.seconds,
    };
    watch::watch(
        &mut channel,
        &mut watcher,
        limits,
        &mut out,
        crate::interrupt::requested,
    )?;
    Ok(())
}

/// The mixer of the board's parameters (a List, answered only while disarmed).
pub fn board_mixer<W: ByteWire>(
    client: &mut ParamClient<W>,
) -> anyhow::Result<sweephold_firmware::mixer::MixerConfig> {
    let values = client.list()?;
    client::check_same_table(&values)?;
    let mut array = [0.0; sweephold_firmware::params::COUNT];
    for (slot, value) in array.iter_mut().zip(&values) {
        *slot = value.value;
    }
    let table = sweephold_firmware::params::ParamTable::from_values(array)
        .map_err(|(id, e)| anyhow::anyhow!("the board's {}: {}", id.def().name, e.message()))?;
    let params = table
        .params()
        .map_err(|e| anyhow::anyhow!("the board's parameters: {}", e.message()))?;
    Ok(params.stack.app.flight.mixer)
}

fn run_params(args: &ParamsArgs) -> anyhow::Result<()> {
    let Some(fc) = &args.fc else {
        bail!("--fc is required (qemu-usart, serial:PATH[@BAUD] or board-sim:FLASH)");
    };
    // Inputs are read, and outputs checked, before the board is reached.
    let file_values = match &args.action {
        ParamsAction::Push { file } | ParamsAction::Diff { file } => Some(read_params_file(file)?),
        _ => None,
    };
    if let ParamsAction::Pull { file } = &args.action {
        output::refuse_inputs_as_outputs(&[], &[("FILE", file)])?;
    }
    if args.save
        && !matches!(
            args.action,
            ParamsAction::Set { .. } | ParamsAction::Push { .. } | ParamsAction::Reset
        )
    {
        bail!("--save goes with set, push or reset");
    }
    let (mut client, source) = connect(fc, args.elf.as_deref())?;
    match &args.action {
        ParamsAction::List => output::print(&listing(&client.list()?)),
        ParamsAction::Get { name } => output::print(&format!("{}\n", client.get(name)?)),
        ParamsAction::Set { name, value } => {
            local_check(name, *value)?;
            let held = client.set(name, *value)?;
            save_if_asked(&mut client, args.save)?;
            output::print(&format!("{name} = {held}\n"))
        }
        ParamsAction::Save => {
            client.save()?;
            output::print("saved\n")
        }
        ParamsAction::Reset => {
            client.reset()?;
            save_if_asked(&mut client, args.save)?;
            output::print(if args.save {
                "defaults saved\n"
            } else {
                "defaults in RAM (not saved)\n"
            })
        }
        ParamsAction::Pull { file } => {
            let values = client.list()?;
            client::check_same_table(&values)?;
            output::write_atomic(file, params_file::write(&source, &values).as_bytes())?;
            output::print(&format!(
                "{} parameters -> {}\n",
                values.len(),
                file.display()
            ))
        }
        ParamsAction::Push { .. } => {
            let values = file_values.unwrap_or_default();
            let pushed = push::push(&mut client, &values)?;
            save_if_asked(&mut client, args.save)?;
            let kept = if args.save {
                "saved"
            } else {
                "in RAM: `sweephold fc params save` to keep them"
            };
            output::print(&format!(
                "{} changed, {} already held ({kept})\n",
                pushed.changed, pushed.unchanged
            ))
        }
        ParamsAction::Diff { .. } => {
            let board = client.list()?;
            output::print(&diff(&board, &file_values.unwrap_or_default()))
        }
    }
}

/// `--save`: save what the command set.
fn save_if_asked(client: &mut ParamClient<FcWire>, save: bool) -> anyhow::Result<()> {
    if save {
        client
            .save()
            .map_err(|e| anyhow::anyhow!("the values were set but not saved: {e}"))?;
    }
    Ok(())
}

/// A value the host's copy of the firmware's table refuses is refused here, with the
/// range, before the board is asked; unknown names are left to the board (its table may
/// be newer).
fn local_check(name: &str, value: f32) -> anyhow::Result<()> {
    let Some(id) = sweephold_firmware::params::ParamId::from_name(name) else {
        return Ok(());
    };
    let def = id.def();
    def.check(value).map_err(|error| {
        anyhow::anyhow!(
            "{name} = {value}: {} ({} … {} {})",
            error.message(),
            def.min,
            def.max,
            def.unit
        )
    })
}

fn read_params_file(path: &Path) -> anyhow::Result<Vec<BoardValue>> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        anyhow::anyhow!("cannot read {}: {}", path.display(), output::io_reason(&e))
    })?;
    // An aircraft file has a [flight_controller] table; a params file never does.
    let is_aircraft = text
        .parse::<toml::Table>()
        .is_ok_and(|table| table.contains_key("flight_controller"));
    if is_aircraft {
        let given = path.to_string_lossy();
        let vehicle = crate::vehicle::Vehicle::parse(&given).map_err(|e| anyhow::anyhow!(e))?;
        return aircraft_params::values(&vehicle);
    }
    params_file::parse(&text, &path.display().to_string())
}

/// Reach the board over `fc`.
fn connect(fc: &FcLink, elf: Option<&Path>) -> anyhow::Result<(ParamClient<FcWire>, Source)> {
    match fc {
        FcLink::QemuUsart => {
            let image = match elf {
                Some(path) => path.to_path_buf(),
                None => link_qemu::default_image()?,
            };
            let session = link_qemu::start_session(
                &image,
                QemuTransport::Usart,
                &link_qemu::extra_args_from_env(),
            )?;
            let channel = session.map_wire(FcWire::Qemu);
            let source = Source {
                fc: fc.name(),
                image: Some(image.display().to_string()),
            };
            Ok((ParamClient::new(channel), source))
        }
        FcLink::BoardSim(path) => {
            let wire = board_sim::BoardSimWire::boot(path)?;
            let channel = FrameChannel::new(FcWire::BoardSim(Box::new(wire)));
            let source = Source {
                fc: fc.name(),
                image: None,
            };
            Ok((ParamClient::new(channel), source))
        }
        FcLink::Serial(port) => {
            let wire = SerialWire::open(port)
                .with_context(|| format!("cannot reach the flight controller on {port}"))?;
            let channel = FrameChannel::new(FcWire::Serial(wire));
            let source = Source {
                fc: fc.name(),
                image: None,
            };
            Ok((ParamClient::new(channel), source))
        }
    }
}

/// `NAME = value` lines.
fn listing(values: &[BoardValue]) -> String {
    values
        .iter()
        .map(|v| format!("{} = {}\n", v.name, v.value))
        .collect()
}

/// The differences between the board and a file, one line each.
pub fn diff(board: &[BoardValue], file: &[BoardValue]) -> String {
    let mut text = String::new();
    for entry in file {
        match board.iter().find(|b| b.name == entry.name) {
            Some(b) if b.value.to_bits() == entry.value.to_bits() => {}
            Some(b) => text.push_str(&format!(
                "{}: board {} file {}\n",
                entry.name, b.value, entry.value
            )),
            None => text.push_str(&format!(
                "{}: not on the board, file {}\n",
                entry.name, entry.value
            )),
        }
    }
    for b in board {
        if !file.iter().any(|entry| entry.name == b.name) {
            text.push_str(&format!("{}: board {}, not in the file\n", b.name, b.value));
        }
    }
    if text.is_empty() {
        text.push_str(&format!("no difference ({} parameters)\n", file.len()));
    }
    text
}
