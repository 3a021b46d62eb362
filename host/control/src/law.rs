//! The board's pilot-mode control law as it runs, in the frequency domain.
//!
//! Per axis the firmware computes (`sweephold_firmware::app::pilot_mode`, one tick T)
//!
//! ```text
//! u = FF_ω·ω_t + FF_α·(ω_t[n] − ω_t[n−1])/T + Kp·(ω_t − ω) + I,   I[n+1] = I[n] + Ki·T·(ω_t − ω)
//! ```
//!
//! so, with z = e^{jωT}, C(z) = Kp + Ki·T/(z − 1) (the integrator adds this tick's error
//! after the output) and F_ω(z) = FF_ω + FF_α·(1 − z⁻¹)/T + C(z):
//!
//! ```text
//! u = F_ω·ω_t − C·ω_m
//! Rate stick:   ω_t = ω_max·stick                  (no feedback through ω_t)
//! Level stick:  ω_t = K_lvl·(angle_max·stick − angle_m)
//! heading hold: ω_t = K_ψ·(ψ_hold − ψ_m);  pedal outside the dead band: ω_t = r_max·(pedal − band)/(1 − band)
//! ```
//!
//! The measured signals pass the board's IMU filter bank (`FilterBank::response`, the
//! gyro channels; the estimator integrates the filtered gyro, so the attitude carries the
//! same lag), are sampled at the tick and the command is held for a tick (zero-order
//! hold (1 − e^{−sT})/(sT)), after a computation delay; a servo pulse frame slower than
//! the tick holds it again ((1 − e^{−sT_f})/(sT_f)). The target shaping (α_max), the
//! clamps, the tail slew limit and the integrator's anti-windup are limits a
//! small-amplitude analysis does not reach, and are left out. Sampled-data aliasing is
//! neglected (the usual digital-controller approximation: the loop's crossovers lie a
//! decade or more below the 100 Hz Nyquist frequency).

use num_complex::Complex64;
use sweephold_firmware::app::pilot_mode::{PilotModeGains, RateAxisGains};
use sweephold_firmware::filters::{FilterBank, FilterBankConfig};
use sysid::fit::model::Actuator;

/// Which stick mode the loops fly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopMode {
    /// Rate stick on roll and pitch, the tail's rate loop (pedal outside the dead band).
    Rate,
    /// Level stick on roll and pitch, heading hold on the tail (pedal centred).
    Level,
}

/// The control law of the board, with what lies between it and the model.
#[derive(Clone, Debug)]
pub struct BoardLaw {
    /// The pilot-mode gains (the firmware preset's, or others).
    pub gains: PilotModeGains,
    /// Control tick T \[s\].
    pub tick_s: f64,
    /// The IMU filter bank ahead of the tick (`None`: raw sensors, as the simulator's
    /// in-process link feeds the sequencer).
    pub filters: Option<FilterBankConfig>,
    /// Computation delay from the sensor sample to the command's output \[s\].
    pub compute_delay_s: f64,
    /// Servo pulse frame rate \[Hz\] (`None`: the command reaches the servo at once).
    pub servo_frame_hz: Option<f64>,
    /// A servo added per control (lat, lon, ped) where the model has neither its own
    /// actuator nor a delay for that control (the model then starts at the servo's output).
    pub servos: [Option<Actuator>; 3],
}

/// The frequency-domain parts of one rate loop at one frequency.
#[derive(Clone, Copy, Debug)]
pub struct AxisTerms {
    /// C(z) = Kp + Ki·T/(z − 1): what the loop does with the measured rate.
    pub feedback: Complex64,
    /// F_ω(z) = FF_ω + FF_α(1 − z⁻¹)/T + C(z): what it does with the rate target.
    pub target: Complex64,
}

impl BoardLaw {
    /// C(z) and F_ω(z) of `axis` at ω.
    pub fn axis_terms(&self, axis: &RateAxisGains, omega: f64) -> AxisTerms {
        let t = self.tick_s;
        let z = Complex64::new(0.0, omega * t).exp();
        let one = Complex64::new(1.0, 0.0);
        let feedback = f64::from(axis.kp) + f64::from(axis.ki) * t / (z - one);
        let target =
            f64::from(axis.ff_rate) + f64::from(axis.ff_accel) * (one - one / z) / t + feedback;
        AxisTerms { feedback, target }
    }

    /// The filter bank's response at ω (1 without a bank).
    pub fn measurement(&self, omega: f64) -> Complex64 {
        let Some(config) = self.filters else {
            return Complex64::new(1.0, 0.0);
        };
        match FilterBank::new(config) {
            Ok(bank) => {
                let (gain, phase) = bank.response((omega / std::f64::consts::TAU) as f32);
                Complex64::from_polar(f64::from(gain), f64::from(phase))
            }
            Err(_) => Complex64::new(f64::NAN, f64::NAN),
        }
    }

    /// From the computed command to the servo input: the tick's hold, the computation
    /// delay and the servo frame's hold.
    pub fn output_path(&self, omega: f64) -> Complex64 {
        let s = Complex64::new(0.0, omega);
        let mut path = zero_order_hold(s, self.tick_s) * (-s * self.compute_delay_s).exp();
        if let Some(hz) = self.servo_frame_hz.filter(|hz| *hz > 0.0) {
            path *= zero_order_hold(s, 1.0 / hz);
        }
        path
    }

    /// The added servo of control `k` at ω (1 without one).
    pub fn servo(&self, k: usize, omega: f64) -> Complex64 {
        match self.servos[k] {
            Some(actuator) => actuator.response(Complex64::new(0.0, omega)),
            None => Complex64::new(1.0, 0.0),
        }
    }

    /// The three axes' gains (roll, pitch, yaw).
    pub fn axes(&self) -> [&RateAxisGains; 3] {
        [&self.gains.roll, &self.gains.pitch, &self.gains.yaw]
    }

    /// The gain from the rate target to the outer loop's variable: K_lvl on roll and
    /// pitch in Level, K_ψ on yaw in Level (heading hold); 0 in Rate.
    pub fn outer_gain(&self, axis: usize, mode: LoopMode) -> f64 {
        match (mode, axis) {
            (LoopMode::Rate, _) => 0.0,
            (LoopMode::Level, 2) => f64::from(self.gains.heading_gain),
            (LoopMode::Level, _) => f64::from(self.gains.level_gain),
        }
    }

    /// The rate target per unit stick: ω_max (Rate), K_lvl·angle_max (Level, roll and
    /// pitch), r_max/(1 − band) (the pedal outside its dead band, both modes).
    pub fn stick_gain(&self, axis: usize, mode: LoopMode) -> f64 {
        let gains = &self.gains;
        match (mode, axis) {
            (_, 2) => f64::from(gains.yaw.max_rate_rad_s) / (1.0 - f64::from(gains.pedal_deadband)),
            (LoopMode::Rate, _) => f64::from(self.axes()[axis].max_rate_rad_s),
            (LoopMode::Level, _) => f64::from(gains.level_gain) * f64::from(gains.max_angle_rad),
        }
    }
}

/// (1 − e^{−sT})/(sT): a hold of period T (unit gain at 0).
fn zero_order_hold(s: Complex64, period: f64) -> Complex64 {
    let x = s * period;
    if x.norm() < 1e-9 {
        return Complex64::new(1.0, 0.0);
    }
    (Complex64::new(1.0, 0.0) - (-x).exp()) / x
}
