//! The broken loops measured in a loop test (`fly --input loop`, the firmware's
//! `InputKind::LoopSweep`): per dump, the loop broken at the swept axis' actuator input,
//! L = −C/U, with its coherence (`sysid::frf::broken_loop`), and the crossover, phase
//! and gain margins of it interpolated on its valid points (`control::margins`, the
//! same code as the predicted margins), for `sweephold margins --measured`.
//!
//! From each Sample of the test's excitation (plus the trim either side that every
//! excitation record keeps): the total command u = `command` of the swept axis (what the
//! servos' pulses express), the injection d = its `sweep`, and the loops' own output
//! c = u − d. A valid point has a normalized random error of at most
//! [`MAX_RANDOM_ERROR`] (0.15, the bound of `frf`'s valid ranges) and lies where the
//! windows resolve it without bias (five times the lowest frequency the longest window
//! resolves, `sysid::frf::broken_loop::RESOLVED_PERIODS`): a gain-reduction margin at the
//! band's bottom (a conditionally stable loop's low-frequency −180° crossing) is not
//! measured.
//!
//! No coherence threshold: with the injection as instrument, the noise that enters the
//! loop elsewhere (the gyro's, through the loop's gains) does not bias L = −G_dc/G_du, it
//! only adds random error, and the random error is what bounds the estimate. The coherence
//! of a sweep against that noise does not grow with the record (at the top of Tischler's
//! sweep the time spent per e-fold of frequency is T/4 and the noise's is T) and sits
//! below 0.6 near a heading loop's phase crossover, where |L| is −10 to −25 dB and the
//! loop's output c is small against the gyro noise it carries; there the random error
//! (about 90 independent one-second windows) is still 0.05–0.15. Measured against the same
//! loop tests flown with perfect sensors (docs/decisions/2026-11-27-loop-test-validity.md)
//! the error grows with the bound's estimate and stays within it.
//!
//! The board-sim pilot flies the mode switch in the middle (Level) with the pedal
//! centred (heading hold), so a loop test measures the loops `sweephold margins`
//! calls roll_attitude (lat), pitch_attitude (lon) and heading (ped): each broken at
//! its actuator input with the others closed.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail};
use control::loops::Sampled;
use control::margins::{margins, Margins};
use control::tune::upper_margins;
use serde::Serialize;
use sweephold_protocol::{Axis, InputKind, Phase};
use sysid::frf::broken_loop::{broken_loop, BrokenLoop, BrokenLoopOptions};
use sysid::records::dump::record_from_samples;
use sysid::records::dump_tests::split_tests;

use control::analysis::MarginsDocument;

use crate::output::check_input_file;

/// Normalized random error above which a point of the measured loop is not used (the
/// bound `frf` applies to its valid ranges, docs/decisions/2026-11-21-random-error-bound.md).
pub const MAX_RANDOM_ERROR: f64 = 0.15;

/// The loop of `margins` a loop test on `axis` measures (see the module documentation).
pub fn predicted_counterpart(axis: Axis) -> Option<&'static str> {
    match axis {
        Axis::Lat => Some("roll_attitude"),
        Axis::Lon => Some("pitch_attitude"),
        Axis::Ped => Some("heading"),
        Axis::Col => None,
    }
}

/// One measured broken loop and its margins.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeasuredLoop {
    /// The dump it came from.
    pub source: String,
    /// The loop of the predicted figures it is compared with.
    pub name: &'static str,
    /// The actuator input it was broken at (lat, lon, ped).
    pub broken_at: &'static str,
    /// The sweep band [rad/s].
    pub band_rad_s: [f64; 2],
    /// Points with random error ≤ [`MAX_RANDOM_ERROR`] at or above `resolved_from_rad_s`,
    /// of all.
    pub valid_points: usize,
    /// The lowest frequency used: five times the lowest the longest window resolves
    /// (`sysid::frf::broken_loop::RESOLVED_PERIODS`) [rad/s].
    pub resolved_from_rad_s: f64,
    /// Grid points.
    pub points: usize,
    /// Gain crossover of the phase margin reported [rad/s].
    pub crossover_rad_s: Option<f64>,
    /// Phase margin \[deg\].
    pub phase_margin_deg: Option<f64>,
    /// Gain margin \[dB\].
    pub gain_margin_db: Option<f64>,
    /// Phase crossover of the gain margin reported [rad/s].
    pub phase_crossover_rad_s: Option<f64>,
    /// The least gain margin over the phase crossovers above the highest gain crossover
    /// \[dB\], the one `tune` constrains. `gain_margin_db` is python-control's pick, the
    /// least |GM| over every phase crossover: on a loop whose phase crosses −180° below
    /// its crossover too (a heading hold's two integrators on a slow yaw pole), that one
    /// is negative, the gain *reduction* the loop tolerates, and this one is the increase.
    pub gain_margin_above_crossover_db: Option<f64>,
    /// One standard deviation of the phase margin from the random error at the crossover
    /// (εr rad of phase, [`margin_uncertainty`]) \[deg\].
    pub phase_margin_random_error_deg: Option<f64>,
    /// One standard deviation of the gain margin from the random error at the phase
    /// crossover (εr of |L|, as 20·log10(e)·εr) \[dB\].
    pub gain_margin_random_error_db: Option<f64>,
    /// The response: frequencies [rad/s], real and imaginary parts, coherence.
    pub response: MeasuredResponse,
}

/// A measured broken loop sampled on its grid.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeasuredResponse {
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// Real parts (null where no window resolves the point).
    pub re: Vec<Option<f64>>,
    /// Imaginary parts.
    pub im: Vec<Option<f64>>,
    /// Coherence.
    pub coherence: Vec<f64>,
    /// Normalized random error (null where no window resolves the point).
    pub random_error: Vec<Option<f64>>,
}

/// Whether the point of a measured loop at `omega` with random error `error` is used:
/// `error` ≤ `max_random_error` and `omega` at or above `resolved_from` (the frequency the
/// windows resolve without bias). The margins, their uncertainty and the report's curves
/// all take the points by this rule.
pub fn is_valid_point(omega: f64, error: f64, resolved_from: f64, max_random_error: f64) -> bool {
    error <= max_random_error && omega >= resolved_from
}

/// The margins of `measured` on its points of random error ≤ `max_random_error` at or
/// above the frequency its windows resolve without bias (`resolved_from_rad_s`).
pub fn valid_margins(measured: &BrokenLoop, max_random_error: f64) -> (Margins, usize) {
    let valid = valid_points(measured, max_random_error);
    let count = valid.omega.len();
    (margins(&valid), count)
}

/// The gain margin above the highest gain crossover of `measured`'s valid points
/// ([`MeasuredLoop::gain_margin_above_crossover_db`]).
pub fn valid_upper_gain_margin(measured: &BrokenLoop, max_random_error: f64) -> Option<f64> {
    upper_margins(&valid_points(measured, max_random_error)).1
}

/// The points of `measured` valid by [`is_valid_point`], with finite values.
fn valid_points(measured: &BrokenLoop, max_random_error: f64) -> Sampled {
    let mut valid = Sampled {
        omega: Vec::new(),
        values: Vec::new(),
    };
    for ((w, l), e) in measured
        .omega
        .iter()
        .zip(&measured.values)
        .zip(&measured.random_error)
    {
        if is_valid_point(*w, *e, measured.resolved_from_rad_s, max_random_error)
            && l.re.is_finite()
            && l.im.is_finite()
        {
            valid.omega.push(*w);
            valid.values.push(*l);
        }
    }
    valid
}

/// One standard deviation of the phase margin \[deg\] and of the gain margin \[dB\] from
/// the random error εr at the crossover and at the phase crossover (each εr of the valid
/// point nearest in log-frequency). Bendat & Piersol's εr is the normalized random error
/// of |L|; the phase's standard deviation is about εr radians: so ±57.3·εr° and
/// ±8.69·εr dB (20·log10(e)·εr). The interpolation between points, which averages two
/// estimates, is not counted: the figures are an upper bound of that kind.
pub fn margin_uncertainty(
    measured: &BrokenLoop,
    crossover: Option<f64>,
    phase_crossover: Option<f64>,
) -> [Option<f64>; 2] {
    let at = |omega: Option<f64>| -> Option<f64> {
        let omega = omega?;
        measured
            .omega
            .iter()
            .zip(&measured.random_error)
            .filter(|(w, e)| {
                is_valid_point(**w, **e, measured.resolved_from_rad_s, MAX_RANDOM_ERROR)
            })
            .min_by(|a, b| {
                let distance = |w: f64| (w / omega).ln().abs();
                distance(*a.0).total_cmp(&distance(*b.0))
            })
            .map(|(_, e)| *e)
    };
    [
        at(crossover).map(|e| e.to_degrees()),
        at(phase_crossover).map(|e| 20.0 * std::f64::consts::LOG10_E * e),
    ]
}

/// The phases whose Samples carry the sweep.
fn is_excitation(phase: Phase) -> bool {
    matches!(phase, Phase::FadeIn | Phase::Sweep | Phase::FadeOut)
}

/// The broken loop of every loop test in the dump `path` (a loop test's own dump, or a
/// logger's file holding several tests: each loop test of it, named `FILE test N`). A
/// dump without a loop test is an error that names what its first test is.
pub fn measure_dump(path: &Path) -> anyhow::Result<Vec<MeasuredLoop>> {
    check_input_file("loop-test dump", path)?;
    let bytes = std::fs::read(path).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    let source = path.display().to_string();
    let split = split_tests(&bytes, &source)?;
    let excited: Vec<_> = split
        .tests
        .iter()
        .filter(|test| test.samples.iter().any(|s| is_excitation(s.phase)))
        .collect();
    let Some(first) = excited.first() else {
        bail!("{source}: no test with an excitation");
    };
    let loops: Vec<_> = excited
        .iter()
        .filter(|test| test.header.test.input == InputKind::LoopSweep)
        .collect();
    if loops.is_empty() {
        bail!(
            "{source}: the test is a {:?}, not a loop test (fly --input loop)",
            first.header.test.input
        );
    }
    let several = split.tests.len() > 1;
    loops
        .iter()
        .map(|test| {
            let name = if several {
                format!("{} test {}", file_name(path), test.number)
            } else {
                file_name(path)
            };
            measure_test(&test.header, &test.samples, &source, name)
        })
        .collect()
}

/// The broken loop of one loop test (its Header and Samples), named `name`.
fn measure_test(
    header: &sweephold_protocol::Header,
    samples: &[sweephold_protocol::Sample],
    source: &str,
    name_in_document: String,
) -> anyhow::Result<MeasuredLoop> {
    let axis = header.test.primary;
    let name = predicted_counterpart(axis)
        .ok_or_else(|| anyhow!("{source}: a loop test on {}", axis.name()))?;
    let record = record_from_samples(header, samples, source)?;
    let k = axis.index();
    let (total, injection) = match (record.inputs.get(k), record.references.get(k)) {
        (Some(u), Some(d)) => (&u.values, &d.values),
        _ => bail!("{source}: the record has no {} channel", axis.name()),
    };
    let band = [
        f64::from(header.test.sweep.omega_min),
        f64::from(header.test.sweep.omega_max),
    ];
    let measured = broken_loop(
        injection,
        total,
        record.sample_rate_hz,
        band,
        &BrokenLoopOptions::default(),
    )
    .map_err(|e| anyhow!("{source}: {e}"))?;
    let (figures, valid_points) = valid_margins(&measured, MAX_RANDOM_ERROR);
    let finite = |v: f64| v.is_finite().then_some(v);
    let [phase_margin_random_error_deg, gain_margin_random_error_db] = margin_uncertainty(
        &measured,
        figures.crossover_rad_s,
        figures.phase_crossover_rad_s,
    );
    Ok(MeasuredLoop {
        source: name_in_document,
        name,
        broken_at: axis.name(),
        band_rad_s: band,
        valid_points,
        resolved_from_rad_s: measured.resolved_from_rad_s,
        points: measured.omega.len(),
        crossover_rad_s: figures.crossover_rad_s,
        phase_margin_deg: figures.phase_margin_deg,
        gain_margin_db: figures.gain_margin_db,
        phase_crossover_rad_s: figures.phase_crossover_rad_s,
        gain_margin_above_crossover_db: valid_upper_gain_margin(&measured, MAX_RANDOM_ERROR),
        phase_margin_random_error_deg,
        gain_margin_random_error_db,
        response: MeasuredResponse {
            re: measured.values.iter().map(|v| finite(v.re)).collect(),
            im: measured.values.iter().map(|v| finite(v.im)).collect(),
            random_error: measured.random_error.iter().map(|&e| finite(e)).collect(),
            omega: measured.omega,
            coherence: measured.coherence,
        },
    })
}

/// The dump's file name (the whole path if it has none): the document names its
/// sources without the folder it was read from, so it does not depend on where.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

/// Every measured loop of `paths`, in order (each dump's loop tests in its order).
pub fn measure_all(paths: &[PathBuf]) -> anyhow::Result<Vec<MeasuredLoop>> {
    let mut all = Vec::new();
    for path in paths {
        all.extend(measure_dump(path)?);
    }
    Ok(all)
}

/// A measured loop beside its predicted figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Compared {
    /// The measurement.
    #[serde(flatten)]
    pub measured: MeasuredLoop,
    /// The predicted loop's nominal figures: crossover, phase margin, gain margin,
    /// phase crossover (null where the prediction has none).
    pub predicted: PredictedFigures,
    /// Measured − predicted gain margin \[dB\].
    pub gain_margin_difference_db: Option<f64>,
    /// Measured − predicted phase margin \[deg\].
    pub phase_margin_difference_deg: Option<f64>,
}

/// The nominal predicted figures of one loop.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PredictedFigures {
    /// Gain crossover [rad/s].
    pub crossover_rad_s: Option<f64>,
    /// Phase margin \[deg\].
    pub phase_margin_deg: Option<f64>,
    /// Gain margin \[dB\].
    pub gain_margin_db: Option<f64>,
    /// Phase crossover [rad/s].
    pub phase_crossover_rad_s: Option<f64>,
}

/// Each measured loop beside the predicted loop of the same name in `predicted`.
pub fn compared(predicted: &MarginsDocument, measured: Vec<MeasuredLoop>) -> Vec<Compared> {
    measured
        .into_iter()
        .map(|measured| {
            let figures = predicted
                .loops
                .iter()
                .find(|l| l.name == measured.name)
                .map_or_else(PredictedFigures::default, |l| PredictedFigures {
                    crossover_rad_s: l.crossover_rad_s.value,
                    phase_margin_deg: l.phase_margin_deg.value,
                    gain_margin_db: l.gain_margin_db.value,
                    phase_crossover_rad_s: l.phase_crossover_rad_s.value,
                });
            let difference = |a: Option<f64>, b: Option<f64>| Some(a? - b?);
            Compared {
                gain_margin_difference_db: difference(
                    measured.gain_margin_db,
                    figures.gain_margin_db,
                ),
                phase_margin_difference_deg: difference(
                    measured.phase_margin_deg,
                    figures.phase_margin_deg,
                ),
                predicted: figures,
                measured,
            }
        })
        .collect()
}

/// The measured loops beside the predicted ones, as a table (empty without any).
pub fn table(loops: &[Compared]) -> String {
    use std::fmt::Write as _;
    if loops.is_empty() {
        return String::new();
    }
    let cell = |v: Option<f64>, decimals: usize| {
        v.map_or("—".to_string(), |v| format!("{v:.decimals$}"))
    };
    let with_error = |v: Option<f64>, error: Option<f64>, decimals: usize| match (v, error) {
        (Some(v), Some(e)) => format!("{v:.decimals$}±{e:.decimals$}"),
        _ => cell(v, decimals),
    };
    let mut text = String::new();
    let _ = writeln!(
        text,
        "\nmeasured (loop tests; ± one standard deviation from the random error; GM>wc: above the crossover)\n{:<15} {:<4} {:>9} {:>9} {:>10} {:>9} {:>10} {:>9} {:>7} {:>9}  dump",
        "loop", "at", "wc", "wc pred", "PM", "PM pred", "GM", "GM pred", "GM>wc", "valid"
    );
    for l in loops {
        let m = &l.measured;
        let _ = writeln!(
            text,
            "{:<15} {:<4} {:>9} {:>9} {:>10} {:>9} {:>10} {:>9} {:>7} {:>9}  {}",
            m.name,
            m.broken_at,
            cell(m.crossover_rad_s, 2),
            cell(l.predicted.crossover_rad_s, 2),
            with_error(m.phase_margin_deg, m.phase_margin_random_error_deg, 1),
            cell(l.predicted.phase_margin_deg, 1),
            with_error(m.gain_margin_db, m.gain_margin_random_error_db, 1),
            cell(l.predicted.gain_margin_db, 1),
            cell(m.gain_margin_above_crossover_db, 1),
            format!("{}/{}", m.valid_points, m.points),
            m.source
        );
    }
    text
}

#[cfg(test)]
mod tests;
