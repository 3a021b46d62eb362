//! The frequency-response stage: `sweephold frf` on the `cah` sweeps (its arguments, on
//! the records the fly stage decoded), `frf.json`. For the Bo-105 the valid ranges come
//! from the sweep-reference estimate's random error ([`RangeSource::SweepReference`](sysid::frf::RangeSource::SweepReference)).

use std::ffi::OsString;

use anyhow::anyhow;
use sysid::document::FrfDocument;
use sysid::frf::analysis::CoherenceCurve;
use sysid::frf::{analyse, group_by_primary, Record};

use super::{verb_args, Campaign};
use crate::artifacts::files;
use crate::artifacts::flown::LATERAL;
use crate::frf::FrfArgs;
use crate::output::write_json;

/// What the stage hands on.
pub struct Responses {
    /// `frf.json`, which the fits read.
    pub document: FrfDocument,
    /// The cross-control coherence curves of the lateral sweeps, which the report draws.
    pub lateral_coherence: Vec<CoherenceCurve>,
}

impl Campaign<'_> {
    /// The frf stage: the responses of `records` (the `cah` sweeps), written to `frf.json`.
    pub(super) fn frequency_responses(
        &mut self,
        records: Vec<Record>,
    ) -> anyhow::Result<(Responses, String)> {
        if records.is_empty() {
            return Err(anyhow!("every cah record aborted: nothing to identify"));
        }
        let mut argv: Vec<OsString> = vec![
            "--out".into(),
            self.dir().join(files::FRF).into(),
            "--quiet".into(),
        ];
        argv.extend(records.iter().map(|r| OsString::from(&r.source)));
        let args: FrfArgs = verb_args("frf", argv)?;
        let mut options = args.options();
        // The aircraft file says where the valid ranges come from: for the Bo-105 they
        // leave out where the hold, not the sweep, drives the swept control
        // (docs/decisions/2026-11-24-joint-trim-cost-and-reference-ranges.md).
        options.ranges = self.args.vehicle.range_source();
        let analysis = analyse(&group_by_primary(records)?, &options)?;
        write_json(&args.out, &analysis.document)?;
        let valid = analysis
            .document
            .pairs
            .iter()
            .filter(|p| p.valid_range.is_some())
            .count();
        let line = format!(
            "{} pairs, {} with a coherent range",
            analysis.document.pairs.len(),
            valid
        );
        let responses = Responses {
            document: analysis.document,
            lateral_coherence: analysis
                .cross_coherence_curves
                .into_iter()
                .filter(|c| c.axis == LATERAL)
                .collect(),
        };
        Ok((responses, line))
    }
}
