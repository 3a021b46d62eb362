//! The figures of one loop under one set of gains, on the identified model and on its
//! draws, and the constraint it breaks: what `tune` scores each candidate by.

use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::Serialize;
use sysid::fit::{Model, ModelDocument, ModelStructure};
use sysid::random::SplitMix64;

use super::options::{TuneOptions, LOOPS};
use crate::law::BoardLaw;
use crate::loops::{self, Configuration, Sampled};
use crate::margins::{self, bode};
use crate::plant::Plant;
use crate::uncertainty::ParameterSampler;

/// A figure on the identified model, its spread and its percentile over the draws.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Spread {
    /// On the identified model (null: not defined; for a gain margin: no phase
    /// crossover above the crossover, unbounded).
    pub value: Option<f64>,
    /// Standard deviation over the draws where it is defined.
    pub spread: Option<f64>,
    /// The options' percentile over the draws (a draw where it is undefined counts as
    /// failing for a phase margin and as unbounded for a gain margin).
    pub percentile: Option<f64>,
}

/// The figures of one loop under one set of gains.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoopCheck {
    /// `roll_rate` … `heading`.
    pub name: &'static str,
    /// The loop's crossover (highest gain crossover) [rad/s].
    pub crossover_rad_s: Spread,
    /// Phase margin there \[deg\].
    pub phase_margin_deg: Spread,
    /// Gain margin above the crossover \[dB\].
    pub gain_margin_db: Spread,
    /// Disturbance-rejection bandwidth [rad/s].
    pub drb_rad_s: Spread,
    /// The constraint it breaks, if any.
    pub violation: Option<String>,
}

/// The identified model and its draws, their responses on the grid computed once.
pub struct Models {
    pub(super) plant: Plant,
    grid: Vec<f64>,
    nominal: Vec<DMatrix<Complex64>>,
    draws: Vec<Option<Vec<DMatrix<Complex64>>>>,
    drawn_parameters: usize,
    /// Why there are no draws.
    pub note: Option<String>,
}

fn responses_on(plant: &Plant, grid: &[f64]) -> Option<Vec<DMatrix<Complex64>>> {
    grid.iter().map(|&w| plant.response(w)).collect()
}

impl Models {
    /// `document` and `samples` draws over its covariance (from `structure`), on the
    /// grid of `law`.
    pub fn new(
        document: &ModelDocument,
        structure: Option<&ModelStructure>,
        law: &BoardLaw,
        options: &TuneOptions,
    ) -> Result<Models, String> {
        let model = document
            .model()
            .ok_or("model.json: a matrix has the wrong size")?;
        let nyquist = std::f64::consts::PI / law.tick_s;
        let grid = loops::log_grid(options.low_rad_s, 0.9 * nyquist, options.grid_points);
        let plant = Plant::new(model)?;
        let nominal = responses_on(&plant, &grid)
            .ok_or("the model is singular at a frequency of the grid")?;
        let mut draws = Vec::new();
        let mut note = None;
        let mut drawn_parameters = 0;
        match structure.map(|s| ParameterSampler::new(s, document)) {
            None => note = Some("no structure for the model: no draws".to_string()),
            Some(Err(why)) => note = Some(format!("no draws: {why}")),
            Some(Ok(sampler)) => {
                drawn_parameters = sampler.free_count();
                let mut random = SplitMix64::new(options.seed);
                for _ in 0..options.samples {
                    let drawn: Option<Model> = sampler.draw(&mut random).ok();
                    draws.push(
                        drawn
                            .and_then(|m| Plant::new(m).ok())
                            .and_then(|p| responses_on(&p, &grid)),
                    );
                }
            }
        }
        Ok(Models {
            plant,
            grid,
            nominal,
            draws,
            drawn_parameters,
            note,
        })
    }

    /// Parameters drawn (0: no draws).
    pub fn drawn_parameters(&self) -> usize {
        self.drawn_parameters
    }

    /// Models drawn.
    pub fn draws(&self) -> usize {
        self.draws.len()
    }

    /// The identified model's plant.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }
}

/// The highest gain crossover of `l` and its phase margin, and the least gain margin
/// over the phase crossovers above it (`None`: none there).
pub fn upper_margins(l: &Sampled) -> (Option<(f64, f64)>, Option<f64>) {
    let highest = margins::gain_crossovers(l).last().copied();
    let Some((wc, _)) = highest else {
        return (None, None);
    };
    let (db, phase) = bode(&l.values);
    let omega = &l.omega;
    let mut least: Option<f64> = None;
    for i in 0..omega.len().saturating_sub(1) {
        if omega[i + 1] <= wc || phase[i] == phase[i + 1] {
            continue;
        }
        let (lo, hi) = (phase[i].min(phase[i + 1]), phase[i].max(phase[i + 1]));
        let mut m = ((lo + 180.0) / 360.0).ceil();
        while -180.0 + 360.0 * m <= hi {
            let level = -180.0 + 360.0 * m;
            let f = (level - phase[i]) / (phase[i + 1] - phase[i]);
            let w = (omega[i].ln() + f * (omega[i + 1].ln() - omega[i].ln())).exp();
            if level > lo && w > wc {
                let gm = -(db[i] + f * (db[i + 1] - db[i]));
                least = Some(least.map_or(gm, |l: f64| l.min(gm)));
            }
            m += 1.0;
        }
    }
    (highest, least)
}

/// Per model: [ω_c, PM, GM above ω_c, DRB] of loop `axis` of `config`.
fn loop_figures(
    responses: &[DMatrix<Complex64>],
    law: &BoardLaw,
    config: Configuration,
    axis: usize,
    grid: &[f64],
) -> Option<[Option<f64>; 4]> {
    let broken = loops::broken_loops_from(responses, law, config, grid)?;
    let l = &broken[axis];
    let (crossover, gm) = upper_margins(l);
    let sensitivity = Sampled {
        omega: l.omega.clone(),
        values: l
            .values
            .iter()
            .map(|v| Complex64::new(1.0, 0.0) / (1.0 + v))
            .collect(),
    };
    Some([
        crossover.map(|c| c.0),
        crossover.map(|c| c.1),
        gm,
        margins::disturbance_rejection_bandwidth(&sensitivity),
    ])
}

fn percentile_of(mut values: Vec<f64>, percent: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let index = ((percent / 100.0) * (values.len() - 1) as f64).floor() as usize;
    Some(values[index.min(values.len() - 1)])
}

fn standard_deviation(values: &[f64]) -> Option<f64> {
    if values.len() < 2 {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    Some((values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
}

/// Loop `index` of [`LOOPS`] under `law`: its figures and the constraint it breaks.
pub fn check_loop(
    models: &Models,
    law: &BoardLaw,
    index: usize,
    options: &TuneOptions,
) -> LoopCheck {
    check_loop_with(models, law, index, options, true)
}

/// [`check_loop`]; without `draws` the draws are skipped when the identified model
/// already fails (a search's quick rejection).
pub(super) fn check_loop_with(
    models: &Models,
    law: &BoardLaw,
    index: usize,
    options: &TuneOptions,
    always_draw: bool,
) -> LoopCheck {
    let (name, config, axis) = LOOPS[index];
    let nominal = loop_figures(&models.nominal, law, config, axis, &models.grid);
    let nominal_passes = nominal.is_some_and(|f| {
        f[1].is_some_and(|pm| pm >= options.min_phase_margin_deg)
            && f[2].is_none_or(|gm| gm >= options.min_gain_margin_db)
    });
    let draws: Vec<Option<[Option<f64>; 4]>> = if always_draw || nominal_passes {
        models
            .draws
            .iter()
            .map(|d| {
                d.as_ref()
                    .and_then(|r| loop_figures(r, law, config, axis, &models.grid))
            })
            .collect()
    } else {
        Vec::new()
    };
    // Undefined in a draw: failing for PM (−∞), unbounded for GM (+∞); left out of
    // the spread and of the crossover's and DRB's percentiles.
    let spread = |k: usize, undefined: Option<f64>| {
        let defined: Vec<f64> = draws.iter().filter_map(|d| d.and_then(|f| f[k])).collect();
        let all: Vec<f64> = match undefined {
            Some(fill) => draws
                .iter()
                .map(|d| d.and_then(|f| f[k]).unwrap_or(fill))
                .collect(),
            None => defined.clone(),
        };
        Spread {
            value: nominal.and_then(|f| f[k]),
            spread: standard_deviation(&defined),
            percentile: percentile_of(all, options.percentile).filter(|v| v.is_finite()),
        }
    };
    let pm = spread(1, Some(f64::NEG_INFINITY));
    let gm = spread(2, Some(f64::INFINITY));
    let mut check = LoopCheck {
        name,
        crossover_rad_s: spread(0, None),
        phase_margin_deg: pm,
        gain_margin_db: gm,
        drb_rad_s: spread(3, None),
        violation: None,
    };
    check.violation = violation(&check, models, options);
    check
}

fn violation(check: &LoopCheck, models: &Models, options: &TuneOptions) -> Option<String> {
    let p = options.percentile;
    let pm_min = options.min_phase_margin_deg;
    let gm_min = options.min_gain_margin_db;
    let pm = &check.phase_margin_deg;
    match pm.value {
        None => return Some("no gain crossover on the identified model".to_string()),
        Some(v) if v < pm_min => {
            return Some(format!(
                "phase margin {v:.1}° < {pm_min}° on the identified model"
            ))
        }
        _ => {}
    }
    if let Some(v) = check.gain_margin_db.value.filter(|v| *v < gm_min) {
        return Some(format!(
            "gain margin {v:.1} dB < {gm_min} dB on the identified model"
        ));
    }
    if models.draws.is_empty() {
        return None;
    }
    match pm.percentile {
        Some(v) if v >= pm_min => {}
        other => {
            let shown = other.map_or("undefined".to_string(), |v| format!("{v:.1}°"));
            return Some(format!(
                "phase margin {shown} < {pm_min}° on the {p}th percentile of {} draws",
                models.draws.len()
            ));
        }
    }
    if let Some(v) = check.gain_margin_db.percentile.filter(|v| *v < gm_min) {
        return Some(format!(
            "gain margin {v:.1} dB < {gm_min} dB on the {p}th percentile of {} draws",
            models.draws.len()
        ));
    }
    None
}
