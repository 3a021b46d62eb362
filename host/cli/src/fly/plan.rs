//! Which records a campaign flies: per axis, the paper's two sweeps (its Fig. 8 and 9).

use sweephold_protocol::{Axis, ExcitationMode, InputKind};
use sysid::random::SplitMix64;

/// One record to fly.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordPlan {
    /// Primary (excited) axis.
    pub axis: Axis,
    /// 1-based index among the records of this axis (file `<axis>-<index>.bin`).
    pub index: u32,
    /// How the off-axis inputs are treated.
    pub mode: ExcitationMode,
    /// The excitation signal.
    pub input: InputKind,
    /// Sweep start frequency [rad/s].
    pub omega_min: f64,
    /// Sweep end frequency [rad/s].
    pub omega_max: f64,
    /// Sweep record length T_rec \[s\].
    pub t_rec_s: f64,
    /// Sweep or pulse amplitude, fraction of full stick travel.
    pub amplitude: f64,
    /// Seed of the firmware's off-axis noise for this record.
    pub seed: u32,
}

impl RecordPlan {
    /// The dump's file name inside the output folder.
    pub fn file_name(&self) -> String {
        format!("{}-{}.bin", self.axis.name(), self.index)
    }
}

/// The paper's two sweep bands per axis [rad/s]: 0.2–31.4 (its Fig. 8) and 0.01–18.85
/// (Fig. 9), 90 s each, concatenated in identification.
pub const PAPER_BANDS: [(f64, f64); 2] = [(0.2, 31.4), (0.01, 18.85)];

/// The TREX 700L's two sweep bands [rad/s]: the first reaches 62.8 rad/s (10 Hz), past
/// its coupled rotor–body modes (about 30 rad/s in pitch, 57 rad/s in roll), which the
/// paper's 31.4 rad/s top leaves out: below them the roll response is a first-order lag
/// whose pole the fit trades against the delay (docs/decisions/2026-11-24-trex700l-servo-band.md).
/// At the 200 Hz loop 62.8 rad/s has 20 samples per period (the firmware accepts up to
/// 0.4 of Nyquist, 251 rad/s); the 5 % sweep asks the servos for 3.1 /s at the top,
/// inside their 4 /s rate. The second band is the paper's.
pub const TREX700L_BANDS: [(f64, f64); 2] = [(0.2, 62.8), (0.01, 18.85)];

/// The paper's sweep amplitude: 5 % of stick travel.
pub const PAPER_AMPLITUDE: f64 = 0.05;

/// The paper's record length \[s\].
pub const PAPER_T_REC_S: f64 = 90.0;

/// Records for `axes`: two sweeps per axis (the vehicle's `bands`, [`PAPER_BANDS`] for the
/// Bo-105), or one pulse input per axis for doublet/3-2-1-1 (verification records, on
/// the first band). Each record gets its own noise seed, derived from `seed` so that the
/// same seed gives the same campaign.
pub fn plan_records(
    bands: &[(f64, f64); 2],
    axes: &[Axis],
    mode: ExcitationMode,
    input: InputKind,
    t_rec_s: f64,
    seed: u64,
) -> Vec<RecordPlan> {
    let mut plans = Vec::new();
    let loop_band = [loop_test_band(bands)];
    for &axis in axes {
        let bands: &[(f64, f64)] = match input {
            InputKind::Sweep | InputKind::AdaptiveSweep => bands,
            InputKind::Doublet | InputKind::ThreeTwoOneOne => &bands[..1],
            InputKind::LoopSweep => &loop_band,
        };
        for (n, &(omega_min, omega_max)) in bands.iter().enumerate() {
            let index = n as u32 + 1;
            plans.push(RecordPlan {
                axis,
                index,
                mode,
                input,
                omega_min,
                omega_max,
                t_rec_s,
                amplitude: PAPER_AMPLITUDE,
                seed: record_seed(seed, axis, index),
            });
        }
    }
    plans
}

/// The band of a loop test: the first band, reaching at least the firmware's
/// `LOOP_TEST_OMEGA_MAX` (62.8 rad/s), so that it holds the loops' phase crossovers.
pub fn loop_test_band(bands: &[(f64, f64); 2]) -> (f64, f64) {
    let [(omega_min, omega_max), _] = *bands;
    let top = f64::from(sweephold_firmware::app::test_list::LOOP_TEST_OMEGA_MAX);
    (omega_min, omega_max.max(top))
}

/// A per-record seed: the first SplitMix64 output from the campaign seed plus the axis
/// (high word) and the record index (low word), truncated to 32 bits.
fn record_seed(seed: u64, axis: Axis, index: u32) -> u32 {
    let offset = (axis.index() as u64) << 32 | u64::from(index);
    SplitMix64::new(seed.wrapping_add(offset)).next_u64() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_sweeps_per_axis_with_distinct_seeds() {
        let plans = plan_records(
            &PAPER_BANDS,
            &Axis::ALL,
            ExcitationMode::ConditionalAttitudeHold,
            InputKind::Sweep,
            90.0,
            7,
        );
        assert_eq!(plans.len(), 8);
        assert_eq!(plans[0].file_name(), "lat-1.bin");
        assert_eq!(plans[1].file_name(), "lat-2.bin");
        assert_eq!((plans[1].omega_min, plans[1].omega_max), (0.01, 18.85));
        let mut seeds: Vec<u32> = plans.iter().map(|p| p.seed).collect();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), 8);
        let again = plan_records(
            &PAPER_BANDS,
            &Axis::ALL,
            ExcitationMode::ConditionalAttitudeHold,
            InputKind::Sweep,
            90.0,
            7,
        );
        assert_eq!(plans, again);
    }

    /// The record seeds as they have always been derived: a change here would change
    /// every flown record of every campaign seed.
    #[test]
    fn record_seeds_are_pinned() {
        assert_eq!(record_seed(1, Axis::Lat, 0), 2_298_633_409);
        assert_eq!(record_seed(1, Axis::Lon, 1), 2_488_299_554);
        assert_eq!(record_seed(7, Axis::Col, 2), 1_808_985_930);
    }

    #[test]
    fn one_pulse_record_per_axis() {
        let plans = plan_records(
            &PAPER_BANDS,
            &[Axis::Lon],
            ExcitationMode::ConditionalAttitudeHold,
            InputKind::Doublet,
            20.0,
            1,
        );
        assert_eq!(plans.len(), 1);
        assert_eq!(plans[0].file_name(), "lon-1.bin");
    }
}
