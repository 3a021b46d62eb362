//! Record groups (the records of one swept axis), and how the records of a group are joined.
//!
//! **Joining.** The paper concatenates its two 90 s records per axis into one 180 s
//! record. Each record has its own trim, so its mean and drift are removed first: every
//! channel of every record is detrended (least-squares straight line removed). A
//! detrended record still ends at some non-zero value, and butting two records together
//! would put a step into every window that spans the join — broadband energy that is
//! in no way a response to the input. So at every *join* (the end of one record and the
//! start of the next, not the outer ends of the group) both records are tapered to zero
//! with a raised cosine `½ − ½cos(πt/T_taper)` over `T_taper` = 2 % of that record
//! (at least 2 samples). Inputs and outputs get the same taper, so the windows that
//! span a join see the same slow gain on both sides of the input/output relation.

use super::error::FrfError;
use crate::records::{remove_line, Channel, MeasurementFilter, Record};

/// The records of one swept axis, analysed as one joined record.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordGroup {
    records: Vec<Record>,
}

impl RecordGroup {
    /// Group records that sweep the same input at the same rate with the same channels.
    pub fn new(records: Vec<Record>) -> Result<RecordGroup, FrfError> {
        let first = records.first().ok_or(FrfError::NoRecords)?;
        for record in &records {
            record.validate()?;
            let names = |cs: &[Channel]| cs.iter().map(|c| c.name.clone()).collect::<Vec<_>>();
            let mismatch = if record.primary != first.primary {
                Some(format!(
                    "sweeps `{}`, not `{}`",
                    record.primary, first.primary
                ))
            } else if (record.sample_rate_hz - first.sample_rate_hz).abs()
                > 1e-9 * first.sample_rate_hz
            {
                Some(format!(
                    "is sampled at {} Hz, not {} Hz",
                    record.sample_rate_hz, first.sample_rate_hz
                ))
            } else if names(&record.inputs) != names(&first.inputs)
                || names(&record.outputs) != names(&first.outputs)
                || names(&record.references) != names(&first.references)
            {
                Some("has other channels".to_string())
            } else if record.measurement_filter != first.measurement_filter {
                Some("went through another measurement filter".to_string())
            } else {
                None
            };
            if let Some(what) = mismatch {
                return Err(FrfError::InconsistentGroup(format!(
                    "{} {what} than {}",
                    record.source, first.source
                )));
            }
        }
        Ok(RecordGroup { records })
    }

    /// The records, in joining order.
    pub fn records(&self) -> &[Record] {
        &self.records
    }

    /// Name of the swept input.
    pub fn primary(&self) -> &str {
        &self.records[0].primary
    }

    /// `true` when every record's swept input is only guessed
    /// ([`Record::primary_guessed`]).
    pub fn primary_guessed(&self) -> bool {
        self.records.iter().all(|r| r.primary_guessed)
    }

    /// Sample rate \[Hz\].
    pub fn sample_rate_hz(&self) -> f64 {
        self.records[0].sample_rate_hz
    }

    /// The filter the flight controller ran on the records' outputs (the same for every
    /// record of the group), if any.
    pub fn measurement_filter(&self) -> Option<&MeasurementFilter> {
        self.records[0].measurement_filter.as_ref()
    }

    /// Total samples over all records.
    pub fn len(&self) -> usize {
        self.records.iter().map(Record::len).sum()
    }

    /// `true` when no record has samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sweep band covering every record's band: [min ω_min, max ω_max].
    pub fn sweep_band(&self) -> Option<[f64; 2]> {
        self.records
            .iter()
            .filter_map(|r| r.sweep_band)
            .reduce(|a, b| [a[0].min(b[0]), a[1].max(b[1])])
    }

    /// The records detrended, tapered at the joins and concatenated (module docs).
    pub fn joined(&self) -> JoinedRecord {
        let count = self.records.len();
        let join = |channel_of: &dyn Fn(&Record) -> &[Channel], index: usize| {
            let mut values = Vec::with_capacity(self.len());
            for (r, record) in self.records.iter().enumerate() {
                let mut piece = channel_of(record)[index].values.clone();
                remove_line(&mut piece);
                let taper = (piece.len() / 50).max(2);
                if r > 0 {
                    taper_start(&mut piece, taper);
                }
                if r + 1 < count {
                    taper_end(&mut piece, taper);
                }
                values.extend_from_slice(&piece);
            }
            values
        };
        let first = &self.records[0];
        let inputs = (0..first.inputs.len())
            .map(|i| Channel::new(first.inputs[i].name.clone(), join(&|r| &r.inputs, i)))
            .collect();
        let outputs = (0..first.outputs.len())
            .map(|i| Channel::new(first.outputs[i].name.clone(), join(&|r| &r.outputs, i)))
            .collect();
        // Same detrend and join tapers as the inputs: the reference estimate relates the
        // references to the inputs and outputs window by window.
        let references = (0..first.references.len())
            .map(|i| {
                Channel::new(
                    first.references[i].name.clone(),
                    join(&|r| &r.references, i),
                )
            })
            .collect();
        JoinedRecord {
            sample_rate_hz: first.sample_rate_hz,
            primary: first.primary.clone(),
            inputs,
            outputs,
            references,
        }
    }
}

/// The detrended, joined channels of a [`RecordGroup`].
#[derive(Clone, Debug, PartialEq)]
pub struct JoinedRecord {
    /// Sample rate \[Hz\].
    pub sample_rate_hz: f64,
    /// Name of the swept input.
    pub primary: String,
    /// Input channels.
    pub inputs: Vec<Channel>,
    /// Output channels.
    pub outputs: Vec<Channel>,
    /// Reference channels (see [`Record::references`]).
    pub references: Vec<Channel>,
}

impl JoinedRecord {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.inputs.first().map_or(0, |c| c.values.len())
    }

    /// `true` when empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Length \[s\].
    pub fn duration_s(&self) -> f64 {
        self.len() as f64 / self.sample_rate_hz
    }
}

/// Put records into one [`RecordGroup`] per swept input, in order of first appearance.
pub fn group_by_primary(records: Vec<Record>) -> Result<Vec<RecordGroup>, FrfError> {
    if records.is_empty() {
        return Err(FrfError::NoRecords);
    }
    let mut by_axis: Vec<(String, Vec<Record>)> = Vec::new();
    for record in records {
        match by_axis.iter_mut().find(|(axis, _)| *axis == record.primary) {
            Some((_, list)) => list.push(record),
            None => by_axis.push((record.primary.clone(), vec![record])),
        }
    }
    by_axis
        .into_iter()
        .map(|(_, list)| RecordGroup::new(list))
        .collect()
}

/// Raised-cosine gain rising from 0 (sample 0) towards 1 over `len` samples.
fn ramp(n: usize, len: usize) -> f64 {
    0.5 - 0.5 * (std::f64::consts::PI * n as f64 / len as f64).cos()
}

fn taper_start(values: &mut [f64], len: usize) {
    let len = len.min(values.len());
    for (n, v) in values.iter_mut().take(len).enumerate() {
        *v *= ramp(n, len);
    }
}

fn taper_end(values: &mut [f64], len: usize) {
    let len = len.min(values.len());
    for (n, v) in values.iter_mut().rev().take(len).enumerate() {
        *v *= ramp(n, len);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::records::record::tests::record;

    #[test]
    fn joins_have_no_step() {
        // Two records with different trims and drifts: joined naively they would jump.
        let a = record(
            "a",
            "lat",
            (0..400).map(|n| 1.0 + 0.01 * n as f64).collect(),
            vec![0.5; 400],
        );
        let b = record(
            "b",
            "lat",
            (0..400).map(|n| -2.0 + (n as f64 * 0.3).sin()).collect(),
            (0..400).map(|n| 7.0 + (n as f64 * 0.2).cos()).collect(),
        );
        let joined = RecordGroup::new(vec![a, b]).unwrap().joined();
        assert_eq!(joined.len(), 800);
        for channel in joined.inputs.iter().chain(&joined.outputs) {
            let v = &channel.values;
            // Around the join both sides go to zero: no step, small differences only.
            assert!(
                v[399].abs() < 0.01 && v[400].abs() < 1e-12,
                "{:?}",
                &v[398..402]
            );
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            assert!(mean.abs() < 0.05, "{mean}");
        }
    }

    #[test]
    fn groups_reject_mixed_axes_and_rates() {
        let a = record("a", "lat", vec![0.0; 10], vec![0.0; 10]);
        let mut b = record("b", "lat", vec![0.0; 10], vec![0.0; 10]);
        b.sample_rate_hz = 50.0;
        assert!(matches!(
            RecordGroup::new(vec![a.clone(), b]),
            Err(FrfError::InconsistentGroup(_))
        ));
        let mut c = a.clone();
        c.inputs.push(Channel::new("lon", vec![0.0; 10]));
        c.primary = "lon".into();
        let groups = group_by_primary(vec![a.clone(), c, a]).unwrap();
        assert_eq!(groups.len(), 2);
        assert_eq!(groups[0].records().len(), 2);
        assert_eq!(groups[1].primary(), "lon");
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(32))]
        /// Whatever the trims and drifts, the joined record has no step at the joins:
        /// both sides reach zero, and near a join the signal changes no faster than the
        /// signal itself plus the taper allow.
        #[test]
        fn joins_never_step(
            offsets in proptest::collection::vec(-10.0f64..10.0, 3),
            slopes in proptest::collection::vec(-0.1f64..0.1, 3),
            len in 100usize..400,
        ) {
            let records: Vec<Record> = offsets
                .iter()
                .zip(&slopes)
                .enumerate()
                .map(|(r, (&offset, &slope))| {
                    let values: Vec<f64> = (0..len)
                        .map(|n| offset + slope * n as f64 + (0.1 * n as f64 + r as f64).sin())
                        .collect();
                    record(&format!("r{r}"), "lat", values.clone(), values)
                })
                .collect();
            let joined = RecordGroup::new(records).unwrap().joined();
            let v = &joined.inputs[0].values;
            for join in [len, 2 * len] {
                proptest::prop_assert!(v[join - 1].abs() < 1e-9 && v[join].abs() < 1e-9);
                let near = v[join - 5..join + 5].windows(2).map(|w| (w[1] - w[0]).abs());
                // |Δ(x·ramp)| ≤ |Δx| + max|x|·max|Δramp|: sin(0.1n) moves ≤ 0.1 per
                // sample and the raised cosine ≤ π/(2·T_taper).
                let taper = (len / 50).max(2) as f64;
                let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let bound = 0.1 + largest * std::f64::consts::PI / (2.0 * taper) + 1e-9;
                proptest::prop_assert!(near.fold(0.0, f64::max) <= bound);
            }
        }
    }
}
