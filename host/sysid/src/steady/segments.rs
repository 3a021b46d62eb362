//! The steady stretches of a flight log: where the pilot held a flight condition, found by
//! a steadiness rule ([`SteadinessRule`]) on the log's Samples and the GNSS fixes, each
//! averaged into a trim point with its standard error ([`SteadySegment`]).
//!
//! The rule works on one-second **blocks** of consecutive Samples out of any test (phase
//! idle or done: the pilot flying, no excitation). A block's means of the body rates, the
//! attitude, the four pilot sticks and the GNSS velocity (north, east, down; a block needs
//! a fix) are its values. A **segment** is a run of consecutive blocks over which each of
//! these block means spreads (largest − smallest) no more than its tolerance; runs are
//! grown greedily from the first block, a block that would break a tolerance starts the
//! next run, and a run of at least `min_blocks` blocks is a steady segment. A manoeuvre
//! moves the block means of the rates or attitude by far more than the tolerances; a
//! steady flight's gusts and sensor noise move them by less (the block mean of 200 gyro
//! readings is ~14 times quieter than one reading).
//!
//! A segment's trim point: the means over its blocks of the body velocities (each fix's
//! NED velocity rotated into the body axes with its own heading and the attitude of the
//! Sample of its tick), the rates and attitude the board measured, and the four commands
//! as the log records them (what the rotor was given: the fit's inputs). Its standard
//! error per column is the spread of the block means, `s/√n` over the `n` blocks: block
//! means one second apart are close to independent where single samples are not.

use sweephold_protocol::{Phase, Sample};

use super::gnss::GnssFix;
use crate::fit::trim::TrimPoint;

/// The steadiness rule (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadinessRule {
    /// Block length \[s\].
    pub block_s: f64,
    /// Fewest blocks of a steady segment.
    pub min_blocks: usize,
    /// Largest spread of the block means of p, q, r \[rad/s\].
    pub rate_spread: f64,
    /// Largest spread of the block means of φ, θ \[rad\].
    pub angle_spread: f64,
    /// Largest spread of the block means of each pilot stick (fraction of travel).
    pub stick_spread: f64,
    /// Largest spread of the block means of each GNSS velocity component [m/s].
    pub velocity_spread: f64,
}

/// The rule `identify` uses (docs/decisions/2026-11-27-steady-segments.md): one-second
/// blocks, at least five of them, rates within 0.05 rad/s, attitude within 0.03 rad
/// (1.7°), sticks within 0.05 of travel, velocity within 0.3 m/s.
pub const STEADINESS_RULE: SteadinessRule = SteadinessRule {
    block_s: 1.0,
    min_blocks: 5,
    rate_spread: 0.05,
    angle_spread: 0.03,
    stick_spread: 0.05,
    velocity_spread: 0.3,
};

/// Channels of a block's steadiness values: p q r, φ θ, 4 sticks, vn ve vd.
const STEADY_CHANNELS: usize = 12;
/// Columns of a trim point: u v w p q r φ θ, lat lon ped col.
const POINT_COLUMNS: usize = 12;

/// One steady stretch of the log, averaged.
#[derive(Clone, Debug, PartialEq)]
pub struct SteadySegment {
    /// Tick of its first and last Sample.
    pub ticks: [u32; 2],
    /// Its blocks.
    pub blocks: usize,
    /// The trim point (label `steady N`, N counting from 1 in log order).
    pub point: TrimPoint,
    /// Standard error of each column of the point, in the order u v w p q r φ θ, lat lon
    /// ped col.
    pub standard_error: [f64; POINT_COLUMNS],
}

/// One block: its ticks, its steadiness values and its point's columns.
#[derive(Clone, Debug)]
struct Block {
    ticks: [u32; 2],
    /// Whether it directly follows the previous block (no gap, no test in between).
    follows: bool,
    steady: [f64; STEADY_CHANNELS],
    columns: [f64; POINT_COLUMNS],
}

/// Whether a Sample is the pilot's flight, out of any test's trim capture or excitation.
fn pilot_flying(sample: &Sample) -> bool {
    matches!(sample.phase, Phase::Idle | Phase::Done)
}

/// The steady segments of `samples` (a log's Samples in order) with the GNSS `fixes` on
/// the same clock, at `rate_hz` Samples per second, by `rule` (module documentation).
pub fn find_steady_segments(
    samples: &[Sample],
    fixes: &[GnssFix],
    rate_hz: f64,
    rule: &SteadinessRule,
) -> Vec<SteadySegment> {
    let blocks = blocks(samples, fixes, rate_hz, rule.block_s);
    let limits = {
        let mut limits = [0.0; STEADY_CHANNELS];
        limits[..3].fill(rule.rate_spread);
        limits[3..5].fill(rule.angle_spread);
        limits[5..9].fill(rule.stick_spread);
        limits[9..].fill(rule.velocity_spread);
        limits
    };
    let mut segments = Vec::new();
    let mut run: Vec<&Block> = Vec::new();
    let mut low = [0.0_f64; STEADY_CHANNELS];
    let mut high = [0.0_f64; STEADY_CHANNELS];
    let close = |run: &mut Vec<&Block>, segments: &mut Vec<SteadySegment>| {
        if run.len() >= rule.min_blocks.max(2) {
            segments.push(average(run, segments.len() + 1));
        }
        run.clear();
    };
    for block in &blocks {
        let fits = block.follows
            && !run.is_empty()
            && (0..STEADY_CHANNELS)
                .all(|k| high[k].max(block.steady[k]) - low[k].min(block.steady[k]) <= limits[k]);
        if fits {
            for k in 0..STEADY_CHANNELS {
                low[k] = low[k].min(block.steady[k]);
                high[k] = high[k].max(block.steady[k]);
            }
        } else {
            close(&mut run, &mut segments);
            low = block.steady;
            high = block.steady;
        }
        run.push(block);
    }
    close(&mut run, &mut segments);
    segments
}

/// The point and standard errors of a run of blocks, labelled `steady {number}`.
fn average(run: &[&Block], number: usize) -> SteadySegment {
    let n = run.len() as f64;
    let mut mean = [0.0; POINT_COLUMNS];
    for block in run {
        for (m, c) in mean.iter_mut().zip(&block.columns) {
            *m += c / n;
        }
    }
    let mut standard_error = [0.0; POINT_COLUMNS];
    for (k, se) in standard_error.iter_mut().enumerate() {
        let variance = run
            .iter()
            .map(|b| (b.columns[k] - mean[k]).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        *se = (variance / n).sqrt();
    }
    let mut states = [0.0; 8];
    states.copy_from_slice(&mean[..8]);
    let mut controls = [0.0; 4];
    controls.copy_from_slice(&mean[8..]);
    SteadySegment {
        ticks: [run[0].ticks[0], run[run.len() - 1].ticks[1]],
        blocks: run.len(),
        point: TrimPoint {
            label: format!("steady {number}"),
            states,
            controls,
        },
        standard_error,
    }
}

/// The blocks of `samples`: `block_s` seconds of consecutive pilot-flying Samples each,
/// with at least one fix; a Sample that is not the pilot's, a tick gap or a block
/// without a fix breaks the chain.
fn blocks(samples: &[Sample], fixes: &[GnssFix], rate_hz: f64, block_s: f64) -> Vec<Block> {
    let size = (block_s * rate_hz).round().max(1.0) as usize;
    let mut blocks = Vec::new();
    let mut current: Vec<&Sample> = Vec::with_capacity(size);
    let mut follows = false;
    for sample in samples {
        let consecutive = current
            .last()
            .is_none_or(|last| sample.tick == last.tick.wrapping_add(1));
        if !pilot_flying(sample) || !consecutive {
            current.clear();
            follows = false;
            if !pilot_flying(sample) {
                continue;
            }
        }
        current.push(sample);
        if current.len() == size {
            match block(&current, fixes, follows) {
                Some(block) => {
                    blocks.push(block);
                    follows = true;
                }
                None => follows = false,
            }
            current.clear();
        }
    }
    blocks
}

/// One block of `samples` (consecutive ticks), or None without a fix in it.
fn block(samples: &[&Sample], fixes: &[GnssFix], follows: bool) -> Option<Block> {
    let first = samples[0].tick;
    let last = samples[samples.len() - 1].tick;
    let within: Vec<&GnssFix> = fixes
        .iter()
        .filter(|f| f.tick.wrapping_sub(first) <= last.wrapping_sub(first))
        .collect();
    if within.is_empty() {
        return None;
    }
    let n = samples.len() as f64;
    let mean = |value: &dyn Fn(&Sample) -> f32| {
        samples.iter().map(|s| f64::from(value(s))).sum::<f64>() / n
    };
    let fixes_n = within.len() as f64;
    let mut ned = [0.0; 3];
    let mut body = [0.0; 3];
    for fix in &within {
        let index = fix.tick.wrapping_sub(first) as usize;
        let at = samples[index.min(samples.len() - 1)];
        let rotated = ned_to_body(
            fix.velocity_ned,
            f64::from(at.meas.phi),
            f64::from(at.meas.theta),
            fix.heading,
        );
        for k in 0..3 {
            ned[k] += fix.velocity_ned[k] / fixes_n;
            body[k] += rotated[k] / fixes_n;
        }
    }
    let rates = [
        mean(&|s| s.meas.p),
        mean(&|s| s.meas.q),
        mean(&|s| s.meas.r),
    ];
    let angles = [mean(&|s| s.meas.phi), mean(&|s| s.meas.theta)];
    let sticks = [
        mean(&|s| s.pilot.lat),
        mean(&|s| s.pilot.lon),
        mean(&|s| s.pilot.ped),
        mean(&|s| s.pilot.col),
    ];
    let commands = [
        mean(&|s| s.command.lat),
        mean(&|s| s.command.lon),
        mean(&|s| s.command.ped),
        mean(&|s| s.command.col),
    ];
    let mut steady = [0.0; STEADY_CHANNELS];
    steady[..3].copy_from_slice(&rates);
    steady[3..5].copy_from_slice(&angles);
    steady[5..9].copy_from_slice(&sticks);
    steady[9..].copy_from_slice(&ned);
    let mut columns = [0.0; POINT_COLUMNS];
    columns[..3].copy_from_slice(&body);
    columns[3..6].copy_from_slice(&rates);
    columns[6..8].copy_from_slice(&angles);
    columns[8..].copy_from_slice(&commands);
    Some(Block {
        ticks: [first, last],
        follows,
        steady,
        columns,
    })
}

/// A velocity north, east, down in the body axes of attitude φ, θ, heading ψ (the 3-2-1
/// Euler rotation).
pub fn ned_to_body(v: [f64; 3], phi: f64, theta: f64, psi: f64) -> [f64; 3] {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    let [n, e, d] = v;
    [
        ct * cp * n + ct * sp * e - st * d,
        (sf * st * cp - cf * sp) * n + (sf * st * sp + cf * cp) * e + sf * ct * d,
        (cf * st * cp + sf * sp) * n + (cf * st * sp - sf * cp) * e + cf * ct * d,
    ]
}
