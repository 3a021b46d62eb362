//! The input → output pairs a structure fits, and over which frequencies.

/// Frequency range of a pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PairRange {
    /// The pair's `valid_range` from the frequency-response document (clipped by the
    /// structure's `auto_range_limit`, if any).
    Auto,
    /// An explicit [lo, hi] rad/s.
    Explicit([f64; 2]),
}

/// One input → output pair to fit.
#[derive(Clone, Debug, PartialEq)]
pub struct PairSpec {
    /// Control name.
    pub input: String,
    /// Output name.
    pub output: String,
    /// Index into `controls`.
    pub input_index: usize,
    /// Index into `outputs`.
    pub output_index: usize,
    /// Range to fit over.
    pub range: PairRange,
    /// Line in the structure file.
    pub line: usize,
}
