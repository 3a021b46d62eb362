//! The margins of the pilot-mode loops on two identified models against python-control's
//! `stability_margins` on the same loops (tests/fixtures/make_reference.py made
//! python_control_reference.json from `sweephold margins --export-loops`). Tolerances:
//! gain margin 0.05 dB, phase margin 0.2°, frequencies 1 %.

use control::analysis::{self, AnalysisOptions, LOOP_NAMES};
use control::law::BoardLaw;
use control::margins;
use control::Plant;
use serde_json::Value;
use sweephold_firmware::app::AppConfig;
use sweephold_firmware::board_stack::StackConfig;
use sweephold_protocol::{Axis, VehicleId};
use sysid::fit::ModelDocument;

fn law(vehicle: VehicleId) -> BoardLaw {
    let app = AppConfig::preset(vehicle, Axis::Lat);
    BoardLaw {
        gains: app.pilot,
        tick_s: f64::from(app.flight.dt_s()),
        filters: Some(StackConfig::with_app(app).filters),
        compute_delay_s: 0.0,
        servo_frame_hz: None,
        servos: [None; 3],
    }
}

fn fixture(name: &str) -> String {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn close(ours: Option<f64>, reference: &Value, what: &str, tolerance: f64, relative: bool) {
    match (ours, reference.as_f64()) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            let error = if relative {
                (a - b).abs() / b.abs()
            } else {
                (a - b).abs()
            };
            assert!(error <= tolerance, "{what}: ours {a}, python-control {b}");
        }
        (a, b) => panic!("{what}: ours {a:?}, python-control {b:?}"),
    }
}

fn check(model_file: &str, vehicle: VehicleId, key: &str) {
    let document: ModelDocument = serde_json::from_str(&fixture(model_file)).unwrap();
    let reference: Value = serde_json::from_str(&fixture("python_control_reference.json")).unwrap();
    let loops = reference["models"][key].as_array().unwrap();
    let law = law(vehicle);
    let model = document.model().unwrap();
    assert_eq!(analysis::added_servos(&model, None), [None; 3]);
    let grid = analysis::grid(&law, &AnalysisOptions::default());
    let sets = analysis::evaluate(&Plant::new(model).unwrap(), &law, &grid).unwrap();
    for ((name, config, axis), expected) in LOOP_NAMES.iter().zip(loops) {
        assert_eq!(expected["name"], *name);
        let set = &sets[analysis::configuration_index(*config)];
        let ours = margins::margins(&set.broken[*axis]);
        let what = |figure: &str| format!("{key} {name} {figure}");
        close(
            ours.gain_margin_db,
            &expected["gain_margin_db"],
            &what("GM dB"),
            0.05,
            false,
        );
        close(
            ours.phase_margin_deg,
            &expected["phase_margin_deg"],
            &what("PM deg"),
            0.2,
            false,
        );
        close(
            ours.crossover_rad_s,
            &expected["gain_crossover_rad_s"],
            &what("wc"),
            0.01,
            true,
        );
        close(
            ours.phase_crossover_rad_s,
            &expected["phase_crossover_rad_s"],
            &what("w180"),
            0.01,
            true,
        );
        let all = margins::gain_crossovers(&set.broken[*axis]);
        let all_expected = expected["all_gain_crossovers_rad_s"].as_array().unwrap();
        assert_eq!(all.len(), all_expected.len(), "{}", what("crossover count"));
        for ((w, _), reference) in all.iter().zip(all_expected) {
            close(Some(*w), reference, &what("a crossover"), 0.01, true);
        }
        let drb = margins::disturbance_rejection_bandwidth(&set.sensitivity[*axis]);
        close(drb, &expected["drb_rad_s"], &what("DRB"), 0.01, true);
    }
}

#[test]
fn trex700l_loops_match_python_control() {
    check(
        "trex700l-quick-seed1-model9.json",
        VehicleId::Trex700l,
        "trex700l",
    );
}

#[test]
fn bo105_loops_with_two_crossovers_match_python_control() {
    check("bo105-quick-seed1-model9.json", VehicleId::Bo105, "bo105");
}
