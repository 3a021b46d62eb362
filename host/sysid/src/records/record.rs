//! The sweep record every reader produces: uniformly sampled, named input, output and
//! reference channels of one excitation, with where it came from.
//!
//! The frequency-response analysis (`crate::frf`) and the time-domain verification
//! (`crate::fit::verify`) read records; the readers beside this module make them.

use super::error::RecordError;
use super::measurement_filter::MeasurementFilter;

/// One named channel of samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Name: for inputs `lat lon ped col`, for outputs `u v w p q r ax ay az phi theta`
    /// (CSV records may use any names).
    pub name: String,
    /// Samples at the record's rate.
    pub values: Vec<f64>,
}

impl Channel {
    /// A channel from a name and its samples.
    pub fn new(name: impl Into<String>, values: Vec<f64>) -> Channel {
        Channel {
            name: name.into(),
            values,
        }
    }
}

/// One excitation record: uniformly sampled inputs (controls) and outputs (responses).
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Where it came from (file name), for messages.
    pub source: String,
    /// Sample rate \[Hz\].
    pub sample_rate_hz: f64,
    /// Name of the swept input (one of `inputs`), e.g. `lat`.
    pub primary: String,
    /// `true` when nothing named the swept input and `primary` is only the most active
    /// one (a CSV file without a `primary` column, read without `frf --swept`): such a
    /// record may excite several inputs at once. `false` for telemetry dumps (their
    /// Header names the swept axis).
    pub primary_guessed: bool,
    /// Sweep band [ω_min, ω_max] rad/s, when known (from the dump Header).
    pub sweep_band: Option<[f64; 2]>,
    /// Input channels (controls), e.g. `lat lon ped col`.
    pub inputs: Vec<Channel>,
    /// Output channels (responses), e.g. `u v w p q r ax ay az phi theta`.
    pub outputs: Vec<Channel>,
    /// Reference channels: for an input, the excitation the flight controller injected
    /// into it (sweep and off-axis noise, not the hold controller's share), named after
    /// that input. Empty when unknown (CSV records without reference columns). Only the
    /// reference estimator
    /// ([`ResponseEstimator::SweepReference`](crate::frf::ResponseEstimator::SweepReference)) reads them.
    pub references: Vec<Channel>,
    /// Remarks made while loading (gaps filled, …); copied into the document's notes.
    pub notes: Vec<String>,
    /// Leading samples taken at trim, before the excitation starts: a telemetry dump's
    /// trim-capture samples kept in front of the fade-in (up to
    /// [`SETTLE_S`](super::dump::SETTLE_S), on the tick grid). 0 when there are none or
    /// the source does not say (CSV records). Time-domain verification takes each
    /// channel's trim (the bias of its perturbations) as its mean over these samples.
    pub trim_samples: usize,
    /// The digital filter the flight controller ran on some outputs before logging them
    /// (a board's IMU filter bank, announced in its telemetry), or `None`: the outputs
    /// are what the sensors gave. The frequency responses divide it out; the
    /// verification passes the model's outputs through it.
    pub measurement_filter: Option<MeasurementFilter>,
}

impl Record {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.inputs
            .first()
            .or(self.outputs.first())
            .map_or(0, |c| c.values.len())
    }

    /// `true` when the record has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Length in seconds.
    pub fn duration_s(&self) -> f64 {
        self.len() as f64 / self.sample_rate_hz
    }

    /// The samples of the input called `name`.
    pub fn input(&self, name: &str) -> Option<&[f64]> {
        self.inputs
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }

    /// The samples of the output called `name`.
    pub fn output(&self, name: &str) -> Option<&[f64]> {
        self.outputs
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }

    /// The reference (injected excitation) of the input called `name`.
    pub fn reference(&self, name: &str) -> Option<&[f64]> {
        self.references
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }

    /// Check the record: positive finite rate, the primary among the inputs, at least one
    /// output, equal channel lengths, unique names, finite samples, a sane band, each
    /// reference named after an input.
    pub fn validate(&self) -> Result<(), RecordError> {
        let bad = |message: String| {
            Err(RecordError::InvalidRecord {
                record: self.source.clone(),
                message,
            })
        };
        if !(self.sample_rate_hz.is_finite() && self.sample_rate_hz > 0.0) {
            return bad(format!("sample rate {} Hz", self.sample_rate_hz));
        }
        if self.input(&self.primary).is_none() {
            return bad(format!(
                "swept input `{}` is not among the inputs",
                self.primary
            ));
        }
        if self.outputs.is_empty() {
            return bad("no output channels".into());
        }
        let len = self.len();
        let mut names = std::collections::HashSet::new();
        for channel in self.inputs.iter().chain(&self.outputs) {
            if !names.insert(channel.name.as_str()) {
                return bad(format!("channel `{}` appears twice", channel.name));
            }
        }
        let mut referenced = std::collections::HashSet::new();
        for reference in &self.references {
            if self.input(&reference.name).is_none() {
                return bad(format!(
                    "reference `{}` is not named after an input",
                    reference.name
                ));
            }
            if !referenced.insert(reference.name.as_str()) {
                return bad(format!("reference `{}` appears twice", reference.name));
            }
        }
        for channel in self
            .inputs
            .iter()
            .chain(&self.outputs)
            .chain(&self.references)
        {
            if channel.values.len() != len {
                return bad(format!(
                    "channel `{}` has {} samples, others {len}",
                    channel.name,
                    channel.values.len()
                ));
            }
            if let Some(i) = channel.values.iter().position(|v| !v.is_finite()) {
                return bad(format!(
                    "channel `{}` sample {i} is not finite",
                    channel.name
                ));
            }
        }
        if let Some([lo, hi]) = self.sweep_band {
            if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
                return bad(format!("sweep band {lo}..{hi} rad/s"));
            }
        }
        Ok(())
    }
}

/// Root mean square.
pub(crate) fn rms(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt()
}

/// Subtract the least-squares line `a + b·(n − n̄)` (mean and trend).
pub(crate) fn remove_line(values: &mut [f64]) {
    let len = values.len();
    if len == 0 {
        return;
    }
    let centre = (len as f64 - 1.0) / 2.0;
    let mean = values.iter().sum::<f64>() / len as f64;
    // b = Σ(n − n̄)(x_n − x̄) / Σ(n − n̄)²
    let (mut num, mut den) = (0.0, 0.0);
    for (n, &v) in values.iter().enumerate() {
        let d = n as f64 - centre;
        num += d * (v - mean);
        den += d * d;
    }
    let slope = if den > 0.0 { num / den } else { 0.0 };
    for (n, v) in values.iter_mut().enumerate() {
        *v -= mean + slope * (n as f64 - centre);
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A 100 Hz record of one input `lat` and one output `p` (the tests of this module
    /// and of `frf::groups`).
    pub(crate) fn record(source: &str, primary: &str, lat: Vec<f64>, p: Vec<f64>) -> Record {
        Record {
            source: source.into(),
            sample_rate_hz: 100.0,
            primary: primary.into(),
            primary_guessed: false,
            sweep_band: Some([1.0, 10.0]),
            inputs: vec![Channel::new("lat", lat)],
            outputs: vec![Channel::new("p", p)],
            references: Vec::new(),
            notes: vec![],
            trim_samples: 0,
            measurement_filter: None,
        }
    }

    #[test]
    fn line_removal_leaves_zero_mean_and_no_trend() {
        let mut values: Vec<f64> = (0..101).map(|n| 3.0 + 0.25 * n as f64).collect();
        remove_line(&mut values);
        assert!(values.iter().all(|v| v.abs() < 1e-9));
    }

    #[test]
    fn validation_catches_bad_records() {
        let mut r = record("x", "lat", vec![0.0; 10], vec![0.0; 9]);
        assert!(r.validate().is_err());
        r.outputs[0].values.push(f64::NAN);
        assert!(r.validate().is_err());
        r.outputs[0].values[9] = 0.0;
        assert!(r.validate().is_ok());
        r.primary = "lon".into();
        assert!(r.validate().is_err());
    }
}
