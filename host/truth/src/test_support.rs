//! Helpers of the crate's tests: the shipped structure files and a response comparison.

use std::path::PathBuf;

use sysid::fit::{Model, ModelStructure};

pub(crate) fn shipped(name: &str) -> ModelStructure {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../sysid/models")
        .join(name);
    ModelStructure::from_path(&path).unwrap()
}

/// Worst magnitude ratio error |(|T_a|/|T_b|) − 1| and worst phase difference [deg]
/// of T_a against T_b over 40 log-spaced frequencies of `band`.
pub(crate) fn worst_errors(
    a: &Model,
    b: &Model,
    output: &str,
    input: &str,
    band: [f64; 2],
) -> (f64, f64) {
    let (ai, ao) = (
        a.control_index(input).unwrap(),
        a.output_index(output).unwrap(),
    );
    let (bi, bo) = (
        b.control_index(input).unwrap(),
        b.output_index(output).unwrap(),
    );
    sysid::fit::cost::log_spaced(band[0], band[1], 40)
        .into_iter()
        .map(|w| {
            let ta = a.frequency_response(ai, ao, w);
            let tb = b.frequency_response(bi, bo, w);
            let phase = sysid::fit::cost::wrap_degrees((ta / tb).arg().to_degrees());
            ((ta.norm() / tb.norm() - 1.0).abs(), phase.abs())
        })
        .fold((0.0, 0.0), |(m, p), (mi, pi)| {
            (f64::max(m, mi), f64::max(p, pi))
        })
}
