//! What the report draws from the folder's dumps rather than from its documents: the first
//! lateral `cah` sweep (its time history) and, per flown mode, the cross-control coherence
//! curves of the lateral sweeps joined. A campaign hands them over from the records it
//! decoded once (the `cah` curves are its frequency-response stage's); `sweephold report
//! DIR` decodes them from the dumps.

use sysid::frf::analysis::CoherenceCurve;
use sysid::frf::{analyse, group_by_primary, FrfError, FrfOptions, Record};

/// The swept control of the records the report draws.
pub const LATERAL: &str = "lat";

/// The lateral cross-control coherence of one mode versus frequency.
#[derive(Clone, Debug)]
pub struct ModeCoherence {
    /// Mode name.
    pub mode: String,
    /// The lat–lon (and other lat–x) curves of the joined lateral records.
    pub curves: Vec<CoherenceCurve>,
}

/// The dump-derived inputs of the report.
#[derive(Clone, Debug, Default)]
pub struct FlownRecords {
    /// The first lateral `cah` sweep (paper Fig. 1/6); `source` is its dump's path.
    pub sweep: Option<Record>,
    /// Lateral cross-control coherence per flown mode, `cah`, `standard`, `noise` (paper
    /// Fig. 3/7).
    pub coherence: Vec<ModeCoherence>,
}

/// The cross-control coherence curves of `records`, the lateral sweeps of one mode, joined
/// as `sweephold frf` joins them (its default options).
pub fn lateral_coherence(records: Vec<Record>) -> Result<Vec<CoherenceCurve>, FrfError> {
    let groups = group_by_primary(records)?;
    Ok(analyse(&groups, &FrfOptions::default())?.cross_coherence_curves)
}
