//! The `aircraft_constants` field of a campaign's `model9.json`: the a-priori constants the
//! 9-DOF structure took from the aircraft file (hub, shaft, tail, inertia ratios, servo,
//! `Kcs`), each with the σ the file's uncertainties give it (`truth::file_constants`), for
//! a later identification to weigh them by.
//!
//! Written only when the file gives a σ that reaches at least one constant: a model of an
//! aircraft file without uncertainties (the shipped Bo-105 and TREX 700L) stays the bytes
//! it was, and the constants' values are in its structure file and its parameters anyway.

use std::path::Path;

use serde::Serialize;
use truth::FileConstant;

use crate::output::write_json;

/// One constant as `model9.json` lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConstantRecord {
    /// Its name in the structure file.
    pub name: String,
    /// The value the fit held it at.
    pub value: f64,
    /// Its standard uncertainty from the file (absent when none of its inputs has one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma: Option<f64>,
}

/// A model document followed by the aircraft's constants.
#[derive(Serialize)]
struct WithConstants<'a, T: Serialize> {
    #[serde(flatten)]
    model: &'a T,
    aircraft_constants: Vec<ConstantRecord>,
}

/// Write `model` to `path` (atomically), with an `aircraft_constants` field when any of
/// `constants` carries a σ.
pub fn write_model<T: Serialize>(
    path: &Path,
    model: &T,
    constants: &[FileConstant],
) -> anyhow::Result<()> {
    if constants.iter().all(|c| c.sigma.is_none()) {
        return write_json(path, model);
    }
    let aircraft_constants = constants
        .iter()
        .map(|c| ConstantRecord {
            name: c.name.clone(),
            value: c.value,
            sigma: c.sigma,
        })
        .collect();
    write_json(
        path,
        &WithConstants {
            model,
            aircraft_constants,
        },
    )
}
