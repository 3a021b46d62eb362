//! `sweephold tune`: pilot-mode gains designed on an identified model (`control::tune`:
//! the method in its module documentation and docs/method.md, "Pilot-mode gains").

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{anyhow, bail};
use clap::Args;
use control::law::BoardLaw;
use control::tune::{self, LoopCheck, Models, TuneOptions};
use serde::Serialize;
use sweephold_firmware::app::pilot_mode::{PilotModeGains, RateAxisGains};
use sweephold_firmware::params::ParamId;

use crate::fc::client::BoardValue;
use crate::fc::params_file;

use crate::margins::{model_and_vehicle, structure_of, vehicle_servo, LawArgs};
use crate::output::{check_input_file, refuse_inputs_as_outputs, write_atomic, write_json};
use crate::vehicle::Vehicle;

/// Arguments of `sweephold tune`.
#[derive(Args, Debug)]
#[command(
    after_help = "Designs the gains of the board's pilot-mode loops on the model, \
under the firmware's law as `sweephold margins` computes it (the vehicle's preset, 200 Hz \
tick, IMU filter bank, the vehicle's servo where the model has none): Kp and Ki of the \
roll, pitch and yaw rate loops for a crossover (stated with --crossover, otherwise the \
highest that meets the constraints, up to 20 rad/s on roll and pitch and 15 rad/s on yaw), \
then the level gain K_lvl and the heading-hold gain K_psi, each the highest up to half \
(--outer-fraction) of its inner loop's crossover. Constraints on every loop broken at its actuator with the \
others closed: phase margin >= 45 deg at its crossover and gain margin >= 6 dB above it, on \
the identified model and on the 5th percentile of --samples models drawn from the fit's \
Cramer-Rao bounds; the servo rate for a full Rate-stick step within the aircraft file's \
servo rate limit (or within the preset gains' rate where these already exceed it). Prints \
the predicted figures of the preset's gains and the tuned ones side by side; --out writes \
the tuned gains and the figures as JSON; --params writes the eight tuned gains as a params \
file (PM_ROLL_KP, PM_ROLL_KI, PM_PITCH_KP, PM_PITCH_KI, PM_YAW_KP, PM_YAW_KI, PM_LEVEL_K, \
PM_HEADING_K) for `sweephold fc params push FILE --save --fc …`. When no gains meet the constraints: one line naming \
the loop and the constraint, exit status 1."
)]
pub struct TuneArgs {
    /// The identified model (`model.json`, `model9.json`).
    #[arg(value_name = "MODEL.json")]
    pub model: PathBuf,
    /// The aircraft whose preset flies the loops and whose servo (and its rate limit) is
    /// used: a shipped name (bo105, trex700l, fbl700) or an aircraft file. Default: the
    /// one the model's structure is named after (bo105 or trex700l).
    #[arg(long, value_name = "NAME|FILE", value_parser = Vehicle::parse)]
    pub vehicle: Option<Vehicle>,
    /// A rate loop's crossover, AXIS=RAD_S with AXIS roll, pitch or yaw (repeatable):
    /// the gains are designed for it or refused.
    #[arg(long, value_name = "AXIS=RAD_S", value_parser = crossover)]
    pub crossover: Vec<(usize, f64)>,
    /// Write the tuned gains and the figures (JSON) to this file.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Write the tuned gains as a params file (`PM_*` parameters only) that `sweephold
    /// fc params push` loads.
    #[arg(long, value_name = "FILE")]
    pub params: Option<PathBuf>,
    /// Print the JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Models drawn over the covariance for the robust margins.
    #[arg(long, default_value_t = 100, value_parser = crate::arg_values::count::<0, 10000>, allow_hyphen_values = true)]
    pub samples: usize,
    /// Seed of the draws.
    #[arg(long, default_value_t = 1, value_parser = crate::arg_values::seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// The highest outer-loop gain tried (K_lvl, K_psi, in 1/s) as a fraction of the
    /// crossover of the rate loop it closes around, 0 < F <= 4.
    #[arg(long, value_name = "F", default_value_t = TuneOptions::default().outer_fraction, value_parser = outer_fraction)]
    pub outer_fraction: f64,
    /// What the board adds around the model.
    #[command(flatten)]
    pub law: LawArgs,
}

/// `--outer-fraction F`: finite, 0 < F <= 4.
fn outer_fraction(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(f) if f.is_finite() && f > 0.0 && f <= 4.0 => Ok(f),
        _ => Err("expected a fraction > 0 and <= 4".to_string()),
    }
}

/// `--crossover AXIS=RAD_S`.
fn crossover(text: &str) -> Result<(usize, f64), String> {
    let (axis, value) = text
        .split_once('=')
        .ok_or("expected AXIS=RAD_S, e.g. roll=8")?;
    let axis = match axis.trim() {
        "roll" => 0,
        "pitch" => 1,
        "yaw" => 2,
        other => return Err(format!("unknown axis `{other}` (roll, pitch or yaw)")),
    };
    match value.trim().parse::<f64>() {
        Ok(w) if w.is_finite() && w > 0.0 => Ok((axis, w)),
        _ => Err("expected a crossover in rad/s > 0".to_string()),
    }
}

/// The gains `tune` sets, by the firmware's field names.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GainSet {
    /// Roll rate loop Kp \[stick/(rad/s)\], Ki \[stick/rad\].
    pub roll: [f32; 2],
    /// Pitch rate loop Kp, Ki.
    pub pitch: [f32; 2],
    /// Yaw rate loop Kp, Ki.
    pub yaw: [f32; 2],
    /// Level gain K_lvl \[1/s\].
    pub level_gain: f32,
    /// Heading-hold gain K_ψ \[1/s\].
    pub heading_gain: f32,
}

impl GainSet {
    fn of(gains: &PilotModeGains) -> GainSet {
        let pi = |axis: &RateAxisGains| [axis.kp, axis.ki];
        GainSet {
            roll: pi(&gains.roll),
            pitch: pi(&gains.pitch),
            yaw: pi(&gains.yaw),
            level_gain: gains.level_gain,
            heading_gain: gains.heading_gain,
        }
    }
}

/// `tune.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TuneDocument {
    /// The model's structure name.
    pub structure: String,
    /// The vehicle whose preset and servo were used.
    pub vehicle: String,
    /// Models drawn, their seed, parameters drawn.
    pub samples: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Free parameters drawn (0: no robust check).
    pub drawn_parameters: usize,
    /// The percentile of the draws the margins hold on.
    pub percentile: f64,
    /// The servo rate limit checked [stick/s] (null: none).
    pub servo_rate_limit_per_s: Option<f64>,
    /// The rate-loop crossovers designed for (roll, pitch, yaw) [rad/s].
    pub designed_crossovers_rad_s: [f64; 3],
    /// The preset's gains.
    pub shipped: GainSet,
    /// The tuned gains.
    pub tuned: GainSet,
    /// The six loops under the preset's gains.
    pub shipped_loops: Vec<LoopCheck>,
    /// The six loops under the tuned gains.
    pub tuned_loops: Vec<LoopCheck>,
    /// Servo rate for a full Rate-stick step per axis [stick/s]: [shipped, tuned].
    pub servo_rate_per_s: [[Option<f64>; 2]; 3],
    /// Why there is no robust check, when there is none.
    pub notes: Vec<String>,
}

/// Run `sweephold tune`.
pub fn run(args: &TuneArgs) -> anyhow::Result<()> {
    check_input_file("model", &args.model)?;
    let mut outputs = Vec::new();
    if let Some(out) = &args.out {
        outputs.push(("--out", out.as_path()));
    }
    if let Some(params) = &args.params {
        outputs.push(("--params", params.as_path()));
    }
    refuse_inputs_as_outputs(&[args.model.as_path()], &outputs)?;
    if let (Some(out), Some(params)) = (&args.out, &args.params) {
        // The same path twice: one file would silently replace the other.
        refuse_inputs_as_outputs(&[out.as_path()], &[("--params", params.as_path())])?;
    }
    let mut crossovers = [None; 3];
    for &(axis, w) in &args.crossover {
        if crossovers[axis].replace(w).is_some() {
            bail!(
                "--crossover: the {} axis is given twice",
                ["roll", "pitch", "yaw"][axis]
            );
        }
    }
    let (document, vehicle) = model_and_vehicle(&args.model, args.vehicle.as_ref())?;
    let model = document
        .model()
        .ok_or_else(|| anyhow!("{}: a matrix has the wrong size", args.model.display()))?;
    let mut law: BoardLaw = args.law.preset_law(&vehicle);
    law.servos = control::analysis::added_servos(&model, vehicle_servo(&vehicle));
    let rate_limit = vehicle.servos().rate_limit_per_s;
    let options = TuneOptions {
        crossovers,
        samples: args.samples,
        seed: args.seed,
        outer_fraction: args.outer_fraction,
        servo_rate_limit_per_s: (rate_limit.is_finite() && rate_limit > 0.0).then_some(rate_limit),
        ..TuneOptions::default()
    };
    let structure = structure_of(&document, &vehicle);
    let models = Models::new(&document, structure.as_ref().ok(), &law, &options)
        .map_err(|e| anyhow!("{}: {e}", args.model.display()))?;
    let mut notes: Vec<String> = models.note.iter().cloned().collect();
    if let Err(why) = &structure {
        notes.push(format!("no robust check: {why}"));
    } else if models.draws() == 0 {
        notes.push(
            "no draws (--samples 0): the constraints held on the identified model only".to_string(),
        );
    }
    let tuned = tune::tune(&models, &law, &options).map_err(|refusal| anyhow!("{refusal}"))?;
    let mut tuned_law = law.clone();
    tuned_law.gains = tuned.gains;
    let checks = |law: &BoardLaw| {
        (0..tune::LOOPS.len())
            .map(|i| tune::check_loop(&models, law, i, &options))
            .collect::<Vec<_>>()
    };
    let servo_rate = |law: &BoardLaw, axis| {
        tune::servo_rate::stick_step_servo_rate(models.plant(), law, axis, options.stick_step)
    };
    let result = TuneDocument {
        structure: document.structure.clone(),
        vehicle: vehicle.name().to_string(),
        samples: models.draws(),
        seed: args.seed,
        drawn_parameters: models.drawn_parameters(),
        percentile: options.percentile,
        servo_rate_limit_per_s: options.servo_rate_limit_per_s,
        designed_crossovers_rad_s: tuned.designed_crossovers,
        shipped: GainSet::of(&law.gains),
        tuned: GainSet::of(&tuned.gains),
        shipped_loops: checks(&law),
        tuned_loops: checks(&tuned_law),
        servo_rate_per_s: std::array::from_fn(|axis| {
            [servo_rate(&law, axis), servo_rate(&tuned_law, axis)]
        }),
        notes,
    };
    // Checked before anything is written: a gain the board's table refuses is an error.
    let params_text = match &args.params {
        Some(_) => Some(params_file::write_tuned(
            &args.model.display().to_string(),
            &result.vehicle,
            &tuned_params(&result.tuned)?,
        )),
        None => None,
    };
    if let Some(out) = &args.out {
        write_json(out, &result)?;
    }
    if let (Some(path), Some(text)) = (&args.params, &params_text) {
        write_atomic(path, text.as_bytes())?;
    }
    if args.json {
        let mut text = serde_json::to_string_pretty(&result)?;
        text.push('\n');
        crate::output::print(&text)
    } else {
        crate::output::print(&table(&result))
    }
}

/// The tuned gains as the board's `PM_*` parameters, in the table's order; a value the
/// table refuses (outside its range) is an error naming it.
fn tuned_params(gains: &GainSet) -> anyhow::Result<Vec<BoardValue>> {
    let values = [
        (ParamId::PilotRollKp, gains.roll[0]),
        (ParamId::PilotRollKi, gains.roll[1]),
        (ParamId::PilotPitchKp, gains.pitch[0]),
        (ParamId::PilotPitchKi, gains.pitch[1]),
        (ParamId::PilotYawKp, gains.yaw[0]),
        (ParamId::PilotYawKi, gains.yaw[1]),
        (ParamId::PilotLevelGain, gains.level_gain),
        (ParamId::PilotHeadingGain, gains.heading_gain),
    ];
    values
        .into_iter()
        .map(|(id, value)| {
            let def = id.def();
            def.check(value).map_err(|why| {
                anyhow!(
                    "--params: tuned {} = {value} is refused by the board's table ({}: {} … {})",
                    def.name,
                    why.message(),
                    def.min,
                    def.max
                )
            })?;
            Ok(BoardValue {
                name: def.name.to_string(),
                value,
            })
        })
        .collect()
}

fn cell(spread: &tune::Spread, decimals: usize) -> String {
    let value = spread
        .value
        .map_or("—".to_string(), |v| format!("{v:.decimals$}"));
    match (spread.spread, spread.percentile) {
        (Some(s), Some(p)) => format!("{value} ± {s:.decimals$} ({p:.decimals$})"),
        (Some(s), None) => format!("{value} ± {s:.decimals$}"),
        _ => value,
    }
}

/// The table on standard output.
fn table(result: &TuneDocument) -> String {
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{} ({}): {} draws of {} parameters (seed {}); figure ± spread (5th percentile); \
         GM: above the crossover, — none there",
        result.vehicle, result.structure, result.samples, result.drawn_parameters, result.seed
    );
    let _ = writeln!(
        text,
        "\n{:<15} {:<7} {:>26} {:>24} {:>24} {:>24}",
        "loop", "gains", "wc [rad/s]", "PM [deg]", "GM [dB]", "DRB [rad/s]"
    );
    for (shipped, tuned) in result.shipped_loops.iter().zip(&result.tuned_loops) {
        for (label, check) in [("shipped", shipped), ("tuned", tuned)] {
            let _ = writeln!(
                text,
                "{:<15} {:<7} {:>26} {:>24} {:>24} {:>24}",
                check.name,
                label,
                cell(&check.crossover_rad_s, 2),
                cell(&check.phase_margin_deg, 1),
                cell(&check.gain_margin_db, 1),
                cell(&check.drb_rad_s, 2),
            );
        }
    }
    let _ = writeln!(text, "\n{:<14} {:>12} {:>12}", "gain", "shipped", "tuned");
    let rows = [
        ("roll Kp", result.shipped.roll[0], result.tuned.roll[0]),
        ("roll Ki", result.shipped.roll[1], result.tuned.roll[1]),
        ("pitch Kp", result.shipped.pitch[0], result.tuned.pitch[0]),
        ("pitch Ki", result.shipped.pitch[1], result.tuned.pitch[1]),
        ("yaw Kp", result.shipped.yaw[0], result.tuned.yaw[0]),
        ("yaw Ki", result.shipped.yaw[1], result.tuned.yaw[1]),
        ("K_lvl", result.shipped.level_gain, result.tuned.level_gain),
        (
            "K_psi",
            result.shipped.heading_gain,
            result.tuned.heading_gain,
        ),
    ];
    for (name, shipped, tuned) in rows {
        let _ = writeln!(text, "{name:<14} {shipped:>12.4} {tuned:>12.4}");
    }
    let limit = result
        .servo_rate_limit_per_s
        .map_or("not checked".to_string(), |l| format!("limit {l} /s"));
    let _ = writeln!(
        text,
        "\nservo rate, full Rate-stick step [stick/s] ({limit}):"
    );
    for (axis, [shipped, tuned]) in ["roll", "pitch", "yaw"]
        .iter()
        .zip(&result.servo_rate_per_s)
    {
        let show = |v: &Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.2}"));
        let _ = writeln!(text, "{axis:<14} {:>12} {:>12}", show(shipped), show(tuned));
    }
    for note in &result.notes {
        let _ = writeln!(text, "note: {note}");
    }
    text
}
