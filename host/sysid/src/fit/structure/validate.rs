//! Checks of a structure file that span several of its tables: the declared constants
//! and the caller's overrides of them, pair bands, and parameters no entry uses.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use toml::Spanned;

use super::limits::{MAX_CONTROLS, MAX_OUTPUTS, MAX_PAIRS, MAX_PARAMETERS, MAX_STATES};
use super::parameter::{ParameterExpression, Prior};
use super::schema::{Context, RawParameter, RawParameterTable, RawStructure, RawValue};
use crate::fit::error::{StructureError, StructureProblem};
use crate::fit::expression::LinearForm;

/// Refuse a structure larger than a fit supports ([`MAX_STATES`] and the others), at the
/// line of the first name beyond the limit, before anything else is checked or built.
pub(super) fn check_sizes(raw: &RawStructure, context: &Context<'_>) -> Result<(), StructureError> {
    let mut parameter_spans: Vec<_> = raw.parameters.keys().map(|key| key.span()).collect();
    parameter_spans.sort_by_key(|span| span.start);
    let pair_spans: Vec<_> = raw.pairs.iter().map(|pair| pair.span()).collect();
    let spans = |list: &[Spanned<String>]| list.iter().map(Spanned::span).collect::<Vec<_>>();
    for (what, spans, limit) in [
        ("states", spans(&raw.states), MAX_STATES),
        ("controls", spans(&raw.controls), MAX_CONTROLS),
        ("outputs", spans(&raw.outputs), MAX_OUTPUTS),
        ("parameters", parameter_spans, MAX_PARAMETERS),
        ("pairs", pair_spans, MAX_PAIRS),
    ] {
        if spans.len() > limit {
            return Err(context.error(
                spans[limit].clone(),
                StructureProblem::TooLarge {
                    what,
                    count: spans.len(),
                    limit,
                },
            ));
        }
    }
    Ok(())
}

/// A `[lo, hi]` band in rad/s: two finite numbers with 0 < lo < hi.
pub(super) fn check_band(band: &[f64]) -> Result<[f64; 2], String> {
    match band {
        [lo, hi] if lo.is_finite() && hi.is_finite() && *lo > 0.0 && lo < hi => Ok([*lo, *hi]),
        [_, _] => Err("need 0 < lo < hi".into()),
        _ => Err(format!("need two numbers [lo, hi], got {}", band.len())),
    }
}

/// The file's `[constants]` with the caller's overrides applied. A constant must be a finite
/// number and must not share a parameter's name; an override must name a declared constant.
pub(super) fn file_constants(
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

/// Refuse parameters that no matrix entry or delay uses: a free one would leave the
/// Hessian singular (every Cramér–Rao bound infinite, and no way to tell which parameter
/// is to blame), a fixed or constrained one says something the model does not. A base
/// parameter is used when some entry or delay depends on it with a non-zero coefficient
/// (through constrained parameters too); a constrained one when an entry, a delay or a
/// used constrained parameter names it. The error names them all, at the first one's line.
pub(super) fn check_every_parameter_is_used<'e>(
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

/// A parameter table's `prior` ± `sigma` (each a number or a constant's name): both or
/// neither, finite, σ > 0.
pub(super) fn parse_prior(
    table: &RawParameterTable,
    constants: &BTreeMap<String, f64>,
) -> Result<Option<Prior>, String> {
    let number = |value: &RawValue, what: &str| match value {
        RawValue::Number(x) => Ok(*x),
        RawValue::Expression(name) => constants.get(name.trim()).copied().ok_or_else(|| {
            format!("{what} `{name}` is neither a number nor a name under [constants]")
        }),
    };
    match (&table.prior, &table.sigma) {
        (None, None) => Ok(None),
        (Some(value), Some(sigma)) => {
            let prior = Prior {
                value: number(value, "prior")?,
                sigma: number(sigma, "sigma")?,
            };
            if !(prior.value.is_finite() && prior.sigma.is_finite() && prior.sigma > 0.0) {
                return Err(format!(
                    "prior {} ± {}: the value must be finite and sigma finite and positive",
                    prior.value, prior.sigma
                ));
            }
            Ok(Some(prior))
        }
        _ => Err("give `prior` and `sigma` together".to_string()),
    }
}
