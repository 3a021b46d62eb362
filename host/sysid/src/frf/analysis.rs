//! The whole computation: record groups → [`FrfDocument`].
//!
//! **How records combine (as in CIFER).** Each swept axis is one [`RecordGroup`]. The
//! response of output y to control x comes from the group in which x is the swept
//! (primary) input, conditioned on the other controls *excited in that group* (the
//! off-axis noise, the attitude-hold commands, pilot inputs). A control that does not
//! move in a group (the collective during a lateral sweep) carries no information and
//! would make the input matrix singular, so it is left out of that group's conditioning
//! and a note says so.
//!
//! **Responses to every excited input.** The MISO solve gives the conditioned response
//! of every input of the group at once; where the group's records excite several inputs
//! together ([`ResponseInputs`]: a multisine, a simultaneous-axis test, a CSV log whose
//! swept input nothing names) each input reaching [`FrfOptions::response_ratio`] of the
//! largest input RMS gets its pairs, with its partial coherence and the output's multiple
//! coherence, and the pairs say which group they came from. When two groups give the
//! same (input, output) pair, the one from the group that sweeps that input is kept; if
//! neither does, the one with the higher mean partial coherence (the earlier group on a
//! tie); a note names the one left out.
//!
//! Per group: join the records ([`RecordGroup::joined`]), choose the grid and window
//! lengths ([`spectra`](super::spectra)), compute the spectral matrices of every window
//! length once, then for every responding input (the primary, or every excited input),
//! every output and every window length the MISO-conditioned response
//! ([`miso`](super::miso)) and the plain SISO H1 estimate, and blend the window lengths
//! ([`composite`](super::composite)).
//!
//! Nothing non-finite reaches the document: frequencies where no window length gives a
//! well-conditioned estimate are left out of that pair (each pair has its own `omega`)
//! and counted in the notes.

use num_complex::Complex64;

use crate::document::{
    CrossCoherence, FrfDocument, PairResponse, FRF_DOCUMENT_VERSION, MAX_PLAUSIBLE_MAG_DB,
};

use super::coherence::{accurate_range, debiased_coherence, random_error};
use super::composite::{blend, Estimate};
use super::miso::{InputFactor, MAX_INPUTS};
use super::options::{FrfOptions, ResponseEstimator, ResponseInputs};
use super::records::{rms, JoinedRecord, RecordGroup};
use super::reference::ReferenceSolve;
use super::spectra::{
    compute_spectra, log_grid, lowest_resolved, window_lengths, SpectraSettings, WindowSpectra,
};
use super::FrfError;

/// Coherence between two controls versus frequency, for one record group.
#[derive(Clone, Debug, PartialEq)]
pub struct CoherenceCurve {
    /// Primary axis of the group.
    pub axis: String,
    /// First control.
    pub a: String,
    /// Second control.
    pub b: String,
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// Composite coherence γ²_ab.
    pub coherence: Vec<f64>,
}

impl CoherenceCurve {
    /// Mean coherence over the curve's (log-spaced) points; 0 for an empty curve.
    pub fn mean(&self) -> f64 {
        if self.coherence.is_empty() {
            0.0
        } else {
            self.coherence.iter().sum::<f64>() / self.coherence.len() as f64
        }
    }
}

/// Multiple coherence of one output with the conditioning inputs of its group.
#[derive(Clone, Debug, PartialEq)]
pub struct MultipleCoherence {
    /// Input of the pair it belongs to (its weights are that pair's).
    pub input: String,
    /// Output.
    pub output: String,
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// γ²_y:u in [0, 1].
    pub coherence: Vec<f64>,
}

/// What was done with one record group.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupSummary {
    /// Primary axis.
    pub axis: String,
    /// Number of records joined.
    pub records: usize,
    /// Length of the joined record \[s\].
    pub seconds: f64,
    /// Frequency grid band [rad/s].
    pub band: [f64; 2],
    /// Window lengths used \[s\].
    pub windows: Vec<f64>,
    /// Controls in the conditioning (primary last).
    pub conditioned_on: Vec<String>,
    /// Inputs whose responses were computed (the primary first).
    pub responses: Vec<String>,
}

/// The document plus what the plots and the command-line summary need.
#[derive(Clone, Debug, PartialEq)]
pub struct FrfAnalysis {
    /// The `frf.json` document.
    pub document: FrfDocument,
    /// Cross-control coherence versus frequency (the document has only the means).
    pub cross_coherence_curves: Vec<CoherenceCurve>,
    /// One summary per group.
    pub groups: Vec<GroupSummary>,
    /// Multiple coherence γ²_y:u of each output with all the conditioning inputs, one
    /// per MISO pair in `document.pairs` order (composite, same weights as the response).
    /// How much of the output the excited controls explain together; the partial
    /// coherence in the document is the share of the swept control alone.
    pub multiple_coherence: Vec<MultipleCoherence>,
}

/// Composite MISO-conditioned and SISO frequency responses of every (responding input,
/// output) pair (the swept input of each group, or every excited one: [`ResponseInputs`]),
/// and the cross-control coherences, of the given record groups (one per swept axis).
pub fn compute_frequency_responses(
    groups: &[RecordGroup],
    opts: &FrfOptions,
) -> Result<FrfDocument, FrfError> {
    analyse(groups, opts).map(|analysis| analysis.document)
}

/// [`compute_frequency_responses`] with the coherence curves and group summaries.
pub fn analyse(groups: &[RecordGroup], opts: &FrfOptions) -> Result<FrfAnalysis, FrfError> {
    opts.validate()?;
    if groups.is_empty() {
        return Err(FrfError::NoRecords);
    }
    for (i, group) in groups.iter().enumerate() {
        if groups[..i].iter().any(|g| g.primary() == group.primary()) {
            return Err(FrfError::DuplicateAxis(group.primary().to_string()));
        }
    }
    let mut analysis = FrfAnalysis {
        document: FrfDocument {
            version: FRF_DOCUMENT_VERSION,
            pairs: Vec::new(),
            siso: Vec::new(),
            cross_coherence: Vec::new(),
            coherence_threshold: opts.coherence_threshold,
            max_random_error: opts.max_random_error,
            notes: Vec::new(),
        },
        cross_coherence_curves: Vec::new(),
        multiple_coherence: Vec::new(),
        groups: Vec::new(),
    };
    for group in groups {
        for record in group.records() {
            analysis.document.notes.extend(record.notes.iter().cloned());
        }
        let prepared = prepare_group(group, opts, true)?;
        analyse_group(&prepared, opts, &mut analysis);
    }
    keep_one_estimate_per_pair(&mut analysis);
    Ok(analysis)
}

/// `true` when `pair` came from the group that sweeps its input.
fn from_its_sweep(pair: &PairResponse) -> bool {
    pair.group
        .as_deref()
        .is_none_or(|group| group == pair.input)
}

/// Mean partial coherence over a pair's frequencies (0 without any).
fn mean_coherence(pair: &PairResponse) -> f64 {
    if pair.coherence.is_empty() {
        0.0
    } else {
        pair.coherence.iter().sum::<f64>() / pair.coherence.len() as f64
    }
}

/// Where several groups gave the same (input, output) pair, keep one (module docs): the
/// estimate from the group that sweeps the input, else the one with the higher mean
/// partial coherence, the earlier on a tie. Its SISO and multiple-coherence companions
/// (same index) go with it; a note names each estimate left out.
fn keep_one_estimate_per_pair(analysis: &mut FrfAnalysis) {
    let pairs = &analysis.document.pairs;
    let group_of = |pair: &PairResponse| pair.group.clone().unwrap_or(pair.input.clone());
    let mut left_out = vec![false; pairs.len()];
    let mut notes = Vec::new();
    for i in 0..pairs.len() {
        for j in i + 1..pairs.len() {
            if left_out[i] {
                break;
            }
            let (a, b) = (&pairs[i], &pairs[j]);
            if left_out[j] || a.input != b.input || a.output != b.output {
                continue;
            }
            let (kept, dropped, why) = if from_its_sweep(a) {
                (i, j, format!("it sweeps `{}`", a.input))
            } else if from_its_sweep(b) {
                (j, i, format!("it sweeps `{}`", b.input))
            } else {
                let (ma, mb) = (mean_coherence(a), mean_coherence(b));
                let why =
                    |high: f64, low: f64| format!("mean partial γ² {high:.2} against {low:.2}");
                if mb > ma {
                    (j, i, why(mb, ma))
                } else {
                    (i, j, why(ma, mb))
                }
            };
            left_out[dropped] = true;
            notes.push(format!(
                "{}→{}: the estimate from the {} records kept ({why}), the one from the {} records left out",
                a.input,
                a.output,
                group_of(&pairs[kept]),
                group_of(&pairs[dropped])
            ));
        }
    }
    let mut index = 0;
    analysis.document.pairs.retain(|_| {
        index += 1;
        !left_out[index - 1]
    });
    index = 0;
    analysis.document.siso.retain(|_| {
        index += 1;
        !left_out[index - 1]
    });
    index = 0;
    analysis.multiple_coherence.retain(|_| {
        index += 1;
        !left_out[index - 1]
    });
    analysis.document.notes.extend(notes);
}

/// A group ready for spectra: joined, with grid, windows and channel selection.
pub(crate) struct PreparedGroup {
    pub primary: String,
    pub joined: JoinedRecord,
    pub grid: Vec<f64>,
    pub windows: Vec<f64>,
    /// Inputs in conditioning order (other excited controls, primary last), as indices
    /// into `joined.inputs`.
    pub conditioning: Vec<usize>,
    /// Inputs whose responses are computed, as positions in `conditioning`: the primary
    /// (position n − 1) first, then, when `every_excited`, the others that reach
    /// [`FrfOptions::response_ratio`], in conditioning order.
    pub responding: Vec<usize>,
    /// Whether the responses to every excited input are computed
    /// ([`ResponseInputs`]); the group's pairs then carry `group` and
    /// `multiple_coherence`.
    pub every_excited: bool,
    /// Outputs with any variation, as indices into `joined.outputs`.
    pub outputs: Vec<usize>,
    /// With the reference estimator: the swept control's recorded excitation, as an
    /// index into `joined.references`.
    pub sweep_reference: Option<usize>,
    pub records: usize,
    pub notes: Vec<String>,
}

/// Join a group and choose its band, grid, windows, excited inputs and usable outputs.
pub(crate) fn prepare_group(
    group: &RecordGroup,
    opts: &FrfOptions,
    with_outputs: bool,
) -> Result<PreparedGroup, FrfError> {
    let axis = group.primary().to_string();
    let fs = group.sample_rate_hz();
    let joined = group.joined();
    let seconds = joined.duration_s();
    let mut notes = Vec::new();

    let [lo, hi] = opts.band.or(group.sweep_band()).ok_or_else(|| {
        FrfError::NoBand(format!(
            "{axis} sweep: the sweep band is unknown (CSV records carry none): pass --band WMIN,WMAX"
        ))
    })?;
    let nyquist = std::f64::consts::PI * fs;
    if hi >= nyquist {
        return Err(FrfError::InvalidOption(format!(
            "band top {hi} rad/s is at or above the Nyquist frequency {nyquist:.1} rad/s of the {fs} Hz records"
        )));
    }
    let too_short = |detail: String| FrfError::RecordTooShort {
        axis: axis.clone(),
        seconds,
        detail,
    };
    let windows: Vec<f64> = window_lengths(seconds, hi, opts.windows)
        .ok_or_else(|| {
            too_short(format!(
                "need at least {:.1} s (two windows of ten periods of ω_max = {hi} rad/s)",
                40.0 * std::f64::consts::PI / hi
            ))
        })?
        .into_iter()
        .map(|t| (t * fs).round().max(2.0) / fs)
        .collect();
    let longest = windows.iter().copied().fold(0.0, f64::max);
    let resolved = lowest_resolved(longest);
    let lo_used = lo.max(resolved);
    if lo_used >= hi {
        return Err(too_short(format!(
            "its longest window ({longest:.1} s) resolves only down to {resolved:.2} rad/s, above the band top {} rad/s",
            rounded(hi)
        )));
    }
    if lo_used > lo * (1.0 + 1e-9) {
        notes.push(format!(
            "{axis} sweep: band starts at {lo_used:.3} rad/s instead of {} rad/s: the longest window ({longest:.1} s, half the record) resolves down to 4π/T",
            rounded(lo)
        ));
    }
    let grid = log_grid(lo_used, hi, opts.points);

    // Excitation of the controls.
    let input_rms: Vec<f64> = joined.inputs.iter().map(|c| rms(&c.values)).collect();
    let primary_index = joined
        .inputs
        .iter()
        .position(|c| c.name == axis)
        .ok_or_else(|| FrfError::NoExcitation { axis: axis.clone() })?;
    let primary_rms = input_rms[primary_index];
    if primary_rms.is_nan() || primary_rms <= 1e-12 {
        return Err(FrfError::NoExcitation { axis });
    }
    let mut others: Vec<usize> = Vec::new();
    for (i, channel) in joined.inputs.iter().enumerate() {
        if i == primary_index {
            continue;
        }
        if input_rms[i] >= opts.excitation_ratio * primary_rms && input_rms[i] > 0.0 {
            others.push(i);
        } else {
            notes.push(format!(
                "{axis} sweep: `{}` not excited (RMS {:.3e} vs {primary_rms:.3e} for `{axis}`): left out of the conditioning and the cross-control coherence",
                channel.name, input_rms[i]
            ));
        }
    }
    if others.len() > MAX_INPUTS - 1 {
        // Keep the most active controls; the conditioning handles four inputs.
        others.sort_by(|&a, &b| input_rms[b].total_cmp(&input_rms[a]));
        for &i in &others[MAX_INPUTS - 1..] {
            notes.push(format!(
                "{axis} sweep: `{}` left out of the conditioning (at most {MAX_INPUTS} inputs; the most active are kept)",
                joined.inputs[i].name
            ));
        }
        others.truncate(MAX_INPUTS - 1);
        others.sort_unstable();
    }
    let mut conditioning = others;
    conditioning.push(primary_index);

    // Which inputs get responses (ResponseInputs).
    let every_excited = match opts.responses {
        ResponseInputs::Swept => false,
        ResponseInputs::Excited => true,
        ResponseInputs::Auto => {
            group.primary_guessed() && opts.estimator == ResponseEstimator::CrossSpectral
        }
    };
    let mut responding = vec![conditioning.len() - 1];
    if every_excited {
        let largest = input_rms.iter().copied().fold(0.0, f64::max);
        let mut names = vec![axis.clone()];
        for (position, &i) in conditioning[..conditioning.len() - 1].iter().enumerate() {
            let name = &joined.inputs[i].name;
            if input_rms[i] >= opts.response_ratio * largest {
                responding.push(position);
                names.push(name.clone());
            } else {
                notes.push(format!(
                    "{axis} records: no responses to `{name}`: its RMS is {:.1} % of the largest input's (below {} %)",
                    100.0 * input_rms[i] / largest,
                    100.0 * opts.response_ratio
                ));
            }
        }
        notes.push(format!(
            "{axis} records: responses to every excited input (RMS ≥ {} % of the largest): {}",
            100.0 * opts.response_ratio,
            names.join(", ")
        ));
    }

    let mut outputs = Vec::new();
    if with_outputs {
        for (o, channel) in joined.outputs.iter().enumerate() {
            if rms(&channel.values) > 0.0 {
                outputs.push(o);
            } else {
                notes.push(format!(
                    "{axis} sweep: output `{}` does not vary: no response computed",
                    channel.name
                ));
            }
        }
    }
    let sweep_reference = if with_outputs && opts.estimator == ResponseEstimator::SweepReference {
        let recorded = joined
            .references
            .iter()
            .position(|r| r.name == axis)
            .filter(|&r| rms(&joined.references[r].values) > 0.0)
            .ok_or_else(|| {
                FrfError::InvalidOption(format!(
                    "{axis} sweep: the sweep-reference estimator needs the excitation injected into `{axis}`, and these records carry none (telemetry dumps do; CSV records do not)"
                ))
            })?;
        notes.push(format!(
            "{axis} sweep: responses estimated against the recorded sweep (sweep-reference estimator)"
        ));
        Some(recorded)
    } else {
        None
    };
    Ok(PreparedGroup {
        primary: group.primary().to_string(),
        joined,
        grid,
        windows,
        conditioning,
        responding,
        every_excited,
        outputs,
        sweep_reference,
        records: group.records().len(),
        notes,
    })
}

/// Spectra of the group's conditioning inputs (positions `0..n`), with the reference
/// estimator also the swept control's recorded excitation (position `n`), and,
/// `with_outputs`, its outputs.
fn spectra_of(
    prepared: &PreparedGroup,
    opts: &FrfOptions,
    with_outputs: bool,
) -> Vec<WindowSpectra> {
    let mut inputs: Vec<&[f64]> = prepared
        .conditioning
        .iter()
        .map(|&i| prepared.joined.inputs[i].values.as_slice())
        .collect();
    if let (true, Some(r)) = (with_outputs, prepared.sweep_reference) {
        inputs.push(prepared.joined.references[r].values.as_slice());
    }
    let outputs: Vec<&[f64]> = if with_outputs {
        prepared
            .outputs
            .iter()
            .map(|&o| prepared.joined.outputs[o].values.as_slice())
            .collect()
    } else {
        Vec::new()
    };
    compute_spectra(
        &inputs,
        &outputs,
        &prepared.grid,
        &prepared.windows,
        SpectraSettings {
            sample_rate_hz: prepared.joined.sample_rate_hz,
            overlap: opts.overlap,
            oversampling: opts.oversampling,
        },
    )
}

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

fn analyse_group(prepared: &PreparedGroup, opts: &FrfOptions, analysis: &mut FrfAnalysis) {
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

/// Cross-control coherence curves of a prepared group (inputs only).
pub(crate) fn cross_control_curves(
    prepared: &PreparedGroup,
    opts: &FrfOptions,
) -> Vec<CoherenceCurve> {
    let spectra = spectra_of(prepared, opts, false);
    curves_from_spectra(prepared, &spectra)
}

/// Composite coherence of every pair of excited controls, in the controls' record order.
fn curves_from_spectra(prepared: &PreparedGroup, spectra: &[WindowSpectra]) -> Vec<CoherenceCurve> {
    // Positions in the conditioning order, sorted by record order of the controls.
    let mut order: Vec<(usize, usize)> = prepared
        .conditioning
        .iter()
        .enumerate()
        .map(|(position, &input)| (input, position))
        .collect();
    order.sort_unstable();
    let mut curves = Vec::new();
    for (x, &(input_a, a)) in order.iter().enumerate() {
        for &(input_b, b) in &order[x + 1..] {
            let mut curve = CoherenceCurve {
                axis: prepared.primary.clone(),
                a: prepared.joined.inputs[input_a].name.clone(),
                b: prepared.joined.inputs[input_b].name.clone(),
                omega: Vec::new(),
                coherence: Vec::new(),
            };
            for (k, &omega) in prepared.grid.iter().enumerate() {
                // Bias-corrected coherence of the windows that span enough periods of ω
                // (`cross_coherence_windows`), weighted by their equivalent numbers of
                // independent averages. The response composite's 1/εr² weighting would
                // favour the long windows, whose few averages inflate coherence by
                // ~1/n_d: two unrelated controls would read ~0.4.
                let (mut sum, mut weight) = (0.0, 0.0);
                for s in cross_coherence_windows(spectra, k, omega) {
                    let (gaa, gbb) = (s.input_input(k, a, a).re, s.input_input(k, b, b).re);
                    if !(gaa > 0.0 && gbb > 0.0) {
                        continue;
                    }
                    let raw = s.input_input(k, a, b).norm_sqr() / (gaa * gbb);
                    if let Some(coherence) = debiased_coherence(raw, s.welch_averages) {
                        sum += s.welch_averages * coherence;
                        weight += s.welch_averages;
                    }
                }
                if weight > 0.0 && sum.is_finite() {
                    curve.omega.push(omega);
                    curve.coherence.push(sum / weight);
                }
            }
            if !curve.omega.is_empty() {
                curves.push(curve);
            }
        }
    }
    curves
}

/// Periods of ω a window must span to count towards the cross-control coherence at ω.
///
/// Two periods (the responses' resolution limit, [`lowest_resolved`]) are too few here.
/// A control that follows the swept one through dynamics with a delay or a lightly
/// damped mode is exactly coherent with it, but in a window only a couple of periods
/// long the chirp's frequency moves on within the window and the answer arrives late,
/// so such windows read it as partly unrelated (Carter's misalignment bias). With the
/// averages-weighted mean below, the shortest window that resolves ω dominates: a
/// noise-free second-order response (1 rad/s, ζ 0.3) of a 0.2–31.4 rad/s sweep read 0.77
/// from two periods on and 0.90 from four (`a_control_driven_through_dynamics_reads_coherent`),
/// while unrelated noise stays near zero either way.
const CROSS_COHERENCE_MIN_PERIODS: f64 = 4.0;

/// The windows that estimate the cross-control coherence at grid point `k` (frequency
/// `omega`): those spanning at least [`CROSS_COHERENCE_MIN_PERIODS`] periods; where
/// none does (the bottom of the band), the longest window that resolves ω at all.
fn cross_coherence_windows(spectra: &[WindowSpectra], k: usize, omega: f64) -> Vec<&WindowSpectra> {
    let resolving = spectra.iter().filter(|s| k >= s.valid_from);
    let periods = |s: &WindowSpectra| omega * s.seconds / std::f64::consts::TAU;
    let long_enough: Vec<&WindowSpectra> = resolving
        .clone()
        .filter(|s| periods(s) >= CROSS_COHERENCE_MIN_PERIODS)
        .collect();
    if long_enough.is_empty() {
        resolving
            .max_by(|a, b| a.seconds.total_cmp(&b.seconds))
            .into_iter()
            .collect()
    } else {
        long_enough
    }
}

/// A frequency for messages: 0.01 rather than the 0.009999999776482582 an f32 sweep band
/// widens to.
fn rounded(omega: f64) -> f64 {
    (omega * 1e4).round() / 1e4
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
fn anchor_phase_branch(pair: &mut PairResponse) {
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

#[cfg(test)]
mod tests;
