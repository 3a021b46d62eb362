//! The TOML form of a structure file as serde reads it. Names and values still carry
//! their spans (`toml::Spanned`); [`Context`] turns a span into the line an error names.

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use crate::fit::error::{StructureError, StructureProblem};

#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum RawValue {
    Number(f64),
    Expression(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawParameterTable {
    pub(super) start: Option<f64>,
    pub(super) fixed: Option<f64>,
    pub(super) expr: Option<String>,
    pub(super) min: Option<f64>,
    pub(super) max: Option<f64>,
    /// A-priori value (a number or a constant's name): the parameter is free, starts
    /// there unless `start` says otherwise, and the cost holds it to `prior ± sigma`.
    pub(super) prior: Option<RawValue>,
    /// The prior's standard uncertainty (a number or a constant's name), > 0.
    pub(super) sigma: Option<RawValue>,
    #[allow(dead_code)]
    pub(super) description: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum RawParameter {
    Start(f64),
    Table(RawParameterTable),
}

#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum RawRange {
    Keyword(String),
    Band(Vec<f64>),
}

/// `[actuators]` entry: `lat = { natural_frequency = 60.0, damping = "servo_damping" }`,
/// numbers, names of `[constants]` or names of base parameters (identified then).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawActuator {
    pub(super) natural_frequency: RawValue,
    pub(super) damping: RawValue,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPair {
    pub(super) output: Spanned<String>,
    pub(super) input: Spanned<String>,
    pub(super) range: Option<Spanned<RawRange>>,
}

pub(super) type RawRows = BTreeMap<Spanned<String>, BTreeMap<Spanned<String>, Spanned<RawValue>>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawStructure {
    pub(super) name: Spanned<String>,
    #[serde(default)]
    pub(super) description: String,
    pub(super) states: Vec<Spanned<String>>,
    pub(super) controls: Vec<Spanned<String>>,
    pub(super) outputs: Vec<Spanned<String>>,
    pub(super) auto_range_limit: Option<Spanned<Vec<f64>>>,
    #[serde(default)]
    pub(super) constants: BTreeMap<Spanned<String>, Spanned<f64>>,
    #[serde(default)]
    pub(super) parameters: BTreeMap<Spanned<String>, Spanned<RawParameter>>,
    #[serde(rename = "M", default)]
    pub(super) m: RawRows,
    #[serde(rename = "F", default)]
    pub(super) f: RawRows,
    #[serde(rename = "G", default)]
    pub(super) g: RawRows,
    #[serde(rename = "H0", default)]
    pub(super) h0: RawRows,
    #[serde(rename = "H1", default)]
    pub(super) h1: RawRows,
    #[serde(default)]
    pub(super) delays: BTreeMap<Spanned<String>, Spanned<RawValue>>,
    #[serde(default)]
    pub(super) actuators: BTreeMap<Spanned<String>, Spanned<RawActuator>>,
    #[serde(default)]
    pub(super) pairs: Vec<Spanned<RawPair>>,
    #[serde(default)]
    pub(super) trim_derived: Vec<Spanned<String>>,
}

/// serde's messages for the untagged enums name internal types; say what is expected.
pub(super) fn explain_syntax(message: &str) -> String {
    let expected = if message.contains("RawParameter") {
        "a parameter is a number (free, its start value) or a table with one of \
         `start`, `fixed`, `expr` (and optional `min`, `max`, `prior` with `sigma`, \
         `description`)"
    } else if message.contains("RawValue") {
        "a matrix entry or delay is a number or a string expression such as \"-tau_f\""
    } else if message.contains("RawActuator") {
        "an actuator is a table { natural_frequency = …, damping = … } of numbers or \
         names of constants or parameters"
    } else if message.contains("RawRange") {
        "a range is \"auto\" or [lo, hi] in rad/s"
    } else {
        return message.trim_end().to_string();
    };
    expected.to_string()
}

/// 1-based line of a byte offset.
pub(super) fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    1 + text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// The text being parsed and its name, to locate errors.
pub(super) struct Context<'a> {
    pub(super) text: &'a str,
    pub(super) source_name: &'a str,
}

impl Context<'_> {
    pub(super) fn line(&self, span: std::ops::Range<usize>) -> usize {
        line_of(self.text, span.start)
    }

    pub(super) fn error(
        &self,
        span: std::ops::Range<usize>,
        problem: StructureProblem,
    ) -> StructureError {
        StructureError {
            source_name: self.source_name.to_string(),
            line: Some(self.line(span)),
            problem,
        }
    }

    pub(super) fn names(
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

    pub(super) fn index_of(
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
