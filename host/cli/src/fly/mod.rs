//! `sweephold fly`: the paper's test campaign, flown on the host with the flight
//! controller in the loop and the nonlinear simulator as the aircraft.

pub mod board_flash;
pub mod board_test_list;
pub mod defmt_log;
pub mod frame_channel;
pub mod imu_fault;
pub mod link;
pub mod link_board_sim;
pub mod link_qemu;
pub mod link_serial;
pub mod pilot_collective;
pub mod plan;
pub mod record;
pub mod servo_plant;
pub mod summary;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::{bail, Context};
use clap::{Args, ValueEnum};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use sweephold_firmware::Config;
use sweephold_protocol::{Axis, ExcitationMode, InputKind};
use sysid::frf::Record;

use crate::arg_values;
use crate::output::{write_atomic, write_json, StagedFolder};
use crate::vehicle::Vehicle;
use link::{FlightControllerLink, InProcessLink};
use plan::{plan_records, RecordPlan};
use record::{fly_record, Disturbances};
use summary::{FlySummary, RunSummary};

/// Excitation mode on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Conditional attitude hold plus off-axis noise (the paper's method).
    Cah,
    /// Attitude-hold controller always on, sweep added (the paper's Fig. 3 case).
    Standard,
    /// Controller always on plus off-axis noise (Tischler's method).
    Noise,
}

impl ModeArg {
    /// The firmware's mode.
    pub fn mode(self) -> ExcitationMode {
        match self {
            ModeArg::Cah => ExcitationMode::ConditionalAttitudeHold,
            ModeArg::Standard => ExcitationMode::Standard,
            ModeArg::Noise => ExcitationMode::OffAxisNoise,
        }
    }

    /// Name in files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            ModeArg::Cah => "cah",
            ModeArg::Standard => "standard",
            ModeArg::Noise => "noise",
        }
    }
}

/// Primary input on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum InputArg {
    /// Tischler's exponential sweep (two records per axis, the paper's bands).
    Sweep,
    /// A doublet (one record per axis).
    Doublet,
    /// A 3-2-1-1 multistep (one record per axis).
    #[value(name = "3211")]
    ThreeTwoOneOne,
}

impl InputArg {
    fn kind(self) -> InputKind {
        match self {
            InputArg::Sweep => InputKind::Sweep,
            InputArg::Doublet => InputKind::Doublet,
            InputArg::ThreeTwoOneOne => InputKind::ThreeTwoOneOne,
        }
    }
}

/// Sweep amplitude law on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum AmplitudeArg {
    /// The paper's constant amplitude A.
    #[default]
    Fixed,
    /// Shaped online by the firmware so that the attitudes stay inside the hold's
    /// release band (`InputKind::AdaptiveSweep`; docs/hil.md).
    Adaptive,
}

impl AmplitudeArg {
    /// The input kind a sweep is flown as under this law.
    pub fn sweep_kind(self) -> InputKind {
        match self {
            AmplitudeArg::Fixed => InputKind::Sweep,
            AmplitudeArg::Adaptive => InputKind::AdaptiveSweep,
        }
    }

    /// Name on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            AmplitudeArg::Fixed => "fixed",
            AmplitudeArg::Adaptive => "adaptive",
        }
    }
}

/// Arguments of `sweephold fly`.
#[derive(Args, Debug, Clone)]
#[command(
    after_help = "Each record is written as DIR/<axis>-<n>.bin (the telemetry exactly as the \
flight controller streamed it: read it with `sweephold decode` or `sweephold frf`), plus \
DIR/summary.json (layout in docs/formats.md). The same seed gives byte-identical dumps. With \
`--fc qemu` each record also gets DIR/<axis>-<n>.log: the image's defmt log decoded against \
its ELF, one line per message (loop tick, level, text). The records are flown into \
DIR.partial, which replaces DIR whole when every record was written; a failed run leaves DIR \
as it was and its own files in DIR.failed. DIR must be new, empty or an earlier run's folder."
)]
pub struct FlyArgs {
    /// Aircraft flown: a shipped one (bo105, trex700l, fbl700) or the path of an aircraft file
    /// (docs/formats.md, "Aircraft files"); its file names the firmware preset flown and
    /// the sweep bands.
    #[arg(long, value_name = "NAME|FILE", default_value = "bo105", value_parser = Vehicle::parse)]
    pub vehicle: Vehicle,
    /// How the off-axis inputs are treated.
    #[arg(long, value_enum, default_value_t = ModeArg::Cah)]
    pub mode: ModeArg,
    /// Axes to excite, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "lat,lon,ped,col", value_parser = parse_axis)]
    pub axes: Vec<Axis>,
    /// Primary input signal.
    #[arg(long, value_enum, default_value_t = InputArg::Sweep)]
    pub input: InputArg,
    /// Sweep amplitude: `fixed` (the paper's A = 0.05) or `adaptive` (shaped online by
    /// the firmware to keep the attitudes inside the hold's release band; sweeps only).
    #[arg(long, value_enum, default_value_t = AmplitudeArg::Fixed)]
    pub amplitude: AmplitudeArg,
    /// Campaign seed (firmware noise, sensor noise, gusts).
    #[arg(long, default_value_t = 1, value_parser = arg_values::seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Sweep record length T_rec in s (the paper: 90), 5–1000: shorter records are too
    /// short for the frequency responses of the sweep's upper band.
    #[arg(long = "t-rec", value_name = "SECONDS", default_value_t = plan::PAPER_T_REC_S,
          value_parser = parse_t_rec, allow_hyphen_values = true)]
    pub t_rec_s: f64,
    /// Control loop rate in Hz (50–1000).
    #[arg(long = "rate", value_name = "HZ", default_value_t = 200, allow_hyphen_values = true,
          value_parser = clap::value_parser!(u16).range(50..=1000))]
    pub rate_hz: u16,
    /// Output folder (built in DIR.partial, swapped in when complete; DIR.lock held
    /// meanwhile: a second run on DIR is refused).
    #[arg(long, value_name = "DIR", default_value = "out/fly")]
    pub out: PathBuf,
    /// Turbulence level [m/s RMS of the body-axis gust], >= 0.
    #[arg(long, value_name = "LEVEL", default_value_t = 0.0, value_parser = arg_values::non_negative, allow_hyphen_values = true)]
    pub gust: f64,
    /// Per-tick probability that the sensor sample is not refreshed, 0–1.
    #[arg(long = "sensor-dropout", value_name = "P", default_value_t = 0.0, value_parser = arg_values::probability, allow_hyphen_values = true)]
    pub sensor_dropout: f64,
    /// Per-tick probability of a sensor spike, 0–1.
    #[arg(long = "sensor-spike", value_name = "P", default_value_t = 0.0, value_parser = arg_values::probability, allow_hyphen_values = true)]
    pub sensor_spike: f64,
    /// Seconds after arming at which the pilot moves the lateral stick 20 % off trim
    /// (>= 0, and before the record ends).
    #[arg(long = "pilot-override", value_name = "AT_S", value_parser = arg_values::non_negative, allow_hyphen_values = true)]
    pub pilot_override_at_s: Option<f64>,
    /// RMS of the pilot's stick motion around trim, fraction of travel, 0 to < 0.5.
    #[arg(
        long = "pilot-noise",
        value_name = "RMS",
        default_value_t = 0.0,
        allow_hyphen_values = true,
        value_parser = arg_values::below_half
    )]
    pub pilot_noise: f64,
    /// The pilot's collective stick moves by DELTA (fraction of travel, -2 to 2) at
    /// record time AT_S (seconds from the record's first tick; the test switch goes on
    /// at 0.05 s) and stays there while the test runs: `-1@0` keeps it down from the
    /// start (a test request on the ground), `-1@10` lowers it during the test (a
    /// landing).
    #[arg(long = "collective-step", value_name = "DELTA@AT_S", value_parser = pilot_collective::CollectiveStep::parse, allow_hyphen_values = true)]
    pub collective_step: Option<pilot_collective::CollectiveStep>,
    /// Perfect sensors (no noise, bias or latency).
    #[arg(long = "perfect-sensors")]
    pub perfect_sensors: bool,
    /// Fly the simulator's first-order expansion about the hover trim instead of the
    /// nonlinear model: the aircraft is then exactly the truth the fit is scored
    /// against, so an identification error left on these dumps is the estimator's
    /// (closed loop, windowing, noise), not the aircraft's nonlinearity. A diagnostic;
    /// still air only (refused with --gust).
    #[arg(long = "linearized-plant")]
    pub linearized_plant: bool,
    /// No progress bars.
    #[arg(short, long)]
    pub quiet: bool,
    /// Flight controller in the loop: `in-process` (the firmware library called
    /// directly), `qemu` (the board image in qemu-system-arm, one per worker; its defmt
    /// log is decoded into OUT/RECORD.log), `qemu-usart` (the same over its emulated
    /// USART: slow, no log), `serial:PATH[@BAUD]` (a real board on a serial port,
    /// default 460800 Bd; records flown one at a time) or `board-sim` (the board
    /// application's sensor-to-servo stack on an emulated IMU and SBUS receiver, booted,
    /// armed and hovering before each record, its servo pulses flown through the
    /// aircraft's `[swash]` geometry; see --vibration, --rc-loss, --imu-fault, --fly-on).
    /// `board-sim` is set up from the aircraft file; `board-sim:FLASH` boots the
    /// parameter set saved in FLASH (`sweephold fc params … --fc board-sim:FLASH`; never
    /// written here) and takes only each record's test and rate from the command line.
    #[arg(long, value_name = "FC", default_value = "in-process", value_parser = parse_fc)]
    pub fc: FcArg,
    /// Board image for `--fc qemu` (a 32-bit ARM ELF, checked before QEMU starts) [default:
    /// $SWEEPHOLD_FC_ELF, else target/thumbv7em-none-eabihf/firmware/sweephold-fc of the
    /// workspace this binary was built in, else of the current folder].
    #[arg(long, value_name = "PATH")]
    pub elf: Option<PathBuf>,
    /// `--fc board-sim`: the emulated IMU's imperfections: `default` (bias, noise, scale
    /// errors and the TREX 700L's rotor vibration lines) or `none` (the chip's white noise
    /// alone) [default: default].
    #[arg(long, value_enum, value_name = "LEVEL")]
    pub vibration: Option<VibrationArg>,
    /// `--fc board-sim`: stop sending SBUS frames from this record time on (seconds, >= 0).
    #[arg(long = "rc-loss", value_name = "AT_S", value_parser = arg_values::non_negative, allow_hyphen_values = true)]
    pub rc_loss_at_s: Option<f64>,
    /// `--fc board-sim`: IMU fault of the emulated chip: `stuck@AT_S`, `saturate@AT_S`,
    /// `missing@AT_S` (from that record time on) or `missing` (no chip from power-on:
    /// the board cannot arm).
    #[arg(long = "imu-fault", value_name = "FAULT", value_parser = link_board_sim::ImuFaultPlan::parse)]
    pub imu_fault: Option<link_board_sim::ImuFaultPlan>,
    /// `--fc board-sim`: keep flying this long after the test ended (Done or an abort),
    /// the pilot's hands at trim (seconds, 0–600).
    #[arg(long = "fly-on", value_name = "SECONDS", value_parser = parse_fly_on, allow_hyphen_values = true)]
    pub fly_on_s: Option<f64>,
}

/// `--vibration` on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum VibrationArg {
    /// Bias, noise, scale errors and the rotor vibration lines.
    Default,
    /// The chip's white noise alone (no bias, scale error or vibration): an ideal chip
    /// reads constant at rest, which the IMU monitor takes for a hung chip.
    None,
}

/// Longest `--fly-on` \[s\].
pub const MAX_FLY_ON_S: f64 = 600.0;

fn parse_fly_on(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(t) if (0.0..=MAX_FLY_ON_S).contains(&t) => Ok(t),
        _ => Err(format!("expected seconds from 0 to {MAX_FLY_ON_S}")),
    }
}

/// Flight controller on the command line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FcArg {
    /// The firmware's flight logic called in-process.
    InProcess,
    /// The board image (`cargo fw`) in QEMU's netduinoplus2, frames over semihosting.
    Qemu,
    /// The same, frames over USART1 on a TCP socket (as on the board; ~200 ticks/s).
    QemuUsart,
    /// A real board on a serial port (`serial:PATH[@BAUD]`).
    Serial(link_serial::SerialPort),
    /// The board application (the firmware's `BoardStack`) in-process on an emulated IMU
    /// and an SBUS byte stream; set up from the aircraft file, or booted from the
    /// parameter set saved in a flash file (`board-sim:FLASH`).
    BoardSim(Option<PathBuf>),
}

/// Parse `--fc`: `in-process`, `qemu`, `qemu-usart`, `serial:PATH[@BAUD]` or `board-sim`.
pub fn parse_fc(text: &str) -> Result<FcArg, FcArgError> {
    match text {
        "in-process" => Ok(FcArg::InProcess),
        "board-sim" => Ok(FcArg::BoardSim(None)),
        "qemu" => Ok(FcArg::Qemu),
        "qemu-usart" => Ok(FcArg::QemuUsart),
        _ => match (
            text.strip_prefix("serial:"),
            text.strip_prefix("board-sim:"),
        ) {
            (Some(port), _) => Ok(FcArg::Serial(link_serial::SerialPort::parse(port)?)),
            (_, Some(flash)) if !flash.is_empty() => Ok(FcArg::BoardSim(Some(flash.into()))),
            _ => Err(FcArgError::Unknown(text.to_string())),
        },
    }
}

/// Why an `--fc` value names no flight controller.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FcArgError {
    /// None of the kinds.
    #[error(
        "unknown flight controller `{0}` (expected in-process, qemu, qemu-usart, \
         serial:PATH[@BAUD], board-sim or board-sim:FLASH)"
    )]
    Unknown(String),
    /// `serial:` with a value that names no port.
    #[error(transparent)]
    Serial(#[from] link_serial::SerialPortError),
}

/// Shortest `--t-rec` \[s\]: the upper-band record must hold two windows of ten periods
/// of its ω_max for the cross-control coherence `fly` reports.
pub const MIN_T_REC_S: f64 = 5.0;

/// Longest `--t-rec` \[s\].
pub const MAX_T_REC_S: f64 = 1000.0;

fn parse_t_rec(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(t) if (MIN_T_REC_S..=MAX_T_REC_S).contains(&t) => Ok(t),
        _ => Err(format!(
            "expected a record length from {MIN_T_REC_S} to {MAX_T_REC_S} s"
        )),
    }
}

fn parse_axis(text: &str) -> Result<Axis, String> {
    Axis::ALL
        .into_iter()
        .find(|a| a.name() == text)
        .ok_or_else(|| format!("unknown axis `{text}` (expected lat, lon, ped or col)"))
}

impl FlyArgs {
    /// The board-sim fault planned during the record, as given on the command line
    /// (`--rc-loss 0`, `--imu-fault stuck@0`); `None` when none is.
    fn board_fault(&self) -> Option<String> {
        if let Some(at) = self.rc_loss_at_s {
            return Some(format!("--rc-loss {at}"));
        }
        let plan = self.imu_fault?;
        Some(match plan.at_s {
            Some(at) => format!("--imu-fault {}@{at}", plan.kind.name()),
            None => format!("--imu-fault {}", plan.kind.name()),
        })
    }

    /// The records these arguments fly, in flying order.
    pub fn plans(&self) -> Vec<RecordPlan> {
        let input = match self.input {
            InputArg::Sweep => self.amplitude.sweep_kind(),
            other => other.kind(),
        };
        plan_records(
            &self.vehicle.sweep_bands(),
            &self.axes,
            self.mode.mode(),
            input,
            self.t_rec_s,
            self.seed,
        )
    }

    fn check(&self) -> anyhow::Result<()> {
        if self.axes.is_empty() {
            bail!("--axes names no axis");
        }
        if self.amplitude == AmplitudeArg::Adaptive && self.input != InputArg::Sweep {
            bail!("--amplitude adaptive shapes a sweep: drop it or use --input sweep");
        }
        for (i, axis) in self.axes.iter().enumerate() {
            if self.axes[..i].contains(axis) {
                bail!(
                    "--axes names {} twice: each axis is flown once (its records are {}-1.bin, {}-2.bin)",
                    axis.name(),
                    axis.name(),
                    axis.name()
                );
            }
        }
        for (name, p) in [
            ("--sensor-dropout", self.sensor_dropout),
            ("--sensor-spike", self.sensor_spike),
        ] {
            if !(0.0..=1.0).contains(&p) {
                bail!("{name} {p}: a probability must be in [0, 1]");
            }
        }
        if !(self.gust >= 0.0 && self.gust.is_finite()) {
            bail!("--gust {}: must be a finite level >= 0", self.gust);
        }
        if self.linearized_plant && self.gust > 0.0 {
            bail!(
                "--linearized-plant flies in still air only: drop --gust {}",
                self.gust
            );
        }
        if !(self.pilot_noise >= 0.0 && self.pilot_noise < 0.5) {
            bail!("--pilot-noise {}: must be in [0, 0.5)", self.pilot_noise);
        }
        if !(MIN_T_REC_S..=MAX_T_REC_S).contains(&self.t_rec_s) {
            bail!(
                "--t-rec {}: expected a record length from {MIN_T_REC_S} to {MAX_T_REC_S} s",
                self.t_rec_s
            );
        }
        if !matches!(self.fc, FcArg::BoardSim(_)) {
            let board_only = [
                ("--vibration", self.vibration.is_some()),
                ("--rc-loss", self.rc_loss_at_s.is_some()),
                ("--imu-fault", self.imu_fault.is_some()),
                ("--fly-on", self.fly_on_s.is_some()),
            ];
            if let Some((flag, _)) = board_only.iter().find(|(_, given)| *given) {
                bail!("{flag} is for --fc board-sim only");
            }
        } else if self.rate_hz == 0 || 1000 % self.rate_hz != 0 {
            bail!(
                "--fc board-sim needs a --rate that divides the IMU's 1000 Hz (50, 100, 125, \
                 200, 250, 500 or 1000), not {}",
                self.rate_hz
            );
        }
        if let Some(t) = self.rc_loss_at_s {
            if !t.is_finite() || t < 0.0 {
                bail!("--rc-loss {t}: expected a record time >= 0 s");
            }
        }
        if let Some(t) = self.fly_on_s {
            if !(0.0..=MAX_FLY_ON_S).contains(&t) {
                bail!("--fly-on {t}: expected seconds from 0 to {MAX_FLY_ON_S}");
            }
        }
        if let Some(at) = self.pilot_override_at_s {
            let shortest = self
                .plans()
                .iter()
                .map(|plan| expected_duration_s(&record_config(&self.vehicle, plan, self.rate_hz)))
                .fold(f64::INFINITY, f64::min);
            if !(at >= 0.0 && at < shortest) {
                bail!(
                    "--pilot-override {at}: expected a time from 0 to {shortest:.1} s after arming \
                     (the end of the shortest record)"
                );
            }
        }
        Ok(())
    }
}

/// The firmware configuration of one record.
pub fn record_config(vehicle: &Vehicle, plan: &RecordPlan, rate_hz: u16) -> Config {
    let mut config = vehicle.firmware_config(plan.axis);
    config.rate_hz = rate_hz;
    config.test.mode = plan.mode;
    config.test.input = plan.input;
    config.test.primary = plan.axis;
    config.test.seed = plan.seed;
    config.test.sweep.omega_min = plan.omega_min as f32;
    config.test.sweep.omega_max = plan.omega_max as f32;
    config.test.sweep.t_rec_s = plan.t_rec_s as f32;
    config.test.sweep.amplitude = plan.amplitude as f32;
    config.test.pulse.amplitude = plan.amplitude as f32;
    config
}

/// Result of a whole `fly` run.
pub struct FlyOutcome {
    /// The summary written to `summary.json`.
    pub summary: FlySummary,
    /// Dump paths, in flying order.
    pub dumps: Vec<PathBuf>,
    /// The sweep record of each dump as decoded for its cross-control coherence, in
    /// flying order (`None` for an aborted record or another input than a sweep), so that
    /// a caller needs not decode the dumps again. Its `source` is the dump's file name.
    pub records: Vec<Option<Record>>,
    /// The trim attitude φ, θ \[rad\] each record's flight controller captured, in flying
    /// order, as the telemetry streamed (`None` where it captured none).
    pub trims: Vec<Option<[f32; 2]>>,
}

/// Run `sweephold fly`: the records are flown into `OUT.partial`, which replaces OUT
/// only when every record was written (see [`crate::output::StagedFolder`]).
pub fn run(args: &FlyArgs) -> anyhow::Result<()> {
    validate(args)?;
    // The board image is found (and checked) before anything is written.
    let image = match (&args.fc, &args.elf) {
        (FcArg::Qemu | FcArg::QemuUsart, elf) => {
            let image = match elf {
                Some(path) => path.clone(),
                None => link_qemu::default_image()?,
            };
            link_qemu::check_image(&image)?;
            link_qemu::qemu_available()?;
            Some(image)
        }
        _ => None,
    };
    let staged = StagedFolder::begin(&args.out)?;
    // The test hook's first point: the lock held and the staging folder made, nothing flown.
    crate::interrupt::pause_point("setup");
    let mut staged_args = args.clone();
    staged_args.out = staged.path().to_path_buf();
    let flown = fly_on_link(&staged_args, image.as_deref()).and_then(|outcome| {
        // The last safe point: a signal up to here leaves DIR as it was.
        crate::interrupt::pause_point("complete");
        crate::interrupt::check().map(|()| outcome)
    });
    let outcome = match flown {
        Ok(outcome) => {
            staged.complete()?;
            outcome
        }
        Err(error) => {
            let kept = match staged.fail() {
                Ok(failed) => format!("its files are in {}", failed.display()),
                Err(e) => format!("{e:#}"),
            };
            return Err(error.context(format!(
                "fly failed ({kept}; {} is unchanged)",
                args.out.display()
            )));
        }
    };
    if !args.quiet {
        for run in &outcome.summary.runs {
            let coherence: Vec<String> = run
                .cross_coherence
                .iter()
                .map(|(k, v)| format!("{k} {v:.2}"))
                .collect();
            crate::note!(
                "{:>9}  {:6.1} s  {}  max |phi| {:4.1} deg, |theta| {:4.1} deg  cross-coherence: {}",
                run.file,
                run.duration_s,
                run.abort_reason.as_deref().map_or("ok     ".to_string(), |r| format!("ABORT {r}")),
                run.max_abs_deg.phi,
                run.max_abs_deg.theta,
                if coherence.is_empty() { "-".to_string() } else { coherence.join(", ") }
            );
            if let Some(estimator) = &run.estimator {
                let e = estimator.max_error_deg;
                crate::note!(
                    "{:>9}  board estimate: max error phi {:.2} deg, theta {:.2} deg",
                    "",
                    e.phi,
                    e.theta
                );
            }
            if let Some(after) = &run.after {
                crate::note!(
                    "{:>9}  after the test: {:.1} s in {}, max |phi| {:4.1} deg, |theta| {:4.1} deg",
                    "", after.duration_s, after.mode, after.max_abs_deg.phi, after.max_abs_deg.theta
                );
            }
        }
        crate::note!(
            "wrote {} records and summary.json to {}",
            outcome.dumps.len(),
            args.out.display()
        );
    }
    Ok(())
}

/// Fly `args` into `args.out` over the link `args.fc` names.
fn fly_on_link(args: &FlyArgs, image: Option<&std::path::Path>) -> anyhow::Result<FlyOutcome> {
    match &args.fc {
        FcArg::InProcess => fly(args, &|| Box::new(InProcessLink::new())),
        FcArg::Qemu | FcArg::QemuUsart => {
            let image = image.ok_or_else(|| anyhow::anyhow!("no board image"))?;
            let extra = link_qemu::extra_args_from_env();
            let transport = if args.fc == FcArg::Qemu {
                link_qemu::QemuTransport::Semihosting
            } else {
                link_qemu::QemuTransport::Usart
            };
            fly(args, &|| {
                Box::new(
                    link_qemu::QemuLink::new(image, transport, &extra).with_log_folder(&args.out),
                )
            })
        }
        // One port, one board: the records are flown one after the other.
        FcArg::Serial(port) => fly_with_workers(
            args,
            &|| Box::new(link_serial::SerialLink::new(port.clone())),
            1,
        ),
        FcArg::BoardSim(_) => fly_board_sim(args),
    }
}

/// Fly `args` into `args.out` on the board-sim link (one per worker).
pub fn fly_board_sim(args: &FlyArgs) -> anyhow::Result<FlyOutcome> {
    let settings = board_sim_settings(args)?;
    fly(args, &|| {
        Box::new(link_board_sim::BoardSimLink::new(settings.clone()))
    })
}

/// The board-sim link's settings for `args`.
pub fn board_sim_settings(args: &FlyArgs) -> anyhow::Result<link_board_sim::BoardSimSettings> {
    let heli = args.vehicle.helicopter();
    let trim = rotorsim::trim(&heli, 0.0)
        .map_err(|e| anyhow::anyhow!("{} does not trim in hover: {e}", args.vehicle.name()))?;
    Ok(link_board_sim::BoardSimSettings {
        heli,
        trim,
        sim_options: sim_options(args),
        vibration: args.vibration != Some(VibrationArg::None),
        rc_loss_at_s: args.rc_loss_at_s,
        imu_fault: args.imu_fault,
        swash: args.vehicle.aircraft().swash,
        test_list: board_test_list::campaign_list(&args.vehicle, args.t_rec_s),
        setup: match &args.fc {
            FcArg::BoardSim(Some(flash)) => link_board_sim::BoardSetup::Stored(Box::new(
                board_flash::load_params(flash, args.vehicle.preset())?,
            )),
            _ => link_board_sim::BoardSetup::FromAircraft,
        },
    })
}

/// The simulator's options for `args` (before the seed and the disturbances).
fn sim_options(args: &FlyArgs) -> rotorsim::SimOptions {
    let mut sim_options = rotorsim::SimOptions {
        actuator: args.vehicle.servos(),
        ..rotorsim::SimOptions::default()
    };
    if args.perfect_sensors {
        // Sensors only: the actuators keep their servo dynamics and delay.
        sim_options.sensor_noise = rotorsim::SensorNoise::perfect();
    }
    sim_options.linearized_plant = args.linearized_plant;
    sim_options
}

/// Refuse a bad command line or a configuration the firmware would refuse, before
/// anything is flown or written.
pub fn validate(args: &FlyArgs) -> anyhow::Result<()> {
    args.check()?;
    if let FcArg::BoardSim(Some(flash)) = &args.fc {
        board_flash::load_params(flash, args.vehicle.preset())?;
    }
    let plans = args.plans();
    for plan in &plans {
        let config = record_config(&args.vehicle, plan, args.rate_hz);
        sweephold_firmware::FlightController::new(config).map_err(|e| {
            anyhow::anyhow!(
                "record {}: the firmware refuses this configuration: {}",
                plan.file_name(),
                e.message()
            )
        })?;
    }
    Ok(())
}

/// Fly every record of `args` with links made by `make_link` (one per worker thread),
/// write the dumps and `summary.json`, and return the summary.
pub fn fly(
    args: &FlyArgs,
    make_link: &(dyn Fn() -> Box<dyn FlightControllerLink> + Sync),
) -> anyhow::Result<FlyOutcome> {
    fly_with_workers(args, make_link, usize::MAX)
}

/// [`fly`] with at most `max_workers` worker threads (links): 1 for a link that cannot
/// be shared, such as a board on a serial port.
pub fn fly_with_workers(
    args: &FlyArgs,
    make_link: &(dyn Fn() -> Box<dyn FlightControllerLink> + Sync),
    max_workers: usize,
) -> anyhow::Result<FlyOutcome> {
    validate(args)?;
    let heli = args.vehicle.helicopter();
    let trim = rotorsim::trim(&heli, 0.0)
        .map_err(|e| anyhow::anyhow!("{} does not trim in hover: {e}", args.vehicle.name()))?;
    let plans = args.plans();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output folder {}", args.out.display()))?;

    let sim_options = sim_options(args);
    let disturbances = Disturbances {
        gust_level: args.gust,
        sensor_dropout: args.sensor_dropout,
        sensor_spike: args.sensor_spike,
        pilot_override_at_s: args.pilot_override_at_s,
        pilot_stick_noise: args.pilot_noise,
        collective_step: args.collective_step,
        fly_on_s: args.fly_on_s.unwrap_or(0.0),
    };

    let bars = MultiProgress::with_draw_target(if args.quiet {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    });
    let style = ProgressStyle::with_template("{prefix:>9} [{bar:30}] {pos:>4}/{len} s {msg}")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");

    let next = Mutex::new(0usize);
    let results: Mutex<Vec<Option<anyhow::Result<FinishedRecord>>>> =
        Mutex::new(plans.iter().map(|_| None).collect());
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(plans.len())
        .min(max_workers)
        .max(1);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                let mut link = make_link();
                loop {
                    let i = {
                        let mut next = next.lock().unwrap_or_else(|e| e.into_inner());
                        let i = *next;
                        *next += 1;
                        i
                    };
                    let Some(plan) = plans.get(i) else { break };
                    let config = record_config(&args.vehicle, plan, args.rate_hz);
                    let max_s = expected_duration_s(&config) + 10.0;
                    let bar = bars.add(ProgressBar::new(max_s as u64));
                    bar.set_style(style.clone());
                    bar.set_prefix(plan.file_name());
                    let mut options = sim_options;
                    options.seed = args.seed ^ u64::from(plan.seed).rotate_left(17);
                    let aircraft = record::Aircraft {
                        heli: &heli,
                        trim: &trim,
                        options,
                    };
                    let result = fly_record(
                        link.as_mut(),
                        &config,
                        aircraft,
                        &disturbances,
                        max_s,
                        |t| bar.set_position(t as u64),
                    );
                    // The link's own record of it (the image's log), even for a failed one.
                    let logged = link.end_record(&plan.file_name());
                    let result = result
                        .and_then(|flown| logged.map(|()| flown))
                        .and_then(|flown| finish_record(args, plan, &config, flown));
                    bar.finish_and_clear();
                    results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(result);
                }
            });
        }
    });

    let mut runs = Vec::new();
    let mut records = Vec::new();
    let mut trims = Vec::new();
    for (plan, result) in plans
        .iter()
        .zip(results.into_inner().unwrap_or_else(|e| e.into_inner()))
    {
        let run = result.unwrap_or_else(|| Err(anyhow::anyhow!("not flown")));
        let (run, record, trim) = run.with_context(|| format!("record {}", plan.file_name()))?;
        runs.push(run);
        records.push(record);
        trims.push(trim);
    }
    let link = make_link().describe();
    let summary = FlySummary {
        vehicle: args.vehicle.name().to_string(),
        mode: args.mode.name().to_string(),
        rate_hz: u32::from(args.rate_hz),
        seed: args.seed,
        link,
        plant: if args.linearized_plant {
            "linearized"
        } else {
            "nonlinear"
        }
        .to_string(),
        runs,
    };
    let path = args.out.join("summary.json");
    // The test hook: every record written, the summary not yet.
    crate::interrupt::pause_point("summary");
    write_json(&path, &summary)?;
    let dumps = plans.iter().map(|p| args.out.join(p.file_name())).collect();
    Ok(FlyOutcome {
        summary,
        dumps,
        records,
        trims,
    })
}

/// Seconds from arming to the end of the excitation for `config` (trim capture, fades,
/// the ω_min hold and the record).
pub fn expected_duration_s(config: &Config) -> f64 {
    let excitation = sweephold_firmware::excitation::Excitation::from_test(&config.test);
    f64::from(config.trim_capture_s) + excitation.duration_s()
}

/// A record written: its summary, its sweep as decoded for the summary (if a sweep that
/// did not abort) and the trim attitude its flight controller captured.
type FinishedRecord = (RunSummary, Option<Record>, Option<[f32; 2]>);

fn finish_record(
    args: &FlyArgs,
    plan: &RecordPlan,
    config: &Config,
    flown: record::FlownRecord,
) -> anyhow::Result<FinishedRecord> {
    write_atomic(&args.out.join(plan.file_name()), &flown.dump)?;
    if !flown.began {
        if let Some(refusal) = &flown.test_refused {
            bail!("the flight controller refused the test ({refusal}): no test started");
        }
        if let Some(fault) = args.board_fault() {
            let mode = flown
                .first_mode_change
                .map_or_else(String::new, |change| format!(": the board went {change}"));
            bail!("{fault} ended the record before it began (no test started{mode})");
        }
    }
    let record = if plan.input.is_sweep() && flown.abort.is_none() {
        Some(sysid::frf::load_dump_bytes(&flown.dump, &plan.file_name())?)
    } else {
        None
    };
    let cross_coherence = match &record {
        Some(record) => record_cross_coherence(record)?,
        None => BTreeMap::new(),
    };
    let run = RunSummary {
        axis: plan.axis.name().to_string(),
        index: plan.index,
        file: plan.file_name(),
        omega_min: plan.omega_min,
        omega_max: plan.omega_max,
        duration_s: flown.ticks as f64 / f64::from(config.rate_hz),
        frames: flown.frames,
        aborted: flown.abort.is_some(),
        abort_reason: flown.abort.map(|r| r.name().to_string()),
        max_abs_deg: flown.max_abs_deg,
        max_from_trim_deg: flown.max_from_trim_deg,
        hold_fraction: flown.hold_fraction,
        cross_coherence,
        estimator: matches!(args.fc, FcArg::BoardSim(_)).then_some(summary::EstimatorSummary {
            max_error_deg: flown.attitude_error_deg,
        }),
        after: flown.after,
    };
    Ok((run, record, flown.trim_captured))
}

/// Mean coherence between the primary control and each other excited control over the
/// sweep band of one record (sysid's cross-control coherence).
pub fn record_cross_coherence(record: &Record) -> anyhow::Result<BTreeMap<String, f64>> {
    let primary = record.primary.clone();
    let pairs = sysid::frf::cross_control_coherence(record, &sysid::frf::FrfOptions::default())?;
    Ok(pairs
        .into_iter()
        .map(|c| (if c.a == primary { c.b } else { c.a }, c.mean))
        .collect())
}
