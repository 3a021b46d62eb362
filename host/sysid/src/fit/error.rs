//! Typed errors of the fit: structure-file problems (always with the line they are on)
//! and data / numerical problems met while fitting.

use std::fmt;

/// What is wrong in a model structure file.
#[derive(Clone, Debug, PartialEq)]
pub enum StructureProblem {
    /// The file is not valid TOML, or a value has the wrong type / an unknown key
    /// (the `toml` crate's message).
    Syntax(String),
    /// A state, control or output name that the structure does not declare.
    UnknownName {
        /// `state`, `control`, `output`, `matrix row` or `constant`.
        kind: &'static str,
        /// The offending name.
        name: String,
    },
    /// A name declared twice (states, controls, outputs or parameters).
    DuplicateName(String),
    /// An expression uses a parameter that `[parameters]` does not define.
    UndefinedParameter(String),
    /// An expression that is not a linear combination of parameters.
    BadExpression {
        /// The expression text.
        expression: String,
        /// Why it was rejected.
        reason: String,
    },
    /// Constrained parameters that refer to each other in a loop.
    CyclicConstraint(String),
    /// A parameter table that is neither free (`start`), fixed (`fixed`) nor
    /// constrained (`expr`), or has several of them, or bad bounds.
    BadParameter {
        /// Parameter name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A number that must be finite is NaN or infinite: a parameter's start, fixed value
    /// or bound, a matrix entry or a delay.
    NotFinite {
        /// What the number is, e.g. ``parameter `Xu` `` or ``parameter `Xu`: min``.
        what: String,
        /// The number.
        value: f64,
    },
    /// Parameters declared under `[parameters]` that no matrix entry or delay uses (or
    /// only with a coefficient of 0): the fit cannot move them, and their Cramér–Rao
    /// bounds would make every bound infinite.
    UnusedParameters(Vec<String>),
    /// A pair range that is neither `"auto"` nor `[lo, hi]` with 0 < lo < hi.
    BadRange(String),
    /// The file could not be read.
    Io(String),
}

impl fmt::Display for StructureProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Syntax(message) => write!(f, "{message}"),
            Self::UnknownName { kind, name } => write!(f, "unknown {kind} `{name}`"),
            Self::DuplicateName(name) => write!(f, "`{name}` is declared twice"),
            Self::UndefinedParameter(name) => write!(
                f,
                "undefined parameter `{name}` (declare it under [parameters])"
            ),
            Self::BadExpression { expression, reason } => {
                write!(f, "bad expression `{expression}`: {reason}")
            }
            Self::CyclicConstraint(name) => {
                write!(f, "constrained parameter `{name}` depends on itself")
            }
            Self::BadParameter { name, reason } => write!(f, "parameter `{name}`: {reason}"),
            Self::NotFinite { what, value } => write!(f, "{what} = {value} is not a finite number"),
            Self::UnusedParameters(names) => {
                let listed = names
                    .iter()
                    .map(|name| format!("`{name}`"))
                    .collect::<Vec<_>>()
                    .join(", ");
                if names.len() == 1 {
                    write!(
                        f,
                        "parameter {listed} is declared but used in no matrix entry or delay"
                    )
                } else {
                    write!(
                        f,
                        "parameters {listed} are declared but used in no matrix entry or delay"
                    )
                }
            }
            Self::BadRange(reason) => write!(f, "bad range: {reason}"),
            Self::Io(message) => write!(f, "cannot read: {message}"),
        }
    }
}

/// A problem in a structure file, located by file name and 1-based line.
#[derive(Clone, Debug, PartialEq)]
pub struct StructureError {
    /// File name (or `<string>` when parsed from text).
    pub source_name: String,
    /// 1-based line of the problem, when known.
    pub line: Option<usize>,
    /// What is wrong.
    pub problem: StructureProblem,
}

impl fmt::Display for StructureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}, line {}: {}", self.source_name, line, self.problem),
            None => write!(f, "{}: {}", self.source_name, self.problem),
        }
    }
}

impl std::error::Error for StructureError {}

/// Everything that can stop a fit.
#[derive(Clone, Debug, PartialEq)]
pub enum FitError {
    /// The structure file is malformed.
    Structure(StructureError),
    /// The structure asks for a pair that the frequency-response document lacks.
    MissingPair {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
        /// Line of the pair in the structure file.
        line: usize,
    },
    /// A pair with `range = "auto"` whose data has no valid (coherent) range.
    NoValidRange {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
        /// Line of the pair in the structure file.
        line: usize,
    },
    /// Every pair of the structure was skipped for lack of a usable coherent range.
    NoUsablePairs {
        /// How many pairs were skipped.
        skipped: usize,
    },
    /// The pair's range does not overlap the frequencies of its data, or the data are
    /// malformed (lengths differ, frequencies not ascending or not positive, NaN).
    BadPairData {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
        /// What is wrong.
        reason: String,
    },
    /// The structure has no pair to fit.
    NoPairs,
    /// Parameter vector of the wrong length for the structure.
    ParameterCount {
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// `sM − F` is singular at a fit frequency (a pole on the jω axis, or M singular):
    /// the model cannot be evaluated there.
    SingularSystem {
        /// Frequency [rad/s].
        omega: f64,
    },
    /// A name used to compare two models does not exist in one of them.
    UnknownPairName {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
    },
    /// A start-value source (a previous model) does not provide what is needed.
    StartValues(String),
    /// The trim points cannot give the structure's `trim_derived` parameters.
    TrimPoints(String),
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Structure(error) => write!(f, "{error}"),
            Self::MissingPair {
                input,
                output,
                line,
            } => write!(
                f,
                "line {line}: pair {output}/{input} is not in the frequency-response data"
            ),
            Self::NoUsablePairs { skipped } => write!(
                f,
                "none of the {skipped} pairs has a usable coherent range in the data (see the skipped pairs; lower the coherence threshold of `sweephold frf` or give explicit ranges)"
            ),
            Self::NoValidRange {
                input,
                output,
                line,
            } => write!(
                f,
                "line {line}: pair {output}/{input} has range \"auto\" but its data have no \
                 valid (coherent) range; give an explicit [lo, hi] or drop the pair"
            ),
            Self::BadPairData {
                input,
                output,
                reason,
            } => write!(f, "pair {output}/{input}: {reason}"),
            Self::NoPairs => write!(f, "the structure lists no pair to fit"),
            Self::ParameterCount { expected, got } => {
                write!(f, "expected {expected} parameter values, got {got}")
            }
            Self::SingularSystem { omega } => write!(
                f,
                "sM − F is singular at ω = {omega} rad/s (pole on the jω axis or singular M)"
            ),
            Self::UnknownPairName { input, output } => {
                write!(f, "pair {output}/{input} is not in both models")
            }
            Self::StartValues(message) => write!(f, "start values: {message}"),
            Self::TrimPoints(message) => write!(f, "trim points: {message}"),
        }
    }
}

impl std::error::Error for FitError {}

impl From<StructureError> for FitError {
    fn from(error: StructureError) -> Self {
        Self::Structure(error)
    }
}
