//! Shared test fixtures: small and hybrid structures with known parameters, and exact
//! synthetic data for them.

use super::cost::PairBand;
use super::model::Model;
use super::structure::{ModelStructure, PairRange};
use super::synthetic::{
    exact_frf_document, paper_table1_range, SyntheticGrid, BO105_HYBRID_REFERENCE,
    BO105_HYBRID_STRUCTURE,
};
use crate::document::FrfDocument;

/// First-order lag with delay, 3 free parameters, two pairs (x explicit range, y = ẋ auto).
pub const FIRST_ORDER: &str = r#"
name = "lag"
states = ["x"]
controls = ["u"]
outputs = ["x", "y"]
pairs = [
  { output = "x", input = "u", range = [0.1, 20.0] },
  { output = "y", input = "u" },
]

[parameters]
a = { start = -2.0, max = 0.0 }
b = 3.0
tau = { start = 0.02, min = 0.0 }

[F.x]
x = "a"

[G.x]
u = "b"

[H1.y]
x = 1.0

[delays]
u = "tau"
"#;

pub fn first_order_structure() -> ModelStructure {
    ModelStructure::parse(FIRST_ORDER, "lag.toml").unwrap()
}

pub fn hybrid_structure() -> ModelStructure {
    ModelStructure::parse(BO105_HYBRID_STRUCTURE, "bo105-9dof-hybrid.toml").unwrap()
}

/// Base-parameter values of the hybrid structure from the reference set.
pub fn hybrid_truth_values(structure: &ModelStructure) -> Vec<f64> {
    structure
        .parameters
        .iter()
        .map(|p| {
            BO105_HYBRID_REFERENCE
                .iter()
                .find(|(name, _)| *name == p.name)
                .map(|(_, value)| *value)
                .unwrap()
        })
        .collect()
}

/// Exact data for every pair of `structure`: valid_range is the pair's explicit range,
/// else its Table 1 range, else [0.3, 30]. `n_points = 20` puts the data exactly on the
/// fit frequencies; other counts span 0.1–40 rad/s (the fit then interpolates).
pub fn synthetic_document(
    truth: &Model,
    structure: &ModelStructure,
    n_points: usize,
) -> FrfDocument {
    let bands: Vec<PairBand> = structure
        .pairs
        .iter()
        .map(|pair| PairBand {
            input: pair.input.clone(),
            output: pair.output.clone(),
            range: match pair.range {
                PairRange::Explicit(range) => range,
                PairRange::Auto => {
                    paper_table1_range(&pair.output, &pair.input).unwrap_or([0.3, 30.0])
                }
            },
        })
        .collect();
    let grid = if n_points == 20 {
        SyntheticGrid::FitPoints(20)
    } else {
        SyntheticGrid::Span {
            lo: 0.1,
            hi: 40.0,
            n: n_points,
        }
    };
    exact_frf_document(truth, &bands, grid)
}

/// The pitch toy of the trim-point tests: q̇ = Mu·u + Mlon·lon, u̇ = Xu·u − g·θ, θ̇ = q
/// (Mu 0.05, Mlon 6, Xu −0.02), one pair q/lon; `Mu` listed in `trim_derived` or not.
pub fn pitch_toy(mu_trim_derived: bool) -> ModelStructure {
    let trim_derived = if mu_trim_derived {
        "trim_derived = [\"Mu\"]\n"
    } else {
        ""
    };
    let text = format!(
        r#"
name = "toy"
states = ["u", "q", "theta"]
controls = ["lat", "lon", "ped", "col"]
outputs = ["q"]
{trim_derived}pairs = [{{ output = "q", input = "lon", range = [1.0, 10.0] }}]
[parameters]
Mu = 0.05
Mlon = 6.0
Xu = -0.02
[F.u]
u = "Xu"
theta = -9.81
[F.q]
u = "Mu"
[F.theta]
q = 1.0
[G.q]
lon = "Mlon"
"#
    );
    ModelStructure::parse(&text, "toy.toml").unwrap()
}

/// The shipped structure file `name`, parsed with its own constants.
pub fn shipped(name: &str) -> ModelStructure {
    crate::models::shipped(name)
        .expect("shipped structure")
        .parse()
        .expect("parses")
}

/// The names of the shipped structures.
pub const SHIPPED_NAMES: [&str; 4] = [
    "bo105-6dof",
    "bo105-9dof-hybrid",
    "trex700l-6dof",
    "trex700l-9dof-hybrid",
];

/// `structure`'s start values with the named parameters set to the given values.
pub fn values_with(structure: &ModelStructure, changes: &[(&str, f64)]) -> Vec<f64> {
    let mut values = structure.values();
    for (name, value) in changes {
        values[structure.parameter_index(name).expect("parameter")] = *value;
    }
    values
}
