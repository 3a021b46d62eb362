//! Reading a structure file: TOML text → [`ModelStructure`], every error with its line.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use toml::Spanned;

use super::matrix::{MatrixEntry, MatrixName};
use super::model_structure::ModelStructure;
use super::pair::{PairRange, PairSpec};
use super::parameter::{DerivedParameter, Parameter, ParameterExpression, ParameterKind};
use super::schema::{
    explain_syntax, line_of, Context, RawActuator, RawParameter, RawRange, RawRows, RawStructure,
    RawValue,
};
use super::validate::{
    check_band, check_every_parameter_is_used, check_sizes, file_constants, parse_prior,
};
use crate::fit::error::{StructureError, StructureProblem};
use crate::fit::expression::{parse_linear_declared, LinearForm, MAX_NESTING};
use crate::fit::model::Actuator;

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
                // One recursion per link of the chain: bounded, like an expression's nesting.
                if visiting.len() > MAX_NESTING {
                    return Err(StructureProblem::ConstraintChainTooLong(name.clone()));
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
        check_sizes(&raw, context)?;
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
        let declared: BTreeSet<String> =
            raw.parameters.keys().map(|k| k.get_ref().clone()).collect();
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
                        prior: None,
                        prior_constant: None,
                    });
                }
                RawParameter::Table(table) => {
                    let given = usize::from(table.start.is_some())
                        + usize::from(table.fixed.is_some())
                        + usize::from(table.expr.is_some());
                    let prior = parse_prior(table, &constants).map_err(|reason| bad(&reason))?;
                    if prior.is_some() && (table.fixed.is_some() || table.expr.is_some()) {
                        return Err(bad(
                            "a parameter with a `prior` is free: `fixed` and `expr` do not go with it",
                        ));
                    }
                    if given != 1 && !(given == 0 && prior.is_some()) {
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
                        let form = parse_linear_declared(expression, &constants, &declared)
                            .map_err(|reason| {
                                context.error(
                                    value.span(),
                                    StructureProblem::BadExpression {
                                        expression: expression.clone(),
                                        reason,
                                    },
                                )
                            })?;
                        derived_forms.insert(name.clone(), form);
                        derived_order.push((name, line, value.span()));
                    } else {
                        let (value, kind) = match (table.start, table.fixed, prior) {
                            (Some(start), None, _) => (start, ParameterKind::Free),
                            (None, Some(fixed), _) => (fixed, ParameterKind::Fixed),
                            // A prior alone: the fit starts from it.
                            (None, None, Some(prior)) => (prior.value, ParameterKind::Free),
                            _ => unreachable!("exactly one of start/fixed/prior was checked above"),
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
                            prior,
                            prior_constant: match &table.prior {
                                Some(RawValue::Expression(name)) => Some(name.trim().to_string()),
                                _ => None,
                            },
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
                    let form =
                        parse_linear_declared(text, &constants, &declared).map_err(|reason| {
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

        // Any other output has nothing that defines it: its response would be 0 at every
        // frequency, and a pair on it would be fitted to nothing.
        if let Some(index) = (0..outputs.len())
            .find(|&index| !rows_with_measurement[index] && !states.contains(&outputs[index]))
        {
            return Err(context.error(
                raw.outputs[index].span(),
                StructureProblem::UndefinedOutput(outputs[index].clone()),
            ));
        }

        let mut delays = vec![ParameterExpression::default(); controls.len()];
        for (key, value) in &raw.delays {
            let control = context.index_of(&controls, key, "control")?;
            delays[control] = resolve_value(value, &|| format!("delay of `{}`", key.get_ref()))?;
        }
        let mut actuators = vec![None; controls.len()];
        let mut actuator_parameters = vec![[None, None]; controls.len()];
        for (key, value) in &raw.actuators {
            let control = context.index_of(&controls, key, "control")?;
            let (actuator, indices) =
                actuator(context, key, value, &constants, &base_index, &parameters)?;
            actuators[control] = Some(actuator);
            actuator_parameters[control] = indices;
        }
        // A parameter an actuator names is used (as a unit term of that actuator).
        let actuator_terms: Vec<ParameterExpression> = actuator_parameters
            .iter()
            .flatten()
            .flatten()
            .map(|&index| ParameterExpression {
                constant: 0.0,
                terms: vec![(index, 1.0)],
            })
            .collect();
        check_every_parameter_is_used(
            context,
            &raw_parameters,
            &base_index,
            &derived_forms,
            referenced,
            entries
                .iter()
                .map(|entry| &entry.expression)
                .chain(&delays)
                .chain(&actuator_terms),
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
            actuators,
            actuator_parameters,
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
}

impl std::str::FromStr for ModelStructure {
    type Err = StructureError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Self::parse_str(text)
    }
}

/// An `[actuators]` entry: each number given as a number, a constant's name or a base
/// parameter's name (then identified: its index is returned, and it needs `min > 0` so
/// that the fit keeps the actuator a stable lag), all finite and positive.
fn actuator(
    context: &Context,
    control: &Spanned<String>,
    raw: &Spanned<RawActuator>,
    constants: &BTreeMap<String, f64>,
    base_index: &HashMap<String, usize>,
    parameters: &[Parameter],
) -> Result<(Actuator, [Option<usize>; 2]), StructureError> {
    let bad = |reason: String| {
        context.error(
            control.span(),
            StructureProblem::BadActuator {
                control: control.get_ref().clone(),
                reason,
            },
        )
    };
    let number = |value: &RawValue, what: &str| match value {
        RawValue::Number(x) => Ok((*x, None)),
        RawValue::Expression(name) => {
            let name = name.trim();
            if let Some(&index) = base_index.get(name) {
                let parameter = &parameters[index];
                if !parameter.lower.is_some_and(|lo| lo > 0.0) {
                    return Err(bad(format!(
                        "{what} `{name}` is a parameter: give it `min` > 0"
                    )));
                }
                return Ok((parameter.value, Some(index)));
            }
            constants.get(name).map(|&x| (x, None)).ok_or_else(|| {
                bad(format!(
                    "{what} `{name}` is neither a number nor a name under [constants] or [parameters]"
                ))
            })
        }
    };
    let (frequency, frequency_index) =
        number(&raw.get_ref().natural_frequency, "natural_frequency")?;
    let (damping, damping_index) = number(&raw.get_ref().damping, "damping")?;
    let actuator = Actuator {
        natural_frequency_rad_s: frequency,
        damping,
    };
    if !actuator.is_valid() {
        return Err(bad(format!(
            "natural_frequency {} rad/s and damping {} must be finite and positive",
            actuator.natural_frequency_rad_s, actuator.damping
        )));
    }
    Ok((actuator, [frequency_index, damping_index]))
}
