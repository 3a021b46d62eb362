//! A record group made ready for spectra: joined, with its frequency band and grid, its
//! window lengths, the controls it conditions on and the inputs and outputs it gives
//! responses for.

use crate::frf::error::FrfError;
use crate::frf::groups::{JoinedRecord, RecordGroup};
use crate::frf::miso::MAX_INPUTS;
use crate::frf::options::{FrfOptions, ResponseEstimator, ResponseInputs};
use crate::frf::spectra::{
    compute_spectra, log_grid, lowest_resolved, window_lengths, SpectraSettings, WindowSpectra,
};
use crate::records::rms;

/// A group ready for spectra: joined, with grid, windows and channel selection.
pub(super) struct PreparedGroup {
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
pub(super) fn prepare_group(
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
                    "{axis} sweep: the sweep-reference estimator needs the excitation injected into `{axis}`, and these records carry none (telemetry dumps do; a CSV file gives it with a reference column: frf --reference {axis}=COLUMN)"
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
pub(super) fn spectra_of(
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

/// A frequency for messages: 0.01 rather than the 0.009999999776482582 an f32 sweep band
/// widens to.
fn rounded(omega: f64) -> f64 {
    (omega * 1e4).round() / 1e4
}
