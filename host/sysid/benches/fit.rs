//! Benchmark of the identification chain's fit stage: a quasi-steady 6-DOF fit, then a
//! 9-DOF hybrid fit started from it (paper Eq. 26–27) and from the file's starts, on exact
//! synthetic responses of the hybrid model (reference parameter set = the simulator's
//! mapped truth; the 16 pairs a default campaign fits, 20 points each on the paper's
//! Table 1 ranges). Prints the median wall time of the pair of fits and its ratio to the
//! 5 s target (one core), plus how well the truth is recovered.
//!
//! Run: `cargo bench -p sysid --bench fit`

use std::time::{Duration, Instant};

use sysid::fit::cost::PairBand;
use sysid::fit::synthetic::{
    exact_frf_document, paper_table1_range, SyntheticGrid, BO105_HYBRID_REFERENCE,
    BO105_HYBRID_STRUCTURE, BO105_SIX_DOF_STRUCTURE, CAMPAIGN_FITTED_PAIRS,
};
use sysid::fit::{
    fit, fit_from_alternative_starts, start_from_quasi_steady, FitOptions, FitResult,
    ModelStructure,
};

const TARGET: Duration = Duration::from_secs(5);
const REPEATS: usize = 5;

fn main() {
    let hybrid = ModelStructure::parse(BO105_HYBRID_STRUCTURE, "bo105-9dof-hybrid.toml")
        .expect("shipped hybrid structure parses");
    let six_dof = ModelStructure::parse(BO105_SIX_DOF_STRUCTURE, "bo105-6dof.toml")
        .expect("shipped 6-DOF structure parses");
    let truth: Vec<f64> = hybrid
        .parameters
        .iter()
        .map(|p| {
            BO105_HYBRID_REFERENCE
                .iter()
                .find(|(name, _)| *name == p.name)
                .map(|(_, value)| *value)
                .expect("reference value for every hybrid parameter")
        })
        .collect();
    let truth_model = hybrid.model(&truth).expect("truth model");
    let keep = |structure: &ModelStructure| {
        let mut structure = structure.clone();
        structure.pairs.retain(|pair| {
            CAMPAIGN_FITTED_PAIRS.contains(&(pair.output.as_str(), pair.input.as_str()))
        });
        structure
    };
    let (hybrid, six_dof) = (keep(&hybrid), keep(&six_dof));
    let bands: Vec<PairBand> = hybrid
        .pairs
        .iter()
        .map(|pair| PairBand {
            input: pair.input.clone(),
            output: pair.output.clone(),
            range: paper_table1_range(&pair.output, &pair.input).unwrap_or([0.3, 30.0]),
        })
        .collect();
    let data = exact_frf_document(&truth_model, &bands, SyntheticGrid::FitPoints(20));
    let options = FitOptions::default();

    let run = || -> (FitResult, FitResult, Duration, Duration) {
        let start = Instant::now();
        let six = fit(&six_dof, &data, &options).expect("6-DOF fit");
        let six_time = start.elapsed();
        let (started, _notes) =
            start_from_quasi_steady(&hybrid, &six.to_document()).expect("start values");
        // As `sweephold fit --start-from`: the file's starts are tried too.
        let starts = [
            ("6-DOF".to_string(), started),
            ("file".to_string(), hybrid.clone()),
        ];
        let (nine, _) = fit_from_alternative_starts(&starts, &data, &options).expect("9-DOF fit");
        (six, nine, six_time, start.elapsed())
    };

    let mut totals = Vec::with_capacity(REPEATS);
    let mut six_times = Vec::with_capacity(REPEATS);
    let mut last = None;
    for _ in 0..REPEATS {
        let (six, nine, six_time, total) = run();
        totals.push(total);
        six_times.push(six_time);
        last = Some((six, nine));
    }
    totals.sort();
    six_times.sort();
    let (six, nine) = last.expect("at least one repeat");

    let worst = hybrid
        .free_indices()
        .into_iter()
        .map(|i| {
            let error = (nine.values[i] - truth[i]).abs() / truth[i].abs();
            (error, hybrid.parameters[i].name.clone())
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .expect("free parameters");
    let median = totals[REPEATS / 2];
    println!(
        "6-DOF: {} free, {} pairs, J_ave {:.3}, starts {}, confirmed {}",
        six_dof.free_indices().len(),
        six.pairs.len(),
        six.average_cost,
        six.starts.len(),
        six.minimum_confirmed
    );
    println!(
        "9-DOF: {} free, {} pairs, J_ave {:.3e}, starts {}, confirmed {}, worst parameter \
         error {:.2e} ({})",
        hybrid.free_indices().len(),
        nine.pairs.len(),
        nine.average_cost,
        nine.starts.len(),
        nine.minimum_confirmed,
        worst.0,
        worst.1
    );
    println!(
        "fit 6-DOF + 9-DOF: median {:.3} s over {REPEATS} runs (6-DOF part {:.3} s), \
         target {:.1} s, ratio {:.3}",
        median.as_secs_f64(),
        six_times[REPEATS / 2].as_secs_f64(),
        TARGET.as_secs_f64(),
        median.as_secs_f64() / TARGET.as_secs_f64()
    );
}
