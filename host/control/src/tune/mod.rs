//! Pilot-mode gains designed on an identified model: `sweephold tune`.
//!
//! **Method: loop shaping of each rate loop's PI for a crossover, the outer loops at a
//! fraction of it, every candidate scored by the margins on the model and on models
//! drawn over its Cramér–Rao covariance.** The firmware's rate loop has two feedback
//! gains (`Kp`, `Ki`, [`RateAxisGains`]), no derivative and no filter of its own, and
//! the outer loops one each (`K_lvl` shared by roll and pitch, `K_ψ`): few enough that a
//! one-dimensional search per loop, each point scored on the full law of [`crate::law`]
//! (tick hold, IMU filter bank, delays, servos, the other loops closed), is both exact
//! and cheap; a general optimiser over all gains would add nothing but tuning knobs.
//! Loop shaping is the textbook design for a PI on a rate plant (Åström & Murray,
//! *Feedback Systems*, ch. 11; the CONDUIT workflow in Tischler & Remple, *Aircraft and
//! Rotorcraft System Identification*, ch. 14, does the same with more specifications).
//!
//! 1. **Rate loop k (roll, pitch, yaw), for a crossover ω_c.** With the other loops
//!    closed the broken loop at actuator k is `L_k = C_k·g_k`, linear in the axis's
//!    feedback `C_k(z) = Kp + Ki·T/(z − 1)`, so `g_k(jω_c) = L_k/C_k` from the loop with
//!    any nonzero gains. The PI's zero is placed at `f·ω_c`, `Ki = f·ω_c·Kp`, and `Kp`
//!    makes `|L_k(jω_c)| = 1`: `Kp = 1/(|g_k|·|1 + f·ω_c·T/(z − 1)|)`. f is chosen from
//!    0.2, 0.5, 1, 2, 4, 8: a zero well below crossover (0.2 costs 11° of phase) suits a
//!    plant that already rolls off there; a rotor whose rate damping is far above the
//!    crossover (L_p ≈ −67 /s on a 700-class rotor) keeps |g_k| flat above ω_c, and
//!    only a zero above the crossover (an integral-dominated loop, gain falling 20 dB per
//!    decade through ω_c) leaves it a gain margin. Of the f that meet the constraints
//!    the one with the most room on its tighter margin is kept (45° of phase counting
//!    as 6 dB of gain).
//! 2. **Which ω_c.** A stated one is checked; otherwise candidates log-spaced from
//!    0.5 rad/s up to a cap per axis (20 rad/s roll and pitch, 15 rad/s yaw: a decade
//!    below the 200 Hz tick's Nyquist and below the servos' 48–60 rad/s) are tried from
//!    the top, and the highest that meets every constraint is taken. The three axes are
//!    designed in turn (roll, pitch, yaw), then once more each with the others' new
//!    gains (the coupling changes g_k a little).
//! 3. **Outer loops.** `K_lvl` (roll and pitch level loops) and `K_ψ` (heading hold) are
//!    the highest of log-spaced candidates from 0.3 /s up to `outer_fraction` (½) of
//!    the inner crossover (the lower of roll's and pitch's for `K_lvl`) that meet the
//!    constraints on the loops they close (roll_attitude and pitch_attitude; heading).
//!    Where none does, the inner crossovers they close (unless stated) step down by 15 %
//!    and the outer design is tried again.
//! 4. **Constraints**, on each loop broken at its actuator with the others closed: phase
//!    margin at the loop's crossover (its highest-frequency gain crossover) ≥ 45° and
//!    the gain margin above it (the least over the phase crossovers above the crossover:
//!    how much the loop gain may grow) ≥ 6 dB, both on the identified model and on the
//!    5th percentile of the draws ([`crate::uncertainty`]; a draw without a crossover or
//!    whose model is singular counts as failing). The rate loops' low-frequency
//!    crossings with the Rate stick (the aircraft's unstabilised hover modes, which the
//!    pilot flies and no rate gain removes) are reported by `sweephold margins`, not
//!    constrained here. Where the vehicle's servo rate limit is known, the servo rate for
//!    a full step of the Rate stick ([`servo_rate`]) must stay within it, or within the
//!    rate of the gains the design starts from where these already exceed it (on a
//!    stick step most of the rate is the feed-forward's, which the design keeps).
//!
//! The feed-forward terms (FF_ω, FF_α), the limits and the stick gains are the preset's:
//! they shape the stick response, not the loops' stability, and are left to the pilot.

pub mod check;
pub mod options;
pub mod servo_rate;

use check::check_loop_with;
pub use check::{check_loop, upper_margins, LoopCheck, Models, Spread};
pub use options::{TuneOptions, LOOPS};

use num_complex::Complex64;
use sweephold_firmware::app::pilot_mode::{PilotModeGains, RateAxisGains};

use crate::law::{BoardLaw, LoopMode};
use crate::loops::{self, Configuration};
use crate::plant::Plant;

fn axis_mut(gains: &mut PilotModeGains, axis: usize) -> &mut RateAxisGains {
    match axis {
        0 => &mut gains.roll,
        1 => &mut gains.pitch,
        _ => &mut gains.yaw,
    }
}

const RATE: Configuration = Configuration {
    mode: LoopMode::Rate,
    heading_hold: false,
};

/// Kp and Ki that put rate loop `axis`'s crossover at `wc` on the identified model,
/// the other loops as in `law`.
pub fn rate_gains_for_crossover(
    plant: &Plant,
    law: &BoardLaw,
    axis: usize,
    wc: f64,
    integral_fraction: f64,
) -> Option<(f64, f64)> {
    let mut probe = law.clone();
    // Any nonzero feedback gives g_k = L_k/C_k.
    let gains = axis_mut(&mut probe.gains, axis);
    if gains.kp <= 0.0 {
        gains.kp = 0.01;
    }
    let response = plant.response(wc)?;
    let broken = loops::broken_loops_from(&[response], &probe, RATE, &[wc])?;
    let c = probe.axis_terms(probe.axes()[axis], wc).feedback;
    let g = broken[axis].values[0] / c;
    let t = law.tick_s;
    let z = Complex64::new(0.0, wc * t).exp();
    let ratio = integral_fraction * wc;
    let shape = 1.0 + ratio * t / (z - 1.0);
    let kp = 1.0 / (g.norm() * shape.norm());
    (kp.is_finite() && kp > 0.0).then_some((kp, ratio * kp))
}

/// The tuned gains and what they give.
#[derive(Clone, Debug, PartialEq)]
pub struct Tuned {
    /// The gains (the preset's but for Kp, Ki of each axis, K_lvl and K_ψ).
    pub gains: PilotModeGains,
    /// The rate-loop crossovers designed for (roll, pitch, yaw) [rad/s].
    pub designed_crossovers: [f64; 3],
}

/// Why a loop has no gains.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    /// The loop.
    pub name: &'static str,
    /// The binding constraint, in words.
    pub why: String,
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: no gains meet the constraints: {}",
            self.name, self.why
        )
    }
}

/// Candidates from `high` down to `low`, log-spaced.
fn descending(low: f64, high: f64, count: usize) -> Vec<f64> {
    if high <= low {
        return vec![high];
    }
    let mut grid = loops::log_grid(low, high, count);
    grid.reverse();
    grid
}

/// The servo rate rate loop `axis` may reach: the servo's limit, or the rate of the
/// gains the design starts from where these already exceed it (the feed-forward,
/// which the design leaves as it is, takes most of it on a stick step).
fn servo_rate_bound(
    models: &Models,
    law: &BoardLaw,
    axis: usize,
    options: &TuneOptions,
) -> Option<f64> {
    let limit = options.servo_rate_limit_per_s?;
    let start = servo_rate::stick_step_servo_rate(&models.plant, law, axis, options.stick_step);
    Some(start.map_or(limit, |rate| rate.max(limit)))
}

/// The servo-rate constraint of rate loop `axis` under `law`.
fn servo_rate_violation(
    models: &Models,
    law: &BoardLaw,
    axis: usize,
    options: &TuneOptions,
    bound: Option<f64>,
) -> Option<String> {
    let limit = bound?;
    match servo_rate::stick_step_servo_rate(&models.plant, law, axis, options.stick_step) {
        Some(rate) if rate <= limit => None,
        Some(rate) => Some(format!(
            "servo rate {rate:.2} /s for a {} stick step > {limit:.2} /s",
            options.stick_step
        )),
        None => Some("the model is singular on the servo-rate grid".to_string()),
    }
}

/// Rate loop `axis` (0 roll, 1 pitch, 2 yaw) designed into `law`, at the `stated`
/// crossover or the highest that meets the constraints: the crossover.
pub fn design_rate_axis(
    models: &Models,
    law: &mut BoardLaw,
    axis: usize,
    options: &TuneOptions,
    stated: Option<f64>,
) -> Result<f64, Refusal> {
    let bound = servo_rate_bound(models, law, axis, options);
    design_rate_axis_within(models, law, axis, options, stated, bound)
}

/// [`design_rate_axis`] with the servo rate bounded by `bound` (that of the gains the
/// whole design started from: a bound taken from gains already changed would creep).
fn design_rate_axis_within(
    models: &Models,
    law: &mut BoardLaw,
    axis: usize,
    options: &TuneOptions,
    stated: Option<f64>,
    bound: Option<f64>,
) -> Result<f64, Refusal> {
    let name = LOOPS[axis].0;
    let candidates = match stated {
        Some(wc) => vec![wc],
        None => descending(
            options.lowest_crossover_rad_s,
            options.crossover_caps[axis],
            options.candidates,
        ),
    };
    let mut last_why = String::from("no candidate crossover");
    for &wc in &candidates {
        // Of the PI zeros that meet the constraints at this crossover, the one with the
        // most room on its tighter margin (phase margin excess, gain margin excess
        // weighted 7.5°/dB: 45° and 6 dB count alike).
        let mut best: Option<(f64, BoardLaw)> = None;
        for &fraction in &options.integral_fractions {
            let Some((kp, ki)) = rate_gains_for_crossover(&models.plant, law, axis, wc, fraction)
            else {
                last_why = format!("no finite gain gives a crossover at {wc:.2} rad/s");
                continue;
            };
            let mut trial = law.clone();
            let gains = axis_mut(&mut trial.gains, axis);
            gains.kp = kp as f32;
            gains.ki = ki as f32;
            let check = check_loop_with(models, &trial, axis, options, false);
            let why = check
                .violation
                .clone()
                .or_else(|| servo_rate_violation(models, &trial, axis, options, bound));
            match why {
                None => {
                    let score = room(&check, options);
                    if best.as_ref().is_none_or(|(b, _)| score > *b) {
                        best = Some((score, trial));
                    }
                }
                Some(why) => last_why = format!("{why} (crossover {wc:.2} rad/s)"),
            }
        }
        if let Some((_, trial)) = best {
            *law = trial;
            return Ok(wc);
        }
    }
    Err(Refusal {
        name,
        why: last_why,
    })
}

/// The room a passing loop has on its tighter margin (percentile where drawn).
fn room(check: &LoopCheck, options: &TuneOptions) -> f64 {
    let pick = |s: &Spread| s.percentile.or(s.value);
    let pm = pick(&check.phase_margin_deg).unwrap_or(f64::NEG_INFINITY);
    let gm = pick(&check.gain_margin_db).unwrap_or(f64::INFINITY);
    (pm - options.min_phase_margin_deg).min(7.5 * (gm - options.min_gain_margin_db))
}

/// An outer gain (`level`: K_lvl on the two attitude loops; otherwise K_ψ on the
/// heading loop) designed into `law`.
fn design_outer(
    models: &Models,
    law: &mut BoardLaw,
    level: bool,
    inner_crossover: f64,
    options: &TuneOptions,
) -> Result<(), Refusal> {
    let loops: &[usize] = if level { &[3, 4] } else { &[5] };
    let high = options.outer_fraction * inner_crossover;
    let mut last = Refusal {
        name: LOOPS[loops[0]].0,
        why: "no candidate gain".to_string(),
    };
    for gain in descending(0.3, high.max(0.3), options.candidates) {
        let mut trial = law.clone();
        if level {
            trial.gains.level_gain = gain as f32;
        } else {
            trial.gains.heading_gain = gain as f32;
        }
        let failed = loops.iter().find_map(|&i| {
            check_loop_with(models, &trial, i, options, false)
                .violation
                .map(|why| (LOOPS[i].0, why))
        });
        match failed {
            None => {
                *law = trial;
                return Ok(());
            }
            Some((name, why)) => {
                last = Refusal {
                    name,
                    why: format!(
                        "{why} ({} {gain:.2} /s)",
                        if level { "K_lvl" } else { "K_psi" }
                    ),
                }
            }
        }
    }
    Err(last)
}

/// How far an inner crossover steps down when its outer loop finds no gain.
const INNER_BACK_OFF: f64 = 0.85;

/// The pilot-mode gains of `law` designed on `models`. A loop that fails once every gain
/// is in place (the loops designed later change the earlier ones a little) has its rate
/// axis's cap lowered to 85 % of the crossover it had, and the design runs again.
pub fn tune(models: &Models, law: &BoardLaw, options: &TuneOptions) -> Result<Tuned, Refusal> {
    let mut options = options.clone();
    loop {
        match design_all(models, law, &options) {
            Ok(tuned) => return Ok(tuned),
            Err((refusal, None)) => return Err(refusal),
            Err((refusal, Some((axis, crossover)))) => {
                let cap = crossover * INNER_BACK_OFF;
                if options.crossovers[axis].is_some() || cap < options.lowest_crossover_rad_s {
                    return Err(refusal);
                }
                options.crossover_caps[axis] = cap;
            }
        }
    }
}

/// The rate axis a loop of [`LOOPS`] closes around.
fn inner_axis(index: usize) -> usize {
    LOOPS[index].2
}

/// One pass of the design; a failure of the final check names the rate axis to lower
/// and its crossover.
#[allow(clippy::type_complexity)]
fn design_all(
    models: &Models,
    law: &BoardLaw,
    options: &TuneOptions,
) -> Result<Tuned, (Refusal, Option<(usize, f64)>)> {
    let bounds: [Option<f64>; 3] =
        std::array::from_fn(|axis| servo_rate_bound(models, law, axis, options));
    let design = |law: &mut BoardLaw, axis: usize, stated: Option<f64>| {
        design_rate_axis_within(models, law, axis, options, stated, bounds[axis])
    };
    let mut law = law.clone();
    let mut crossovers = [0.0; 3];
    for (axis, crossover) in crossovers.iter_mut().enumerate() {
        *crossover = design(&mut law, axis, options.crossovers[axis]).map_err(|r| (r, None))?;
    }
    // Once more with the other axes' new gains, each at the crossover found.
    for (axis, crossover) in crossovers.iter_mut().enumerate() {
        *crossover = design(&mut law, axis, Some(*crossover))
            .or_else(|_| design(&mut law, axis, options.crossovers[axis]))
            .map_err(|r| (r, None))?;
    }
    // The outer loops; where none of their gains meets the constraints, the inner loops
    // they close (unless stated) step down by 15 % and the outer design is tried again.
    for (level, axes) in [(true, &[0usize, 1][..]), (false, &[2usize][..])] {
        loop {
            let inner = axes
                .iter()
                .map(|&a| crossovers[a])
                .fold(f64::INFINITY, f64::min);
            let refusal = match design_outer(models, &mut law, level, inner, options) {
                Ok(()) => break,
                Err(refusal) => refusal,
            };
            if axes.iter().any(|&a| options.crossovers[a].is_some()) {
                return Err((refusal, None));
            }
            for &axis in axes {
                // Down until a crossover meets the rate loop's own constraints again.
                loop {
                    let wc = crossovers[axis] * INNER_BACK_OFF;
                    if wc < options.lowest_crossover_rad_s {
                        return Err((refusal, None));
                    }
                    crossovers[axis] = wc;
                    if design(&mut law, axis, Some(wc)).is_ok() {
                        break;
                    }
                }
            }
        }
    }
    // Every loop and servo rate with every gain in place.
    for (axis, bound) in bounds.iter().enumerate() {
        if let Some(why) = servo_rate_violation(models, &law, axis, options, *bound) {
            let refusal = Refusal {
                name: LOOPS[axis].0,
                why: format!("{why} with all gains in place"),
            };
            return Err((refusal, Some((axis, crossovers[axis]))));
        }
    }
    for (index, &(name, _, _)) in LOOPS.iter().enumerate() {
        if let Some(why) = check_loop(models, &law, index, options).violation {
            let refusal = Refusal {
                name,
                why: format!("{why} with all gains in place"),
            };
            let axis = inner_axis(index);
            return Err((refusal, Some((axis, crossovers[axis]))));
        }
    }
    Ok(Tuned {
        gains: law.gains,
        designed_crossovers: crossovers,
    })
}
