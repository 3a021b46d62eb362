//! `identify --steady-flights LOG --gnss CSV`: trim points from the flight. The steady
//! segments of the log (`sysid::steady`, the steadiness rule in
//! docs/decisions/2026-11-27-steady-segments.md), each averaged into a trim point with the
//! body velocities of the GNSS file, written into the output folder as `trim-points.csv`
//! (with each column's standard error) and used by the fit as `--trim-points` is.

use std::path::Path;

use anyhow::{anyhow, Context};
use sweephold_protocol::{Decoder, Frame, Sample};
use sysid::fit::trim::TrimPoints;
use sysid::steady::{
    find_steady_segments, parse_gnss_csv, steady_trim_points_csv, SteadySegment, STEADINESS_RULE,
};

use crate::artifacts::identify_summary::SteadySegmentSummary;
use crate::output::check_input_file;

/// The trim points of the flight, the CSV to write and the segments' summary.
pub struct FlightTrim {
    /// The points, as the fit reads them.
    pub points: TrimPoints,
    /// `trim-points.csv` with the standard errors.
    pub csv: String,
    /// One entry per segment.
    pub segments: Vec<SteadySegmentSummary>,
}

/// Read the steady flights of `log` with the fixes of `gnss` (`rate_hz` Samples per
/// second) into trim points. Fewer than two steady segments, or points the fit refuses,
/// are errors naming the files.
pub fn flight_trim_points(log: &Path, gnss: &Path, rate_hz: f64) -> anyhow::Result<FlightTrim> {
    check_input_file("--steady-flights", log)?;
    check_input_file("--gnss", gnss)?;
    let bytes = std::fs::read(log).with_context(|| format!("cannot read {}", log.display()))?;
    let samples: Vec<Sample> = Decoder::new()
        .feed(&bytes)
        .flatten()
        .filter_map(|frame| match frame {
            Frame::Sample(sample) => Some(sample),
            _ => None,
        })
        .collect();
    let text =
        std::fs::read_to_string(gnss).with_context(|| format!("cannot read {}", gnss.display()))?;
    let fixes = parse_gnss_csv(&text).map_err(|e| anyhow!("{}: {e}", gnss.display()))?;
    let segments = find_steady_segments(&samples, &fixes, rate_hz, &STEADINESS_RULE);
    if segments.len() < 2 {
        anyhow::bail!(
            "{} with {}: {} steady segment(s) of at least {} s: at least two are needed for \
             trim points",
            log.display(),
            gnss.display(),
            segments.len(),
            STEADINESS_RULE.min_blocks as f64 * STEADINESS_RULE.block_s
        );
    }
    let csv = steady_trim_points_csv(&segments);
    let points = TrimPoints::parse_csv(&csv)
        .map_err(|e| anyhow!("the trim points of {}: {e}", log.display()))?;
    Ok(FlightTrim {
        points,
        csv,
        segments: segments.iter().map(summary).collect(),
    })
}

/// The summary entry of one segment.
fn summary(segment: &SteadySegment) -> SteadySegmentSummary {
    let states = &segment.point.states;
    let se = &segment.standard_error;
    SteadySegmentSummary {
        label: segment.point.label.clone(),
        ticks: segment.ticks,
        blocks: segment.blocks,
        velocity_m_s: [states[0], states[1], states[2]],
        velocity_se_m_s: [se[0], se[1], se[2]],
    }
}
