//! A uniform sample grid from the timestamps a logger wrote.
//!
//! The spectra need samples on a uniform grid; loggers write timestamps with jitter (a
//! scheduler's ±1 ms), drop samples, and write rows with a missing field (which the
//! reader leaves out, so they look like dropped samples here). The rules, in order:
//!
//! 1. **Uniform**: when every timestamp lies within [`UNIFORM_TOLERANCE`] (5 %) of a step
//!    of the straight line from the first to the last, the samples are used as they are,
//!    at the mean step. This is how every file read before resampling existed was read,
//!    so such files give the same records, value for value.
//! 2. Otherwise the **nominal step** is the median step; each step counts as
//!    `max(1, round(step / median))` nominal steps, and the grid step is the span over
//!    that count (the mean step of the samples that are there, so a jittered clock keeps
//!    its rate).
//! 3. A step of more than [`MAX_FILLED_SAMPLES`] + 1 nominal steps (more than 5 samples
//!    missing) **splits** the record: the parts either side are separate records of the
//!    same swept axis, joined as the records of several files are (each detrended,
//!    tapered to zero at the joins). A part of fewer than [`MIN_PART_SAMPLES`] samples is
//!    left out (a record that is not split is kept whatever its length).
//! 4. Each part is **resampled** onto the grid `t_first + k·step` by linear interpolation
//!    between the neighbouring samples: jitter is taken out and shorter gaps are filled.
//!    The interpolation filters every channel alike (inputs and outputs), so the ratio
//!    of their spectra, the response, is not changed by it.
//!
//! Every departure from rule 1 is said in a note. Hand-written: a linear interpolation
//! on sorted times is a few lines, and no resampling crate decides gaps and splits.

/// Timestamps within this fraction of a step of the straight line from the first to the
/// last are uniform: the samples are used as they are.
pub const UNIFORM_TOLERANCE: f64 = 0.05;

/// The most consecutive missing samples a gap may have to be filled by interpolation;
/// a longer gap splits the record.
pub const MAX_FILLED_SAMPLES: usize = 5;

/// Parts between long gaps with fewer samples than this are left out.
pub const MIN_PART_SAMPLES: usize = 20;

/// Samples on one uniform grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Time of the first sample, on the file's time axis \[s\].
    pub start_s: f64,
    /// Samples per channel, in the order given.
    pub channels: Vec<Vec<f64>>,
}

/// Samples on a uniform grid: one part, or several when long gaps split the record.
#[derive(Clone, Debug, PartialEq)]
pub struct UniformSamples {
    /// Grid step \[s\], the same for every part.
    pub step_s: f64,
    /// The parts, in time order.
    pub parts: Vec<Part>,
    /// What was done to get here (resampling, gaps filled, splits), for the record.
    pub notes: Vec<String>,
}

/// Put `channels` (each as long as `times`) sampled at `times` (strictly increasing, at
/// least two) onto a uniform grid by the rules of the module docs. The error says why no
/// part is left.
pub fn uniform_samples(times: &[f64], channels: Vec<Vec<f64>>) -> Result<UniformSamples, String> {
    let n = times.len();
    debug_assert!(n >= 2 && channels.iter().all(|c| c.len() == n));
    let span = times[n - 1] - times[0];
    let mean_step = span / (n - 1) as f64;
    let off_line = times
        .iter()
        .enumerate()
        .map(|(i, t)| (t - (times[0] + i as f64 * mean_step)).abs())
        .fold(0.0, f64::max);
    if off_line <= UNIFORM_TOLERANCE * mean_step {
        return Ok(UniformSamples {
            step_s: mean_step,
            parts: vec![Part {
                start_s: times[0],
                channels,
            }],
            notes: Vec::new(),
        });
    }

    let steps: Vec<f64> = times.windows(2).map(|t| t[1] - t[0]).collect();
    let median = median(&steps);
    let counts: Vec<usize> = steps
        .iter()
        .map(|s| ((s / median).round() as usize).max(1))
        .collect();
    let step = span / counts.iter().sum::<usize>() as f64;
    let mut notes = Vec::new();

    // Jitter: how far a step that is not a gap strays from the grid step.
    let jitter = steps
        .iter()
        .zip(&counts)
        .filter(|(_, &c)| c == 1)
        .map(|(s, _)| (s - step).abs())
        .fold(0.0, f64::max);
    if jitter > UNIFORM_TOLERANCE * step {
        notes.push(format!(
            "timestamps jitter (steps up to {:.2} ms off the {:.3} ms grid step): resampled onto a uniform grid by linear interpolation",
            jitter * 1e3,
            step * 1e3
        ));
    }

    // Gaps: filled up to MAX_FILLED_SAMPLES missing samples, else the record splits there.
    let mut filled = (0usize, 0usize, 0.0f64); // gaps, most missing samples, where
    let mut bounds = vec![0usize];
    for (i, &count) in counts.iter().enumerate() {
        let missing = count - 1;
        if missing > MAX_FILLED_SAMPLES {
            bounds.push(i + 1);
        } else if missing > 0 {
            filled.0 += 1;
            if missing > filled.1 {
                filled.1 = missing;
                filled.2 = times[i];
            }
        }
    }
    bounds.push(n);
    if filled.0 > 0 {
        notes.push(format!(
            "{} gap(s) of up to {} missing samples filled by linear interpolation (the longest after {:.3} s)",
            filled.0, filled.1, filled.2
        ));
    }

    let mut parts = Vec::new();
    let mut left_out = Vec::new();
    for range in bounds.windows(2) {
        let (a, b) = (range[0], range[1]);
        let part_times = &times[a..b];
        let len =
            ((part_times[part_times.len() - 1] - part_times[0]) / step + 1e-9).floor() as usize + 1;
        if len < MIN_PART_SAMPLES && bounds.len() > 2 {
            left_out.push(format!("{:.3}–{:.3} s", part_times[0], times[b - 1]));
            continue;
        }
        let grid: Vec<f64> = (0..len).map(|k| part_times[0] + k as f64 * step).collect();
        parts.push(Part {
            start_s: part_times[0],
            channels: channels
                .iter()
                .map(|values| interpolate(part_times, &values[a..b], &grid))
                .collect(),
        });
    }
    if bounds.len() > 2 {
        let gaps: Vec<String> = bounds[1..bounds.len() - 1]
            .iter()
            .map(|&i| format!("{:.3}–{:.3} s", times[i - 1], times[i]))
            .collect();
        notes.push(format!(
            "gap(s) of more than {MAX_FILLED_SAMPLES} missing samples ({}) split the file into {} records of the same axis, joined as the records of several files are{}",
            gaps.join(", "),
            parts.len(),
            if left_out.is_empty() {
                String::new()
            } else {
                format!(
                    "; part(s) shorter than {MIN_PART_SAMPLES} samples left out: {}",
                    left_out.join(", ")
                )
            }
        ));
    }
    if parts.is_empty() {
        return Err(format!(
            "gaps of more than {MAX_FILLED_SAMPLES} missing samples leave no part of at least {MIN_PART_SAMPLES} samples; choose rows without them (--window)"
        ));
    }
    Ok(UniformSamples {
        step_s: step,
        parts,
        notes,
    })
}

/// Median of a non-empty slice.
pub fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    if sorted.len() % 2 == 1 {
        sorted[mid]
    } else {
        0.5 * (sorted[mid - 1] + sorted[mid])
    }
}

/// `values` (at increasing `times`) linearly interpolated at increasing `grid` times
/// within `[times[0], times[last]]` (a grid time past the last, by rounding, takes the
/// last value).
fn interpolate(times: &[f64], values: &[f64], grid: &[f64]) -> Vec<f64> {
    let mut i = 0;
    grid.iter()
        .map(|&t| {
            while i + 2 < times.len() && times[i + 1] <= t {
                i += 1;
            }
            if times.len() == 1 {
                return values[0];
            }
            let (t0, t1) = (times[i], times[i + 1]);
            let a = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
            values[i] + a * (values[i + 1] - values[i])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(times: &[f64]) -> Vec<f64> {
        times.iter().map(|t| 3.0 * t - 1.0).collect()
    }

    #[test]
    fn uniform_timestamps_are_used_as_they_are() {
        // Printed with rounding: within 5 % of a step of the line.
        let times: Vec<f64> = (0..100)
            .map(|k| k as f64 * 0.01 + 1e-4 * (k % 3) as f64)
            .collect();
        let values: Vec<f64> = (0..100).map(|k| (k * k) as f64).collect();
        let out = uniform_samples(&times, vec![values.clone()]).unwrap();
        assert_eq!(out.parts.len(), 1);
        assert_eq!(out.parts[0].channels[0], values);
        assert_eq!(out.step_s, (times[99] - times[0]) / 99.0);
        assert!(out.notes.is_empty());
    }

    #[test]
    fn jitter_is_resampled_and_a_straight_line_stays_straight() {
        let times: Vec<f64> = (0..200)
            .map(|k| k as f64 * 0.01 + [0.0, 0.001, -0.001, 0.0005][k % 4])
            .collect();
        let out = uniform_samples(&times, vec![ramp(&times)]).unwrap();
        assert_eq!(out.parts.len(), 1);
        assert!((out.step_s - 0.01).abs() < 1e-5, "{}", out.step_s);
        let part = &out.parts[0];
        for (k, v) in part.channels[0].iter().enumerate() {
            let t = part.start_s + k as f64 * out.step_s;
            assert!((v - (3.0 * t - 1.0)).abs() < 1e-9);
        }
        assert_eq!(out.notes.len(), 1);
        assert!(out.notes[0].contains("jitter"), "{:?}", out.notes);
    }

    #[test]
    fn short_gaps_are_filled_and_long_ones_split() {
        // 5 samples missing after 0.5 s: filled; 6 missing after 1.5 s: split.
        let times: Vec<f64> = (0..300)
            .filter(|k| !(51..=55).contains(k) && !(151..=156).contains(k))
            .map(|k| k as f64 * 0.01)
            .collect();
        let out = uniform_samples(&times, vec![ramp(&times)]).unwrap();
        assert!((out.step_s - 0.01).abs() < 1e-12);
        assert_eq!(out.parts.len(), 2);
        assert_eq!(out.parts[0].channels[0].len(), 151);
        assert_eq!(out.parts[1].channels[0].len(), 143);
        assert!((out.parts[1].start_s - 1.57).abs() < 1e-12);
        assert!((out.parts[0].channels[0][53] - (3.0 * 0.53 - 1.0)).abs() < 1e-9);
        assert_eq!(out.notes.len(), 2, "{:?}", out.notes);
        assert!(out.notes[0].contains("1 gap(s) of up to 5 missing samples"));
        assert!(out.notes[1].contains("into 2 records"), "{:?}", out.notes);
    }

    #[test]
    fn short_parts_are_left_out_and_nothing_left_is_refused() {
        let mut times: Vec<f64> = (0..10).map(|k| k as f64 * 0.01).collect();
        times.extend((0..100).map(|k| 1.0 + k as f64 * 0.01));
        let out = uniform_samples(&times, vec![ramp(&times)]).unwrap();
        assert_eq!(out.parts.len(), 1);
        assert!(
            out.notes[0].contains("left out: 0.000–0.090 s"),
            "{:?}",
            out.notes
        );
        let times: Vec<f64> = vec![0.0, 0.01, 0.02, 1.0, 1.01, 1.02];
        let err = uniform_samples(&times, vec![ramp(&times)]).unwrap_err();
        assert!(err.contains("--window"), "{err}");
    }
}
