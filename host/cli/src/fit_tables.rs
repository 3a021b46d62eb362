//! The console tables `sweephold fit` prints from a fit result and its truth section:
//! the parameters (like the paper's Table 3), J per pair, J against the truth model and
//! the reduction steps. The library returns the data (`sysid::fit`); its text is here.

use std::fmt::Write as _;

use sysid::fit::report::TruthSection;
use sysid::fit::{AccuracyFlag, FitResult, PairFit, ParameterStatus, ReductionStep};

fn percent_cell(value: Option<f64>) -> String {
    match value {
        Some(v) if v.is_finite() => format!("{v:.3}"),
        Some(_) => "inf".into(),
        None => "-".into(),
    }
}

/// The parameter table (like the paper's Table 3): name, value, CR %, insensitivity %,
/// status and flags (`CR>20%`, `I>10%`, `|r|>0.9 with X`).
pub fn parameter_table(result: &FitResult) -> String {
    parameter_rows(result, None)
}

/// [`parameter_table`] with two more columns from a truth scoring: the truth value and the
/// error in % of |truth| (`-` where the truth mapping has no value).
pub fn parameter_table_with_truth(result: &FitResult, truth: &TruthSection) -> String {
    parameter_rows(result, Some(truth))
}

fn parameter_rows(result: &FitResult, truth: Option<&TruthSection>) -> String {
    let mut out = String::new();
    let truth_header = if truth.is_some() {
        format!(" {:>14} {:>10}", "truth", "error %")
    } else {
        String::new()
    };
    let _ = writeln!(
        out,
        "{:<10} {:>14} {:>10} {:>10}{truth_header}  {:<11} flags",
        "parameter", "value", "CR %", "insens. %", "status"
    );
    for p in &result.parameters {
        let status = match p.status {
            ParameterStatus::Free => "free",
            ParameterStatus::Fixed => "fixed",
            ParameterStatus::Trim => "trim",
            ParameterStatus::Constrained => "constrained",
        };
        let flags: Vec<String> = p
            .flags
            .iter()
            .map(|flag| match flag {
                AccuracyFlag::CramerRao => "CR>20%".to_string(),
                AccuracyFlag::Insensitive => "I>10%".to_string(),
                AccuracyFlag::Correlated { with, correlation } => {
                    format!("r={correlation:+.2} with {with}")
                }
                AccuracyFlag::Needed { .. } => "needed".to_string(),
            })
            .collect();
        let truth_cells = match truth {
            Some(section) => {
                let entry = section.parameters.iter().find(|t| t.name == p.name);
                let cell = |v: Option<f64>, precision: usize| {
                    v.map_or_else(|| "-".to_string(), |v| format!("{v:.precision$}"))
                };
                format!(
                    " {:>14} {:>10}",
                    cell(entry.and_then(|t| t.truth), 6),
                    cell(entry.and_then(|t| t.error_percent), 1)
                )
            }
            None => String::new(),
        };
        let _ = writeln!(
            out,
            "{:<10} {:>14.6} {:>10} {:>10}{truth_cells}  {:<11} {}",
            p.name,
            p.value,
            percent_cell(p.cramer_rao_percent),
            percent_cell(p.insensitivity_percent),
            status,
            flags.join(", ")
        );
    }
    out
}

/// The cost table: output/input, range and J per pair, then J_ave.
pub fn cost_table(result: &FitResult) -> String {
    let mut out = String::new();
    write_pair_costs(&mut out, "J", &result.pairs, result.average_cost);
    out
}

/// Rows `output/input  lo-hi  J` under a header naming the cost column, then J_ave.
fn write_pair_costs(out: &mut String, cost_column: &str, pairs: &[PairFit], average: f64) {
    let _ = writeln!(
        out,
        "{:<12} {:>17} {:>10}",
        "pair", "range [rad/s]", cost_column
    );
    for pair in pairs {
        let _ = writeln!(
            out,
            "{:<12} {:>8.3}-{:<8.3} {:>10.3}",
            format!("{}/{}", pair.output, pair.input),
            pair.range[0],
            pair.range[1],
            pair.cost
        );
    }
    let _ = writeln!(out, "{:<12} {:>17} {:>10.3}", "J_ave", "", average);
}

/// The reduction steps, one line each.
pub fn reduction_table(steps: &[ReductionStep]) -> String {
    let mut out = String::new();
    for (number, step) in steps.iter().enumerate() {
        let _ = writeln!(
            out,
            "step {}: drop {} ({}): J_ave {:.3} -> {:.3}  {}",
            number + 1,
            step.dropped,
            step.reason,
            step.average_cost_before,
            step.average_cost_after,
            match step.needed_because() {
                None => "kept out".to_string(),
                Some(reason) => format!("restored: needed ({reason})"),
            }
        );
    }
    out
}

/// The text table of J against the truth model per pair, then J_ave (the parameters
/// with their truth are in [`parameter_table_with_truth`]).
pub fn truth_cost_table(section: &TruthSection) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "J against the truth model ({}):", section.vehicle);
    write_pair_costs(&mut out, "J truth", &section.pairs, section.average_cost);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truth_cost_table_lists_each_pair_then_the_average() {
        let section = TruthSection {
            vehicle: "bo105".into(),
            parameters: Vec::new(),
            pairs: vec![PairFit {
                input: "lat".into(),
                output: "p".into(),
                range: [0.5, 20.0],
                cost: 12.25,
            }],
            average_cost: 12.25,
            unmapped: Vec::new(),
            modes: Vec::new(),
        };
        assert_eq!(
            truth_cost_table(&section),
            "J against the truth model (bo105):\n\
             pair             range [rad/s]    J truth\n\
             p/lat           0.500-20.000       12.250\n\
             J_ave                              12.250\n"
        );
    }
}
