//! Model structure files (TOML): which entries of M, F, G, H0, H1 and which delays are
//! free, fixed, zero or constrained, and which input/output pairs to fit over which
//! frequency range. The format is documented in `host/sysid/models/README.md`.
//!
//! Every error names the line it is on: syntax errors through the span that
//! `toml::de::Error` carries, semantic errors (unknown state, undefined parameter, …)
//! through `toml::Spanned` values.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use serde::Deserialize;
use toml::Spanned;

use super::error::{FitError, StructureError, StructureProblem};
use super::expression::{parse_linear_with_constants, LinearForm};
use super::model::Model;

/// Whether the optimizer moves a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ParameterKind {
    /// Identified by the fit, starting from `value`.
    Free,
    /// Held at `value` (by the file, or dropped by `--reduce` at zero).
    Fixed,
    /// Held at the value the trim points give ([`super::trim`]); the fit re-derives it as
    /// the other parameters move. Only parameters the file lists in `trim_derived` become
    /// `trim`, and only when trim points are given.
    Trim,
}

/// A base parameter: free or fixed. Constrained parameters are [`DerivedParameter`]s.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Engineering name (`Lb1s`, `tau_f`, `Zcol`, …).
    pub name: String,
    /// Start value (free) or value (fixed).
    pub value: f64,
    /// Free or fixed.
    pub kind: ParameterKind,
    /// Optional lower bound the optimizer respects (e.g. 0 for a time constant).
    pub lower: Option<f64>,
    /// Optional upper bound.
    pub upper: Option<f64>,
    /// Line of the definition in the structure file.
    pub line: usize,
}

/// `constant + Σ coefficient·θ_k` over base-parameter indices.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ParameterExpression {
    /// Constant part.
    pub constant: f64,
    /// (base parameter index, coefficient) pairs.
    pub terms: Vec<(usize, f64)>,
}

impl ParameterExpression {
    /// Value for a vector of base-parameter values.
    pub fn evaluate(&self, values: &[f64]) -> f64 {
        self.terms
            .iter()
            .fold(self.constant, |sum, &(index, coefficient)| {
                sum + coefficient * values[index]
            })
    }
}

/// A parameter constrained to a linear expression of base parameters (paper Table 3,
/// note d: `Yb1s = -Xb1c`).
#[derive(Clone, Debug, PartialEq)]
pub struct DerivedParameter {
    /// Engineering name.
    pub name: String,
    /// The constraint, in base parameters.
    pub expression: ParameterExpression,
    /// Line of the definition.
    pub line: usize,
}

/// The five matrices of `M ẋ = F x + G u(t − τ)`, `y = H0 x + H1 ẋ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MatrixName {
    /// Mass matrix (states × states); defaults to the identity.
    M,
    /// Dynamics (states × states).
    F,
    /// Control (states × controls).
    G,
    /// Output from states (outputs × states).
    H0,
    /// Output from state derivatives (outputs × states).
    H1,
}

impl MatrixName {
    /// The name as written in structure files.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::M => "M",
            Self::F => "F",
            Self::G => "G",
            Self::H0 => "H0",
            Self::H1 => "H1",
        }
    }
}

/// One non-default matrix entry.
#[derive(Clone, Debug, PartialEq)]
pub struct MatrixEntry {
    /// Which matrix.
    pub matrix: MatrixName,
    /// Row index (state for M F G, output for H0 H1).
    pub row: usize,
    /// Column index (state, or control for G).
    pub column: usize,
    /// Value as a linear expression of base parameters.
    pub expression: ParameterExpression,
    /// Line in the structure file.
    pub line: usize,
}

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

/// A parsed, checked model structure.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelStructure {
    /// Structure name (`bo105-9dof-hybrid`).
    pub name: String,
    /// Free text.
    pub description: String,
    /// State names, in order.
    pub states: Vec<String>,
    /// Control names, in order.
    pub controls: Vec<String>,
    /// Output names, in order.
    pub outputs: Vec<String>,
    /// Base parameters (free and fixed), in file order.
    pub parameters: Vec<Parameter>,
    /// Constrained parameters, in file order.
    pub derived: Vec<DerivedParameter>,
    /// Matrix entries that differ from the defaults (M = I, H0 selects states that are
    /// also outputs, everything else zero).
    pub entries: Vec<MatrixEntry>,
    /// Delay τ per control [s], as expressions (constant 0 when not given).
    pub delays: Vec<ParameterExpression>,
    /// Pairs to fit.
    pub pairs: Vec<PairSpec>,
    /// Clips every `auto` range to this band [rad/s] (e.g. 6-DOF fits stop below the
    /// rotor modes).
    pub auto_range_limit: Option<[f64; 2]>,
    /// Outputs measured directly as a state by default (no H0/H1 row given): output
    /// index → state index.
    pub default_output_states: Vec<(usize, usize)>,
    /// File name used in error messages.
    pub source_name: String,
    /// Named numbers of the file's `[constants]` (e.g. `hub_height`), with any override
    /// the caller gave ([`Self::parse_with_constants`]); expressions were built with these.
    pub constants: BTreeMap<String, f64>,
    /// Base parameters the file's `trim_derived` names: with trim points
    /// ([`super::trim`]) they are derived from the steady-state balance at the points
    /// instead of fitted; without, they are fitted like the others.
    pub trim_derived: Vec<String>,
}

// ---------------------------------------------------------------------------------------
// Raw (serde) form.

#[derive(Deserialize)]
#[serde(untagged)]
enum RawValue {
    Number(f64),
    Expression(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParameterTable {
    start: Option<f64>,
    fixed: Option<f64>,
    expr: Option<String>,
    min: Option<f64>,
    max: Option<f64>,
    #[allow(dead_code)]
    description: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawParameter {
    Start(f64),
    Table(RawParameterTable),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawRange {
    Keyword(String),
    Band(Vec<f64>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPair {
    output: Spanned<String>,
    input: Spanned<String>,
    range: Option<Spanned<RawRange>>,
}

type RawRows = BTreeMap<Spanned<String>, BTreeMap<Spanned<String>, Spanned<RawValue>>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStructure {
    name: Spanned<String>,
    #[serde(default)]
    description: String,
    states: Vec<Spanned<String>>,
    controls: Vec<Spanned<String>>,
    outputs: Vec<Spanned<String>>,
    auto_range_limit: Option<Spanned<Vec<f64>>>,
    #[serde(default)]
    constants: BTreeMap<Spanned<String>, Spanned<f64>>,
    #[serde(default)]
    parameters: BTreeMap<Spanned<String>, Spanned<RawParameter>>,
    #[serde(rename = "M", default)]
    m: RawRows,
    #[serde(rename = "F", default)]
    f: RawRows,
    #[serde(rename = "G", default)]
    g: RawRows,
    #[serde(rename = "H0", default)]
    h0: RawRows,
    #[serde(rename = "H1", default)]
    h1: RawRows,
    #[serde(default)]
    delays: BTreeMap<Spanned<String>, Spanned<RawValue>>,
    #[serde(default)]
    pairs: Vec<Spanned<RawPair>>,
    #[serde(default)]
    trim_derived: Vec<Spanned<String>>,
}

// ---------------------------------------------------------------------------------------

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    1 + text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

struct Context<'a> {
    text: &'a str,
    source_name: &'a str,
}

impl Context<'_> {
    fn line(&self, span: std::ops::Range<usize>) -> usize {
        line_of(self.text, span.start)
    }

    fn error(&self, span: std::ops::Range<usize>, problem: StructureProblem) -> StructureError {
        StructureError {
            source_name: self.source_name.to_string(),
            line: Some(self.line(span)),
            problem,
        }
    }

    fn names(
        &self,
        list: &[Spanned<String>],
        kind: &'static str,
    ) -> Result<Vec<String>, StructureError> {
        let mut names: Vec<String> = Vec::with_capacity(list.len());
        for item in list {
            let name = item.get_ref();
            if names.contains(name) {
                return Err(self.error(item.span(), StructureProblem::DuplicateName(name.clone())));
            }
            if name.is_empty() {
                return Err(self.error(
                    item.span(),
                    StructureProblem::UnknownName {
                        kind,
                        name: String::new(),
                    },
                ));
            }
            names.push(name.clone());
        }
        Ok(names)
    }

    fn index_of(
        &self,
        names: &[String],
        item: &Spanned<String>,
        kind: &'static str,
    ) -> Result<usize, StructureError> {
        names
            .iter()
            .position(|n| n == item.get_ref())
            .ok_or_else(|| {
                self.error(
                    item.span(),
                    StructureProblem::UnknownName {
                        kind,
                        name: item.get_ref().clone(),
                    },
                )
            })
    }
}

/// Resolves expressions against base and constrained parameters.
struct Resolver<'a> {
    base: &'a HashMap<String, usize>,
    derived_forms: &'a HashMap<String, LinearForm>,
}

impl Resolver<'_> {
    /// Substitute constrained parameters (recursively) and map names to base indices.
    fn resolve(
        &self,
        form: &LinearForm,
        visiting: &mut Vec<String>,
    ) -> Result<ParameterExpression, StructureProblem> {
        let mut constant = form.constant;
        let mut coefficients: BTreeMap<usize, f64> = BTreeMap::new();
        for (name, &coefficient) in &form.terms {
            if let Some(&index) = self.base.get(name) {
                *coefficients.entry(index).or_insert(0.0) += coefficient;
            } else if let Some(inner) = self.derived_forms.get(name) {
                if visiting.contains(name) {
                    return Err(StructureProblem::CyclicConstraint(name.clone()));
                }
                visiting.push(name.clone());
                let resolved = self.resolve(inner, visiting)?;
                visiting.pop();
                constant += coefficient * resolved.constant;
                for (index, inner_coefficient) in resolved.terms {
                    *coefficients.entry(index).or_insert(0.0) += coefficient * inner_coefficient;
                }
            } else {
                return Err(StructureProblem::UndefinedParameter(name.clone()));
            }
        }
        Ok(ParameterExpression {
            constant,
            terms: coefficients
                .into_iter()
                .filter(|&(_, c)| c != 0.0)
                .collect(),
        })
    }
}

impl ModelStructure {
    /// Parse a structure from TOML text; `source_name` names it in error messages.
    pub fn parse(text: &str, source_name: &str) -> Result<Self, StructureError> {
        Self::parse_with_constants(text, source_name, &BTreeMap::new())
    }

    /// Parse a structure with some of its `[constants]` replaced — the same structure for
    /// another aircraft (its hub height, say). Overriding a constant the file does not
    /// declare is an error, so a misspelt name cannot pass unnoticed.
    pub fn parse_with_constants(
        text: &str,
        source_name: &str,
        overrides: &BTreeMap<String, f64>,
    ) -> Result<Self, StructureError> {
        let context = Context { text, source_name };
        let raw: RawStructure = toml::from_str(text).map_err(|error| StructureError {
            source_name: source_name.to_string(),
            line: error.span().map(|span| line_of(text, span.start)),
            problem: StructureProblem::Syntax(explain_syntax(error.message())),
        })?;
        Self::from_raw(raw, &context, overrides)
    }

    /// Read and parse a structure file.
    pub fn from_path(path: &Path) -> Result<Self, StructureError> {
        Self::from_path_with_constants(path, &BTreeMap::new())
    }

    /// Read and parse a structure file with some of its `[constants]` replaced (see
    /// [`Self::parse_with_constants`]).
    pub fn from_path_with_constants(
        path: &Path,
        overrides: &BTreeMap<String, f64>,
    ) -> Result<Self, StructureError> {
        let source_name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|error| StructureError {
            source_name: source_name.clone(),
            line: None,
            problem: StructureProblem::Io(error.to_string()),
        })?;
        Self::parse_with_constants(&text, &source_name, overrides)
    }

    fn from_raw(
        raw: RawStructure,
        context: &Context<'_>,
        overrides: &BTreeMap<String, f64>,
    ) -> Result<Self, StructureError> {
        let states = context.names(&raw.states, "state")?;
        let controls = context.names(&raw.controls, "control")?;
        let outputs = context.names(&raw.outputs, "output")?;

        let constants = file_constants(&raw, context, overrides)?;
        if states.is_empty() || controls.is_empty() || outputs.is_empty() {
            return Err(context.error(
                raw.name.span(),
                StructureProblem::Syntax("states, controls and outputs must not be empty".into()),
            ));
        }

        // Parameters, in file order.
        let mut raw_parameters: Vec<_> = raw.parameters.into_iter().collect();
        raw_parameters.sort_by_key(|(key, _)| key.span().start);
        let mut parameters = Vec::new();
        let mut base_index = HashMap::new();
        let mut derived_forms = HashMap::new();
        let mut derived_order = Vec::new();
        for (key, value) in &raw_parameters {
            let name = key.get_ref().clone();
            let line = context.line(key.span());
            let bad = |reason: &str| {
                context.error(
                    key.span(),
                    StructureProblem::BadParameter {
                        name: name.clone(),
                        reason: reason.to_string(),
                    },
                )
            };
            let not_finite = |what: String, number: f64| {
                context.error(
                    key.span(),
                    StructureProblem::NotFinite {
                        what,
                        value: number,
                    },
                )
            };
            match value.get_ref() {
                RawParameter::Start(start) => {
                    if !start.is_finite() {
                        return Err(not_finite(format!("parameter `{name}`"), *start));
                    }
                    base_index.insert(name.clone(), parameters.len());
                    parameters.push(Parameter {
                        name,
                        value: *start,
                        kind: ParameterKind::Free,
                        lower: None,
                        upper: None,
                        line,
                    });
                }
                RawParameter::Table(table) => {
                    let given = usize::from(table.start.is_some())
                        + usize::from(table.fixed.is_some())
                        + usize::from(table.expr.is_some());
                    if given != 1 {
                        return Err(bad("give exactly one of `start`, `fixed`, `expr`"));
                    }
                    for (label, number) in [
                        ("", table.start),
                        ("", table.fixed),
                        (": min", table.min),
                        (": max", table.max),
                    ] {
                        if let Some(number) = number.filter(|n| !n.is_finite()) {
                            return Err(not_finite(format!("parameter `{name}`{label}"), number));
                        }
                    }
                    if let (Some(lo), Some(hi)) = (table.min, table.max) {
                        if lo >= hi {
                            return Err(bad("`min` must be below `max`"));
                        }
                    }
                    if let Some(expression) = &table.expr {
                        if table.min.is_some() || table.max.is_some() {
                            return Err(bad("a constrained parameter cannot have bounds"));
                        }
                        let form = parse_linear_with_constants(expression, &constants).map_err(
                            |reason| {
                                context.error(
                                    value.span(),
                                    StructureProblem::BadExpression {
                                        expression: expression.clone(),
                                        reason,
                                    },
                                )
                            },
                        )?;
                        derived_forms.insert(name.clone(), form);
                        derived_order.push((name, line, value.span()));
                    } else {
                        let (value, kind) = match (table.start, table.fixed) {
                            (Some(start), None) => (start, ParameterKind::Free),
                            (None, Some(fixed)) => (fixed, ParameterKind::Fixed),
                            _ => unreachable!("exactly one of start/fixed was checked above"),
                        };
                        if table.min.is_some_and(|lo| value < lo)
                            || table.max.is_some_and(|hi| value > hi)
                        {
                            return Err(bad("the value lies outside [min, max]"));
                        }
                        base_index.insert(name.clone(), parameters.len());
                        parameters.push(Parameter {
                            name,
                            value,
                            kind,
                            lower: table.min,
                            upper: table.max,
                            line,
                        });
                    }
                }
            }
        }

        let resolver = Resolver {
            base: &base_index,
            derived_forms: &derived_forms,
        };
        let mut derived = Vec::new();
        for (name, line, span) in derived_order {
            let mut visiting = vec![name.clone()];
            let expression = resolver
                .resolve(&derived_forms[&name], &mut visiting)
                .map_err(|problem| context.error(span.clone(), problem))?;
            derived.push(DerivedParameter {
                name,
                expression,
                line,
            });
        }

        // Parameter names the matrix entries and delays refer to (constrained ones too).
        let mut referenced: BTreeSet<String> = BTreeSet::new();
        let mut resolve_value = |value: &Spanned<RawValue>,
                                 what: &dyn Fn() -> String|
         -> Result<ParameterExpression, StructureError> {
            match value.get_ref() {
                RawValue::Number(number) if !number.is_finite() => Err(context.error(
                    value.span(),
                    StructureProblem::NotFinite {
                        what: what(),
                        value: *number,
                    },
                )),
                RawValue::Number(number) => Ok(ParameterExpression {
                    constant: *number,
                    terms: Vec::new(),
                }),
                RawValue::Expression(text) => {
                    let form = parse_linear_with_constants(text, &constants).map_err(|reason| {
                        context.error(
                            value.span(),
                            StructureProblem::BadExpression {
                                expression: text.clone(),
                                reason,
                            },
                        )
                    })?;
                    referenced.extend(form.terms.keys().cloned());
                    resolver
                        .resolve(&form, &mut Vec::new())
                        .map_err(|problem| context.error(value.span(), problem))
                }
            }
        };

        // Matrix entries.
        let mut entries = Vec::new();
        let matrices: [(MatrixName, &RawRows); 5] = [
            (MatrixName::M, &raw.m),
            (MatrixName::F, &raw.f),
            (MatrixName::G, &raw.g),
            (MatrixName::H0, &raw.h0),
            (MatrixName::H1, &raw.h1),
        ];
        let mut rows_with_measurement = vec![false; outputs.len()];
        for (matrix, rows) in matrices {
            let (row_names, row_kind, column_names, column_kind) = match matrix {
                MatrixName::M | MatrixName::F => (&states, "state", &states, "state"),
                MatrixName::G => (&states, "state", &controls, "control"),
                MatrixName::H0 | MatrixName::H1 => (&outputs, "output", &states, "state"),
            };
            for (row_key, columns) in rows {
                let row = context.index_of(row_names, row_key, row_kind)?;
                if matches!(matrix, MatrixName::H0 | MatrixName::H1) {
                    rows_with_measurement[row] = true;
                }
                for (column_key, value) in columns {
                    let column = context.index_of(column_names, column_key, column_kind)?;
                    let what = || {
                        format!(
                            "entry {}[{}, {}]",
                            matrix.as_str(),
                            row_key.get_ref(),
                            column_key.get_ref()
                        )
                    };
                    entries.push(MatrixEntry {
                        matrix,
                        row,
                        column,
                        expression: resolve_value(value, &what)?,
                        line: context.line(column_key.span()),
                    });
                }
            }
        }
        entries.sort_by_key(|entry| entry.line);

        // Outputs that are states and have no measurement row measure that state.
        let default_output_states = outputs
            .iter()
            .enumerate()
            .filter(|&(index, _)| !rows_with_measurement[index])
            .filter_map(|(index, name)| {
                states
                    .iter()
                    .position(|state| state == name)
                    .map(|state| (index, state))
            })
            .collect();

        let mut delays = vec![ParameterExpression::default(); controls.len()];
        for (key, value) in &raw.delays {
            let control = context.index_of(&controls, key, "control")?;
            delays[control] = resolve_value(value, &|| format!("delay of `{}`", key.get_ref()))?;
        }
        check_every_parameter_is_used(
            context,
            &raw_parameters,
            &base_index,
            &derived_forms,
            referenced,
            entries.iter().map(|entry| &entry.expression).chain(&delays),
        )?;

        let auto_range_limit = match &raw.auto_range_limit {
            None => None,
            Some(band) => Some(check_band(band.get_ref()).map_err(|reason| {
                context.error(band.span(), StructureProblem::BadRange(reason))
            })?),
        };

        let mut pairs: Vec<PairSpec> = Vec::new();
        for pair in &raw.pairs {
            let pair_ref = pair.get_ref();
            let input_index = context.index_of(&controls, &pair_ref.input, "control")?;
            let output_index = context.index_of(&outputs, &pair_ref.output, "output")?;
            let line = context.line(pair.span());
            let range = match &pair_ref.range {
                None => PairRange::Auto,
                Some(range) => match range.get_ref() {
                    RawRange::Keyword(keyword) if keyword == "auto" => PairRange::Auto,
                    RawRange::Keyword(keyword) => {
                        return Err(context.error(
                            range.span(),
                            StructureProblem::BadRange(format!(
                                "`{keyword}`: expected \"auto\" or [lo, hi]"
                            )),
                        ))
                    }
                    RawRange::Band(band) => {
                        PairRange::Explicit(check_band(band).map_err(|reason| {
                            context.error(range.span(), StructureProblem::BadRange(reason))
                        })?)
                    }
                },
            };
            if pairs
                .iter()
                .any(|p| p.input_index == input_index && p.output_index == output_index)
            {
                return Err(context.error(
                    pair.span(),
                    StructureProblem::DuplicateName(format!(
                        "pair {}/{}",
                        pair_ref.output.get_ref(),
                        pair_ref.input.get_ref()
                    )),
                ));
            }
            pairs.push(PairSpec {
                input: controls[input_index].clone(),
                output: outputs[output_index].clone(),
                input_index,
                output_index,
                range,
                line,
            });
        }

        let mut trim_derived: Vec<String> = Vec::new();
        for name in &raw.trim_derived {
            let problem = if trim_derived.contains(name.get_ref()) {
                Some("listed twice in `trim_derived`")
            } else if base_index.contains_key(name.get_ref()) {
                None
            } else if derived_forms.contains_key(name.get_ref()) {
                Some("constrained (`expr`): only a free or fixed parameter can be derived from trim points")
            } else {
                Some("not a parameter of `[parameters]`")
            };
            if let Some(reason) = problem {
                return Err(context.error(
                    name.span(),
                    StructureProblem::BadParameter {
                        name: name.get_ref().clone(),
                        reason: reason.to_string(),
                    },
                ));
            }
            trim_derived.push(name.get_ref().clone());
        }

        Ok(Self {
            name: raw.name.into_inner(),
            description: raw.description,
            states,
            controls,
            outputs,
            parameters,
            derived,
            entries,
            delays,
            pairs,
            auto_range_limit,
            default_output_states,
            source_name: context.source_name.to_string(),
            constants,
            trim_derived,
        })
    }

    /// Parse a structure from TOML text named `<string>` in errors (see [`Self::parse`]).
    pub fn parse_str(text: &str) -> Result<Self, StructureError> {
        Self::parse(text, "<string>")
    }

    /// Index of a base (free or fixed) parameter.
    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p.name == name)
    }

    /// Current base-parameter values (the start values of a fresh structure).
    pub fn values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// Indices of the free parameters, in order.
    pub fn free_indices(&self) -> Vec<usize> {
        (0..self.parameters.len())
            .filter(|&i| self.parameters[i].kind == ParameterKind::Free)
            .collect()
    }

    /// Value of any parameter (base or constrained) by name.
    pub fn parameter_value(&self, name: &str, values: &[f64]) -> Option<f64> {
        if let Some(index) = self.parameter_index(name) {
            return values.get(index).copied();
        }
        self.derived
            .iter()
            .find(|d| d.name == name)
            .map(|d| d.expression.evaluate(values))
    }

    /// The numeric model for a vector of base-parameter values.
    pub fn model(&self, values: &[f64]) -> Result<Model, FitError> {
        if values.len() != self.parameters.len() {
            return Err(FitError::ParameterCount {
                expected: self.parameters.len(),
                got: values.len(),
            });
        }
        let n = self.states.len();
        let mut model = Model::zeros(
            self.states.clone(),
            self.controls.clone(),
            self.outputs.clone(),
        );
        for i in 0..n {
            model.m[(i, i)] = 1.0;
        }
        for &(output, state) in &self.default_output_states {
            model.h0[(output, state)] = 1.0;
        }
        for entry in &self.entries {
            let value = entry.expression.evaluate(values);
            let matrix = match entry.matrix {
                MatrixName::M => &mut model.m,
                MatrixName::F => &mut model.f,
                MatrixName::G => &mut model.g,
                MatrixName::H0 => &mut model.h0,
                MatrixName::H1 => &mut model.h1,
            };
            matrix[(entry.row, entry.column)] = value;
        }
        for (control, delay) in self.delays.iter().enumerate() {
            model.delays[control] = delay.evaluate(values);
        }
        Ok(model)
    }

    /// A copy whose base parameters take `values` (as new start / fixed values).
    pub fn with_values(&self, values: &[f64]) -> Result<Self, FitError> {
        if values.len() != self.parameters.len() {
            return Err(FitError::ParameterCount {
                expected: self.parameters.len(),
                got: values.len(),
            });
        }
        let mut copy = self.clone();
        for (parameter, &value) in copy.parameters.iter_mut().zip(values) {
            parameter.value = value;
        }
        Ok(copy)
    }
}

/// Refuse parameters that no matrix entry or delay uses: a free one would leave the
/// Hessian singular (every Cramér–Rao bound infinite, and no way to tell which parameter
/// is to blame), a fixed or constrained one says something the model does not. A base
/// parameter is used when some entry or delay depends on it with a non-zero coefficient
/// (through constrained parameters too); a constrained one when an entry, a delay or a
/// used constrained parameter names it. The error names them all, at the first one's line.
fn check_every_parameter_is_used<'e>(
    context: &Context<'_>,
    declared: &[(Spanned<String>, Spanned<RawParameter>)],
    base_index: &HashMap<String, usize>,
    derived_forms: &HashMap<String, LinearForm>,
    mut referenced: BTreeSet<String>,
    expressions: impl Iterator<Item = &'e ParameterExpression>,
) -> Result<(), StructureError> {
    let mut used_base = vec![false; base_index.len()];
    for expression in expressions {
        for &(index, _) in &expression.terms {
            if let Some(slot) = used_base.get_mut(index) {
                *slot = true;
            }
        }
    }
    // Constrained parameters named by used constrained parameters are used too.
    let mut pending: Vec<String> = referenced.iter().cloned().collect();
    while let Some(name) = pending.pop() {
        if let Some(form) = derived_forms.get(&name) {
            for inner in form.terms.keys() {
                if referenced.insert(inner.clone()) {
                    pending.push(inner.clone());
                }
            }
        }
    }
    let unused: Vec<&Spanned<String>> = declared
        .iter()
        .map(|(key, _)| key)
        .filter(|key| {
            let name = key.get_ref();
            match base_index.get(name) {
                Some(&index) => !used_base.get(index).copied().unwrap_or(false),
                None => !referenced.contains(name),
            }
        })
        .collect();
    match unused.first() {
        None => Ok(()),
        Some(first) => Err(context.error(
            first.span(),
            StructureProblem::UnusedParameters(
                unused.iter().map(|key| key.get_ref().clone()).collect(),
            ),
        )),
    }
}

/// serde's messages for the untagged enums name internal types; say what is expected.
fn explain_syntax(message: &str) -> String {
    let expected = if message.contains("RawParameter") {
        "a parameter is a number (free, its start value) or a table with one of \
         `start`, `fixed`, `expr` (and optional `min`, `max`, `description`)"
    } else if message.contains("RawValue") {
        "a matrix entry or delay is a number or a string expression such as \"-tau_f\""
    } else if message.contains("RawRange") {
        "a range is \"auto\" or [lo, hi] in rad/s"
    } else {
        return message.trim_end().to_string();
    };
    expected.to_string()
}

impl std::str::FromStr for ModelStructure {
    type Err = StructureError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Self::parse_str(text)
    }
}

fn check_band(band: &[f64]) -> Result<[f64; 2], String> {
    match band {
        [lo, hi] if lo.is_finite() && hi.is_finite() && *lo > 0.0 && lo < hi => Ok([*lo, *hi]),
        [_, _] => Err("need 0 < lo < hi".into()),
        _ => Err(format!("need two numbers [lo, hi], got {}", band.len())),
    }
}

/// The file's `[constants]` with the caller's overrides applied. A constant must be a finite
/// number and must not share a parameter's name; an override must name a declared constant.
fn file_constants(
    raw: &RawStructure,
    context: &Context<'_>,
    overrides: &BTreeMap<String, f64>,
) -> Result<BTreeMap<String, f64>, StructureError> {
    let mut constants = BTreeMap::new();
    for (key, value) in &raw.constants {
        let name = key.get_ref().clone();
        if !value.get_ref().is_finite() {
            return Err(context.error(
                value.span(),
                StructureProblem::BadParameter {
                    name,
                    reason: "a constant must be a finite number".to_string(),
                },
            ));
        }
        if raw.parameters.keys().any(|p| p.get_ref() == &name) {
            return Err(context.error(key.span(), StructureProblem::DuplicateName(name)));
        }
        constants.insert(name, *value.get_ref());
    }
    for (name, &value) in overrides {
        match constants.get_mut(name) {
            Some(slot) if value.is_finite() => *slot = value,
            Some(_) => {
                return Err(StructureError {
                    source_name: context.source_name.to_string(),
                    line: None,
                    problem: StructureProblem::BadParameter {
                        name: name.clone(),
                        reason: "a constant must be a finite number".to_string(),
                    },
                })
            }
            None => {
                return Err(StructureError {
                    source_name: context.source_name.to_string(),
                    line: None,
                    problem: StructureProblem::UnknownName {
                        kind: "constant",
                        name: name.clone(),
                    },
                })
            }
        }
    }
    Ok(constants)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = r#"
name = "first-order"
states = ["x"]
controls = ["u"]
outputs = ["x", "y"]

[parameters]
a = { start = -2.0, max = 0.0 }
b = 3.0
c = { fixed = 0.5 }
d = { expr = "-2*b + 1" }
tau = { start = 0.01, min = 0.0 }

[F.x]
x = "a"

[G.x]
u = "b"

[H0.y]
x = "c"

[H1.y]
x = "d"

[delays]
u = "tau"

[[pairs]]
output = "x"
input = "u"
range = [0.1, 10.0]

[[pairs]]
output = "y"
input = "u"
"#;

    fn error_of(text: &str) -> StructureError {
        ModelStructure::parse(text, "test.toml").unwrap_err()
    }

    #[test]
    fn parses_a_small_structure() {
        let structure = ModelStructure::parse(SMALL, "small.toml").unwrap();
        assert_eq!(structure.parameters.len(), 4);
        assert_eq!(structure.free_indices().len(), 3);
        assert_eq!(structure.derived.len(), 1);
        assert_eq!(structure.pairs.len(), 2);
        assert_eq!(structure.pairs[0].range, PairRange::Explicit([0.1, 10.0]));
        assert_eq!(structure.pairs[1].range, PairRange::Auto);
        assert_eq!(structure.pairs[1].line, 34);
        let model = structure.model(&structure.values()).unwrap();
        assert_eq!(model.f[(0, 0)], -2.0);
        assert_eq!(model.g[(0, 0)], 3.0);
        // Output x measures the state by default, output y through H0/H1.
        assert_eq!(model.h0[(0, 0)], 1.0);
        assert_eq!(model.h0[(1, 0)], 0.5);
        assert_eq!(model.h1[(1, 0)], -5.0);
        assert_eq!(model.delays[0], 0.01);
        assert_eq!(
            structure.parameter_value("d", &structure.values()),
            Some(-5.0)
        );
    }

    #[test]
    fn constants_enter_expressions_and_can_be_overridden() {
        let text = SMALL
            .replace("[parameters]", "[constants]\narm = 2.0\n\n[parameters]")
            .replace("[F.x]\nx = \"a\"", "[F.x]\nx = \"a - arm*b\"");
        let structure = ModelStructure::parse(&text, "arm.toml").unwrap();
        assert_eq!(structure.constants["arm"], 2.0);
        // F = a − arm·b = −2 − 2·3.
        let model = structure.model(&structure.values()).unwrap();
        assert_eq!(model.f[(0, 0)], -8.0);
        // A constant is no parameter: nothing to fit.
        assert!(structure.parameter_index("arm").is_none());

        let overrides = BTreeMap::from([("arm".to_string(), 0.5)]);
        let other = ModelStructure::parse_with_constants(&text, "arm.toml", &overrides).unwrap();
        assert_eq!(other.constants["arm"], 0.5);
        assert_eq!(other.model(&other.values()).unwrap().f[(0, 0)], -3.5);

        let misspelt = BTreeMap::from([("amr".to_string(), 0.5)]);
        let error = ModelStructure::parse_with_constants(&text, "arm.toml", &misspelt).unwrap_err();
        assert!(
            error.to_string().contains("unknown constant `amr`"),
            "{error}"
        );

        let clash = text.replace("arm = 2.0", "arm = 2.0\nb = 1.0");
        let error = ModelStructure::parse(&clash, "clash.toml").unwrap_err();
        assert!(
            error.to_string().contains("`b` is declared twice"),
            "{error}"
        );
    }

    #[test]
    fn from_str_parses_and_names_the_source() {
        let structure: ModelStructure = SMALL.parse().unwrap();
        assert_eq!(structure.source_name, "<string>");
        let error = "name = ".parse::<ModelStructure>().unwrap_err();
        assert!(error.to_string().starts_with("<string>, line 1"), "{error}");
    }

    #[test]
    fn syntax_error_names_the_line() {
        let text = SMALL.replace("b = 3.0", "b = = 3.0");
        let error = error_of(&text);
        assert_eq!(error.line, Some(9), "{error}");
        assert!(matches!(error.problem, StructureProblem::Syntax(_)));
        assert!(error.to_string().contains("test.toml, line 9"), "{error}");
    }

    #[test]
    fn wrong_value_types_are_explained() {
        let error = error_of(&SMALL.replace("b = 3.0", "b = \"Zq\""));
        assert_eq!(error.line, Some(9));
        assert!(
            error.to_string().contains("a parameter is a number"),
            "{error}"
        );
        let error = error_of(&SMALL.replace("x = \"a\"", "x = [1]"));
        assert_eq!(error.line, Some(15));
        assert!(error.to_string().contains("string expression"), "{error}");
    }

    #[test]
    fn unknown_state_names_the_line() {
        let text = SMALL.replace("[G.x]\nu = \"b\"", "[G.x]\nu = \"b\"\n[G.z]\nu = 1.0");
        let error = error_of(&text);
        assert_eq!(error.line, Some(19), "{error}");
        assert_eq!(
            error.problem,
            StructureProblem::UnknownName {
                kind: "state",
                name: "z".into()
            }
        );
        let text = SMALL.replace("[F.x]\nx = \"a\"", "[F.x]\nx = \"a\"\nqq = 2.0");
        let error = error_of(&text);
        assert_eq!(error.line, Some(16), "{error}");
    }

    #[test]
    fn undefined_parameter_names_the_line() {
        let text = SMALL.replace("x = \"c\"", "x = \"c + Zq\"");
        let error = error_of(&text);
        assert_eq!(error.line, Some(21), "{error}");
        assert_eq!(
            error.problem,
            StructureProblem::UndefinedParameter("Zq".into())
        );
        assert!(error.to_string().contains("undefined parameter `Zq`"));
    }

    #[test]
    fn non_finite_numbers_are_refused_naming_the_parameter_and_line() {
        for (from, to, line, message) in [
            (
                "b = 3.0",
                "b = nan",
                9,
                "parameter `b` = NaN is not a finite number",
            ),
            (
                "b = 3.0",
                "b = -inf",
                9,
                "parameter `b` = -inf is not a finite number",
            ),
            (
                "a = { start = -2.0, max = 0.0 }",
                "a = { start = inf, max = 0.0 }",
                8,
                "parameter `a` = inf is not a finite number",
            ),
            (
                "c = { fixed = 0.5 }",
                "c = { fixed = nan }",
                10,
                "parameter `c` = NaN is not a finite number",
            ),
            (
                "tau = { start = 0.01, min = 0.0 }",
                "tau = { start = 0.01, min = nan }",
                12,
                "parameter `tau`: min = NaN is not a finite number",
            ),
            (
                "a = { start = -2.0, max = 0.0 }",
                "a = { start = -2.0, max = inf }",
                8,
                "parameter `a`: max = inf is not a finite number",
            ),
            (
                "[F.x]\nx = \"a\"",
                "[F.x]\nx = nan",
                15,
                "entry F[x, x] = NaN is not a finite number",
            ),
            (
                "u = \"tau\"",
                "u = inf",
                27,
                "delay of `u` = inf is not a finite number",
            ),
        ] {
            let text = SMALL.replace(from, to);
            assert_ne!(text, SMALL, "{from}");
            let error = error_of(&text);
            assert_eq!(error.line, Some(line), "{error}");
            assert_eq!(
                error.to_string(),
                format!("test.toml, line {line}: {message}")
            );
        }
    }

    #[test]
    fn bounds_must_be_ordered_and_hold_the_start() {
        for (from, to, reason) in [
            (
                "a = { start = -2.0, max = 0.0 }",
                "a = { start = -2.0, min = 0.0, max = -3.0 }",
                "`min` must be below `max`",
            ),
            (
                "a = { start = -2.0, max = 0.0 }",
                "a = { start = -2.0, min = 1.0, max = 1.0 }",
                "`min` must be below `max`",
            ),
            (
                "a = { start = -2.0, max = 0.0 }",
                "a = { start = 1.0, max = 0.0 }",
                "outside [min, max]",
            ),
            (
                "c = { fixed = 0.5 }",
                "c = { fixed = 0.5, min = 1.0 }",
                "outside [min, max]",
            ),
            (
                "d = { expr = \"-2*b + 1\" }",
                "d = { expr = \"-2*b + 1\", max = 1.0 }",
                "cannot have bounds",
            ),
        ] {
            let error = error_of(&SMALL.replace(from, to));
            assert!(
                matches!(error.problem, StructureProblem::BadParameter { .. }),
                "{error}"
            );
            assert!(error.to_string().contains(reason), "{error}");
        }
    }

    #[test]
    fn a_parameter_no_entry_uses_is_refused_naming_it() {
        let tau = "tau = { start = 0.01, min = 0.0 }";
        let error = error_of(&SMALL.replace(tau, &format!("{tau}\nFoo = 1.0")));
        assert_eq!(error.line, Some(13), "{error}");
        assert_eq!(
            error.to_string(),
            "test.toml, line 13: parameter `Foo` is declared but used in no matrix entry or delay"
        );
        // Fixed and constrained ones too, all named at once; a base parameter that only an
        // unused constrained one names is unused.
        let text = SMALL.replace(
            tau,
            &format!("{tau}\ne = {{ fixed = 1.0 }}\nf = {{ expr = \"2*e\" }}"),
        );
        let error = error_of(&text);
        assert_eq!(error.line, Some(13), "{error}");
        assert_eq!(
            error.problem,
            StructureProblem::UnusedParameters(vec!["e".into(), "f".into()])
        );
        assert!(
            error
                .to_string()
                .contains("parameters `e`, `f` are declared"),
            "{error}"
        );
        // A parameter whose coefficients cancel has no effect: unused.
        let text = SMALL
            .replace("[F.x]\nx = \"a\"", "[F.x]\nx = \"a + c - c\"")
            .replace("[H0.y]\nx = \"c\"", "[H0.y]\nx = 0.5");
        let error = error_of(&text);
        assert_eq!(
            error.problem,
            StructureProblem::UnusedParameters(vec!["c".into()])
        );
        assert_eq!(error.line, Some(10));
        // Used through a constrained parameter (and a delay) is used.
        let text = SMALL
            .replace(tau, &format!("{tau}\ng = {{ expr = \"a\" }}"))
            .replace("\"-2*b + 1\"", "\"g - 2*b + 1\"");
        ModelStructure::parse(&text, "chain.toml").unwrap();
    }

    #[test]
    fn other_semantic_errors_name_the_line() {
        let error = error_of(&SMALL.replace("\"-2*b + 1\"", "\"b * a\""));
        assert_eq!(error.line, Some(11));
        assert!(matches!(
            error.problem,
            StructureProblem::BadExpression { .. }
        ));

        let cyclic = SMALL
            .replace("c = { fixed = 0.5 }", "c = { expr = \"d\" }")
            .replace("\"-2*b + 1\"", "\"2*c\"");
        let error = error_of(&cyclic);
        assert!(
            matches!(error.problem, StructureProblem::CyclicConstraint(_)),
            "{error}"
        );
        assert_eq!(error.line, Some(10));

        let error = error_of(&SMALL.replace("range = [0.1, 10.0]", "range = [10.0, 0.1]"));
        assert_eq!(error.line, Some(32));
        assert!(matches!(error.problem, StructureProblem::BadRange(_)));

        let error = error_of(&SMALL.replace(
            "output = \"y\"\ninput = \"u\"",
            "output = \"y\"\ninput = \"v\"",
        ));
        assert_eq!(error.line, Some(36), "{error}");
        assert!(matches!(
            error.problem,
            StructureProblem::UnknownName {
                kind: "control",
                ..
            }
        ));

        let error = error_of(&SMALL.replace("b = 3.0", "b = { start = 3.0, fixed = 1.0 }"));
        assert_eq!(error.line, Some(9));
        assert!(matches!(
            error.problem,
            StructureProblem::BadParameter { .. }
        ));

        let error =
            error_of(&SMALL.replace("outputs = [\"x\", \"y\"]", "outputs = [\"x\", \"x\"]"));
        assert_eq!(error.line, Some(5));
        assert_eq!(error.problem, StructureProblem::DuplicateName("x".into()));

        let error =
            error_of(&SMALL.replace("[[pairs]]\noutput = \"y\"", "[[pairs]]\noutput = \"x\""));
        assert!(matches!(error.problem, StructureProblem::DuplicateName(_)));
        assert_eq!(error.line, Some(34));
    }
}
