//! The law's C(z) and F_ω(z) against the firmware's own rate loop stepped tick by tick:
//! a sinusoid on the measured rate (or on the desired rate) and the command's component
//! at that frequency (one DFT bin over whole periods after the start-up transient).
//! Small amplitudes keep the target shaping, clamps and integrator limit out of play.

use control::law::BoardLaw;
use num_complex::Complex64;
use sweephold_firmware::app::pilot_mode::{Drive, LoopFactors, PilotModeGains, RateLoop};

fn bin(samples: &[f64], omega: f64, tick: f64) -> Complex64 {
    let n = samples.len() as f64;
    samples
        .iter()
        .enumerate()
        .map(|(i, &y)| y * Complex64::new(0.0, -omega * tick * i as f64).exp())
        .sum::<Complex64>()
        * (2.0 / n)
}

#[test]
fn the_rate_loop_terms_are_the_firmware_loop_at_every_frequency() {
    let gains = PilotModeGains::trex700l();
    let tick = 0.005_f64;
    let factors = LoopFactors::new(&gains, tick as f32);
    let law = BoardLaw {
        gains,
        tick_s: f64::from(tick as f32),
        filters: None,
        compute_delay_s: 0.0,
        servo_frame_hz: None,
        servos: [None; 3],
    };
    let drive = Drive {
        integrate: true,
        preload: None,
        slew: None,
    };
    for axis in [gains.roll, gains.pitch, gains.yaw] {
        // Periods of whole ticks: 200, 40 and 8 ticks.
        for period_ticks in [200usize, 40, 8] {
            let omega = std::f64::consts::TAU / (period_ticks as f64 * law.tick_s);
            let terms = law.axis_terms(&axis, omega);
            let amplitude = 0.002;
            let (settle, keep) = (4000, 50 * period_ticks);
            let run = |on_measured: bool| {
                let mut state = RateLoop::default();
                let mut out = Vec::new();
                let mut input = Vec::new();
                for i in 0..settle + keep {
                    let x = amplitude * (omega * law.tick_s * i as f64).sin();
                    let (desired, measured) = if on_measured { (0.0, x) } else { (x, 0.0) };
                    let u = state.step(&axis, desired as f32, measured as f32, &factors, drive);
                    if i >= settle {
                        out.push(f64::from(u));
                        input.push(x);
                    }
                }
                bin(&out, omega, law.tick_s) / bin(&input, omega, law.tick_s)
            };
            let feedback = -run(true);
            let target = run(false);
            let e1 = (feedback - terms.feedback).norm() / terms.feedback.norm();
            let e2 = (target - terms.target).norm() / terms.target.norm();
            assert!(
                e1 < 2e-3,
                "C at {omega}: firmware {feedback}, law {}",
                terms.feedback
            );
            assert!(
                e2 < 2e-3,
                "F at {omega}: firmware {target}, law {}",
                terms.target
            );
        }
    }
}
