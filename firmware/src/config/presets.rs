//! The presets' named settings that are not gains: the TREX 700L's command slew, the
//! holds' slew and the two presets' hold hysteresis, each with the measurement it rests on.

use crate::slew::{CommandSlew, HoldSlew};

const DEG: f32 = core::f32::consts::PI / 180.0;

/// The TREX 700L preset's command slew limit: the pedal at 4 /s, the simulated tail
/// servo's rate ([`CommandSlew::pedal`]), so that the recorded pedal command is one the
/// servo achieves; the heading hold otherwise outruns it on 7 % of the ticks. Over seeds
/// 1–10 it takes r/ped's J against the truth from 199–2764 to 31–63 and every seed's truth
/// J_ave down (docs/decisions/2026-11-24-trex700l-pedal-slew.md).
pub const TREX700L_SLEW: CommandSlew = CommandSlew::pedal(4.0);

/// The TREX 700L preset's hold hysteresis from trim (engage 4.5°, release 3°) and the slew
/// of its roll and pitch holds' share (3.6 /s, inside the servos' 4 /s, so the restoring
/// command faded over 0.8 s after a release,
/// [`Gains::trex700l`](crate::attitude_hold::Gains::trex700l), moves no faster than the
/// servos follow): cah lat–lon coherence 0.240 over seeds 1–10 (0.279 with the paper's 6° /
/// 4° and 0.3 s fades), every excursion within 9.2° of trim
/// (docs/decisions/2026-11-27-trex-cah-coherence-release.md).
pub const TREX700L_HOLD_SLEW: HoldSlew = HoldSlew {
    per_s: [3.6, 3.6, f32::INFINITY],
};
/// See [`TREX700L_HOLD_SLEW`].
pub const TREX700L_HOLD_ENGAGE_RAD: f32 = 4.5 * DEG;
/// See [`TREX700L_HOLD_SLEW`].
pub const TREX700L_HOLD_RELEASE_RAD: f32 = 3.0 * DEG;

/// The Bo-105 preset's hold hysteresis, from the captured trim: engage 5°, release 3.5°.
/// The paper's 6° / 4° from level let the aircraft (trim φ −2.6°, θ +2.2°) swing 9.9–11.0°
/// from its trim over seeds 1–10; these keep every cah excursion within 8.6°, the lat–lon
/// coherence at 0.239 and every identification bar (same decision file).
pub const BO105_HOLD_ENGAGE_RAD: f32 = 5.0 * DEG;
/// See [`BO105_HOLD_ENGAGE_RAD`].
pub const BO105_HOLD_RELEASE_RAD: f32 = 3.5 * DEG;
