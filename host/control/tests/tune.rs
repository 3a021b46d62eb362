//! `tune`: the PI of a rate loop against its closed form, and the constraints honoured
//! on the shipped aircraft's identified models.
//!
//! Known plant: three decoupled rate axes ω̇ = −a·ω + k·δ behind a control delay τ
//! (p, q, r; φ, θ their integrals), the law with a tick short enough (0.1 ms) that its
//! hold and discrete integrator are those of the continuous PI, no filter bank, no
//! servo. On the roll axis (the other loops closed but decoupled) with the PI's zero at
//! r = 0.2·ω_c, L(s) = Kp·(1 + r/s)·k·e^{−sτ}/(s + a), and |L(jω_c)| = 1 gives
//! Kp = √(ω_c² + a²)/(k·√(1 + 0.2²)), Ki = 0.2·ω_c·Kp, with
//! PM(ω_c) = 90° − atan(ω_c/a) − ω_c·τ + atan(5) (the PI's phase is −atan(0.2)). The
//! highest crossover with PM ≥ 45° solves atan(ω/a) + ωτ + atan(0.2) = 135°
//! (bisection); with a ≪ ω_c the 6 dB gain margin does not bind first.

use control::law::BoardLaw;
use control::tune::{self, Models, TuneOptions};
use nalgebra::DMatrix;
use sweephold_firmware::app::pilot_mode::PilotModeGains;
use sysid::fit::model::Model;
use sysid::fit::report::ModelMatrices;
use sysid::fit::ModelDocument;

fn fixture(name: &str) -> ModelDocument {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Rate axes k/(s + a) behind τ, as a model.json (the Bo-105 fixture's layout).
fn rate_plant(k: f64, a: f64, tau: f64) -> ModelDocument {
    let states = ["p", "q", "r", "phi", "theta"];
    let mut f = DMatrix::<f64>::zeros(5, 5);
    let mut g = DMatrix::<f64>::zeros(5, 3);
    for i in 0..3 {
        f[(i, i)] = -a;
        g[(i, i)] = k;
    }
    f[(3, 0)] = 1.0;
    f[(4, 1)] = 1.0;
    let names = |list: &[&str]| list.iter().map(|n| n.to_string()).collect::<Vec<_>>();
    let model = Model {
        states: names(&states),
        controls: names(&["lat", "lon", "ped"]),
        outputs: names(&states),
        m: DMatrix::identity(5, 5),
        f,
        g,
        h0: DMatrix::identity(5, 5),
        h1: DMatrix::zeros(5, 5),
        delays: vec![tau; 3],
        actuators: vec![None; 3],
    };
    let mut value = serde_json::to_value(fixture("bo105-quick-seed1-model9.json")).unwrap();
    value["structure"] = "rate-plant".into();
    value["states"] = serde_json::json!(states);
    value["outputs"] = serde_json::json!(states);
    value["controls"] = serde_json::json!(["lat", "lon", "ped"]);
    value["matrices"] = serde_json::to_value(ModelMatrices::from_model(&model)).unwrap();
    value["delays"] = serde_json::json!([tau, tau, tau]);
    value["actuators"] = serde_json::json!([]);
    value["parameters"] = serde_json::json!([]);
    value["correlation"] = serde_json::Value::Null;
    serde_json::from_value(value).unwrap()
}

fn fine_law() -> BoardLaw {
    BoardLaw {
        gains: PilotModeGains::trex700l(),
        tick_s: 1e-4,
        filters: None,
        compute_delay_s: 0.0,
        servo_frame_hz: None,
        servos: [None; 3],
    }
}

fn no_draws() -> TuneOptions {
    TuneOptions {
        samples: 0,
        grid_points: 3000,
        candidates: 400,
        integral_fractions: vec![0.2],
        ..TuneOptions::default()
    }
}

#[test]
fn the_pi_for_a_crossover_is_the_closed_form() {
    for (k, a, tau, wc) in [
        (350.0, 67.0, 0.02, 8.0),
        (24.0, 14.0, 0.05, 3.0),
        (5.0, 1.0, 0.1, 1.5),
    ] {
        let document = rate_plant(k, a, tau);
        let law = fine_law();
        let models = Models::new(&document, None, &law, &no_draws()).unwrap();
        let (kp, ki) = tune::rate_gains_for_crossover(models.plant(), &law, 0, wc, 0.2).unwrap();
        let expected = (wc * wc + a * a).sqrt() / (k * (1.0f64 + 0.04).sqrt());
        // The 0.1 ms tick's discrete integrator differs from 1/s by ~ωT/2 in phase.
        assert!(
            (kp - expected).abs() / expected < 1e-3,
            "Kp {kp} vs {expected}"
        );
        assert!((ki - 0.2 * wc * kp).abs() < 1e-12);
        let mut tuned = law.clone();
        tuned.gains.roll.kp = kp as f32;
        tuned.gains.roll.ki = ki as f32;
        let check = tune::check_loop(&models, &tuned, 0, &no_draws());
        let found = check.crossover_rad_s.value.unwrap();
        assert!((found - wc).abs() / wc < 2e-3, "crossover {found} vs {wc}");
        let pm = 90.0 - (wc / a).atan().to_degrees() - (wc * tau).to_degrees()
            + 5f64.atan().to_degrees();
        let got = check.phase_margin_deg.value.unwrap();
        assert!((got - pm).abs() < 0.2, "PM {got} vs {pm}");
    }
}

/// The highest crossover with PM ≥ 45°: atan(ω/a) + ωτ + atan(0.2) = 135°.
fn closed_form_highest_crossover(a: f64, tau: f64) -> f64 {
    let target = 135f64.to_radians() - 0.2f64.atan();
    let (mut lo, mut hi) = (1e-6, 1e4);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (mid / a).atan() + mid * tau < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn the_highest_crossover_found_is_where_the_phase_margin_binds() {
    // A delay large enough that PM binds below the 20 rad/s cap (GM: the phase keeps
    // falling with the delay, |L| falls as 1/ω: checked below that PM binds first).
    for (k, a, tau) in [(350.0, 2.0, 0.08), (24.0, 1.0, 0.1), (5.0, 0.5, 0.15)] {
        let document = rate_plant(k, a, tau);
        let law = fine_law();
        let options = no_draws();
        let models = Models::new(&document, None, &law, &options).unwrap();
        let expected = closed_form_highest_crossover(a, tau);
        let mut tuned = law.clone();
        let found = tune::design_rate_axis(&models, &mut tuned, 0, &options, None).unwrap();
        // The search's candidates are log-spaced, 400 from 0.5 to 20 rad/s (0.9 %).
        assert!(
            found <= expected * 1.001 && found > expected * 0.985,
            "{found} vs {expected}"
        );
        let check = tune::check_loop(&models, &tuned, 0, &options);
        assert!(check.phase_margin_deg.value.unwrap() >= 45.0);
        assert!(check.gain_margin_db.value.unwrap() >= 6.0);
    }
}

fn preset_law(vehicle: sweephold_protocol::VehicleId) -> BoardLaw {
    use sweephold_firmware::app::AppConfig;
    use sweephold_firmware::board_stack::StackConfig;
    let app = AppConfig::preset(vehicle, sweephold_protocol::Axis::Lat);
    BoardLaw {
        gains: app.pilot,
        tick_s: f64::from(app.flight.dt_s()),
        filters: Some(StackConfig::with_app(app).filters),
        compute_delay_s: 0.0,
        servo_frame_hz: None,
        servos: [None; 3],
    }
}

#[test]
fn the_tuned_gains_meet_every_constraint_on_the_identified_models() {
    use sweephold_protocol::VehicleId;
    for (file, structure, vehicle) in [
        (
            "trex700l-quick-seed1-model9.json",
            "trex700l-9dof-hybrid",
            VehicleId::Trex700l,
        ),
        (
            "bo105-quick-seed1-model9.json",
            "bo105-9dof-hybrid",
            VehicleId::Bo105,
        ),
    ] {
        let document = fixture(file);
        let structure: sysid::fit::ModelStructure =
            sysid::models::shipped(structure).unwrap().parse().unwrap();
        let law = preset_law(vehicle);
        let options = TuneOptions {
            samples: 40,
            servo_rate_limit_per_s: Some(4.0),
            ..TuneOptions::default()
        };
        let models = Models::new(&document, Some(&structure), &law, &options).unwrap();
        assert!(models.drawn_parameters() > 0);
        let tuned = tune::tune(&models, &law, &options).unwrap();
        let mut tuned_law = law.clone();
        tuned_law.gains = tuned.gains;
        assert!(tuned.gains.is_valid());
        for index in 0..6 {
            let check = tune::check_loop(&models, &tuned_law, index, &options);
            let shipped = tune::check_loop(&models, &law, index, &options);
            eprintln!(
                "{file} {} shipped {:?}\n   tuned {:?}",
                check.name, shipped, check
            );
            assert_eq!(check.violation, None, "{file} {}", check.name);
            assert!(check.phase_margin_deg.value.unwrap() >= 45.0);
            assert!(check.phase_margin_deg.percentile.unwrap() >= 45.0);
            assert!(check.gain_margin_db.percentile.is_none_or(|gm| gm >= 6.0));
        }
        for axis in 0..3 {
            let rate =
                tune::servo_rate::stick_step_servo_rate(models.plant(), &tuned_law, axis, 1.0)
                    .unwrap();
            let shipped =
                tune::servo_rate::stick_step_servo_rate(models.plant(), &law, axis, 1.0).unwrap();
            let half =
                tune::servo_rate::stick_step_servo_rate(models.plant(), &law, axis, 0.25).unwrap();
            eprintln!("{file} axis {axis} servo rate tuned {rate} shipped {shipped} shipped quarter {half}");
            assert!(rate <= shipped.max(4.0) + 1e-9);
        }
        eprintln!("{file} {:?} {:?}", tuned.designed_crossovers, tuned.gains);
        // The outer gains within their cap: a fraction of the rate loops they close.
        let cap = |axes: &[usize]| {
            options.outer_fraction
                * axes
                    .iter()
                    .map(|&a| tuned.designed_crossovers[a])
                    .fold(f64::INFINITY, f64::min)
        };
        assert!(f64::from(tuned.gains.level_gain) <= cap(&[0, 1]).max(0.3) + 1e-6);
        assert!(f64::from(tuned.gains.heading_gain) <= cap(&[2]).max(0.3) + 1e-6);
    }
}
