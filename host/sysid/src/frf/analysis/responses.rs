//! The responses of one prepared group: per responding input, output, window length and
//! frequency the MISO-conditioned (or sweep-reference) and SISO estimates, blended over
//! the window lengths into the document's pairs.

use num_complex::Complex64;

use crate::document::{CrossCoherence, PairResponse, MAX_PLAUSIBLE_MAG_DB};
use crate::frf::coherence::{accurate_range, random_error};
use crate::frf::composite::{blend, Estimate};
use crate::frf::miso::{InputFactor, MAX_INPUTS};
use crate::frf::options::FrfOptions;
use crate::frf::reference::ReferenceSolve;
use crate::frf::spectra::WindowSpectra;

use super::cross_coherence::curves_from_spectra;
use super::outcome::{FrfAnalysis, GroupSummary, MultipleCoherence};
use super::prepare::{spectra_of, PreparedGroup};

/// The conditioning inputs' n×n block of a window's input matrix at grid index k, in
/// `order` (positions in the spectra; n = `order.len()`).
fn conditioning_block(
    s: &WindowSpectra,
    k: usize,
    order: &[usize],
) -> [Complex64; MAX_INPUTS * MAX_INPUTS] {
    let n = order.len();
    let mut block = [Complex64::new(0.0, 0.0); MAX_INPUTS * MAX_INPUTS];
    for (i, &a) in order.iter().enumerate() {
        for (j, &b) in order.iter().enumerate() {
            block[i * n + j] = s.input_input(k, a, b);
        }
    }
    block
}

/// The conditioning positions `0..n` with `last` moved to the end. The factorisation
/// then gives, in its last pivot, that input's autospectrum conditioned on all the others,
/// which its partial coherence needs ([`miso`](super::miso)); the other positions keep
/// their order, so for the swept input (already last) this is the group's own order.
fn order_with_last(n: usize, last: usize) -> Vec<usize> {
    (0..n).filter(|&i| i != last).chain([last]).collect()
}

/// Instrument j of the conditioning inputs (module docs of [`reference`]): the recorded
/// sweep (spectra position n) for the primary (position n − 1), the input itself for
/// the others.
///
/// [`reference`]: super::reference
fn instrument(j: usize, n: usize) -> usize {
    if j + 1 == n {
        n
    } else {
        j
    }
}

/// The reference solve of a window at grid index k (recorded sweep at position n).
fn reference_solve(
    s: &WindowSpectra,
    k: usize,
    n: usize,
    min_pivot: f64,
) -> Option<ReferenceSolve> {
    let mut gzu = [Complex64::new(0.0, 0.0); MAX_INPUTS * MAX_INPUTS];
    let mut gzz = [Complex64::new(0.0, 0.0); MAX_INPUTS * MAX_INPUTS];
    let mut guu = [0.0; MAX_INPUTS];
    for i in 0..n {
        guu[i] = s.input_input(k, i, i).re;
        for j in 0..n {
            gzu[i * n + j] = s.input_input(k, instrument(i, n), j);
            gzz[i * n + j] = s.input_input(k, instrument(i, n), instrument(j, n));
        }
    }
    ReferenceSolve::new(&gzu, &gzz, &guu, n, min_pivot).ok()
}

pub(super) fn analyse_group(
    prepared: &PreparedGroup,
    opts: &FrfOptions,
    analysis: &mut FrfAnalysis,
) {
    let axis = &prepared.primary;
    let spectra = spectra_of(prepared, opts, true);
    let grid = &prepared.grid;
    let n_in = prepared.conditioning.len();
    let primary = n_in - 1;
    let mut notes = prepared.notes.clone();
    let input_name = |i: usize| {
        prepared.joined.inputs[prepared.conditioning[i]]
            .name
            .clone()
    };

    // With the sweep-reference estimator (swept input only), its solve per window and
    // frequency.
    let with_references = prepared.sweep_reference.is_some();
    let reference_solves: Vec<Vec<Option<ReferenceSolve>>> = if with_references {
        spectra
            .iter()
            .map(|s| {
                (s.valid_from.min(grid.len())..grid.len())
                    .map(|k| reference_solve(s, k, n_in, opts.min_pivot))
                    .collect()
            })
            .collect()
    } else {
        Vec::new()
    };

    for &responding in &prepared.responding {
        let order = order_with_last(n_in, responding);
        let input = input_name(responding);
        // Factor every window's input matrix once, with this input last; all outputs
        // share it.
        let factors: Vec<Vec<Option<InputFactor>>> = spectra
            .iter()
            .map(|s| {
                (s.valid_from.min(grid.len())..grid.len())
                    .map(|k| {
                        InputFactor::new(&conditioning_block(s, k, &order), n_in, opts.min_pivot)
                            .ok()
                    })
                    .collect()
            })
            .collect();
        let factor_at = |w: usize, k: usize| -> Option<&InputFactor> {
            let s = &spectra[w];
            (k >= s.valid_from)
                .then(|| factors[w][k - s.valid_from].as_ref())
                .flatten()
        };
        let unconditioned: Vec<f64> = (0..grid.len())
            .filter(|&k| (0..spectra.len()).all(|w| factor_at(w, k).is_none()))
            .map(|k| grid[k])
            .collect();
        if let (Some(first), Some(last)) = (unconditioned.first(), unconditioned.last()) {
            let which = if responding == primary {
                String::new()
            } else {
                format!(" to `{input}`")
            };
            notes.push(format!(
                "{axis} sweep: MISO responses{which} left out at {} of {} frequencies ({first:.3}–{last:.3} rad/s): the excited controls are nearly collinear there (normalised pivot < {:e})",
                unconditioned.len(),
                grid.len(),
                opts.min_pivot
            ));
        }

        for (o_local, &o) in prepared.outputs.iter().enumerate() {
            let output = &prepared.joined.outputs[o].name;
            let mut miso = Vec::with_capacity(grid.len());
            // The multiple coherence at each `miso` point (same windows and weights).
            let mut miso_multiple = Vec::with_capacity(grid.len());
            let mut multiple = MultipleCoherence {
                input: input.clone(),
                output: output.clone(),
                omega: Vec::with_capacity(grid.len()),
                coherence: Vec::with_capacity(grid.len()),
            };
            let mut siso = Vec::with_capacity(grid.len());
            let mut guy = [Complex64::new(0.0, 0.0); MAX_INPUTS];
            let mut gzy = [Complex64::new(0.0, 0.0); MAX_INPUTS];
            for (k, &omega) in grid.iter().enumerate() {
                let mut miso_estimates = Vec::with_capacity(spectra.len());
                let mut multiple_estimates = Vec::with_capacity(spectra.len());
                let mut siso_estimates = Vec::with_capacity(spectra.len());
                for (w, s) in spectra.iter().enumerate() {
                    if k < s.valid_from {
                        continue;
                    }
                    let gyy = s.output_auto(k, o_local);
                    if gyy.is_nan() || gyy <= 0.0 {
                        continue;
                    }
                    if let Some(factor) = factor_at(w, k) {
                        for (g, &position) in guy.iter_mut().zip(&order) {
                            *g = s.input_output(k, position, o_local);
                        }
                        let c = factor.condition(&guy[..n_in], gyy);
                        let error = random_error(c.partial_coherence, s.independent);
                        if with_references {
                            // Reference estimate: this window counts only where the
                            // recorded sweep drives the swept control.
                            let solve = reference_solves
                                .get(w)
                                .and_then(|solves| solves.get(k - s.valid_from))
                                .and_then(Option::as_ref);
                            if let Some(solve) = solve {
                                for (i, g) in gzy.iter_mut().enumerate().take(n_in) {
                                    *g = s.input_output(k, instrument(i, n_in), o_local);
                                }
                                miso_estimates.push(Estimate {
                                    response: solve.solve(&gzy[..n_in])[primary],
                                    coherence: c.partial_coherence,
                                    random_error: error
                                        * solve.variance_ratio(factor.conditioned_primary()).sqrt(),
                                });
                            }
                        } else {
                            miso_estimates.push(Estimate {
                                response: c.response,
                                coherence: c.partial_coherence,
                                random_error: error,
                            });
                        }
                        multiple_estimates.push(Estimate {
                            response: Complex64::new(0.0, 0.0),
                            coherence: c.multiple_coherence,
                            random_error: error,
                        });
                    }
                    let gpp = s.input_input(k, responding, responding).re;
                    if gpp > 0.0 {
                        let gpy = s.input_output(k, responding, o_local);
                        let coherence = (gpy.norm_sqr() / (gpp * gyy)).clamp(0.0, 1.0);
                        siso_estimates.push(Estimate {
                            response: gpy / gpp,
                            coherence,
                            random_error: random_error(coherence, s.independent),
                        });
                    }
                }
                let multiple_here = blend(multiple_estimates)
                    .map(|e| e.coherence)
                    .filter(|c| c.is_finite());
                if let Some(e) = blend(miso_estimates) {
                    miso.push((omega, e));
                    miso_multiple.push(multiple_here.map_or(f64::NAN, |c| c.clamp(0.0, 1.0)));
                }
                if let Some(coherence) = multiple_here {
                    multiple.omega.push(omega);
                    multiple.coherence.push(coherence.clamp(0.0, 1.0));
                }
                if let Some(e) = blend(siso_estimates) {
                    siso.push((omega, e));
                }
            }
            let multiple_kept = prepared.every_excited.then_some(miso_multiple.as_slice());
            let (mut pair, dropped) = pair_response(&input, output, &miso, multiple_kept, opts);
            let (mut siso_pair, siso_dropped) = pair_response(&input, output, &siso, None, opts);
            if dropped + siso_dropped > 0 {
                notes.push(format!(
                    "{input}→{output}: {} non-finite points (or beyond ±{MAX_PLAUSIBLE_MAG_DB} dB) left out",
                    dropped + siso_dropped
                ));
            }
            if prepared.every_excited {
                pair.group = Some(axis.clone());
                siso_pair.group = Some(axis.clone());
            }
            analysis.document.pairs.push(pair);
            analysis.multiple_coherence.push(multiple);
            analysis.document.siso.push(siso_pair);
        }
    }

    let curves = curves_from_spectra(prepared, &spectra);
    for curve in &curves {
        analysis.document.cross_coherence.push(CrossCoherence {
            axis: curve.axis.clone(),
            a: curve.a.clone(),
            b: curve.b.clone(),
            mean: curve.mean(),
        });
    }
    analysis.cross_coherence_curves.extend(curves);
    analysis.document.notes.extend(notes);
    analysis.groups.push(GroupSummary {
        axis: axis.clone(),
        records: prepared.records,
        seconds: prepared.joined.duration_s(),
        band: [grid[0], grid[grid.len() - 1]],
        windows: spectra.iter().map(|s| s.seconds).collect(),
        conditioned_on: (0..n_in).map(input_name).collect(),
        responses: prepared.responding.iter().map(|&i| input_name(i)).collect(),
    });
}

/// Magnitude, unwrapped phase, coherence, random error, valid range and, when given (one
/// value per point), multiple coherence of composite estimates; non-finite points, and those beyond ±[`MAX_PLAUSIBLE_MAG_DB`] (which
/// every reader of `frf.json` refuses), are left out (their count is returned). The valid range
/// takes the coherence threshold and, when set, the largest random error of `opts`.
fn pair_response(
    input: &str,
    output: &str,
    points: &[(f64, Estimate)],
    multiple: Option<&[f64]>,
    opts: &FrfOptions,
) -> (PairResponse, usize) {
    let mut pair = PairResponse {
        input: input.to_string(),
        output: output.to_string(),
        omega: Vec::with_capacity(points.len()),
        mag_db: Vec::with_capacity(points.len()),
        phase_deg: Vec::with_capacity(points.len()),
        coherence: Vec::with_capacity(points.len()),
        random_error: Vec::with_capacity(points.len()),
        valid_range: None,
        group: None,
        multiple_coherence: Vec::new(),
    };
    let mut dropped = 0;
    let mut previous_wrapped: Option<f64> = None;
    for (index, &(omega, e)) in points.iter().enumerate() {
        let multiple_here = multiple.map(|m| m[index]);
        let magnitude = e.response.norm();
        let mag_db = 20.0 * magnitude.max(1e-300).log10();
        // What `FrfDocument::validate` would refuse is left out here: a reader must
        // accept every document this writes.
        let finite = omega.is_finite()
            && e.response.re.is_finite()
            && e.response.im.is_finite()
            && e.coherence.is_finite()
            && e.random_error.is_finite()
            && mag_db.abs() <= MAX_PLAUSIBLE_MAG_DB
            && multiple_here.is_none_or(f64::is_finite);
        if !finite {
            dropped += 1;
            continue;
        }
        let wrapped = e.response.arg().to_degrees();
        // Unwrap: add the step to the previous point, brought into (−180°, 180°].
        let phase = match (previous_wrapped, pair.phase_deg.last()) {
            (Some(previous), Some(&last)) => {
                let mut step = wrapped - previous;
                step -= 360.0 * ((step + 180.0) / 360.0).floor();
                if step == -180.0 {
                    step = 180.0;
                }
                last + step
            }
            _ => wrapped,
        };
        previous_wrapped = Some(wrapped);
        pair.omega.push(omega);
        pair.mag_db.push(mag_db);
        pair.phase_deg.push(phase);
        pair.coherence.push(e.coherence.clamp(0.0, 1.0));
        pair.random_error.push(e.random_error);
        if let Some(m) = multiple_here {
            pair.multiple_coherence.push(m);
        }
    }
    pair.valid_range = accurate_range(
        &pair.omega,
        &pair.coherence,
        &pair.random_error,
        opts.coherence_threshold,
        opts.max_random_error,
    );
    anchor_phase_branch(&mut pair);
    (pair, dropped)
}

/// Shift the unwrapped phase by a whole number of turns so that it lies in (−180°, 180°]
/// at the low end of the valid range (or, without one, at the most coherent point).
/// Unwrapping starts at the lowest frequency, where coherence is often poor; a spurious
/// turn there would otherwise offset the whole valid band by ±360°.
pub(super) fn anchor_phase_branch(pair: &mut PairResponse) {
    let anchor = match pair.valid_range {
        Some([lo, _]) => pair.omega.iter().position(|&w| w >= lo),
        None => pair
            .coherence
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(k, _)| k),
    };
    let Some(&phase) = anchor.and_then(|k| pair.phase_deg.get(k)) else {
        return;
    };
    let turns = ((phase - 180.0) / 360.0).ceil();
    if turns != 0.0 {
        for p in &mut pair.phase_deg {
            *p -= 360.0 * turns;
        }
    }
}
