//! `sweephold margins`: the loop margins and handling qualities of the board's pilot-mode
//! loops predicted from an identified model (`control` crate: method in its module
//! documentation and docs/method.md, "Loop margins and handling qualities").

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context};
use clap::Args;
use control::analysis::{self, AnalysisOptions, Figure, MarginsDocument, POOR_PAIR_COST};
use control::law::BoardLaw;
use control::Plant;
use serde::{Deserialize, Serialize};
use sweephold_firmware::app::AppConfig;
use sweephold_firmware::board_stack::StackConfig;
use sweephold_protocol::Axis;
use sysid::fit::model::Actuator;
use sysid::fit::{ModelDocument, ModelStructure};
use sysid::models;

use crate::artifacts::files;
use crate::measured_loop;
use crate::output::{check_input_file, refuse_inputs_as_outputs, write_json};
use crate::structures;
use crate::vehicle::Vehicle;

/// Arguments of `sweephold margins`.
#[derive(Args, Debug)]
#[command(
    after_help = "Each loop is broken at its actuator input (the command the board \
sends to the servo) with the other loops closed: roll_rate, pitch_rate, yaw_rate with the \
Rate stick (mode switch Low; the pedal outside its dead band), roll_attitude, pitch_attitude, \
heading with the Level stick and the heading hold (Middle, High; pedal centred). Per loop: \
gain crossover wc, phase margin PM, gain margin GM at the phase crossover w180, and the \
disturbance-rejection bandwidth DRB (|1/(1+L)| = -3 dB). Per stick: the ADS-33E-PRF \
bandwidth wBW and phase delay tau_p of the attitude response, and its level for hover and \
low speed (target acquisition and tracking / all other MTEs; boundaries in docs/method.md). \
Each figure's spread (+-) is the standard deviation over models drawn from the fit's \
Cramer-Rao bounds and correlations (--samples, --seed).\n\nThe law is the firmware preset's \
that the vehicle names (gains, 200 Hz tick with its zero-order hold), with the board's IMU \
filter bank (--no-filters: raw sensors, as the simulator's in-process link), \
--compute-delay and --servo-frame-hz (the shipped boards drive the servos at 50 Hz). Where \
the model has neither a servo nor a delay for a control, the vehicle's servo is added."
)]
pub struct MarginsArgs {
    /// The identified model (`model.json`, `model9.json`, `model6.json`).
    #[arg(value_name = "MODEL.json")]
    pub model: PathBuf,
    /// The aircraft whose firmware preset flies the loops and whose servo is added where
    /// the model has none: a shipped name (bo105, trex700l, fbl700) or an aircraft file.
    /// Default: the one the model's structure is named after (bo105 or trex700l).
    #[arg(long, value_name = "NAME|FILE", value_parser = Vehicle::parse)]
    pub vehicle: Option<Vehicle>,
    /// Write the figures as JSON (margins.json, docs/formats.md) to this file.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Print the JSON document on standard output instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Models drawn for the spreads (0: none).
    #[arg(long, default_value_t = 200, value_parser = crate::arg_values::count::<0, 10000>, allow_hyphen_values = true)]
    pub samples: usize,
    /// Seed of the draws.
    #[arg(long, default_value_t = 1, value_parser = crate::arg_values::seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// What the board adds around the model.
    #[command(flatten)]
    pub law: LawArgs,
    /// Write the broken loops and sensitivities sampled on the analysis grid (JSON:
    /// omega, re, im per loop) to this file, for an outside check.
    #[arg(long, value_name = "FILE")]
    pub export_loops: Option<PathBuf>,
    /// Loop-test dumps (`fly --input loop`): each one's broken loop measured at its
    /// axis' actuator input, with its margins, beside the predicted ones of the loop it
    /// breaks (lat: roll_attitude, lon: pitch_attitude, ped: heading); repeatable.
    #[arg(long, value_name = "DUMP")]
    pub measured: Vec<PathBuf>,
}

/// `--servo-frame-hz`: a finite frequency > 0.
pub(crate) fn positive_hz(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(hz) if hz.is_finite() && hz > 0.0 => Ok(hz),
        _ => Err("expected a frequency in Hz > 0".to_string()),
    }
}

/// One model analysed under the board's law: what `sweephold margins` prints and writes.
pub struct MarginsAnalysis {
    /// The model read.
    pub document: ModelDocument,
    /// The vehicle whose law flies the loops.
    pub vehicle: Vehicle,
    /// The law (its servos still those of the preset: the analysis adds the vehicle's).
    pub law: BoardLaw,
    /// The vehicle's servo, added where the model has none.
    pub vehicle_servo: Option<Actuator>,
    /// How the analysis ran.
    pub options: AnalysisOptions,
    /// The figures (`margins.json`).
    pub result: MarginsDocument,
}

/// The identified model at `path` (a `model.json`) and the aircraft whose preset flies
/// it: `vehicle`, else the one its structure names (a TREX 700L structure, else the
/// Bo-105). `margins` and `tune` read their model so.
pub(crate) fn model_and_vehicle(
    path: &Path,
    vehicle: Option<&Vehicle>,
) -> anyhow::Result<(ModelDocument, Vehicle)> {
    check_input_file("model", path)?;
    let text =
        fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let document: ModelDocument = serde_json::from_str(&text)
        .map_err(|e| anyhow!("{}: not a model.json: {e}", path.display()))?;
    let vehicle = match vehicle {
        Some(vehicle) => vehicle.clone(),
        None if document.structure.starts_with("trex700l") => Vehicle::shipped("trex700l"),
        None => Vehicle::shipped("bo105"),
    };
    Ok((document, vehicle))
}

/// Read the model of `args` and analyse it (no output written).
pub fn analyse(args: &MarginsArgs) -> anyhow::Result<MarginsAnalysis> {
    let (document, vehicle) = model_and_vehicle(&args.model, args.vehicle.as_ref())?;
    let law = args.law.preset_law(&vehicle);
    let vehicle_servo = vehicle_servo(&vehicle);
    let structure = structure_of(&document, &vehicle);
    let options = AnalysisOptions {
        samples: args.samples,
        seed: args.seed,
        ..AnalysisOptions::default()
    };
    let mut result = analysis::analyse(
        &document,
        structure.as_ref().ok(),
        &law,
        vehicle_servo,
        &options,
    )
    .map_err(|e| anyhow!("{}: {e}", args.model.display()))?;
    if let Err(why) = &structure {
        result.notes.push(format!("no spread: {why}"));
    }
    Ok(MarginsAnalysis {
        document,
        vehicle,
        law,
        vehicle_servo,
        options,
        result,
    })
}

impl MarginsAnalysis {
    /// The nominal model's broken loops, sensitivities and stick responses on the
    /// analysis grid, or on `points` log-spaced frequencies of the same band.
    pub fn sampled(&self, points: Option<usize>) -> anyhow::Result<ExportedLoops> {
        let options = AnalysisOptions {
            grid_points: points.unwrap_or(self.options.grid_points),
            ..self.options
        };
        exported_loops(&self.document, &self.law, self.vehicle_servo, &options)
    }
}

/// Run `sweephold margins`.
pub fn run(args: &MarginsArgs) -> anyhow::Result<()> {
    let outputs: Vec<(&str, &std::path::Path)> =
        [("--out", &args.out), ("--export-loops", &args.export_loops)]
            .into_iter()
            .filter_map(|(name, path)| path.as_deref().map(|p| (name, p)))
            .collect();
    check_input_file("model", &args.model)?;
    let inputs: Vec<&std::path::Path> = std::iter::once(args.model.as_path())
        .chain(args.measured.iter().map(PathBuf::as_path))
        .collect();
    refuse_inputs_as_outputs(&inputs, &outputs)?;
    let measured = measured_loop::measure_all(&args.measured)?;
    let analysis = analyse(args)?;
    if let Some(path) = &args.export_loops {
        write_json(path, &analysis.sampled(None)?)?;
    }
    let document = WithMeasured {
        predicted: &analysis.result,
        measured: measured_loop::compared(&analysis.result, measured),
    };
    if let Some(path) = &args.out {
        write_json(path, &document)?;
    }
    if args.json {
        let mut text = serde_json::to_string_pretty(&document)?;
        text.push('\n');
        crate::output::print(&text)
    } else {
        let mut text = table(&analysis.result, analysis.vehicle.name(), &args.model);
        text.push_str(&measured_loop::table(&document.measured));
        crate::output::print(&text)
    }
}

/// Models drawn for the spreads in the margins stage of `campaign` and `identify`: fewer
/// than the verb's 200, so that the stage stays a small part of the run (each draw
/// analyses every loop on the full grid); a spread from 60 draws is within about 9 % of
/// its value (relative standard error 1/√(2·59)). `sweephold margins` on the folder's
/// `model9.json` gives the 200.
pub const STAGE_SAMPLES: usize = 60;

/// Frequencies of the loops sampled for the report's plots: the Bode plots need a few
/// hundred points, not the analysis grid's 2400 (the figures come from margins.json).
pub const PLOTTED_POINTS: usize = 400;

/// The margins stage of `campaign` and `identify` in `dir`: `margins.json`, the figures of
/// `args.model` under `args`' law with the loop tests of `args.measured` measured beside
/// them, and `margins-loops.json`, the nominal loops on [`PLOTTED_POINTS`] frequencies for
/// the report's plots; the stage's progress line. A model the analysis cannot take
/// (singular at a frequency of the grid) is reported in the line, not fatal, as a loop test
/// that cannot be measured is: the fit and the report still stand, and the report says
/// what is absent.
pub fn write_stage_files(dir: &Path, args: &MarginsArgs) -> anyhow::Result<String> {
    let analysis = match analyse(args) {
        Ok(analysis) => analysis,
        Err(error) => return Ok(format!("not computed: {error:#}")),
    };
    let (measured, unmeasured) = match measured_loop::measure_all(&args.measured) {
        Ok(measured) => (measured, None),
        Err(error) => (Vec::new(), Some(format!("{error:#}"))),
    };
    let document = WithMeasured {
        predicted: &analysis.result,
        measured: measured_loop::compared(&analysis.result, measured),
    };
    write_json(&dir.join(files::MARGINS), &document)?;
    write_json(
        &dir.join(files::MARGINS_LOOPS),
        &analysis.sampled(Some(PLOTTED_POINTS))?,
    )?;
    let mut line = stage_headline(&analysis.result);
    if !document.measured.is_empty() {
        let largest = |pick: &dyn Fn(&measured_loop::Compared) -> Option<f64>| {
            document
                .measured
                .iter()
                .filter_map(pick)
                .map(f64::abs)
                .fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.max(b))))
                .map_or("-".to_string(), |v| format!("{v:.1}"))
        };
        line += &format!(
            "; {} loop tests measured: |dGM| up to {} dB, |dPM| up to {} deg",
            document.measured.len(),
            largest(&|c| c.gain_margin_difference_db),
            largest(&|c| c.phase_margin_difference_deg)
        );
    }
    if let Some(why) = unmeasured {
        line += &format!("; loop tests not measured: {why}");
    }
    Ok(line)
}

/// The stage's progress line: the least phase and gain margins over the loops, and the
/// ADS-33 levels (tracking/other) per stick.
pub fn stage_headline(result: &MarginsDocument) -> String {
    let least = |pick: &dyn Fn(&control::analysis::LoopFigures) -> Option<f64>| {
        result
            .loops
            .iter()
            .filter_map(|l| pick(l).map(|v| (v, l.name)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    let pm = least(&|l| l.min_phase_margin_deg.value)
        .map_or("-".to_string(), |(v, name)| format!("{v:.1} deg ({name})"));
    let gm = least(&|l| l.gain_margin_db.value)
        .map_or("-".to_string(), |(v, name)| format!("{v:.1} dB ({name})"));
    let level = |l: Option<u8>| l.map_or("-".to_string(), |l| l.to_string());
    let levels: Vec<String> = result
        .handling
        .iter()
        .map(|h| {
            format!(
                "{} {} {}/{}",
                h.axis,
                match h.mode {
                    control::law::LoopMode::Rate => "rate",
                    control::law::LoopMode::Level => "level",
                },
                level(h.level_tracking),
                level(h.level_other)
            )
        })
        .collect();
    format!(
        "least PM {pm}, least GM {gm}; ADS-33 levels T/O {}",
        levels.join(", ")
    )
}

/// `margins.json`: the predicted figures and, with `--measured`, the measured loops
/// beside them (no `measured` key without).
#[derive(Serialize)]
struct WithMeasured<'a> {
    #[serde(flatten)]
    predicted: &'a MarginsDocument,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    measured: Vec<measured_loop::Compared>,
}

/// What the board adds between the sensors and the servos around an identified model
/// (`margins` and `tune`).
#[derive(Args, Clone, Debug)]
pub struct LawArgs {
    /// Leave the board's IMU filter bank out (raw sensors).
    #[arg(long)]
    pub no_filters: bool,
    /// Computation delay from the sensor sample to the command, in seconds.
    #[arg(long, value_name = "S", default_value_t = 0.0, value_parser = crate::arg_values::non_negative, allow_hyphen_values = true)]
    pub compute_delay: f64,
    /// Servo pulse frame rate in Hz (each pulse held for a frame); none by default, as the
    /// simulator.
    #[arg(long, value_name = "HZ", value_parser = positive_hz, allow_hyphen_values = true)]
    pub servo_frame_hz: Option<f64>,
}

impl LawArgs {
    /// The firmware preset's pilot-mode law of `vehicle` on the board, with these
    /// additions.
    pub(crate) fn preset_law(&self, vehicle: &Vehicle) -> BoardLaw {
        let app = AppConfig::preset(vehicle.preset(), Axis::Lat);
        let stack = StackConfig::with_app(app);
        BoardLaw {
            gains: app.pilot,
            tick_s: f64::from(app.flight.dt_s()),
            filters: (!self.no_filters).then_some(stack.filters),
            compute_delay_s: self.compute_delay,
            servo_frame_hz: self.servo_frame_hz,
            servos: [None; 3],
        }
    }
}

/// The vehicle's servo as an actuator (`None`: an instant one).
pub(crate) fn vehicle_servo(vehicle: &Vehicle) -> Option<Actuator> {
    let servos = vehicle.servos();
    (servos.natural_frequency_rad_s.is_finite() && servos.natural_frequency_rad_s > 0.0).then_some(
        Actuator {
            natural_frequency_rad_s: servos.natural_frequency_rad_s,
            damping: servos.damping,
        },
    )
}

/// The structure `document` was fitted with, for the spread: the 6-DOF, the vehicle's
/// own hybrid (its numbers), or a shipped structure of that name.
pub(crate) fn structure_of(
    document: &ModelDocument,
    vehicle: &Vehicle,
) -> Result<ModelStructure, String> {
    let structure = if document.structure == models::BO105_6DOF.name {
        structures::six_dof().map_err(anyhow::Error::from)
    } else if document.structure == vehicle.structure() {
        structures::nine_dof_hybrid(vehicle.aircraft(), None).map_err(anyhow::Error::from)
    } else {
        structures::shipped(&document.structure, &BTreeMap::new())
            .unwrap_or_else(|| Err(anyhow!("structure `{}` is not shipped", document.structure)))
    };
    structure.map_err(|e| format!("{e:#}"))
}

/// One sampled response of the export.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExportedResponse {
    /// The loop's or stick's name.
    pub name: String,
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// Real parts.
    pub re: Vec<f64>,
    /// Imaginary parts.
    pub im: Vec<f64>,
}

/// The nominal model's broken loops, sensitivities and stick responses, sampled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExportedLoops {
    /// The model's structure name.
    pub structure: String,
    /// The six broken loops.
    pub loops: Vec<ExportedResponse>,
    /// Their sensitivities 1/(1 + L).
    pub sensitivities: Vec<ExportedResponse>,
    /// The five stick-to-attitude responses.
    pub sticks: Vec<ExportedResponse>,
}

fn exported_loops(
    document: &ModelDocument,
    law: &BoardLaw,
    vehicle_servo: Option<Actuator>,
    options: &AnalysisOptions,
) -> anyhow::Result<ExportedLoops> {
    let model = document
        .model()
        .ok_or_else(|| anyhow!("model.json: a matrix has the wrong size"))?;
    let mut law = law.clone();
    law.servos = analysis::added_servos(&model, vehicle_servo);
    let grid = analysis::grid(&law, options);
    let plant = Plant::new(model).map_err(|e| anyhow!(e))?;
    let sets = analysis::evaluate(&plant, &law, &grid).map_err(|e| anyhow!(e))?;
    let mut loops = Vec::new();
    let mut sensitivities = Vec::new();
    for (name, config, axis) in analysis::LOOP_NAMES {
        let set = &sets[analysis::configuration_index(config)];
        let export = |sampled: &control::loops::Sampled| ExportedResponse {
            name: name.to_string(),
            omega: sampled.omega.clone(),
            re: sampled.values.iter().map(|v| v.re).collect(),
            im: sampled.values.iter().map(|v| v.im).collect(),
        };
        loops.push(export(&set.broken[axis]));
        sensitivities.push(export(&set.sensitivity[axis]));
    }
    let mut sticks = Vec::new();
    for (name, config, axis) in analysis::STICK_NAMES {
        let sampled = &sets[analysis::configuration_index(config)].stick_attitude[axis];
        sticks.push(ExportedResponse {
            name: name.to_string(),
            omega: sampled.omega.clone(),
            re: sampled.values.iter().map(|v| v.re).collect(),
            im: sampled.values.iter().map(|v| v.im).collect(),
        });
    }
    Ok(ExportedLoops {
        structure: document.structure.clone(),
        loops,
        sensitivities,
        sticks,
    })
}

fn cell(figure: &Figure, decimals: usize) -> String {
    match (figure.value, figure.spread) {
        (Some(v), Some(s)) => format!("{v:.decimals$} ± {s:.decimals$}"),
        (Some(v), None) => format!("{v:.decimals$}"),
        (None, _) => "—".to_string(),
    }
}

/// The table on standard output.
fn table(result: &MarginsDocument, vehicle: &str, model: &std::path::Path) -> String {
    let mut text = String::new();
    let law = &result.law;
    let spread = if result.drawn_parameters == 0 {
        "no spread".to_string()
    } else {
        format!(
            "spread over {} draws of {} parameters (seed {})",
            result.samples - result.failed_draws,
            result.drawn_parameters,
            result.seed
        )
    };
    let _ = writeln!(
        text,
        "{} ({}), {} law: tick {:.1} ms, filter bank {}, compute delay {:.1} ms, servo frame {}; \
         {spread}",
        model.display(),
        result.structure,
        vehicle,
        law.tick_s * 1e3,
        if law.filter_bank { "on" } else { "off" },
        law.compute_delay_s * 1e3,
        law.servo_frame_hz
            .map_or("none".to_string(), |hz| format!("{hz} Hz")),
    );
    let _ = writeln!(
        text,
        "\n{:<15} {:<4} {:>15} {:>14} {:>14} {:>14} {:>15} {:>14}",
        "loop",
        "at",
        "wc [rad/s]",
        "PM [deg]",
        "min PM [deg]",
        "GM [dB]",
        "w180 [rad/s]",
        "DRB [rad/s]"
    );
    for l in &result.loops {
        // `*`: read where the model is extrapolated (beyond its fitted pairs' band).
        let mark = |what: &str, text: String| {
            if l.extrapolated.contains(&what) {
                text + "*"
            } else {
                text
            }
        };
        let _ = writeln!(
            text,
            "{:<15} {:<4} {:>15} {:>14} {:>14} {:>14} {:>15} {:>14}",
            l.name,
            l.broken_at,
            mark("crossover", cell(&l.crossover_rad_s, 2)),
            mark("crossover", cell(&l.phase_margin_deg, 1)),
            cell(&l.min_phase_margin_deg, 1),
            mark("phase_crossover", cell(&l.gain_margin_db, 1)),
            mark("phase_crossover", cell(&l.phase_crossover_rad_s, 2)),
            cell(&l.drb_rad_s, 2),
        );
    }
    for l in &result.loops {
        if let Some((pair, cost)) = l.worst_pair.as_ref().filter(|(_, j)| *j > POOR_PAIR_COST) {
            let _ = writeln!(
                text,
                "! {}: the model fits {pair} at J {cost:.0} (> {POOR_PAIR_COST:.0}): the loop's \
                 figures rest on a response the model does not follow",
                l.name
            );
        }
    }
    for l in result.loops.iter().filter(|l| !l.extrapolated.is_empty()) {
        let _ = writeln!(
            text,
            "* {}: read above {:.1} rad/s, the top of the model's fitted {} pairs: extrapolated \
             by the model's structure, not identified",
            l.name,
            l.fitted_to_rad_s.unwrap_or(f64::NAN),
            l.broken_at
        );
    }
    let _ = writeln!(
        text,
        "\n{:<6} {:<6} {:>16} {:>18} {:>10}",
        "stick", "mode", "wBW [rad/s]", "tau_p [s]", "level T/O"
    );
    for h in &result.handling {
        let level = |l: Option<u8>| l.map_or("—".to_string(), |l| l.to_string());
        let _ = writeln!(
            text,
            "{:<6} {:<6} {:>16} {:>18} {:>10}",
            h.axis,
            match h.mode {
                control::law::LoopMode::Rate => "rate",
                control::law::LoopMode::Level => "level",
            },
            cell(&h.bandwidth_rad_s, 2),
            cell(&h.phase_delay_s, 3),
            format!("{}/{}", level(h.level_tracking), level(h.level_other)),
        );
    }
    for note in &result.notes {
        let _ = writeln!(text, "note: {note}");
    }
    text
}
