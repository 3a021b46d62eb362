//! Steady flights on the board (`fly --fc board-sim --steady-flights`): after the
//! power-up, the simulated pilot flies each steady condition of `sim trim-points` in the
//! pilot mode (Level), as between tests, on a free simulator started at that condition's
//! trim, for [`SETTLE_S`] + [`HOLD_S`] seconds. The board's log records it (every frame,
//! as it records a flight's tests); a simulated GNSS/compass unit gives the velocity over
//! the ground and the heading at [`GNSS_RATE_HZ`] on the log's clock (`gnss.csv`).
//!
//! The pilot holds the target by eye: a slow outer loop on the true velocity into the
//! Level sticks (attitude demands about the condition's trim attitude, proportional and
//! integral), the collective on the true climb rate, and for a turn the pedal stick at the
//! condition's yaw rate. The simulator has the flight's gusts and sensor noise.

use rotorsim::{trim_steady, Sim, SteadyFlight};
use sweephold_firmware::app::Mode;
use sweephold_firmware::receiver::{ModeSwitch, RcInput};
use sweephold_firmware::Config;
use sweephold_protocol::Controls;
use sysid::random::SplitMix64;
use sysid::steady::GnssFix;

use super::power_up::{devices_seed, power_up};
use super::settings::{BoardSimSettings, HOVER_THROTTLE};

/// Seconds flown at each condition before the pilot counts it steady: the jump from the
/// last condition's trim dies out (the outer loop's time constant is ~4 s).
pub const SETTLE_S: f64 = 8.0;
/// Seconds each condition is held once settled: ten one-second blocks of the steadiness
/// rule.
pub const HOLD_S: f64 = 10.0;
/// Fixes per second of the simulated GNSS.
pub const GNSS_RATE_HZ: u32 = 10;
/// White noise of each GNSS velocity component [m/s].
pub const GNSS_VELOCITY_NOISE_M_S: f64 = 0.1;
/// White noise of the compass heading \[rad\] (1°).
pub const COMPASS_NOISE_RAD: f64 = 0.0175;

/// The pilot's attitude demand per m/s of velocity error \[rad\] (≈ 6° per m/s). With
/// 0.05 and an integral gain of 0.02 the TREX's velocity swung ±0.3 m/s with a period of
/// about 9 s in the translating flights (seed 1); with 0.1 and 0.01 the one-second means
/// of each velocity spread ≤ 0.18 m/s over each hold, the GNSS noise included.
const VELOCITY_GAIN: f64 = 0.1;
/// Its integral on the velocity error \[rad per m\].
const VELOCITY_INTEGRAL_GAIN: f64 = 0.01;
/// Largest integral attitude demand \[rad\].
const INTEGRAL_LIMIT_RAD: f64 = 0.05;
/// The collective per m/s of climb-rate error (fraction of travel).
const CLIMB_GAIN: f64 = 0.05;

/// One steady condition: its label, the velocity over the ground north, east, down
/// [m/s] and the turn rate [rad/s].
pub type SteadyCondition = (&'static str, [f64; 3], f64);

/// What the steady flights left: the board's log of the power-up and the GNSS fixes.
pub struct SteadyFlights {
    /// Every frame of the power-up.
    pub log: Vec<u8>,
    /// The fixes, stamped with the board's tick.
    pub fixes: Vec<GnssFix>,
}

/// Power the board up for `config` and fly `conditions` one after the other, each on a
/// free simulator with turbulence `gust_level` [m/s RMS] (module documentation).
pub fn fly_steady_flights(
    settings: &BoardSimSettings,
    config: &Config,
    conditions: &[SteadyCondition],
    gust_level: f64,
) -> anyhow::Result<SteadyFlights> {
    let mut board = power_up(settings, config, true)?;
    let seed = devices_seed(config.test.seed);
    let mut gnss_rng = SplitMix64::new(seed ^ 0x6E55_0000);
    let pilot = board.stack.app().config().pilot;
    let max_angle = f64::from(pilot.max_angle_rad);
    let rate = f64::from(config.rate_hz);
    let dt = board.dt;
    let gnss_every = (rate / f64::from(GNSS_RATE_HZ)).round().max(1.0) as u64;
    let ticks = ((SETTLE_S + HOLD_S) * rate).ceil() as u64;
    let mut fixes = Vec::new();
    let mut flown_ticks = 0_u64;
    for (index, &(label, velocity_ned, turn_rate)) in conditions.iter().enumerate() {
        let flight = SteadyFlight {
            velocity_ned,
            turn_rate,
        };
        let trim = trim_steady(&settings.heli, &flight)
            .map_err(|e| anyhow::anyhow!("steady flight `{label}` does not trim: {e}"))?;
        let mut options = settings.sim_options;
        options.seed = seed ^ 0x57EA_D900 ^ (index as u64 + 1) << 40;
        options.gust_level = gust_level;
        let mut sim = Sim::at_trim(settings.heli.clone(), &trim, options);
        let mut reading = sim.step(dt, trim.controls);
        let pedal = pedal_for(turn_rate, &pilot);
        let mut integral = [0.0_f64; 2];
        for _ in 0..ticks {
            // A safe point every second of flight, as in a record.
            if flown_ticks.is_multiple_of(u64::from(config.rate_hz).max(1)) {
                crate::interrupt::check()?;
            }
            let state = sim.state();
            let [phi, theta, psi] = state.attitude();
            let ned = body_to_ned(state.velocity(), phi, theta, psi);
            // Errors in the heading's frame: forward and right.
            let (s, c) = psi.sin_cos();
            let along = |v: [f64; 3]| [c * v[0] + s * v[1], -s * v[0] + c * v[1]];
            let [fwd, right] = along(ned);
            let [fwd_target, right_target] = along(velocity_ned);
            let error = [fwd_target - fwd, right_target - right];
            for (i, e) in integral.iter_mut().zip(error) {
                *i = (*i + VELOCITY_INTEGRAL_GAIN * e * dt)
                    .clamp(-INTEGRAL_LIMIT_RAD, INTEGRAL_LIMIT_RAD);
            }
            let theta_demand = trim.theta - (VELOCITY_GAIN * error[0] + integral[0]);
            let phi_demand = trim.phi + (VELOCITY_GAIN * error[1] + integral[1]);
            let col = trim.controls[3] + CLIMB_GAIN * (ned[2] - velocity_ned[2]);
            let rc = RcInput {
                sticks: Controls {
                    lat: (phi_demand / max_angle) as f32,
                    lon: (theta_demand / max_angle) as f32,
                    ped: pedal,
                    col: col as f32,
                },
                throttle: HOVER_THROTTLE,
                arm: true,
                test_switch: false,
                mode: ModeSwitch::Middle,
                selector: board.selector,
            };
            board.set_truth(
                [reading.p, reading.q, reading.r].map(|v| v as f32),
                [reading.ax, reading.ay, reading.az].map(|v| v as f32),
            );
            board.unrecorded_tick(&rc);
            if flown_ticks.is_multiple_of(gnss_every) {
                let tick = board.stack.app().flight_controller().tick().wrapping_sub(1);
                let mut noisy = ned;
                for v in &mut noisy {
                    *v += GNSS_VELOCITY_NOISE_M_S * gnss_rng.normal_pair().0;
                }
                let heading = wrap_pi(psi + COMPASS_NOISE_RAD * gnss_rng.normal_pair().0);
                fixes.push(GnssFix {
                    tick,
                    velocity_ned: noisy,
                    heading,
                });
            }
            flown_ticks += 1;
            reading = sim.step(dt, board.flown);
        }
        let mode = board.stack.app().mode();
        if mode != Mode::Pilot {
            anyhow::bail!(
                "the board left the pilot mode in steady flight `{label}` ({})",
                mode.name()
            );
        }
    }
    Ok(SteadyFlights {
        log: board.log.take().unwrap_or_default(),
        fixes,
    })
}

/// The pedal stick that asks the board's heading hold for `turn_rate` [rad/s]: past the
/// dead band, the rest of the travel spans the yaw rate limit.
fn pedal_for(turn_rate: f64, pilot: &sweephold_firmware::app::pilot_mode::PilotModeGains) -> f32 {
    if turn_rate == 0.0 {
        return 0.0;
    }
    let band = f64::from(pilot.pedal_deadband);
    let share = (turn_rate.abs() / f64::from(pilot.yaw.max_rate_rad_s)).min(1.0);
    (turn_rate.signum() * (band + share * (1.0 - band))) as f32
}

/// A body velocity in the north, east, down axes (the 3-2-1 Euler rotation).
fn body_to_ned(v: [f64; 3], phi: f64, theta: f64, psi: f64) -> [f64; 3] {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    let [u, v, w] = v;
    [
        ct * cp * u + (sf * st * cp - cf * sp) * v + (cf * st * cp + sf * sp) * w,
        ct * sp * u + (sf * st * sp + cf * cp) * v + (cf * st * sp - sf * cp) * w,
        -st * u + sf * ct * v + cf * ct * w,
    ]
}

/// An angle in (−π, π].
fn wrap_pi(angle: f64) -> f64 {
    let wrapped = angle.rem_euclid(std::f64::consts::TAU);
    if wrapped > std::f64::consts::PI {
        wrapped - std::f64::consts::TAU
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn body_to_ned_inverts_the_identify_rotation() {
        let v = [0.7, -0.3, 0.2];
        let (phi, theta, psi) = (0.1, -0.2, 2.5);
        let ned = body_to_ned(v, phi, theta, psi);
        let back = sysid::steady::segments::ned_to_body(ned, phi, theta, psi);
        for k in 0..3 {
            assert!((back[k] - v[k]).abs() < 1e-12);
        }
    }
}
