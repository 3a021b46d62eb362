//! Models drawn from the identified model's parameter covariance, for the spread of
//! every figure (Monte-Carlo: first-order propagation would miss the margins' jumps
//! between crossings).
//!
//! The covariance of the free parameters is `Σ = D·R·D`, `D = diag(CR_i)` (the
//! Cramér–Rao bounds of `model.json`, `cramer_rao_percent`·|θ_i|/100) and `R` the file's
//! `correlation` (the identity when the file has none). A draw is `θ = θ̂ + V·√Λ·z`
//! (`Σ = VΛVᵀ`, negative rounding-level eigenvalues set to 0), z standard normal from
//! `sysid::random::SplitMix64` with a fixed seed: the same file gives the same spread.
//! Every matrix entry and delay is affine in the parameters, so the drawn model is the
//! file's matrices plus the structure's change between θ̂ and θ: the file's fixed numbers
//! (trim attitude, geometry) are kept as the fit had them even when the structure is
//! rebuilt with other constants. Free parameters without a finite bound are held.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use sysid::fit::ParameterStatus;
use sysid::fit::{Model, ModelDocument, ModelStructure};
use sysid::random::SplitMix64;

/// Draws models around an identified one.
#[derive(Clone, Debug)]
pub struct ParameterSampler {
    nominal: Model,
    structure: ModelStructure,
    base: Vec<f64>,
    base_model: Model,
    free: Vec<usize>,
    factor: DMatrix<f64>,
}

impl ParameterSampler {
    /// The sampler of `document` fitted with `structure`; one line when they do not
    /// belong together.
    pub fn new(structure: &ModelStructure, document: &ModelDocument) -> Result<Self, String> {
        let nominal = document
            .model()
            .ok_or("model.json: a matrix has the wrong size")?;
        if structure.states != document.states
            || structure.controls != document.controls
            || structure.outputs != document.outputs
        {
            return Err(format!(
                "structure `{}` has other states, controls or outputs than the model",
                structure.name
            ));
        }
        let mut base = Vec::with_capacity(structure.parameters.len());
        let mut free = Vec::new();
        let mut sigma = Vec::new();
        for (index, parameter) in structure.parameters.iter().enumerate() {
            let Some(reported) = document
                .parameters
                .iter()
                .find(|p| p.name == parameter.name)
            else {
                // A model fitted before the structure estimated this parameter under its
                // prior (the TREX's servo ω_n) held it at that prior: held here too.
                match parameter.prior {
                    Some(prior) => {
                        base.push(prior.value);
                        continue;
                    }
                    None => {
                        return Err(format!("model.json has no parameter `{}`", parameter.name))
                    }
                }
            };
            base.push(reported.value);
            let bound = reported
                .cramer_rao_percent
                .map(|percent| percent / 100.0 * reported.value.abs());
            if let (ParameterStatus::Free, Some(bound)) = (reported.status, bound) {
                if bound.is_finite() && bound > 0.0 {
                    free.push(index);
                    sigma.push(bound);
                }
            }
        }
        let names: Vec<&str> = free
            .iter()
            .map(|&i| structure.parameters[i].name.as_str())
            .collect();
        let n = free.len();
        let mut covariance =
            DMatrix::from_diagonal(&DVector::from_vec(sigma.iter().map(|s| s * s).collect()));
        if let Some(correlation) = &document.correlation {
            let position = |name: &str| correlation.names.iter().position(|c| c == name);
            let size = correlation.names.len();
            for a in 0..n {
                for b in 0..n {
                    if a == b {
                        continue;
                    }
                    if let (Some(i), Some(j)) = (position(names[a]), position(names[b])) {
                        let rho = correlation.values.get(i * size + j).copied().unwrap_or(0.0);
                        if rho.is_finite() {
                            covariance[(a, b)] = rho * sigma[a] * sigma[b];
                        }
                    }
                }
            }
        }
        if n == 0 {
            return Err("no free parameter has a finite Cramér–Rao bound".to_string());
        }
        let eigen = SymmetricEigen::new(covariance);
        let roots = eigen.eigenvalues.map(|l| l.max(0.0).sqrt());
        let factor = &eigen.eigenvectors * DMatrix::from_diagonal(&roots);
        let base_model = structure.model(&base).map_err(|e| e.to_string())?;
        Ok(ParameterSampler {
            nominal,
            structure: structure.clone(),
            base,
            base_model,
            free,
            factor,
        })
    }

    /// How many parameters are drawn.
    pub fn free_count(&self) -> usize {
        self.free.len()
    }

    /// The identified model itself.
    pub fn nominal(&self) -> &Model {
        &self.nominal
    }

    /// One drawn model.
    pub fn draw(&self, random: &mut SplitMix64) -> Result<Model, String> {
        let n = self.free.len();
        let mut z = DVector::zeros(n);
        let mut i = 0;
        while i < n {
            let (a, b) = random.normal_pair();
            z[i] = a;
            if i + 1 < n {
                z[i + 1] = b;
            }
            i += 2;
        }
        let step = &self.factor * z;
        let mut values = self.base.clone();
        for (k, &index) in self.free.iter().enumerate() {
            values[index] += step[k];
        }
        let drawn = self.structure.model(&values).map_err(|e| e.to_string())?;
        let mut model = self.nominal.clone();
        model.m += &drawn.m - &self.base_model.m;
        model.f += &drawn.f - &self.base_model.f;
        model.g += &drawn.g - &self.base_model.g;
        model.h0 += &drawn.h0 - &self.base_model.h0;
        model.h1 += &drawn.h1 - &self.base_model.h1;
        for (j, delay) in model.delays.iter_mut().enumerate() {
            *delay = (*delay + drawn.delays[j] - self.base_model.delays[j]).max(0.0);
        }
        Ok(model)
    }
}
