//! Failsafes: the receiver and IMU monitors and the policies applied when either fails.
//!
//! # Receiver lost (armed)
//!
//! A helicopter in flight must not lose its rotor to a radio glitch, and without the
//! pilot nothing may take it somewhere new. On the first tick without a valid frame:
//!
//! * a running test is aborted ([`AbortReason::RcLost`](sweephold_protocol::AbortReason));
//! * the pilot-mode loops stabilise about the captured trim: Level stick towards the
//!   trim attitude φ, θ that the sequencer captured in this armed period (level, 0/0,
//!   if none was captured), heading held where it is, taken over bumplessly from the
//!   last command; without a valid attitude the loops hold zero rates;
//! * the collective and the throttle are held at their last values;
//! * after `rc_hold_s` the collective is lowered by `rc_descent_collective` over
//!   `rc_descent_ramp_s` and kept there: a slow, steady descent (heave is stable, so a
//!   fixed collective decrement settles at a descent rate of a few m/s at most);
//! * after `rc_cut_s` without the signal the board disarms (throttle cut, servos safe):
//!   an aircraft descending from a test height has landed by then, and a powered rotor
//!   on the ground with nobody at the sticks is the larger hazard. An aircraft still in
//!   the air then is lost either way.
//!
//! The signal counts as regained after `rc_regain_s` of valid frames in a row; only
//! then does the pilot mode (and the pilot's collective and throttle) come back, taken
//! over bumplessly. A valid frame with the arm switch off disarms at once, regained or
//! not. When disarmed, a lost receiver keeps the throttle cut and blocks arming.
//!
//! # IMU fault (armed)
//!
//! No rates, no loops. A fault is the driver's `Fault` or `Calibrating` status, any
//! non-finite rate or specific force, or more than `SafetyLimits::stale_limit_ticks`
//! ticks in a row without a fresh sample. On the tick it is seen:
//!
//! * a running test is aborted (`ImuFault`);
//! * the command is the trim sticks plus a fraction (`imu_direct_authority`) of the
//!   pilot's lat, lon and ped sticks, and the pilot's collective: the least-bad output
//!   without rate feedback. Trim sticks are the sequencer's captured trim when the fault
//!   hits during a test's excitation, else the loops' trim estimate (integrator plus
//!   transfer remainder). The fraction is small because, without damping, full stick
//!   would flip a flybarless rotor; it lets the pilot steer towards a landing;
//! * the throttle follows the pilot (held if the receiver is lost as well).
//!
//! After `imu_recover_s` of healthy samples in a row the loops come back (bumplessly),
//! in the pilot mode, or in the receiver failsafe if the signal is not back. While
//! disarmed an IMU fault blocks arming.
//!
//! An invalid attitude estimate with healthy rates is no fault for the rate loops: a
//! Level stick flies as Rate and the heading hold is off. It does end a running test
//! (`ImuFault`: the attitude hold needs the attitude).

use sweephold_protocol::Controls;

use super::inputs::{ImuFaultKind, ImuInput, ImuStatus, RcInput, Receiver};
use super::throttle::unit_fraction;
use crate::attitude_hold::clamp_finite;

/// Failsafe settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FailsafeSettings {
    /// Valid frames in a row for the signal to count as regained \[s\].
    pub rc_regain_s: f32,
    /// Time the collective is held after the loss before the descent \[s\].
    pub rc_hold_s: f32,
    /// Collective decrement of the descent (stick fraction).
    pub rc_descent_collective: f32,
    /// Time over which the decrement is applied \[s\].
    pub rc_descent_ramp_s: f32,
    /// Time after the loss at which the board disarms \[s\].
    pub rc_cut_s: f32,
    /// Healthy samples in a row for the IMU to count as recovered \[s\].
    pub imu_recover_s: f32,
    /// IMU failsafe: fraction of the pilot's lat, lon, ped sticks added to the trim.
    pub imu_direct_authority: [f32; 3],
}

impl FailsafeSettings {
    /// Defaults for a model helicopter: regained after 0.2 s of valid frames (a frame
    /// glitch costs the pilot 0.2 s, a flickering link does not hand control back and
    /// forth); hold 1 s (covers a receiver's re-sync), then lower the collective by 0.08
    /// (about 1° of blade pitch on a TREX 700L's 12° per stick) over 2 s; disarm after
    /// 30 s; IMU recovered after 0.5 s; 20 % direct authority on lat, lon, ped.
    pub const fn standard() -> Self {
        FailsafeSettings {
            rc_regain_s: 0.2,
            rc_hold_s: 1.0,
            rc_descent_collective: 0.08,
            rc_descent_ramp_s: 2.0,
            rc_cut_s: 30.0,
            imu_recover_s: 0.5,
            imu_direct_authority: [0.2, 0.2, 0.2],
        }
    }

    /// Whether every time is finite and ≥ 0 (the cut after the hold) and every fraction
    /// in [0, 1].
    pub fn is_valid(&self) -> bool {
        let time = |v: f32| v.is_finite() && v >= 0.0;
        let fraction = |v: f32| v.is_finite() && (0.0..=1.0).contains(&v);
        time(self.rc_regain_s)
            && time(self.rc_hold_s)
            && time(self.rc_descent_ramp_s)
            && time(self.rc_cut_s)
            && self.rc_cut_s > self.rc_hold_s
            && time(self.imu_recover_s)
            && fraction(self.rc_descent_collective)
            && self.imu_direct_authority.iter().all(|&v| fraction(v))
    }
}

/// Why the IMU's data cannot be used this tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ImuProblem {
    /// The driver reports a fault.
    Fault(ImuFaultKind),
    /// The gyro bias calibration is running.
    Calibrating,
    /// A rate or specific-force value is NaN or infinite.
    NotFinite,
    /// No fresh sample for more than the stale limit.
    Stale,
}

/// This tick's IMU, as the application uses it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuView {
    /// Health this tick.
    pub health: Result<(), ImuProblem>,
    /// Healthy for the recovery time in a row.
    pub recovered: bool,
    /// φ, θ, ψ if the IMU is healthy and the estimate valid and finite.
    pub attitude: Option<[f32; 3]>,
    /// p, q, r (meaningful only when healthy).
    pub rates: [f32; 3],
}

/// Tracks the IMU's freshness and health over ticks, and the sample counter the
/// sequencer's stale check reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ImuMonitor {
    seq: u32,
    stale_ticks: u32,
    healthy_ticks: u32,
}

impl ImuMonitor {
    /// The sample counter: advanced by every fresh sample.
    pub fn seq(&self) -> u32 {
        self.seq
    }

    /// Observe this tick's sample; `stale_limit` ticks without a fresh sample are
    /// tolerated, one more is a fault; `recover_ticks` healthy ticks in a row count as
    /// recovered.
    pub fn observe(&mut self, imu: &ImuInput, stale_limit: u32, recover_ticks: u32) -> ImuView {
        if imu.fresh {
            self.seq = self.seq.wrapping_add(1);
            self.stale_ticks = 0;
        } else {
            self.stale_ticks = self.stale_ticks.saturating_add(1);
        }
        let finite = [imu.p, imu.q, imu.r, imu.ax, imu.ay, imu.az]
            .iter()
            .all(|v| v.is_finite());
        let health = match imu.status {
            ImuStatus::Fault(kind) => Err(ImuProblem::Fault(kind)),
            ImuStatus::Calibrating => Err(ImuProblem::Calibrating),
            ImuStatus::Ok if !finite => Err(ImuProblem::NotFinite),
            ImuStatus::Ok if self.stale_ticks > stale_limit => Err(ImuProblem::Stale),
            ImuStatus::Ok => Ok(()),
        };
        self.healthy_ticks = if health.is_ok() {
            self.healthy_ticks.saturating_add(1)
        } else {
            0
        };
        let attitude_finite = [imu.phi, imu.theta, imu.psi].iter().all(|v| v.is_finite());
        ImuView {
            health,
            recovered: self.healthy_ticks >= recover_ticks.max(1),
            attitude: (health.is_ok() && imu.attitude_valid && attitude_finite)
                .then_some([imu.phi, imu.theta, imu.psi]),
            rates: [imu.p, imu.q, imu.r],
        }
    }
}

/// Tracks the receiver's validity over ticks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RcMonitor {
    valid_ticks: u32,
}

impl RcMonitor {
    /// Observe this tick's receiver state; returns the frame if valid, its sticks
    /// clamped to [−1, 1] and throttle to [0, 1]. A frame with any non-finite channel
    /// is not valid.
    pub fn observe(&mut self, receiver: &Receiver) -> Option<RcInput> {
        let frame = match receiver {
            Receiver::Valid(rc)
                if rc.sticks.to_array().iter().all(|v| v.is_finite())
                    && rc.throttle.is_finite() =>
            {
                Some(RcInput {
                    sticks: Controls::from_array(
                        rc.sticks.to_array().map(|v| clamp_finite(v, 1.0)),
                    ),
                    throttle: unit_fraction(rc.throttle),
                    ..*rc
                })
            }
            _ => None,
        };
        self.valid_ticks = if frame.is_some() {
            self.valid_ticks.saturating_add(1)
        } else {
            0
        };
        frame
    }

    /// Valid frames in a row, this tick's included.
    pub fn valid_ticks(&self) -> u32 {
        self.valid_ticks
    }
}

/// What is held while the receiver is lost (armed), from the first lost tick until the
/// signal counts as regained.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RcLossHold {
    /// Collective command at the loss.
    pub collective: f32,
    /// Throttle output at the loss.
    pub throttle: f32,
    /// Ticks since the loss.
    pub ticks: u32,
}

impl RcLossHold {
    /// The collective `ticks` after the loss: held, then lowered (see the module
    /// documentation).
    pub fn collective(&self, settings: &FailsafeSettings, dt_s: f32) -> f32 {
        let t = self.ticks as f32 * dt_s;
        let into_descent = t - settings.rc_hold_s;
        let fraction = if into_descent <= 0.0 {
            0.0
        } else if settings.rc_descent_ramp_s > 0.0 {
            unit_fraction(into_descent / settings.rc_descent_ramp_s)
        } else {
            1.0
        };
        clamp_finite(
            self.collective - fraction * settings.rc_descent_collective,
            1.0,
        )
    }

    /// Whether the loss has lasted `rc_cut_s`.
    pub fn expired(&self, settings: &FailsafeSettings, dt_s: f32) -> bool {
        self.ticks as f32 * dt_s >= settings.rc_cut_s
    }
}

/// The IMU failsafe's command: `trim` (lat, lon, ped) plus `authority` times the pilot's
/// sticks (none without a usable receiver), and `collective`.
pub fn imu_failsafe_command(
    trim: [f32; 3],
    sticks: Option<&Controls>,
    authority: [f32; 3],
    collective: f32,
) -> Controls {
    let pilot = sticks.map_or([0.0; 3], |s| [s.lat, s.lon, s.ped]);
    let mut out = [0.0; 3];
    for (((out, trim), pilot), authority) in out.iter_mut().zip(trim).zip(pilot).zip(authority) {
        *out = clamp_finite(trim + authority * pilot, 1.0);
    }
    let [lat, lon, ped] = out;
    Controls {
        lat,
        lon,
        ped,
        col: clamp_finite(collective, 1.0),
    }
}
