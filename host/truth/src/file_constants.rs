//! The a-priori constants a structure takes from the aircraft file, each with the σ the
//! file's uncertainties give it: what `model.json` records so that a later stage (an
//! identification from logs) knows how far to trust each fixed number.
//!
//! σ is propagated to first order by central differences: each value of the file that
//! carries a σ is moved by ±σ alone, every constant recomputed through the same code that
//! put it into the structure, and the changes added in quadrature (the file's values taken
//! as independent). No derivative is written by hand, so a constant added to
//! [`crate::vehicle_data`] gets its σ without another formula. A constant none of whose
//! inputs carries a σ has none.

use aircraft::Aircraft;
use rotorsim::Helicopter;
use sysid::fit::structure::ParameterKind;
use sysid::fit::StructureError;
use sysid::models::ShippedStructure;

use crate::vehicle_data::vehicle_constants;

/// One constant a structure took from the aircraft file.
#[derive(Clone, Debug, PartialEq)]
pub struct FileConstant {
    /// Its name in the structure file (`hub_height`, … and `Kcs`, the fixed flap
    /// cross-coupling).
    pub name: String,
    /// The value put into the structure.
    pub value: f64,
    /// Its standard uncertainty from the file's σ, when any of its inputs carries one.
    pub sigma: Option<f64>,
}

/// The constants `shipped` declares that [`crate::with_vehicle_data`] takes from
/// `aircraft` (and `Kcs` when the structure fixes it), in name order, with their σ.
pub fn file_constants(
    shipped: &ShippedStructure,
    aircraft: &Aircraft,
) -> Result<Vec<FileConstant>, StructureError> {
    let structure = shipped.parse()?;
    let fixes_kcs = structure
        .parameter_index("Kcs")
        .is_some_and(|index| structure.parameters[index].kind == ParameterKind::Fixed);
    let constants_of = |aircraft: &Aircraft| -> Vec<(String, f64)> {
        let mut all: Vec<(String, f64)> = vehicle_constants(aircraft)
            .into_iter()
            .filter(|(name, _)| structure.constants.contains_key(name))
            // A prior's σ is not an a-priori constant of its own.
            .filter(|(name, _)| !name.ends_with("_sigma"))
            .collect();
        if fixes_kcs {
            let kcs = Helicopter::from_aircraft(aircraft).flap_cross_coupling();
            all.push(("Kcs".to_string(), kcs));
        }
        all.sort_by(|a, b| a.0.cmp(&b.0));
        all
    };
    let nominal = constants_of(aircraft);
    let mut variance: Vec<Option<f64>> = vec![None; nominal.len()];
    let sigmas: Vec<Option<f64>> = aircraft
        .clone()
        .quantities_mut()
        .iter()
        .map(|q| q.sigma)
        .collect();
    for (k, sigma) in sigmas.into_iter().enumerate() {
        let Some(sigma) = sigma else {
            continue;
        };
        let moved = |step: f64| {
            let mut varied = aircraft.clone();
            varied.quantities_mut()[k].value += step;
            constants_of(&varied)
        };
        let (up, down) = (moved(sigma), moved(-sigma));
        for (slot, ((_, hi), (_, lo))) in variance.iter_mut().zip(up.iter().zip(&down)) {
            let change = (hi - lo) / 2.0;
            if change != 0.0 {
                *slot = Some(slot.unwrap_or(0.0) + change * change);
            }
        }
    }
    Ok(nominal
        .into_iter()
        .zip(variance)
        .map(|((name, value), variance)| FileConstant {
            name,
            value,
            sigma: variance.map(f64::sqrt),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use sysid::models;

    fn constant<'a>(all: &'a [FileConstant], name: &str) -> &'a FileConstant {
        all.iter().find(|c| c.name == name).unwrap()
    }

    #[test]
    fn the_values_are_the_structures_and_a_file_without_sigma_gives_none() {
        let trex = aircraft::shipped("trex700l").unwrap();
        let file = &models::TREX700L_9DOF_HYBRID;
        let all = file_constants(file, &trex).unwrap();
        let structure = crate::nine_dof_hybrid(&trex, None).unwrap();
        assert!(all.len() >= 10, "{all:?}");
        for c in &all {
            assert_eq!(c.sigma, None, "{}", c.name);
            if c.name == "Kcs" {
                let index = structure.parameter_index("Kcs").unwrap();
                assert_eq!(c.value, structure.parameters[index].value);
            } else {
                assert_eq!(c.value, structure.constants[&c.name], "{}", c.name);
            }
        }
    }

    #[test]
    fn sigma_follows_the_files_uncertainties_to_first_order() {
        let fbl = aircraft::shipped("fbl700").unwrap();
        let all = file_constants(&models::TREX700L_9DOF_HYBRID, &fbl).unwrap();
        // A constant that is one of the file's values takes its σ: hub_height = −hub[2],
        // written "-0.27 ± 0.01 m".
        let hub = constant(&all, "hub_height");
        assert_eq!(hub.value, 0.27);
        assert!((hub.sigma.unwrap() - 0.01).abs() < 1e-12, "{hub:?}");
        // A ratio's relative σ is the quadrature sum of its parts': I_zz/I_xx with
        // 0.45 ± 0.045 over 0.15 ± 0.015 (10 % each) gives 14.14 % to first order; the
        // central difference of 1/I_xx over ±σ adds its second order, (σ/I_xx)² = 1 % of
        // that term: 14.21 %.
        let ratio = constant(&all, "izz_over_ixx");
        let relative = ratio.sigma.unwrap() / ratio.value;
        let expected = (0.1f64.powi(2) + (0.1 / 0.99f64).powi(2)).sqrt();
        assert!(
            (relative - expected).abs() < 1e-9,
            "{relative} vs {expected}"
        );
        // The servo's ω_n is written "48 ± 5 rad/s".
        let servo = constant(&all, "servo_natural_frequency");
        assert!((servo.sigma.unwrap() - 5.0).abs() < 1e-12, "{servo:?}");
        // K_cs follows the blades' flap inertia and the hub's stiffness (both with σ).
        let kcs = constant(&all, "Kcs");
        assert!(kcs.sigma.unwrap() > 0.0, "{kcs:?}");
        // Gravity is written without σ: none.
        assert_eq!(constant(&all, "gravity").sigma, None);
    }
}
