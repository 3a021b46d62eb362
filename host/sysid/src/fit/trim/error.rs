//! What is wrong with a trim-point file or a derivation ([`TrimError`]).

/// What is wrong with a trim-point file or a derivation.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrimError {
    /// The CSV text is malformed (line number, 1-based, and what is wrong).
    #[error("line {line}: {reason}")]
    Csv {
        /// Line of the problem.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// Fewer than two points: no gradient.
    #[error("{0} trim point(s): at least two are needed for a gradient")]
    TooFewPoints(usize),
    /// A derived parameter appears in M or among the hidden states' own couplings (F_hh),
    /// so the balance is not linear in it.
    #[error(
        "`{0}` couples the states the trim points do not give (or is in M): it cannot be derived from trim points"
    )]
    NotLinear(String),
    /// The hidden states' rows cannot be solved (F_hh singular).
    #[error("the rows of the states the trim points do not give cannot be solved (singular)")]
    HiddenStatesSingular,
    /// The points do not vary the state a derived parameter multiplies.
    #[error(
        "the trim points do not vary what `{parameter}` multiplies: add points that do (see docs/formats.md, trim points)"
    )]
    NotInformed {
        /// The parameter.
        parameter: String,
    },
    /// The points vary what the derived parameters multiply, but not independently of
    /// each other (collinear or duplicate points): the balance cannot tell them apart.
    #[error(
        "the trim points do not vary what {} multiply independently of each other: their \
         differences in {varied} span only {directions} direction(s) (collinear or \
         duplicate points); add points that vary them separately (see docs/formats.md, \
         trim points)",
        quoted(.parameters)
    )]
    NotIndependent {
        /// The parameters the points cannot tell apart.
        parameters: Vec<String>,
        /// The state columns the points vary, space-separated.
        varied: String,
        /// The rank of the points' differences in those columns.
        directions: usize,
    },
    /// The model could not be built from the values.
    #[error("{0}")]
    Model(String),
}

/// `` `a`, `b` `` for an error message.
fn quoted(names: &[String]) -> String {
    names
        .iter()
        .map(|name| format!("`{name}`"))
        .collect::<Vec<_>>()
        .join(", ")
}
