//! The simulator's tests: physics checks (free fall, applied moments), trim hold, seeded
//! repeatability and faults, stick signs, attitude hold through a sweep, the linearized
//! plant, latency and delay, dynamic inflow, and bad inputs.

use super::*;
use crate::trim::trim;
use nalgebra::{Matrix3, Vector3};

#[test]
fn free_fall_at_g_with_rotors_off() {
    let heli = Helicopter::bo105();
    let g = heli.gravity;
    let mut sim = Sim::new(heli, SimOptions::perfect());
    sim.set_aerodynamics(false);
    let mut reading = SensorReading::default();
    for _ in 0..200 {
        reading = sim.step(0.005, [0.0; 4]);
    }
    let t = sim.time();
    assert!((t - 1.0).abs() < 1e-9);
    let x = sim.state();
    assert!((x.0[model::W] - g * t).abs() < 1e-9, "w {}", x.0[model::W]);
    assert!((x.0[model::DOWN] - 0.5 * g * t * t).abs() < 1e-9);
    // An accelerometer in free fall reads zero specific force.
    assert!(reading.az.abs() < 1e-12 && reading.ax.abs() < 1e-12);
}

#[test]
fn applied_moment_gives_inverse_inertia_times_moment() {
    let heli = Helicopter::bo105();
    let inertia = Matrix3::new(
        heli.ixx, 0.0, -heli.ixz, 0.0, heli.iyy, 0.0, -heli.ixz, 0.0, heli.izz,
    );
    let model = Model::new(heli);
    let moment = Vector3::new(500.0, -300.0, 200.0);
    let mut flags = ModelFlags {
        no_aero: true,
        ..ModelFlags::default()
    };
    flags.external_load[3..].copy_from_slice(moment.as_slice());
    // From rest: ω̇ = I⁻¹ M exactly.
    let x = [0.0; STATE_LEN];
    let pitch = model.heli.blade_pitch([0.0; 4]);
    let (dx, _) = model.derivative(&x, &pitch, [0.0; 3], flags, &mut [0.05; 2]);
    let expected = inertia.try_inverse().unwrap() * moment;
    for i in 0..3 {
        assert!((dx[model::P + i] - expected[i]).abs() < 1e-12 * expected.norm());
    }
    // Spinning: ω̇ = I⁻¹ (M − ω × Iω).
    let mut spinning = x;
    spinning[model::P] = 0.3;
    spinning[model::Q] = -0.2;
    spinning[model::R] = 0.5;
    let omega = Vector3::new(0.3, -0.2, 0.5);
    let expected = inertia.try_inverse().unwrap() * (moment - omega.cross(&(inertia * omega)));
    let (dx, _) = model.derivative(&spinning, &pitch, [0.0; 3], flags, &mut [0.05; 2]);
    for i in 0..3 {
        assert!((dx[model::P + i] - expected[i]).abs() < 1e-12 * expected.norm());
    }
}

#[test]
fn hover_trim_holds_and_accelerometer_reads_minus_g() {
    let heli = Helicopter::bo105();
    let g = heli.gravity;
    let t = trim(&heli, 0.0).unwrap();
    let mut sim = Sim::at_trim(heli, &t, SimOptions::perfect());
    let mut reading = SensorReading::default();
    for _ in 0..40 {
        reading = sim.step(0.005, t.controls);
    }
    // 0.2 s after release the trimmed state has not drifted (unstable modes are slow).
    assert!(
        reading.p.abs() < 1e-5 && reading.q.abs() < 1e-5,
        "{reading:?}"
    );
    assert!((reading.az + g * t.phi.cos() * t.theta.cos()).abs() < 1e-3 && reading.seq == 40);
}

#[test]
fn seeded_runs_repeat_and_faults_behave() {
    let heli = Helicopter::bo105();
    let t = trim(&heli, 0.0).unwrap();
    let options = SimOptions {
        seed: 99,
        gust_level: 1.0,
        dropout_probability: 0.2,
        spike_probability: 0.05,
        ..SimOptions::default()
    };
    let run = || {
        let mut sim = Sim::at_trim(heli.clone(), &t, options);
        (0..200)
            .map(|_| sim.step(0.005, t.controls))
            .collect::<Vec<_>>()
    };
    let a = run();
    let b = run();
    assert_eq!(a, b);
    // Dropouts repeat the previous sample with its sequence number.
    let repeats = a.windows(2).filter(|w| w[0] == w[1]).count();
    assert!((20..70).contains(&repeats), "repeats {repeats}");
    let last = a.last().unwrap();
    assert_eq!(last.seq as usize, 200 - repeats);
    assert!(a
        .iter()
        .all(|r| r.psi > -std::f64::consts::PI && r.psi <= std::f64::consts::PI));
}

/// Stick sign convention: a positive stick gives a positive response (lat → roll right,
/// lon → nose up, ped → nose right, col → climb), for both vehicles.
#[test]
fn positive_sticks_give_positive_moments_on_both_vehicles() {
    for heli in [Helicopter::bo105(), Helicopter::trex700l()] {
        let t = trim(&heli, 0.0).unwrap();
        for axis in 0..4 {
            let mut sim = Sim::at_trim(heli.clone(), &t, SimOptions::perfect());
            let mut controls = t.controls;
            controls[axis] += 0.05;
            let mut reading = SensorReading::default();
            for _ in 0..20 {
                reading = sim.step(0.005, controls);
            }
            let response = [reading.p, reading.q, reading.r, -reading.w][axis];
            assert!(response > 0.0, "{} axis {axis}: {reading:?}", heli.name);
        }
    }
}

/// A plain PD attitude hold (what the firmware's hold does) keeps the Bo-105 in hover
/// while a 5 %-of-stick lateral sweep (0.3 → 12 rad/s over 30 s) runs.
#[test]
fn pd_attitude_hold_keeps_bo105_hovering_through_a_five_percent_sweep() {
    let heli = Helicopter::bo105();
    let t = trim(&heli, 0.0).unwrap();
    let mut sim = Sim::at_trim(
        heli,
        &t,
        SimOptions {
            seed: 3,
            ..SimOptions::default()
        },
    );
    let dt = 0.005;
    let (duration, w_min, w_max) = (30.0, 0.3, 12.0);
    let mut reading = sim.step(dt, t.controls);
    let mut worst: f64 = 0.0;
    for tick in 1..(duration / dt) as usize {
        let time = tick as f64 * dt;
        // Linear chirp phase θ(t) = w_min t + (w_max − w_min) t² / (2T).
        let phase = w_min * time + (w_max - w_min) * time * time / (2.0 * duration);
        let sweep = 0.05 * phase.sin();
        let lat = t.controls[0] - 0.4 * (reading.phi - t.phi) - 0.1 * reading.p + sweep;
        let lon = t.controls[1] - 1.1 * (reading.theta - t.theta) - 0.5 * reading.q;
        let ped = t.controls[2] - 0.9 * reading.psi - 0.3 * reading.r;
        let col = t.controls[3] + 0.1 * reading.w;
        reading = sim.step(dt, [lat, lon, ped, col]);
        worst = worst
            .max((reading.phi - t.phi).abs())
            .max((reading.theta - t.theta).abs());
    }
    eprintln!(
        "PD hold through a 5 % lateral sweep: largest attitude excursion {:.2} deg",
        worst.to_degrees()
    );
    assert!(
        worst < 6f64.to_radians(),
        "largest attitude excursion {} deg",
        worst.to_degrees()
    );
}

/// Largest |r| difference between the linearized plant and the model over 3 s of a
/// pedal pulse of `size` (1 s long), relative to the model's largest |r|.
fn linearized_plant_relative_error(size: f64) -> f64 {
    let heli = Helicopter::bo105();
    let t = crate::trim(&heli, 0.0).expect("hover trims");
    let fly = |linearized_plant: bool| {
        let options = SimOptions {
            linearized_plant,
            ..SimOptions::perfect()
        };
        let mut sim = Sim::at_trim(heli.clone(), &t, options);
        let dt = 0.005;
        (0..600)
            .map(|tick| {
                let mut controls = t.controls;
                if tick < 200 {
                    controls[2] += size;
                }
                sim.step(dt, controls).r
            })
            .collect::<Vec<f64>>()
    };
    let (model, linear) = (fly(false), fly(true));
    let peak = model.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    let worst = model
        .iter()
        .zip(&linear)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(peak > 0.0, "the pulse must yaw the aircraft");
    worst / peak
}

#[test]
fn the_linearized_plant_is_the_model_for_small_inputs_only() {
    let small = linearized_plant_relative_error(0.001);
    let large = linearized_plant_relative_error(0.1);
    eprintln!("linearized vs model, r over 3 s: {small:.2e} (0.001 pulse), {large:.2e} (0.1)");
    // First order: the error of the expansion shrinks with the input (∝ size²/size).
    assert!(small < 2e-3, "small pulse: relative error {small}");
    assert!(large > 10.0 * small, "large {large} vs small {small}");
}

#[test]
fn sensor_latency_and_transport_delay_shift_the_signals() {
    let heli = Helicopter::bo105();
    let g = heli.gravity;
    let noise = SensorNoise {
        latency_s: 0.010,
        ..SensorNoise::perfect()
    };
    let mut sim = Sim::new(
        heli.clone(),
        SimOptions {
            sensor_noise: noise,
            ..SimOptions::perfect()
        },
    );
    sim.set_aerodynamics(false);
    let mut reading = SensorReading::default();
    for _ in 0..100 {
        reading = sim.step(0.005, [0.0; 4]);
    }
    // Free fall read 10 ms late: w = g (t − 0.010).
    assert!((reading.w - g * 0.490).abs() < 1e-9, "{}", reading.w);
    assert!((reading.time_s - 0.490).abs() < 1e-9);

    let actuator = ActuatorModel {
        transport_delay_s: 0.020,
        ..ActuatorModel::ideal()
    };
    let mut sim = Sim::new(
        heli,
        SimOptions {
            actuator,
            ..SimOptions::perfect()
        },
    );
    for _ in 0..3 {
        sim.step(0.005, [0.5; 4]);
    }
    assert_eq!(sim.actuator_position(), [0.0; 4]);
    for _ in 0..2 {
        sim.step(0.005, [0.5; 4]);
    }
    assert_eq!(sim.actuator_position(), [0.5; 4]);
}

#[test]
fn dynamic_inflow_trim_is_an_equilibrium() {
    let heli = Helicopter::bo105();
    let t = trim(&heli, 20.0).unwrap();
    let options = SimOptions {
        dynamic_inflow: true,
        ..SimOptions::perfect()
    };
    let mut sim = Sim::at_trim(heli, &t, options);
    let mut reading = SensorReading::default();
    for _ in 0..40 {
        reading = sim.step(0.005, t.controls);
    }
    assert!(reading.p.abs() < 1e-5 && reading.q.abs() < 1e-5 && reading.r.abs() < 1e-5);
    assert!((sim.state().inflow() - t.inflow).abs() < 1e-6);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

    /// Any stick input, even non-finite or out of range, leaves a finite state.
    #[test]
    fn bad_controls_never_poison_the_state(
        sticks in proptest::collection::vec(
            proptest::prop_oneof![
                -3.0f64..3.0,
                proptest::strategy::Just(f64::NAN),
                proptest::strategy::Just(f64::INFINITY),
            ],
            40,
        ),
        dt in proptest::prop_oneof![0.001f64..0.02, proptest::strategy::Just(f64::NAN), proptest::strategy::Just(-1.0)],
    ) {
        let heli = Helicopter::bo105();
        let t = trim(&heli, 0.0).unwrap();
        let mut sim = Sim::at_trim(heli, &t, SimOptions::default());
        for chunk in sticks.chunks(4) {
            let reading = sim.step(dt, [chunk[0], chunk[1], chunk[2], chunk[3]]);
            proptest::prop_assert!(reading.p.is_finite() && reading.az.is_finite());
        }
        proptest::prop_assert!(sim.state().0.iter().all(|v| v.is_finite()));
        proptest::prop_assert!(sim.actuator_position().iter().all(|v| v.abs() <= 1.0));
    }
}
