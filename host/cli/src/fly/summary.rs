//! `summary.json` of `sweephold fly` (layout documented in docs/formats.md; later checks read
//! these names).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// Peak absolute attitude excursions over a record \[deg\].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MaxAbsDeg {
    /// Peak |φ| \[deg\] (absolute attitude, trim included).
    pub phi: f64,
    /// Peak |θ| \[deg\] (absolute attitude, trim included).
    pub theta: f64,
    /// Peak |ψ − ψ_start| wrapped to ±180° \[deg\].
    pub psi: f64,
}

/// Peak excursions from the trim the flight controller captured, over a record's
/// excitation \[deg\]: |φ − φ_trim|, |θ − θ_trim|. On a helicopter that hovers rolled
/// (the TREX 700L: about −5°) this, not the absolute attitude, is what the hold's
/// thresholds and the pilot see.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FromTrimDeg {
    /// Peak |φ − φ_trim| \[deg\].
    pub phi: f64,
    /// Peak |θ − θ_trim| \[deg\].
    pub theta: f64,
}

/// Share of the excitation ticks with the hold controller engaged, per held axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HoldFraction {
    /// Lateral.
    pub lat: f64,
    /// Longitudinal.
    pub lon: f64,
    /// Pedal.
    pub ped: f64,
}

/// A pair of roll and pitch angles \[deg\].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AttitudeDeg {
    /// Roll φ \[deg\].
    pub phi: f64,
    /// Pitch θ \[deg\].
    pub theta: f64,
}

/// The board's attitude estimate against the simulator (`--fc board-sim`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EstimatorSummary {
    /// Largest |estimate − simulator| over the excitation (over the whole test if it
    /// had none) \[deg\].
    pub max_error_deg: AttitudeDeg,
}

/// The flight after the test (`fly --fly-on`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AfterTest {
    /// The board application's mode at the end (`pilot`, `rc_failsafe`,
    /// `imu_failsafe`, `disarmed`).
    pub mode: String,
    /// Time flown after the test ended \[s\].
    pub duration_s: f64,
    /// Peak |φ|, |θ| of the simulated aircraft over that time \[deg\].
    pub max_abs_deg: AttitudeDeg,
    /// The discrete gust flown after the test (`--gust-pulse`), if it began.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_pulse: Option<GustPulseSummary>,
}

/// A discrete gust flown after the test (`fly --gust-pulse`) and the aircraft's response.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GustPulseSummary {
    /// Onset, seconds after the test ended.
    pub at_s: f64,
    /// Duration of its 1 − cos rise and fall \[s\].
    pub length_s: f64,
    /// Peak body-axis air velocity (u, v, w) \[m/s\].
    pub body_wind_m_s: [f64; 3],
    /// Peak |φ − φ_onset|, |θ − θ_onset| of the simulated aircraft from the onset to the
    /// end of the flight \[deg\].
    pub peak_excursion_deg: AttitudeDeg,
    /// φ − φ_onset, θ − θ_onset over that time, one sample per `step_s`.
    #[serde(default)]
    pub excursion_deg: ExcursionTrace,
}

/// An attitude trace sampled at a fixed step (`fly --gust-pulse`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExcursionTrace {
    /// Spacing of the samples \[s\], the first at the onset.
    pub step_s: f64,
    /// φ − φ_onset \[deg\].
    pub phi: Vec<f64>,
    /// θ − θ_onset \[deg\].
    pub theta: Vec<f64>,
}

/// One flown record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// Primary axis name.
    pub axis: String,
    /// 1-based record index for this axis.
    pub index: u32,
    /// Dump file name, relative to the summary.
    pub file: String,
    /// Sweep start frequency [rad/s].
    pub omega_min: f64,
    /// Sweep end frequency [rad/s].
    pub omega_max: f64,
    /// Flown duration, from the record's start to the end of the test (Done or the abort)
    /// \[s\]; the time flown on after it is `after.duration_s`.
    pub duration_s: f64,
    /// Frames in the dump.
    pub frames: u64,
    /// Whether the firmware aborted the test.
    pub aborted: bool,
    /// Abort reason (`attitude_limit`, …) or null.
    pub abort_reason: Option<String>,
    /// Peak attitude excursions during the excitation.
    pub max_abs_deg: MaxAbsDeg,
    /// Peak excursions from the captured trim during the excitation; null when the
    /// flight controller captured no trim.
    #[serde(default)]
    pub max_from_trim_deg: Option<FromTrimDeg>,
    /// Share of excitation ticks with the hold engaged, per axis.
    pub hold_fraction: HoldFraction,
    /// Average coherence between the primary control and each other control over the
    /// sweep band, keyed by control name.
    pub cross_coherence: BTreeMap<String, f64>,
    /// The board's attitude estimate against the simulator (`--fc board-sim` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimator: Option<EstimatorSummary>,
    /// The flight after the test (`--fly-on` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after: Option<AfterTest>,
}

/// The whole `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlySummary {
    /// Vehicle name: the aircraft file's `name` (`bo105`, `trex700l`, `fbl700`, …).
    pub vehicle: String,
    /// Excitation mode (`cah`, `standard`, `noise`).
    pub mode: String,
    /// Tick rate \[Hz\].
    pub rate_hz: u32,
    /// Campaign seed.
    pub seed: u64,
    /// Flight-controller link (`in-process`, `qemu`, `serial:PATH`, `board-sim`).
    pub link: String,
    /// The aircraft flown: `nonlinear` (the simulator) or `linearized` (its expansion
    /// about the hover trim, `--linearized-plant`). Absent in older files: `nonlinear`.
    #[serde(default = "nonlinear_plant")]
    pub plant: String,
    /// The records, in flying order.
    pub runs: Vec<RunSummary>,
}

/// The plant of a summary written before `plant` existed.
fn nonlinear_plant() -> String {
    "nonlinear".to_string()
}

impl FlySummary {
    /// Mean over the records of `axis` of their cross-control coherence with `other`.
    pub fn mean_cross_coherence(&self, axis: &str, other: &str) -> Option<f64> {
        let values: Vec<f64> = self
            .runs
            .iter()
            .filter(|r| r.axis == axis)
            .filter_map(|r| r.cross_coherence.get(other).copied())
            .collect();
        (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
    }
}
