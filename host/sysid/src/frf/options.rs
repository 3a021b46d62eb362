//! Settings of the frequency-response computation.

use super::error::FrfError;

/// Settings of [`compute_frequency_responses`](super::compute_frequency_responses).
/// `FrfOptions::default()` gives the CIFER-like defaults listed per field.
#[derive(Clone, Debug, PartialEq)]
pub struct FrfOptions {
    /// Frequency band [ω_lo, ω_hi] rad/s of the output grid. `None`: the sweep band of
    /// each group's records (ω_min..ω_max of the dump Header).
    pub band: Option<[f64; 2]>,
    /// Number of log-spaced grid frequencies (default 200).
    pub points: usize,
    /// Number of window lengths (default 5), log-spaced from ten periods of the highest
    /// grid frequency (20π/ω_hi) up to half the record.
    pub windows: usize,
    /// Fraction of overlap between consecutive windows, in [0, 0.95] (default 0.8).
    pub overlap: f64,
    /// Coherence γ² at or above which a frequency counts as valid (default 0.6).
    pub coherence_threshold: f64,
    /// Largest random error ε_r = √(1−γ²)/(|γ|·√(2·n_d)) a valid frequency may also have
    /// (default 0.15; `None`: the coherence alone decides). The coherence threshold does
    /// not see how many windows an estimate rests on: at the bottom of the band only the
    /// longest window resolves the frequency, with two or three independent averages, and
    /// a γ² = 0.65 estimate there scatters by ε_r ≈ 0.3 where the same γ² from the shorter
    /// windows scatters by 0.1. The value and its trade are measured over 20 simulated
    /// Bo-105 campaigns in docs/decisions/2026-11-21-random-error-bound.md.
    pub max_random_error: Option<f64>,
    /// A control whose RMS is below this fraction of the swept control's RMS counts as
    /// not excited and is left out of the conditioning (default 0.01).
    pub excitation_ratio: f64,
    /// Smallest normalised Cholesky pivot of the input spectral matrix accepted by the
    /// MISO solve (default 1e-3): a pivot is 1 − (multiple coherence of that input with
    /// the others), so 1e-3 rejects inputs that are > 99.9 % coherent with the rest.
    pub min_pivot: f64,
    /// Chirp-Z points per resolution bin 2π/T of a window (default 8): spectra are
    /// computed on this linear grid and interpolated onto the log grid.
    pub oversampling: usize,
    /// How the conditioned responses are estimated (default [`ResponseEstimator::CrossSpectral`]).
    pub estimator: ResponseEstimator,
    /// Which inputs of a record group get conditioned responses (default
    /// [`ResponseInputs::Auto`]).
    pub responses: ResponseInputs,
    /// An input other than the swept one counts as excited, and gets responses where
    /// [`responses`](Self::responses) asks for every excited input, when its RMS (about
    /// each record's trend line, over the joined records) is at least this fraction of
    /// the largest input RMS of the group (default 0.1, i.e. 20 dB below). The controls
    /// are compared in their own units, so CSV inputs should share one (stick fraction,
    /// degrees, …). An input below it still conditions the others when it reaches
    /// [`excitation_ratio`](Self::excitation_ratio) of the swept one's RMS.
    pub response_ratio: f64,
    /// Where the valid ranges come from (default [`RangeSource::Estimate`]).
    pub ranges: RangeSource,
}

/// Whose random error sets the pairs' valid ranges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RangeSource {
    /// The estimate's own (coherence and random error of the responses written).
    #[default]
    Estimate,
    /// The sweep-reference estimate's ([`ResponseEstimator::SweepReference`]): its random
    /// error is the cross-spectral one times the square root of its variance ratio, which
    /// grows where the recorded sweep does not drive the swept control (the hold does), so
    /// the ranges leave out the frequencies an engaged hold biases. The responses,
    /// coherences and random errors written stay those of [`FrfOptions::estimator`].
    /// Needs records with reference channels (telemetry dumps).
    SweepReference,
}

/// Which inputs of a record group get MISO-conditioned responses.
///
/// All of them come from the same solve `H = G_uu⁻¹·G_uy`: with the inputs u of a group
/// and output y, H_i is the response to input i with the other inputs accounted for,
/// whichever input was swept. Its partial coherence needs G_ii·(others), the autospectrum
/// of input i conditioned on the others, so each responding input is ordered last in its
/// own factorisation of G_uu ([`miso`](super::miso)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ResponseInputs {
    /// [`Excited`](Self::Excited) for a group whose every record has its swept input
    /// only guessed ([`Record::primary_guessed`](super::Record::primary_guessed): CSV
    /// without a `primary` column or `frf --swept`), where nothing says one input was
    /// swept while the others stayed small; [`Swept`](Self::Swept) otherwise (telemetry
    /// dumps, decoded CSV, a named swept input) and with the sweep-reference estimator.
    #[default]
    Auto,
    /// The swept input of each group only: in a flight-test sweep the other controls move
    /// only by the holds' corrections and the off-axis noise, conditioning inputs rather
    /// than responses of their own.
    Swept,
    /// Every excited input of each group (the swept one and each input reaching
    /// [`FrfOptions::response_ratio`]): records in which several inputs are excited at
    /// once (multisines, simultaneous-axis tests, another logger's flight). Not with the
    /// sweep-reference estimator, which instruments the swept input only.
    Excited,
}

/// How the conditioned (MISO) responses are estimated from the spectra.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ResponseEstimator {
    /// H = G_uu⁻¹·G_uy (CIFER's MISOSA). Unbiased when the controls are independent of
    /// whatever in the outputs they do not cause; pulled towards the controller's inverse
    /// where an engaged hold drives the swept control from noisy measurements.
    #[default]
    CrossSpectral,
    /// H = G_zu⁻¹·G_zy with the swept control's recorded excitation (the sweep) as its
    /// instrument and the other controls as their own ([`reference`](super::reference)).
    /// Needs records with reference channels (telemetry dumps, CSV files read with
    /// [`CsvColumns::references`](crate::records::CsvColumns::references)). Coherences stay those of
    /// the cross-spectral estimate; the random error grows by the estimator's variance
    /// ratio, and the valid ranges with it. Less biased, more scattered: the measured trade is
    /// in docs/decisions/2026-11-21-sweep-reference-estimator.md.
    SweepReference,
}

impl Default for FrfOptions {
    fn default() -> Self {
        FrfOptions {
            band: None,
            points: 200,
            windows: 5,
            overlap: 0.8,
            coherence_threshold: 0.6,
            max_random_error: Some(0.15),
            excitation_ratio: 0.01,
            min_pivot: 1e-3,
            oversampling: 8,
            estimator: ResponseEstimator::CrossSpectral,
            responses: ResponseInputs::Auto,
            response_ratio: 0.1,
            ranges: RangeSource::Estimate,
        }
    }
}

impl FrfOptions {
    /// Check every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), FrfError> {
        let bad = |message: String| Err(FrfError::InvalidOption(message));
        if let Some([lo, hi]) = self.band {
            if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
                return bad(format!("band {lo},{hi}: need 0 < WMIN < WMAX"));
            }
        }
        if !(2..=100_000).contains(&self.points) {
            return bad(format!("points {}: need 2..=100000", self.points));
        }
        if !(1..=20).contains(&self.windows) {
            return bad(format!("windows {}: need 1..=20", self.windows));
        }
        if !(0.0..=0.95).contains(&self.overlap) {
            return bad(format!("overlap {}: need 0..=0.95", self.overlap));
        }
        if !(0.0..=1.0).contains(&self.coherence_threshold) {
            return bad(format!(
                "coherence threshold {}: need 0..=1",
                self.coherence_threshold
            ));
        }
        if let Some(max) = self.max_random_error {
            if !(max.is_finite() && max > 0.0) {
                return bad(format!("max random error {max}: need a finite value > 0"));
            }
        }
        if !(0.0..1.0).contains(&self.excitation_ratio) {
            return bad(format!(
                "excitation ratio {}: need 0..1",
                self.excitation_ratio
            ));
        }
        if !(self.min_pivot > 0.0 && self.min_pivot < 1.0) {
            return bad(format!("min pivot {}: need 0 < p < 1", self.min_pivot));
        }
        if !(1..=64).contains(&self.oversampling) {
            return bad(format!("oversampling {}: need 1..=64", self.oversampling));
        }
        if !(self.response_ratio > 0.0 && self.response_ratio <= 1.0) {
            return bad(format!(
                "response ratio {}: need 0 < r ≤ 1",
                self.response_ratio
            ));
        }
        if self.responses == ResponseInputs::Excited
            && (self.estimator == ResponseEstimator::SweepReference
                || self.ranges == RangeSource::SweepReference)
        {
            return bad(
                "the sweep-reference estimator gives only the swept input's response: responses to every excited input need the cross-spectral estimator"
                    .into(),
            );
        }
        Ok(())
    }
}
