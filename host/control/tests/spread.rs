//! The spread of the figures: from the fit's Cramér–Rao bounds, reproducible with its seed,
//! absent (with a note, no panic) when no bound is finite.

use control::analysis::{analyse, AnalysisOptions};
use control::law::BoardLaw;
use sweephold_firmware::app::AppConfig;
use sweephold_firmware::board_stack::StackConfig;
use sweephold_protocol::{Axis, VehicleId};
use sysid::fit::ModelDocument;

fn document(edit: impl FnOnce(&mut serde_json::Value)) -> ModelDocument {
    let path = format!(
        "{}/tests/fixtures/bo105-quick-seed1-model9.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut value);
    serde_json::from_value(value).unwrap()
}

fn law() -> BoardLaw {
    let app = AppConfig::preset(VehicleId::Bo105, Axis::Lat);
    BoardLaw {
        gains: app.pilot,
        tick_s: f64::from(app.flight.dt_s()),
        filters: Some(StackConfig::with_app(app).filters),
        compute_delay_s: 0.0,
        servo_frame_hz: None,
        servos: [None; 3],
    }
}

fn structure() -> sysid::fit::ModelStructure {
    sysid::models::shipped("bo105-9dof-hybrid")
        .unwrap()
        .parse()
        .unwrap()
}

const OPTIONS: AnalysisOptions = AnalysisOptions {
    samples: 30,
    seed: 7,
    grid_points: 600,
    low_rad_s: 0.05,
};

#[test]
fn the_spread_grows_with_the_bounds_and_repeats_with_the_seed() {
    let nominal = document(|_| {});
    let first = analyse(&nominal, Some(&structure()), &law(), None, &OPTIONS).unwrap();
    let again = analyse(&nominal, Some(&structure()), &law(), None, &OPTIONS).unwrap();
    assert_eq!(first, again);
    assert!(first.drawn_parameters > 0);
    let wider = document(|v| {
        for p in v["parameters"].as_array_mut().unwrap() {
            if let Some(cr) = p["cramer_rao_percent"].as_f64() {
                p["cramer_rao_percent"] = (cr * 3.0).into();
            }
        }
    });
    let wide = analyse(&wider, Some(&structure()), &law(), None, &OPTIONS).unwrap();
    let heading = |d: &control::MarginsDocument| d.loops[5].phase_margin_deg.spread.unwrap();
    assert!(
        heading(&wide) > 2.0 * heading(&first),
        "{} vs {}",
        heading(&wide),
        heading(&first)
    );
    // The figures themselves are the identified model's, whatever the bounds.
    assert_eq!(
        wide.loops[5].phase_margin_deg.value,
        first.loops[5].phase_margin_deg.value
    );
}

#[test]
fn without_a_finite_bound_there_is_no_spread_and_a_note() {
    let unbounded = document(|v| {
        for p in v["parameters"].as_array_mut().unwrap() {
            p["cramer_rao_percent"] = serde_json::Value::Null;
        }
    });
    let result = analyse(&unbounded, Some(&structure()), &law(), None, &OPTIONS).unwrap();
    assert!(result
        .loops
        .iter()
        .all(|l| l.phase_margin_deg.spread.is_none()));
    assert!(
        result.notes.iter().any(|n| n.contains("Cramér–Rao")),
        "{:?}",
        result.notes
    );
}

/// The Bo-105 model is fitted to 31.4 rad/s on every control; its heading loop's phase
/// crossover (about 45 rad/s) is read where the model is extrapolated, and says so; its
/// attitude loops' figures lie inside the fitted band.
#[test]
fn figures_beyond_the_fitted_band_are_marked() {
    let options = AnalysisOptions {
        samples: 0,
        ..AnalysisOptions::default()
    };
    let result = analyse(&document(|_| {}), None, &law(), None, &options).unwrap();
    let find = |name: &str| result.loops.iter().find(|l| l.name == name).unwrap();
    let heading = find("heading");
    assert!((heading.fitted_to_rad_s.unwrap() - 31.4).abs() < 1e-3);
    assert!(heading.phase_crossover_rad_s.value.unwrap() > 35.0);
    assert_eq!(heading.extrapolated, vec!["phase_crossover"]);
    let roll = find("roll_attitude");
    assert!(roll.extrapolated.is_empty(), "{:?}", roll.extrapolated);
}

/// Each loop names the costliest fitted pair its actuator drives: a ped pair refitted at
/// J 334 is the heading and yaw-rate loops' worst, above the bound that marks it.
#[test]
fn each_loop_names_its_worst_fitted_pair() {
    let options = AnalysisOptions {
        samples: 0,
        ..AnalysisOptions::default()
    };
    let edited = document(|value| {
        for pair in value["pairs"].as_array_mut().unwrap() {
            if pair["input"] == "ped" && pair["output"] == "r" {
                pair["cost"] = serde_json::json!(334.0);
            }
        }
    });
    let result = analyse(&edited, None, &law(), None, &options).unwrap();
    let find = |name: &str| result.loops.iter().find(|l| l.name == name).unwrap();
    for name in ["heading", "yaw_rate"] {
        let (pair, cost) = find(name).worst_pair.clone().unwrap();
        assert_eq!((pair.as_str(), cost), ("r/ped", 334.0));
        assert!(cost > control::analysis::POOR_PAIR_COST);
    }
    let (pair, cost) = find("roll_attitude").worst_pair.clone().unwrap();
    assert!(
        pair.ends_with("/lat") && cost < control::analysis::POOR_PAIR_COST,
        "{pair} {cost}"
    );
}
