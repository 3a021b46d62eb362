//! Every figure of one identified model under the board's law, with its spread: the
//! `margins.json` document of `sweephold margins`.

use serde::Serialize;
use sysid::fit::model::Actuator;
use sysid::fit::{Model, ModelDocument, ModelStructure};
use sysid::random::SplitMix64;

use crate::handling::{self, Bandwidth, ChartBoundary, ResponseType, TaskClass};
use crate::law::{BoardLaw, LoopMode};
use crate::loops::{self, Configuration, LoopResponses};
use crate::margins::{self, Margins};
use crate::plant::Plant;
use crate::uncertainty::ParameterSampler;

/// Layout version of `margins.json`.
pub const MARGINS_DOCUMENT_VERSION: u32 = 2;

/// How the analysis runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalysisOptions {
    /// Models drawn for the spread (0: none).
    pub samples: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Grid points (log-spaced from `low_rad_s` to 0.9 of the tick's Nyquist frequency).
    pub grid_points: usize,
    /// Lowest frequency of the grid [rad/s].
    pub low_rad_s: f64,
}

impl Default for AnalysisOptions {
    /// 200 draws, seed 1, 2400 points from 0.05 rad/s.
    fn default() -> Self {
        AnalysisOptions {
            samples: 200,
            seed: 1,
            grid_points: 2400,
            low_rad_s: 0.05,
        }
    }
}

/// A figure with its spread over the drawn models.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Figure {
    /// On the identified model (null: not defined, e.g. no crossing in the grid).
    pub value: Option<f64>,
    /// Standard deviation over the draws where it is defined (null without draws).
    pub spread: Option<f64>,
    /// Draws where it is defined.
    pub defined_in: usize,
}

/// One loop broken at its actuator input.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoopFigures {
    /// `roll_rate`, `pitch_rate`, `yaw_rate`, `roll_attitude`, `pitch_attitude`, `heading`.
    pub name: &'static str,
    /// The actuator where it is broken (`lat`, `lon`, `ped`).
    pub broken_at: &'static str,
    /// The stick mode flown.
    pub mode: LoopMode,
    /// The loop's crossover: its highest-frequency gain crossover [rad/s].
    pub crossover_rad_s: Figure,
    /// Phase margin at that crossover \[deg\].
    pub phase_margin_deg: Figure,
    /// The least phase margin over all gain crossovers (python-control's
    /// `stability_margins` pick) \[deg\].
    pub min_phase_margin_deg: Figure,
    /// The gain crossover of that least margin [rad/s].
    pub min_phase_margin_crossover_rad_s: Figure,
    /// Gain margin \[dB\].
    pub gain_margin_db: Figure,
    /// Phase crossover (−180°) [rad/s].
    pub phase_crossover_rad_s: Figure,
    /// Disturbance-rejection bandwidth (|S| = −3 dB) [rad/s].
    pub drb_rad_s: Figure,
    /// Every gain crossover of the identified model's loop: [ω_c rad/s, PM deg]. More
    /// than one where the loop is conditionally stable around unstable hover modes.
    pub all_crossovers: Vec<[f64; 2]>,
    /// The highest frequency of the model's fitted pairs driven by the loop's actuator
    /// [rad/s] (null: the model document lists none).
    pub fitted_to_rad_s: Option<f64>,
    /// The figures read beyond `fitted_to_rad_s` on the identified model (`crossover`,
    /// `phase_crossover`): there the model is extrapolated, not identified, and the
    /// figure rests on its structure alone.
    pub extrapolated: Vec<&'static str>,
    /// The model's worst-fitted pair driven by the loop's actuator, `output/input`, and its
    /// cost J (null: the model document lists none).
    pub worst_pair: Option<(String, f64)>,
}

/// A fitted pair's cost above which the figures of a loop it drives are marked: Tischler's
/// guideline lets a few pairs of an acceptable fit (J_ave ≤ 100) reach 150–200; above it
/// the model does not follow that response, and neither need its loop.
pub const POOR_PAIR_COST: f64 = 200.0;

/// The costliest of `document`'s fitted pairs whose input is `control`.
pub fn worst_pair(document: &ModelDocument, control: &str) -> Option<(String, f64)> {
    document
        .pairs
        .iter()
        .filter(|pair| pair.input == control && pair.cost.is_finite())
        .max_by(|a, b| a.cost.total_cmp(&b.cost))
        .map(|pair| (format!("{}/{}", pair.output, pair.input), pair.cost))
}

/// The highest frequency of `document`'s fitted pairs whose input is `control` [rad/s].
pub fn fitted_to(document: &ModelDocument, control: &str) -> Option<f64> {
    document
        .pairs
        .iter()
        .filter(|pair| pair.input == control && pair.range[1].is_finite())
        .map(|pair| pair.range[1])
        .reduce(f64::max)
}

/// Which of `figures`' frequencies lie beyond `fitted_to` (1 % above, for the grid).
fn beyond(
    fitted_to: Option<f64>,
    crossover: Option<f64>,
    phase_crossover: Option<f64>,
) -> Vec<&'static str> {
    let Some(top) = fitted_to else {
        return Vec::new();
    };
    [
        ("crossover", crossover),
        ("phase_crossover", phase_crossover),
    ]
    .into_iter()
    .filter(|(_, w)| w.is_some_and(|w| w > 1.01 * top))
    .map(|(name, _)| name)
    .collect()
}

/// ADS-33 figures of one stick.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HandlingFigures {
    /// `roll`, `pitch`, `yaw`.
    pub axis: &'static str,
    /// The stick mode flown.
    pub mode: LoopMode,
    /// `rate` or `attitude_command`.
    pub response_type: &'static str,
    /// ω_BW [rad/s].
    pub bandwidth_rad_s: Figure,
    /// ω_BW,phase [rad/s].
    pub phase_bandwidth_rad_s: Figure,
    /// ω_BW,gain [rad/s].
    pub gain_bandwidth_rad_s: Figure,
    /// τ_p \[s\].
    pub phase_delay_s: Figure,
    /// Level for target acquisition and tracking (hover and low speed).
    pub level_tracking: Option<u8>,
    /// Level for all other MTEs (hover and low speed).
    pub level_other: Option<u8>,
    /// The charts' boundaries used (tracking, other).
    pub boundaries: [ChartBoundary; 2],
}

/// What the analysis assumed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LawSummary {
    /// Control tick \[s\].
    pub tick_s: f64,
    /// Whether the board's IMU filter bank is in the loop.
    pub filter_bank: bool,
    /// Computation delay \[s\].
    pub compute_delay_s: f64,
    /// Servo frame rate \[Hz\], null: none.
    pub servo_frame_hz: Option<f64>,
    /// Servo added per control (lat, lon, ped) where the model has none.
    pub added_servos: [Option<Actuator>; 3],
}

/// `margins.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MarginsDocument {
    /// [`MARGINS_DOCUMENT_VERSION`].
    pub version: u32,
    /// The model's structure name.
    pub structure: String,
    /// The law around it.
    pub law: LawSummary,
    /// Draws for the spreads, their seed, and how many parameters were drawn.
    pub samples: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Free parameters drawn.
    pub drawn_parameters: usize,
    /// Draws that failed (a singular model) and were left out.
    pub failed_draws: usize,
    /// Why there is no spread, when there is none.
    pub notes: Vec<String>,
    /// The six loops.
    pub loops: Vec<LoopFigures>,
    /// The sticks' attitude responses.
    pub handling: Vec<HandlingFigures>,
}

const RATE: Configuration = Configuration {
    mode: LoopMode::Rate,
    heading_hold: false,
};
const LEVEL: Configuration = Configuration {
    mode: LoopMode::Level,
    heading_hold: true,
};
const LEVEL_PEDAL_OUT: Configuration = Configuration {
    mode: LoopMode::Level,
    heading_hold: false,
};

/// The loops: name, the actuator it is broken at, the configuration, the axis.
const LOOPS: [(&str, &str, Configuration, usize); 6] = [
    ("roll_rate", "lat", RATE, 0),
    ("pitch_rate", "lon", RATE, 1),
    ("yaw_rate", "ped", RATE, 2),
    ("roll_attitude", "lat", LEVEL, 0),
    ("pitch_attitude", "lon", LEVEL, 1),
    ("heading", "ped", LEVEL, 2),
];

const STICKS: [(&str, Configuration, usize, ResponseType); 5] = [
    ("roll", RATE, 0, ResponseType::Rate),
    ("pitch", RATE, 1, ResponseType::Rate),
    ("yaw", RATE, 2, ResponseType::Rate),
    ("roll", LEVEL_PEDAL_OUT, 0, ResponseType::AttitudeCommand),
    ("pitch", LEVEL_PEDAL_OUT, 1, ResponseType::AttitudeCommand),
];

/// Scalar figures of one model: per loop [ω_c, PM, ω_c of the least PM, least PM, GM,
/// ω_180, DRB], per stick [ω_BW,
/// ω_BW,phase, ω_BW,gain, τ_p].
struct Scalars {
    loops: Vec<[Option<f64>; 7]>,
    crossovers: Vec<Vec<[f64; 2]>>,
    sticks: Vec<[Option<f64>; 4]>,
    bandwidths: Vec<Bandwidth>,
}

/// The law's added servos for `model`: `vehicle_servo` where a control has neither an
/// actuator nor a delay in the model.
pub fn added_servos(model: &Model, vehicle_servo: Option<Actuator>) -> [Option<Actuator>; 3] {
    let mut servos = [None; 3];
    for (slot, name) in servos.iter_mut().zip(crate::plant::CONTROLS) {
        if let Some(j) = model.controls.iter().position(|c| c == name) {
            let has_actuator = model.actuators.get(j).copied().flatten().is_some();
            if !has_actuator && model.delays.get(j).is_some_and(|d| *d == 0.0) {
                *slot = vehicle_servo;
            }
        }
    }
    servos
}

/// The six broken loops and five stick responses of `plant` on `grid`.
pub fn evaluate(plant: &Plant, law: &BoardLaw, grid: &[f64]) -> Result<[LoopResponses; 3], String> {
    let run = |config| {
        loops::responses(plant, law, config, grid)
            .ok_or_else(|| "the model is singular at a frequency of the grid".to_string())
    };
    Ok([run(RATE)?, run(LEVEL)?, run(LEVEL_PEDAL_OUT)?])
}

/// The loops' names, configurations and axes, in the document's order.
pub const LOOP_NAMES: [(&str, Configuration, usize); 6] = [
    (LOOPS[0].0, LOOPS[0].2, LOOPS[0].3),
    (LOOPS[1].0, LOOPS[1].2, LOOPS[1].3),
    (LOOPS[2].0, LOOPS[2].2, LOOPS[2].3),
    (LOOPS[3].0, LOOPS[3].2, LOOPS[3].3),
    (LOOPS[4].0, LOOPS[4].2, LOOPS[4].3),
    (LOOPS[5].0, LOOPS[5].2, LOOPS[5].3),
];

/// The stick responses' names (`roll_rate_stick`, …), configurations and axes.
pub const STICK_NAMES: [(&str, Configuration, usize); 5] = [
    ("roll_rate_stick", RATE, 0),
    ("pitch_rate_stick", RATE, 1),
    ("yaw_rate_stick", RATE, 2),
    ("roll_level_stick", LEVEL_PEDAL_OUT, 0),
    ("pitch_level_stick", LEVEL_PEDAL_OUT, 1),
];

/// Which of [`evaluate`]'s three response sets `config` is.
pub fn configuration_index(config: Configuration) -> usize {
    match config {
        RATE => 0,
        LEVEL => 1,
        _ => 2,
    }
}

fn scalars(plant: &Plant, law: &BoardLaw, grid: &[f64]) -> Result<Scalars, String> {
    let sets = evaluate(plant, law, grid)?;
    let loops = LOOPS
        .iter()
        .map(|&(_, _, config, axis)| {
            let set = &sets[configuration_index(config)];
            let Margins {
                crossover_rad_s,
                phase_margin_deg,
                gain_margin_db,
                phase_crossover_rad_s,
            } = margins::margins(&set.broken[axis]);
            let drb = margins::disturbance_rejection_bandwidth(&set.sensitivity[axis]);
            let highest = margins::gain_crossovers(&set.broken[axis]).last().copied();
            [
                highest.map(|(w, _)| w),
                highest.map(|(_, pm)| pm),
                crossover_rad_s,
                phase_margin_deg,
                gain_margin_db,
                phase_crossover_rad_s,
                drb,
            ]
        })
        .collect();
    let crossovers = LOOPS
        .iter()
        .map(|&(_, _, config, axis)| {
            margins::gain_crossovers(&sets[configuration_index(config)].broken[axis])
                .into_iter()
                .map(|(w, pm)| [w, pm])
                .collect()
        })
        .collect();
    let bandwidths: Vec<Bandwidth> = STICKS
        .iter()
        .map(|&(_, config, axis, kind)| {
            handling::bandwidth(
                &sets[configuration_index(config)].stick_attitude[axis],
                kind,
            )
        })
        .collect();
    let sticks = bandwidths
        .iter()
        .map(|b| {
            [
                b.bandwidth_rad_s,
                b.phase_bandwidth_rad_s,
                b.gain_bandwidth_rad_s,
                b.phase_delay_s,
            ]
        })
        .collect();
    Ok(Scalars {
        loops,
        crossovers,
        sticks,
        bandwidths,
    })
}

/// `work` applied to every item, on up to as many threads as the machine has cores, the
/// results in the items' order.
fn in_parallel<T: Send, R: Send>(items: Vec<T>, work: impl Fn(T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    if threads < 2 || items.len() < 2 {
        return items.into_iter().map(work).collect();
    }
    let chunk = items.len().div_ceil(threads);
    let mut chunks: Vec<Vec<T>> = Vec::new();
    let mut items = items.into_iter().peekable();
    while items.peek().is_some() {
        chunks.push(items.by_ref().take(chunk).collect());
    }
    let work = &work;
    std::thread::scope(|scope| {
        let handles: Vec<_> = chunks
            .into_iter()
            .map(|chunk| scope.spawn(move || chunk.into_iter().map(work).collect::<Vec<R>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|handle| match handle.join() {
                Ok(results) => results,
                Err(panic) => std::panic::resume_unwind(panic),
            })
            .collect()
    })
}

/// The analysis grid of `law` under `options`.
pub fn grid(law: &BoardLaw, options: &AnalysisOptions) -> Vec<f64> {
    let nyquist = std::f64::consts::PI / law.tick_s;
    loops::log_grid(options.low_rad_s, 0.9 * nyquist, options.grid_points)
}

/// Figures of `document` under `law` (its `servos` are replaced by [`added_servos`] of
/// `vehicle_servo`), with spreads from `structure` when given.
pub fn analyse(
    document: &ModelDocument,
    structure: Option<&ModelStructure>,
    law: &BoardLaw,
    vehicle_servo: Option<Actuator>,
    options: &AnalysisOptions,
) -> Result<MarginsDocument, String> {
    let model = document
        .model()
        .ok_or("model.json: a matrix has the wrong size")?;
    let mut law = law.clone();
    law.servos = added_servos(&model, vehicle_servo);
    let grid = grid(&law, options);
    let nominal = scalars(&Plant::new(model)?, &law, &grid)?;
    let mut notes = Vec::new();
    let mut draws: Vec<Scalars> = Vec::new();
    let mut failed = 0;
    let mut drawn_parameters = 0;
    match structure.map(|s| ParameterSampler::new(s, document)) {
        None => notes.push("no structure for the model: no spread".to_string()),
        Some(Err(why)) => notes.push(format!("no spread: {why}")),
        Some(Ok(sampler)) if options.samples > 0 => {
            drawn_parameters = sampler.free_count();
            // The models are drawn in sequence from one generator, then analysed on every
            // core, each draw's figures kept in its place: the same seed gives the same
            // figures whatever the number of cores.
            let mut random = SplitMix64::new(options.seed);
            let models: Vec<_> = (0..options.samples)
                .map(|_| sampler.draw(&mut random))
                .collect();
            let analysed = in_parallel(models, |drawn| {
                drawn
                    .and_then(Plant::new)
                    .and_then(|plant| scalars(&plant, &law, &grid))
            });
            for figures in analysed {
                match figures {
                    Ok(figures) => draws.push(figures),
                    Err(_) => failed += 1,
                }
            }
        }
        Some(Ok(_)) => {}
    }
    let figure = |value: Option<f64>, pick: &dyn Fn(&Scalars) -> Option<f64>| {
        let values: Vec<f64> = draws.iter().filter_map(pick).collect();
        Figure {
            value,
            spread: standard_deviation(&values),
            defined_in: values.len(),
        }
    };
    let loops = LOOPS
        .iter()
        .enumerate()
        .map(|(i, &(name, broken_at, config, _))| {
            let f = |k: usize| figure(nominal.loops[i][k], &move |s: &Scalars| s.loops[i][k]);
            let fitted_to_rad_s = fitted_to(document, broken_at);
            LoopFigures {
                name,
                broken_at,
                mode: config.mode,
                crossover_rad_s: f(0),
                phase_margin_deg: f(1),
                min_phase_margin_crossover_rad_s: f(2),
                min_phase_margin_deg: f(3),
                gain_margin_db: f(4),
                phase_crossover_rad_s: f(5),
                drb_rad_s: f(6),
                all_crossovers: nominal.crossovers[i].clone(),
                fitted_to_rad_s,
                extrapolated: beyond(fitted_to_rad_s, nominal.loops[i][0], nominal.loops[i][5]),
                worst_pair: worst_pair(document, broken_at),
            }
        })
        .collect();
    let handling = STICKS
        .iter()
        .enumerate()
        .map(|(i, &(axis_name, config, axis, kind))| {
            let f = |k: usize| figure(nominal.sticks[i][k], &move |s: &Scalars| s.sticks[i][k]);
            let boundaries = [
                handling::boundary(axis, TaskClass::Tracking),
                handling::boundary(axis, TaskClass::Other),
            ];
            let figures = &nominal.bandwidths[i];
            HandlingFigures {
                axis: axis_name,
                mode: config.mode,
                response_type: match kind {
                    ResponseType::Rate => "rate",
                    ResponseType::AttitudeCommand => "attitude_command",
                },
                bandwidth_rad_s: f(0),
                phase_bandwidth_rad_s: f(1),
                gain_bandwidth_rad_s: f(2),
                phase_delay_s: f(3),
                level_tracking: handling::level(figures, &boundaries[0]),
                level_other: handling::level(figures, &boundaries[1]),
                boundaries,
            }
        })
        .collect();
    Ok(MarginsDocument {
        version: MARGINS_DOCUMENT_VERSION,
        structure: document.structure.clone(),
        law: LawSummary {
            tick_s: law.tick_s,
            filter_bank: law.filters.is_some(),
            compute_delay_s: law.compute_delay_s,
            servo_frame_hz: law.servo_frame_hz,
            added_servos: law.servos,
        },
        samples: options.samples,
        seed: options.seed,
        drawn_parameters,
        failed_draws: failed,
        notes,
        loops,
        handling,
    })
}

/// Sample standard deviation; `None` below two values.
fn standard_deviation(values: &[f64]) -> Option<f64> {
    if values.len() < 2 {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    Some(variance.sqrt())
}

#[cfg(test)]
mod fitted_band_tests {
    use super::*;

    #[test]
    fn figures_above_the_fitted_band_are_named() {
        assert_eq!(
            beyond(Some(31.4), Some(4.5), Some(44.5)),
            vec!["phase_crossover"]
        );
        assert_eq!(
            beyond(Some(62.8), Some(4.5), Some(44.5)),
            Vec::<&str>::new()
        );
        assert_eq!(beyond(None, Some(4.5), Some(44.5)), Vec::<&str>::new());
        assert_eq!(beyond(Some(31.4), Some(40.0), None), vec!["crossover"]);
        // On the grid's edge: 1 % above the top is still the fitted band.
        assert_eq!(beyond(Some(31.4), Some(31.6), None), Vec::<&str>::new());
    }
}
