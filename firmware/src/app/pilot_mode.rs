//! The stabilised pilot mode: roll and pitch rate loops (rate or self-levelling stick),
//! a heading-hold tail, collective straight from the stick.
//!
//! A flybarless rotor has no mechanical rate damping of its own worth flying with: the
//! pilot's sticks command body rates and these loops turn them into cyclic and pedal,
//! as flybarless units and ArduPilot's helicopter rate controllers do.
//!
//! # One rate loop (roll p, pitch q, yaw r)
//!
//! ```text
//! desired   ω_d = stick · ω_max                 (Rate stick), or
//!           ω_d = K_lvl · (angle_d − angle)     (Level stick; angle_d = stick · angle_max)
//!           both clamped to ±ω_max
//! target    ω_t[n] = ω_t[n−1] + clamp(ω_d − ω_t[n−1], ±α_max·dt)   (shaped target)
//! output    u = FF_ω·ω_t + FF_α·(ω_t[n] − ω_t[n−1])/dt + Kp·(ω_t − ω) + I + B
//!           clamped to ±u_max
//! I[n+1]  = clamp(I[n] + Ki·(ω_t − ω)·dt, ±I_max)  (not while u is saturated, or the
//!           tail slew-limited, in the direction I would grow)
//! B[n+1]  = B[n]·e^{−dt/τ_B}                     (bumpless-transfer remainder)
//! ```
//!
//! The two feed-forward terms are the inverse of the rigid-body rate model
//! ω̇ = L_ω·ω + L_δ·δ: FF_ω = −L_ω/L_δ (the rotor's rate damping) and FF_α = 1/L_δ
//! (the control power). The defaults take FF_α at 0.8/L_δ and FF_ω at about half of
//! −L_ω/L_δ of the model they are sized on: a feed-forward *above* the aircraft's
//! true damping overshoots, one below it undershoots and leaves the rest to the
//! integrator, which is the safe side for a model that has not been identified. The
//! acceleration limit α_max shapes the target (no step in the desired rate reaches the
//! swash) and keeps the FF_α term bounded by FF_α·α_max.
//!
//! # Heading hold (tail)
//!
//! With the pedal outside its dead band the tail is a rate loop on r with
//! ω_d = pedal · r_max (the dead band taken out of the travel). When the pedal enters
//! the dead band the heading is latched and ω_d = K_ψ · wrap(ψ_hold − ψ): the tail
//! returns to the heading where the pedal was centred, as a heading-hold gyro does. An
//! error beyond `heading_error_limit_rad` drags the latched heading along, so that a
//! tail that was blown far round (or a heading that jumped) is not swung back violently.
//! Without a valid attitude the heading term is off and the centred pedal holds r = 0.
//! The tail command then moves by at most `tail_slew_per_s` per second (the tail servo's
//! rate limit), and its integrator does not wind up against that limit.
//!
//! # Integrators on the ground
//!
//! While the rotor is not under power (throttle below `ThrottleSettings::spooled_min`)
//! an integrator cannot do anything useful (skids on the ground, no rotor thrust) and
//! would wind up against the ground contact, tipping the aircraft at lift-off. There
//! the integrators do not integrate and leak towards zero with `ground_leak_time_s`.
//!
//! # Bumpless transfer
//!
//! When the loops take over from another command source (a test's end, the IMU
//! failsafe, arming), `preload` makes their first output equal the command applied the
//! tick before: each shaped target restarts at the measured rate and the integrator
//! takes up the difference (what exceeds its limit goes into B, which decays with
//! τ_B). The heading is latched afresh.

use core::f32::consts::PI;

use sweephold_protocol::Controls;

use crate::attitude_hold::clamp_finite;
use crate::controller::wrap_pi;

mod gains;
pub use gains::{PilotModeGains, RateAxisGains};

const DEG: f32 = PI / 180.0;

/// Largest bumpless-transfer remainder \[stick\]: commands lie in [−1, 1].
const MAX_TRANSFER: f32 = 2.0;

/// How the roll and pitch sticks are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StickMode {
    /// Stick commands a body rate; centred holds the attitude the aircraft has (the
    /// flybarless standard).
    Rate,
    /// Stick commands a roll and pitch attitude; centred levels the aircraft. Needs a
    /// valid attitude estimate; without one it flies as [`StickMode::Rate`].
    Level,
}

/// Per-tick factors fixed by the gains and the tick interval (computed once: the
/// exponentials are too slow for every tick).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopFactors {
    /// Tick interval \[s\].
    pub dt_s: f32,
    /// e^{−dt/τ_leak}: integrator leak per tick on the ground.
    pub leak: f32,
    /// e^{−dt/τ_B}: transfer-remainder decay per tick.
    pub transfer_decay: f32,
    /// Largest tail command change per tick.
    pub tail_step: f32,
}

impl LoopFactors {
    /// Factors for `gains` at tick interval `dt_s` (> 0).
    pub fn new(gains: &PilotModeGains, dt_s: f32) -> Self {
        LoopFactors {
            dt_s,
            leak: decay(gains.ground_leak_time_s, dt_s),
            transfer_decay: decay(gains.transfer_time_s, dt_s),
            tail_step: gains.tail_slew_per_s * dt_s,
        }
    }
}

/// e^{−dt/τ}; 0 for τ = 0.
fn decay(tau_s: f32, dt_s: f32) -> f32 {
    if tau_s > 0.0 {
        micromath::F32Ext::exp(-dt_s / tau_s)
    } else {
        0.0
    }
}

/// How a rate loop is driven this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// The rotor is under power: the integrator runs (otherwise it leaks).
    pub integrate: bool,
    /// Bumpless take-over: make this tick's output equal to this command.
    pub preload: Option<f32>,
    /// Slew limit: (the command applied last tick, largest change this tick).
    pub slew: Option<(f32, f32)>,
}

/// State of one rate loop.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RateLoop {
    target: f32,
    integral: f32,
    transfer: f32,
}

impl RateLoop {
    /// The shaped rate target ω_t [rad/s].
    pub fn target(&self) -> f32 {
        self.target
    }

    /// The integrator's contribution \[stick\].
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The integrator plus the transfer remainder: the loop's slowly varying part, its
    /// estimate of the trim \[stick\].
    pub fn steady(&self) -> f32 {
        self.integral + self.transfer
    }

    /// One tick: the command for desired rate `desired` and measured rate `measured`
    /// [rad/s]. Non-finite inputs give a finite output (a non-finite measurement counts
    /// as no error).
    pub fn step(
        &mut self,
        gains: &RateAxisGains,
        desired: f32,
        measured: f32,
        factors: &LoopFactors,
        drive: Drive,
    ) -> f32 {
        let max_rate = gains.max_rate_rad_s;
        let desired = clamp_finite(desired, max_rate);
        if drive.preload.is_some() {
            self.target = clamp_finite(measured, max_rate);
        }
        let previous = self.target;
        let max_step = gains.max_accel_rad_s2 * factors.dt_s;
        self.target = clamp_finite(
            previous + clamp_finite(desired - previous, max_step),
            max_rate,
        );
        let accel = if factors.dt_s > 0.0 {
            (self.target - previous) / factors.dt_s
        } else {
            0.0
        };
        let error = if measured.is_finite() {
            self.target - measured
        } else {
            0.0
        };
        let base = gains.ff_rate * self.target + gains.ff_accel * accel + gains.kp * error;
        if let Some(command) = drive.preload {
            let needed = clamp_finite(command - base, MAX_TRANSFER);
            self.integral = clamp_finite(needed, gains.integrator_limit);
            self.transfer = clamp_finite(needed - self.integral, MAX_TRANSFER);
        }
        let unsaturated = base + self.integral + self.transfer;
        let limit = gains.output_limit;
        let output = clamp_finite(unsaturated, limit);
        let applied = match drive.slew {
            Some((last, step)) => {
                let last = clamp_finite(last, limit);
                last + clamp_finite(output - last, step)
            }
            None => output,
        };
        self.transfer = clamp_finite(self.transfer * factors.transfer_decay, MAX_TRANSFER);
        if drive.preload.is_none() {
            if drive.integrate {
                let increment = gains.ki * error * factors.dt_s;
                let winding_up = (increment > 0.0 && (unsaturated >= limit || applied < output))
                    || (increment < 0.0 && (unsaturated <= -limit || applied > output));
                if !winding_up {
                    self.integral = clamp_finite(self.integral + increment, gains.integrator_limit);
                }
            } else {
                self.integral = clamp_finite(self.integral * factors.leak, gains.integrator_limit);
            }
        }
        applied
    }
}

/// What the pilot (or a failsafe) asks of the roll or pitch axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AxisDemand {
    /// A stick in [−1, 1] commanding a rate (stick · ω_max).
    Rate(f32),
    /// An attitude target \[rad\], clamped to ±`max_angle_rad`. Without a valid attitude
    /// the axis holds zero rate.
    Angle(f32),
}

/// This tick's demand on the loops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Demand {
    /// Roll (lat) demand.
    pub roll: AxisDemand,
    /// Pitch (lon) demand.
    pub pitch: AxisDemand,
    /// Pedal stick in [−1, 1]; in the dead band the heading is held.
    pub pedal: f32,
    /// Collective command, straight through (clamped to [−1, 1]).
    pub collective: f32,
}

impl Demand {
    /// The demand of the pilot's `sticks` in stick mode `mode`.
    pub fn from_sticks(sticks: &Controls, mode: StickMode, gains: &PilotModeGains) -> Self {
        let axis = |stick: f32| match mode {
            StickMode::Rate => AxisDemand::Rate(stick),
            StickMode::Level => AxisDemand::Angle(clamp_finite(stick, 1.0) * gains.max_angle_rad),
        };
        Demand {
            roll: axis(sticks.lat),
            pitch: axis(sticks.lon),
            pedal: sticks.ped,
            collective: sticks.col,
        }
    }
}

/// The sensed state the loops act on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopSensors {
    /// Body rates p, q, r [rad/s].
    pub rates: [f32; 3],
    /// φ, θ, ψ \[rad\] when the attitude estimate is valid.
    pub attitude: Option<[f32; 3]>,
}

/// The three loops and the heading hold.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PilotLoops {
    roll: RateLoop,
    pitch: RateLoop,
    yaw: RateLoop,
    /// The latched heading while the heading hold is active.
    heading: Option<f32>,
}

impl PilotLoops {
    /// Forget all state (integrators, targets, heading).
    pub fn reset(&mut self) {
        *self = PilotLoops::default();
    }

    /// The roll, pitch and yaw loops.
    pub fn loops(&self) -> [RateLoop; 3] {
        [self.roll, self.pitch, self.yaw]
    }

    /// The latched heading, if the heading hold is active.
    pub fn held_heading(&self) -> Option<f32> {
        self.heading
    }

    /// The loops' trim estimate: each loop's integrator plus transfer remainder (lat,
    /// lon, ped).
    pub fn steady(&self) -> [f32; 3] {
        [self.roll.steady(), self.pitch.steady(), self.yaw.steady()]
    }

    /// One tick. `last` is the command applied the tick before (tail slew, preload);
    /// `integrate` whether the rotor is under power; `preload` takes over bumplessly
    /// from `last`. Every output is finite and in [−1, 1].
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        gains: &PilotModeGains,
        factors: &LoopFactors,
        demand: &Demand,
        sensors: &LoopSensors,
        last: &Controls,
        integrate: bool,
        preload: bool,
    ) -> Controls {
        if preload {
            self.heading = None;
        }
        let [p, q, r] = sensors.rates;
        let attitude = sensors.attitude;
        let (phi, theta, psi) = match attitude {
            Some([phi, theta, psi]) => (Some(phi), Some(theta), Some(psi)),
            None => (None, None, None),
        };
        let roll_desired = axis_desired(demand.roll, phi, &gains.roll, gains);
        let pitch_desired = axis_desired(demand.pitch, theta, &gains.pitch, gains);
        let yaw_desired = self.yaw_desired(demand.pedal, psi, gains);

        let drive = |last: f32, slew: Option<f32>| Drive {
            integrate,
            preload: preload.then_some(last),
            slew: slew.map(|step| (last, step)),
        };
        let lat = self
            .roll
            .step(&gains.roll, roll_desired, p, factors, drive(last.lat, None));
        let lon = self.pitch.step(
            &gains.pitch,
            pitch_desired,
            q,
            factors,
            drive(last.lon, None),
        );
        let ped = self.yaw.step(
            &gains.yaw,
            yaw_desired,
            r,
            factors,
            drive(last.ped, Some(factors.tail_step)),
        );
        Controls {
            lat,
            lon,
            ped,
            col: clamp_finite(demand.collective, 1.0),
        }
    }

    /// Desired yaw rate: pedal rate outside the dead band, heading hold inside it.
    fn yaw_desired(&mut self, pedal: f32, psi: Option<f32>, gains: &PilotModeGains) -> f32 {
        let pedal = clamp_finite(pedal, 1.0);
        let band = gains.pedal_deadband;
        let outside = pedal.abs() - band;
        if outside > 0.0 {
            self.heading = None;
            let travel = 1.0 - band;
            return pedal.signum() * outside / travel * gains.yaw.max_rate_rad_s;
        }
        let Some(psi) = psi.filter(|psi| psi.is_finite()) else {
            self.heading = None;
            return 0.0;
        };
        let held = *self.heading.get_or_insert(psi);
        let limit = gains.heading_error_limit_rad;
        let mut error = wrap_pi(held - psi);
        if error.abs() > limit {
            error = limit.copysign(error);
            self.heading = Some(wrap_pi(psi + error));
        }
        gains.heading_gain * error
    }
}

/// Desired rate of a roll or pitch axis.
fn axis_desired(
    demand: AxisDemand,
    angle: Option<f32>,
    axis: &RateAxisGains,
    gains: &PilotModeGains,
) -> f32 {
    match demand {
        AxisDemand::Rate(stick) => clamp_finite(stick, 1.0) * axis.max_rate_rad_s,
        AxisDemand::Angle(target) => match angle.filter(|a| a.is_finite()) {
            Some(angle) => {
                let target = clamp_finite(target, gains.max_angle_rad);
                clamp_finite(gains.level_gain * (target - angle), axis.max_rate_rad_s)
            }
            None => 0.0,
        },
    }
}
