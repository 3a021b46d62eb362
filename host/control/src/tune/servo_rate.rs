//! How fast the servo moves when the pilot steps a Rate stick: the check of a design
//! against the servo's rate limit (the aircraft file's `[servos] rate_limit`, stick
//! fraction per second).
//!
//! A step of `step` (fraction of full stick) asks for a rate `step·ω_max`; the firmware
//! shapes it into a ramp of slope α_max (`ω_t[n] = min((n + 1)·α_max·T, step·ω_max)`).
//! With the loops closed on the model, the servo's rate per unit of the rate target is
//!
//! ```text
//! R(jω) = jω · A(jω) · hold(jω) · [(I + L)⁻¹]_kk · F_ω(jω)
//! ```
//!
//! (A: the model's own servo for that control, or the law's added one, or 1 where the
//! model has neither: then the command's rate). R is sampled on the tick's frequency
//! grid `2πm/(N·T)`, m = 0 … N/2 (R(0) = 0: a rate), and an inverse FFT (rustfft, the
//! FFT the workspace already uses in `sysid`) gives the tick-sampled impulse response
//! over N·T = 20.48 s; its running sum is the response to a unit step of the target,
//! and the ramp is a sum of such steps. The figure is the largest |rate| over the first
//! half of the window. Approximations, stated: the loop's sampled-data aliasing is
//! neglected as in the margins; the window's circular wrap leaves any mode slower than
//! the window (the unstabilised hover modes of the Rate stick) in the response only as a
//! small periodic remainder; the clamps and the tail's slew limit are left out (they
//! only lower the rate).

use num_complex::Complex64;
use rustfft::FftPlanner;

use crate::law::{BoardLaw, LoopMode};
use crate::loops::{self, Configuration};
use crate::plant::{Plant, CONTROLS};

/// Ticks in the window of the impulse response (20.48 s at 200 Hz).
const WINDOW_TICKS: usize = 4096;

const RATE: Configuration = Configuration {
    mode: LoopMode::Rate,
    heading_hold: false,
};

/// The largest servo rate [stick/s] for a step of `step` (fraction of full stick) of
/// axis `axis`'s Rate stick (pedal outside its dead band on the yaw axis); `None` when
/// the model is singular at a frequency of the grid.
pub fn stick_step_servo_rate(plant: &Plant, law: &BoardLaw, axis: usize, step: f64) -> Option<f64> {
    let n = WINDOW_TICKS;
    let t = law.tick_s;
    let model = plant.model();
    let own_servo = model
        .controls
        .iter()
        .position(|c| c == CONTROLS[axis])
        .and_then(|j| model.actuators.get(j).copied().flatten());
    let mut spectrum = vec![Complex64::new(0.0, 0.0); n];
    for m in 1..=n / 2 {
        let omega = std::f64::consts::TAU * m as f64 / (n as f64 * t);
        let response = plant.response(omega)?;
        let command = loops::command_per_target(&response, law, RATE, axis, omega)?;
        let s = Complex64::new(0.0, omega);
        let servo = match own_servo {
            Some(actuator) => actuator.response(s),
            None => law.servo(axis, omega),
        };
        let value = s * servo * law.output_path(omega) * command;
        if !value.is_finite() {
            return None;
        }
        spectrum[m] = value;
        if m < n / 2 {
            spectrum[n - m] = value.conj();
        }
    }
    // The Nyquist bin of a real sequence is real.
    spectrum[n / 2] = Complex64::new(spectrum[n / 2].re, 0.0);
    FftPlanner::<f64>::new()
        .plan_fft_inverse(n)
        .process(&mut spectrum);
    let impulse: Vec<f64> = spectrum.iter().map(|v| v.re / n as f64).collect();
    let mut step_response = Vec::with_capacity(n / 2);
    let mut sum = 0.0;
    for value in impulse.iter().take(n / 2) {
        sum += value;
        step_response.push(sum);
    }
    // The shaped target's increments: α_max·T a tick until it reaches step·ω_max.
    let gains = law.axes()[axis];
    let total = step.abs() * law.stick_gain(axis, LoopMode::Rate);
    let slope = f64::from(gains.max_accel_rad_s2) * t;
    let mut increments = Vec::new();
    let mut reached = 0.0;
    while reached < total && slope > 0.0 {
        let next = (reached + slope).min(total);
        increments.push(next - reached);
        reached = next;
        if increments.len() > n / 2 {
            break;
        }
    }
    let peak = (0..n / 2)
        .map(|i| {
            increments
                .iter()
                .enumerate()
                .take_while(|(j, _)| *j <= i)
                .map(|(j, d)| d * step_response[i - j])
                .sum::<f64>()
                .abs()
        })
        .fold(0.0, f64::max);
    Some(peak)
}
