//! `sweephold fly`'s command line: the clap types of its options (mode, input,
//! amplitude, link, vibration), their parsers and the checks a command line must pass
//! before anything is flown.

use anyhow::bail;
use clap::{Args, ValueEnum};
use sweephold_protocol::{Axis, ExcitationMode, InputKind};

use std::path::PathBuf;

use super::plan::{self, plan_records, RecordPlan};
use super::{expected_duration_s, link_board_sim, link_serial, pilot_collective, record_config};
use crate::arg_values;
use crate::vehicle::Vehicle;

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
    /// A loop test (one record per axis, from the first band's lower end to at least
    /// 62.8 rad/s; the board-sim link only, axes lat, lon, ped): the sweep added at the
    /// pilot-mode loop's output with the board's loops closed, for `margins --measured`.
    Loop,
}

impl InputArg {
    fn kind(self) -> InputKind {
        match self {
            InputArg::Sweep => InputKind::Sweep,
            InputArg::Doublet => InputKind::Doublet,
            InputArg::ThreeTwoOneOne => InputKind::ThreeTwoOneOne,
            InputArg::Loop => InputKind::LoopSweep,
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
    /// `--fc board-sim`, with --fly-on: a discrete gust AT_S seconds after the test ended,
    /// the pilot's hands at trim: body-axis air velocity rising from zero to (U, V, W)
    /// m/s and falling back as 1 - cos over 1 s (each component within ±20 m/s; the
    /// flight must go on at least 1 s beyond AT_S). summary.json's `after.gust_pulse`
    /// holds the peak |phi|, |theta| excursion from the attitude at its onset.
    #[arg(long = "gust-pulse", value_name = "AT_S:U,V,W", value_parser = super::gust_pulse::GustPulse::parse, allow_hyphen_values = true)]
    pub gust_pulse: Option<super::gust_pulse::GustPulse>,
    /// `--fc board-sim`: `per-record` powers the board up for every record (its settings
    /// the record's); `once` flies every record on one power-up, one after the other, each
    /// test chosen from the board's test list by the transmitter's selector with 10 s of
    /// steady hover between two tests, and writes the board's log of the power-up, every
    /// frame from power-on, as `log/power-up-N.bin` (a record that ends outside the pilot
    /// mode ends the power-up: the next one starts another) [default: per-record].
    #[arg(long = "power-up", value_enum, value_name = "HOW")]
    pub power_up: Option<PowerUpArg>,
    /// `--fc board-sim`: fly no test but the steady flights of `sim trim-points` (hover,
    /// 1 m/s forward, aft, right, left, 0.5 m/s climb and descent, ±0.1 rad/s turns), each
    /// 8 s to settle and 10 s held, in the pilot mode on one power-up with the flight's
    /// --seed and --gust; writes the board's log `log/power-up-1.bin` and the simulated
    /// GNSS's `gnss.csv` (10 Hz, 0.1 m/s white noise per velocity; docs/formats.md).
    #[arg(long = "steady-flights")]
    pub steady_flights: bool,
}

/// `--power-up` on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PowerUpArg {
    /// One power-up per record.
    PerRecord,
    /// Every record on one power-up.
    Once,
}

impl PowerUpArg {
    /// The link's setting for `--power-up` (None: per record).
    pub fn link(arg: Option<PowerUpArg>) -> link_board_sim::PowerUp {
        match arg {
            Some(PowerUpArg::Once) => link_board_sim::PowerUp::Once,
            Some(PowerUpArg::PerRecord) | None => link_board_sim::PowerUp::PerRecord,
        }
    }
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
    pub(super) fn board_fault(&self) -> Option<String> {
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

    pub(super) fn check(&self) -> anyhow::Result<()> {
        if self.axes.is_empty() {
            bail!("--axes names no axis");
        }
        if self.amplitude == AmplitudeArg::Adaptive && self.input != InputArg::Sweep {
            bail!("--amplitude adaptive shapes a sweep: drop it or use --input sweep");
        }
        if self.input == InputArg::Loop {
            if !matches!(self.fc, FcArg::BoardSim(_)) {
                bail!("--input loop breaks the board's pilot-mode loops: it needs --fc board-sim");
            }
            if self.axes.contains(&Axis::Col) {
                bail!("--input loop: the collective has no loop to break (use --axes lat,lon,ped)");
            }
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
                ("--gust-pulse", self.gust_pulse.is_some()),
                ("--power-up", self.power_up.is_some()),
                ("--steady-flights", self.steady_flights),
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
        if self.steady_flights {
            let timed = [
                ("--rc-loss", self.rc_loss_at_s.is_some()),
                ("--fly-on", self.fly_on_s.is_some()),
                ("--pilot-override", self.pilot_override_at_s.is_some()),
                (
                    "--imu-fault KIND@AT_S",
                    self.imu_fault.is_some_and(|f| f.at_s.is_some()),
                ),
            ];
            if let Some((flag, _)) = timed.iter().find(|(_, given)| *given) {
                bail!("{flag} counts record time: --steady-flights flies no record");
            }
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
        if let Some(gust) = self.gust_pulse {
            let end = gust.at_s + super::gust_pulse::GUST_LENGTH_S;
            if self.fly_on_s.is_none_or(|t| t < end) {
                bail!(
                    "--gust-pulse {}: the gust blows after the test, while flying on: it needs \
                     --fly-on {end} or longer",
                    gust.at_s
                );
            }
            if self.linearized_plant {
                bail!("--linearized-plant flies in still air only: drop --gust-pulse");
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
