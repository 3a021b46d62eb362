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
//!
//! The steps are submodules: `prepare` (join a group, choose its band, grid, windows
//! and channels), `responses` (spectra, MISO solves and composites of one group),
//! `outcome` (what an analysis gives: [`FrfAnalysis`] and its parts),
//! `filter_removal` (a measurement filter the flight controller announced, divided out
//! of the responses) and `cross_coherence` (coherence between the controls of a group).
//!
//! [`ResponseInputs`]: super::ResponseInputs

use crate::document::{FrfDocument, PairResponse, FRF_DOCUMENT_VERSION};

use super::error::FrfError;
use super::groups::RecordGroup;
use super::options::{FrfOptions, RangeSource, ResponseEstimator};

mod cross_coherence;
mod filter_removal;
mod outcome;
mod prepare;
mod responses;

pub use cross_coherence::{cross_control_coherence, CoherenceCurve};
pub use outcome::{FrfAnalysis, GroupSummary, MultipleCoherence};

use filter_removal::remove_measurement_filter;
use prepare::prepare_group;
use responses::analyse_group;

/// Composite MISO-conditioned and SISO frequency responses of every (responding input,
/// output) pair (the swept input of each group, or every excited one: [`ResponseInputs`]),
/// and the cross-control coherences, of the given record groups (one per swept axis).
///
/// [`ResponseInputs`]: super::ResponseInputs
pub fn compute_frequency_responses(
    groups: &[RecordGroup],
    opts: &FrfOptions,
) -> Result<FrfDocument, FrfError> {
    analyse(groups, opts).map(|analysis| analysis.document)
}

/// [`compute_frequency_responses`] with the coherence curves and group summaries.
pub fn analyse(groups: &[RecordGroup], opts: &FrfOptions) -> Result<FrfAnalysis, FrfError> {
    opts.validate()?;
    if opts.ranges == RangeSource::SweepReference
        && opts.estimator != ResponseEstimator::SweepReference
    {
        let own = FrfOptions {
            ranges: RangeSource::Estimate,
            ..opts.clone()
        };
        let mut analysis = analyse(groups, &own)?;
        let reference = analyse(
            groups,
            &FrfOptions {
                estimator: ResponseEstimator::SweepReference,
                ..own
            },
        )?;
        take_reference_ranges(&mut analysis.document, &reference.document);
        return Ok(analysis);
    }
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
        let (pairs_before, siso_before) =
            (analysis.document.pairs.len(), analysis.document.siso.len());
        analyse_group(&prepared, opts, &mut analysis);
        if let Some(filter) = group.measurement_filter() {
            let document = &mut analysis.document;
            let mut notes = Vec::new();
            remove_measurement_filter(
                &mut document.pairs[pairs_before..],
                filter,
                group.primary(),
                &mut notes,
            );
            remove_measurement_filter(
                &mut document.siso[siso_before..],
                filter,
                group.primary(),
                &mut Vec::new(),
            );
            document.notes.extend(notes);
        }
    }
    keep_one_estimate_per_pair(&mut analysis);
    Ok(analysis)
}

/// [`RangeSource::SweepReference`]: each pair of `document` gets the valid range of the
/// same pair in `reference` (none when it has none or is missing), and its phase branch
/// anchored at the new range's low end.
fn take_reference_ranges(document: &mut FrfDocument, reference: &FrfDocument) {
    for pair in &mut document.pairs {
        pair.valid_range = reference
            .pair(&pair.input, &pair.output)
            .and_then(|r| r.valid_range);
        responses::anchor_phase_branch(pair);
    }
    document.notes.push(
        "valid ranges from the sweep-reference estimate's random error (frequencies where the hold, not the sweep, drives the swept control left out); responses, coherences and random errors from the cross-spectral estimate"
            .to_string(),
    );
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

#[cfg(test)]
mod tests;
