//! The score of one output: the bias b removed from the measurement and Theil's
//! inequality coefficient of the prediction (formula in the module documentation of
//! [`super`]).

/// The fit of one output.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OutputScore {
    /// Output name.
    pub output: String,
    /// The constant b removed from the measurement: the output's trim mean
    /// ([`BiasMode::Trim`]) or the least-squares mean(y − ŷ) ([`BiasMode::Fitted`]).
    ///
    /// [`BiasMode::Trim`]: super::BiasMode::Trim
    /// [`BiasMode::Fitted`]: super::BiasMode::Fitted
    pub bias: f64,
    /// RMS of the residual y − b − ŷ.
    pub rms_error: f64,
    /// RMS of the measured perturbation y − b.
    pub rms_measured: f64,
    /// RMS of the prediction ŷ.
    pub rms_predicted: f64,
    /// Theil's inequality coefficient.
    pub theil: f64,
}

pub(super) fn rms(values: impl Iterator<Item = f64>, n: usize) -> f64 {
    (values.map(|v| v * v).sum::<f64>() / n as f64).sqrt()
}

/// Score a prediction against a measurement of one output with the bias fitted by least
/// squares, `b = mean(y − ŷ)` ([`BiasMode::Fitted`]), then the TIC.
///
/// [`BiasMode::Fitted`]: super::BiasMode::Fitted
pub fn score_output(name: &str, measured: &[f64], predicted: &[f64]) -> OutputScore {
    let n = measured.len().min(predicted.len()).max(1);
    let bias = measured
        .iter()
        .zip(predicted)
        .map(|(y, p)| y - p)
        .sum::<f64>()
        / n as f64;
    score_output_with_bias(name, measured, predicted, bias)
}

/// Score a prediction against a measurement of one output with a given bias b (e.g. the
/// output's trim): the RMS of `y − b − ŷ`, `y − b` and ŷ, and the TIC.
pub fn score_output_with_bias(
    name: &str,
    measured: &[f64],
    predicted: &[f64],
    bias: f64,
) -> OutputScore {
    let n = measured.len().min(predicted.len()).max(1);
    let rms_error = rms(measured.iter().zip(predicted).map(|(y, p)| y - bias - p), n);
    let rms_measured = rms(measured.iter().map(|y| y - bias), n);
    let rms_predicted = rms(predicted.iter().copied(), n);
    let denominator = rms_measured + rms_predicted;
    // A prediction that overflowed the sums is the limit ŷ → ∞: TIC → 1.
    let theil = if !(rms_error.is_finite() && denominator.is_finite()) {
        1.0
    } else if denominator > 0.0 {
        rms_error / denominator
    } else {
        0.0
    };
    OutputScore {
        output: name.to_string(),
        bias,
        rms_error,
        rms_measured,
        rms_predicted,
        theil,
    }
}
