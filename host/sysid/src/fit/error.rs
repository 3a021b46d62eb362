//! Typed errors of the fit: structure-file problems (always with the line they are on)
//! and data / numerical problems met while fitting.

/// What is wrong in a model structure file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StructureProblem {
    /// The file is not valid TOML, or a value has the wrong type / an unknown key
    /// (the `toml` crate's message).
    #[error("{0}")]
    Syntax(String),
    /// A state, control or output name that the structure does not declare.
    #[error("unknown {kind} `{name}`")]
    UnknownName {
        /// `state`, `control`, `output`, `matrix row` or `constant`.
        kind: &'static str,
        /// The offending name.
        name: String,
    },
    /// A name declared twice (states, controls, outputs or parameters).
    #[error("`{0}` is declared twice")]
    DuplicateName(String),
    /// An expression uses a parameter that `[parameters]` does not define.
    #[error("undefined parameter `{0}` (declare it under [parameters])")]
    UndefinedParameter(String),
    /// An expression that is not a linear combination of parameters.
    #[error("bad expression `{}`: {reason}", shortened(.expression))]
    BadExpression {
        /// The expression text.
        expression: String,
        /// Why it was rejected.
        reason: String,
    },
    /// Constrained parameters that refer to each other in a loop.
    #[error("constrained parameter `{0}` depends on itself")]
    CyclicConstraint(String),
    /// A parameter table that is neither free (`start`), fixed (`fixed`) nor
    /// constrained (`expr`), or has several of them, or bad bounds.
    #[error("parameter `{name}`: {reason}")]
    BadParameter {
        /// Parameter name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A number that must be finite is NaN or infinite: a parameter's start, fixed value
    /// or bound, a matrix entry or a delay.
    #[error("{what} = {value} is not a finite number")]
    NotFinite {
        /// What the number is, e.g. ``parameter `Xu` `` or ``parameter `Xu`: min``.
        what: String,
        /// The number.
        value: f64,
    },
    /// Parameters declared under `[parameters]` that no matrix entry or delay uses (or
    /// only with a coefficient of 0): the fit cannot move them, and their Cramér–Rao
    /// bounds would make every bound infinite.
    #[error("{}", unused_parameters(.0))]
    UnusedParameters(Vec<String>),
    /// A pair range that is neither `"auto"` nor `[lo, hi]` with 0 < lo < hi.
    #[error("bad range: {0}")]
    BadRange(String),
    /// An `[actuators]` entry whose natural frequency or damping is not a positive
    /// number (or the name of a `[constants]` entry holding one).
    #[error("actuator of `{control}`: {reason}")]
    BadActuator {
        /// The control.
        control: String,
        /// What is wrong.
        reason: String,
    },
    /// Constrained parameters that name each other in a chain longer than
    /// [`crate::fit::expression::MAX_NESTING`] (resolving it recurses once per link).
    #[error(
        "constrained parameter `{0}` is defined through a chain of more than {limit} \
         constrained parameters",
        limit = crate::fit::expression::MAX_NESTING
    )]
    ConstraintChainTooLong(String),
    /// An output that is not a state and has no row of H0 or H1: its response would be
    /// identically 0.
    #[error(
        "output `{0}` is neither a state nor given a row of H0 or H1: nothing defines its \
         response"
    )]
    UndefinedOutput(String),
    /// More states, controls, outputs, parameters or pairs than a fit supports (limits
    /// documented in `host/sysid/models/README.md`); refused before any work.
    #[error("{count} {what}: at most {limit} are supported")]
    TooLarge {
        /// `states`, `controls`, `outputs`, `parameters` or `pairs`.
        what: &'static str,
        /// How many the file declares.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// The file could not be read.
    #[error("cannot read: {0}")]
    Io(String),
}

/// An expression as quoted in an error: at most 60 characters, so that a pathological
/// one still gives a one-line message.
fn shortened(expression: &str) -> String {
    const SHOWN: usize = 60;
    match expression.char_indices().nth(SHOWN) {
        None => expression.to_string(),
        Some((end, _)) => format!("{}…", &expression[..end]),
    }
}

/// A problem in a structure file, located by file name and 1-based line. The problem is
/// part of the message, not a `source()`: a chain printed with `{:#}` would say it twice.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{source_name}{}: {problem}", at_line(.line))]
pub struct StructureError {
    /// File name (or `<string>` when parsed from text).
    pub source_name: String,
    /// 1-based line of the problem, when known.
    pub line: Option<usize>,
    /// What is wrong.
    pub problem: StructureProblem,
}

/// Everything that can stop a fit.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The structure file is malformed (the structure error itself: its message, and no
    /// further source).
    #[error(transparent)]
    Structure(#[from] StructureError),
    /// The structure asks for a pair that the frequency-response document lacks.
    #[error("line {line}: pair {output}/{input} is not in the frequency-response data")]
    MissingPair {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
        /// Line of the pair in the structure file.
        line: usize,
    },
    /// Reduced to the outputs the data hold, the structure has no pair of a control left.
    #[error(
        "structure {structure}: no pair of control `{control}` left: its outputs ({outputs}) are not in the frequency-response data"
    )]
    NoMeasuredPairOfControl {
        /// Structure name.
        structure: String,
        /// Control name.
        control: String,
        /// The outputs of the control's pairs, space-separated.
        outputs: String,
    },
    /// A pair with `range = "auto"` whose data has no valid (coherent) range.
    #[error(
        "line {line}: pair {output}/{input} has range \"auto\" but its data have no \
         valid (coherent) range; give an explicit [lo, hi] or drop the pair"
    )]
    NoValidRange {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
        /// Line of the pair in the structure file.
        line: usize,
    },
    /// Every pair of the structure was skipped for lack of a usable coherent range.
    #[error(
        "none of the {skipped} pairs has a usable coherent range in the data (see the skipped pairs; lower the coherence threshold of `sweephold frf` or give explicit ranges)"
    )]
    NoUsablePairs {
        /// How many pairs were skipped.
        skipped: usize,
    },
    /// The pair's range does not overlap the frequencies of its data, or the data are
    /// malformed (lengths differ, frequencies not ascending or not positive, NaN).
    #[error("pair {output}/{input}: {reason}")]
    BadPairData {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
        /// What is wrong.
        reason: String,
    },
    /// The structure has no pair to fit.
    #[error("the structure lists no pair to fit")]
    NoPairs,
    /// Parameter vector of the wrong length for the structure.
    #[error("expected {expected} parameter values, got {got}")]
    ParameterCount {
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// `sM − F` is singular at a fit frequency (a pole on the jω axis, or M singular):
    /// the model cannot be evaluated there.
    #[error("sM − F is singular at ω = {omega} rad/s (pole on the jω axis or singular M)")]
    SingularSystem {
        /// Frequency [rad/s].
        omega: f64,
    },
    /// A name used to compare two models does not exist in one of them.
    #[error("pair {output}/{input} is not in both models")]
    UnknownPairName {
        /// Control name.
        input: String,
        /// Output name.
        output: String,
    },
    /// A start-value source (a previous model) does not provide what is needed.
    #[error("start values: {0}")]
    StartValues(String),
    /// The trim points cannot give the structure's `trim_derived` parameters.
    #[error("trim points: {0}")]
    TrimPoints(String),
}

/// `, line N` after the file name when the line is known.
fn at_line(line: &Option<usize>) -> String {
    line.map(|line| format!(", line {line}"))
        .unwrap_or_default()
}

/// The message of [`StructureProblem::UnusedParameters`]: the names, in backticks.
fn unused_parameters(names: &[String]) -> String {
    let listed = names
        .iter()
        .map(|name| format!("`{name}`"))
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() == 1 {
        format!("parameter {listed} is declared but used in no matrix entry or delay")
    } else {
        format!("parameters {listed} are declared but used in no matrix entry or delay")
    }
}
