//! What an analysis gives: the document, and what the plots and the command-line summary
//! need besides ([`FrfAnalysis`]).

use super::cross_coherence::CoherenceCurve;
use crate::document::FrfDocument;

/// Multiple coherence of one output with the conditioning inputs of its group.
#[derive(Clone, Debug, PartialEq)]
pub struct MultipleCoherence {
    /// Input of the pair it belongs to (its weights are that pair's).
    pub input: String,
    /// Output.
    pub output: String,
    /// Frequencies [rad/s].
    pub omega: Vec<f64>,
    /// γ²_y:u in [0, 1].
    pub coherence: Vec<f64>,
}

/// What was done with one record group.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupSummary {
    /// Primary axis.
    pub axis: String,
    /// Number of records joined.
    pub records: usize,
    /// Length of the joined record \[s\].
    pub seconds: f64,
    /// Frequency grid band [rad/s].
    pub band: [f64; 2],
    /// Window lengths used \[s\].
    pub windows: Vec<f64>,
    /// Controls in the conditioning (primary last).
    pub conditioned_on: Vec<String>,
    /// Inputs whose responses were computed (the primary first).
    pub responses: Vec<String>,
}

/// The document plus what the plots and the command-line summary need.
#[derive(Clone, Debug, PartialEq)]
pub struct FrfAnalysis {
    /// The `frf.json` document.
    pub document: FrfDocument,
    /// Cross-control coherence versus frequency (the document has only the means).
    pub cross_coherence_curves: Vec<CoherenceCurve>,
    /// One summary per group.
    pub groups: Vec<GroupSummary>,
    /// Multiple coherence γ²_y:u of each output with all the conditioning inputs, one
    /// per MISO pair in `document.pairs` order (composite, same weights as the response).
    /// How much of the output the excited controls explain together; the partial
    /// coherence in the document is the share of the swept control alone.
    pub multiple_coherence: Vec<MultipleCoherence>,
}
