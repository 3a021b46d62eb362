//! Pilot cues: what the board's status LED shows, one pattern per phase the pilot must
//! tell apart (disarmed, parameter store invalid, armed pilot mode, trim capture, sweep,
//! hold engaged, test done, aborted or refused).
//!
//! [`Cue`] is chosen from the application's state ([`CueState`]), and the LED's level
//! is a pure function of the cue and the ticks since the cue began ([`Cue::lit`]): every
//! pattern is 2 s long, cut into 40 steps of 50 ms, and starts with the cue, so a Done's
//! three flashes are seen from their first. [`StatusLed`] puts the level on any
//! `embedded-hal` 1.0 [`OutputPin`], writing the pin only when the level changes.
//!
//! Why these patterns: the states the pilot reads at rest (disarmed, store invalid,
//! done) are counted flashes (1, 2, 3 per 2 s); the states that run are rhythms (steady
//! in the pilot mode, 1 s on/off during the trim capture, 2 Hz during a sweep, mostly on
//! with short gaps while the hold is engaged); anything wrong (an abort, a refusal, a
//! failsafe) is a 10 Hz flicker, unlike any other. A test's end (done, aborted) and a
//! refusal are shown for [`END_CUE_S`] and then give way to the mode's own pattern.
//!
//! No allocation, no panic path; each call is a handful of integer operations.

use embedded_hal::digital::OutputPin;
use sweephold_protocol::{HoldState, Phase};

use super::modes::Mode;

/// Steps of one pattern.
pub const STEPS: u32 = 40;
/// Length of one step \[ms\].
pub const STEP_MS: u32 = 50;
/// How long a test's end (done, aborted) or a refusal is shown \[s\].
pub const END_CUE_S: u32 = 3;

/// What the pilot is told.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Cue {
    /// Disarmed, a valid parameter set in use: 1 flash of 100 ms per 2 s.
    Disarmed,
    /// Disarmed, the parameter store held no valid set (arming refused): 2 flashes.
    ParamsInvalid,
    /// Armed, stabilised pilot mode (and a test switch not yet engaged): steady on.
    Pilot,
    /// A test engaged, trim capture running (the sequencer's Armed and TrimCapture):
    /// 1 s on, 1 s off.
    TrimCapture,
    /// The excitation (fade in, sweep or pulses, fade out), hold released: 250 ms on,
    /// 250 ms off.
    Sweep,
    /// The excitation with the attitude hold engaged on an axis: 400 ms on, 100 ms off.
    HoldEngaged,
    /// The test ran to its end: 3 flashes per 2 s, for [`END_CUE_S`].
    Done,
    /// A test aborted, an arm or test request refused, or a failsafe: 50 ms on, 50 ms off.
    Aborted,
}

/// `count` flashes of `on` steps every `period` steps, from step 0, in a 40-step mask
/// (bit k: step k lit).
const fn flashes(count: u32, on: u32, period: u32) -> u64 {
    let mut mask = 0u64;
    let mut n = 0;
    while n < count {
        let mut k = 0;
        while k < on {
            mask |= 1 << (n * period + k);
            k += 1;
        }
        n += 1;
    }
    mask
}

impl Cue {
    /// Every cue, in the order of the documentation's table.
    pub const ALL: [Cue; 8] = [
        Cue::Disarmed,
        Cue::ParamsInvalid,
        Cue::Pilot,
        Cue::TrimCapture,
        Cue::Sweep,
        Cue::HoldEngaged,
        Cue::Done,
        Cue::Aborted,
    ];

    /// The pattern: bit k is step k (50 ms each) of the 2 s cycle.
    pub const fn mask(self) -> u64 {
        match self {
            Cue::Disarmed => const { flashes(1, 2, 40) },
            Cue::ParamsInvalid => const { flashes(2, 2, 4) },
            Cue::Pilot => const { flashes(1, 40, 40) },
            Cue::TrimCapture => const { flashes(1, 20, 40) },
            Cue::Sweep => const { flashes(4, 5, 10) },
            Cue::HoldEngaged => const { flashes(4, 8, 10) },
            Cue::Done => const { flashes(3, 2, 4) },
            Cue::Aborted => const { flashes(20, 1, 2) },
        }
    }

    /// Whether the LED is lit `ticks` control ticks after the cue began, at `rate_hz`
    /// ticks per second (a rate of 0 counts as 1).
    pub const fn lit(self, ticks: u32, rate_hz: u16) -> bool {
        let rate = if rate_hz == 0 { 1 } else { rate_hz as u32 };
        // Within the cycle first, so the product stays far below u32::MAX.
        let cycle_ticks = rate * (STEPS * STEP_MS / 1000);
        let ms = ticks % cycle_ticks * 1000 / rate;
        let step = ms / STEP_MS;
        self.mask() >> step & 1 == 1
    }

    /// Short snake_case name.
    pub const fn name(self) -> &'static str {
        match self {
            Cue::Disarmed => "disarmed",
            Cue::ParamsInvalid => "params_invalid",
            Cue::Pilot => "pilot",
            Cue::TrimCapture => "trim_capture",
            Cue::Sweep => "sweep",
            Cue::HoldEngaged => "hold_engaged",
            Cue::Done => "done",
            Cue::Aborted => "aborted",
        }
    }
}

/// What the cue is chosen from: the application's state after a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CueState {
    /// The application's mode.
    pub mode: Mode,
    /// The sequencer's phase.
    pub phase: Phase,
    /// The hold states of lat, lon, ped.
    pub hold: [HoldState; 3],
    /// A valid parameter set is in use.
    pub params_valid: bool,
    /// The test's end or refusal still shown ([`END_CUE_S`]), if any.
    pub ending: Option<Cue>,
}

impl CueState {
    /// The cue of this state. A running test shows its phase; then a recent end or
    /// refusal; then the mode (failsafes as [`Cue::Aborted`]).
    pub fn cue(&self) -> Cue {
        match self.phase {
            Phase::Armed | Phase::TrimCapture if self.mode == Mode::Test => {
                return Cue::TrimCapture
            }
            Phase::FadeIn | Phase::Sweep | Phase::FadeOut if self.mode == Mode::Test => {
                return if self.hold.contains(&HoldState::Engaged) {
                    Cue::HoldEngaged
                } else {
                    Cue::Sweep
                };
            }
            _ => {}
        }
        if let Some(ending) = self.ending {
            return ending;
        }
        match self.mode {
            Mode::Disarmed if self.params_valid => Cue::Disarmed,
            Mode::Disarmed => Cue::ParamsInvalid,
            Mode::Pilot | Mode::Test => Cue::Pilot,
            Mode::RcFailsafe | Mode::ImuFailsafe => Cue::Aborted,
        }
    }
}

/// Which cue shows and since when: the application's memory for the cues.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CueTracker {
    cue: Cue,
    /// The tick the cue began.
    since: u32,
    /// A test's end or a refusal, and the tick it was seen.
    ending: Option<(Cue, u32)>,
}

impl Default for CueTracker {
    fn default() -> Self {
        CueTracker {
            cue: Cue::Disarmed,
            since: 0,
            ending: None,
        }
    }
}

impl CueTracker {
    /// Note the state after the tick `tick` (at `rate_hz`): `ended` is a test's end seen
    /// in it (Done, or Aborted for an abort or a refusal); `state.ending` is filled in
    /// here from the ends still shown.
    pub fn update(&mut self, tick: u32, rate_hz: u16, ended: Option<Cue>, mut state: CueState) {
        if let Some(cue) = ended {
            self.ending = Some((cue, tick));
        }
        let shown_ticks = END_CUE_S.saturating_mul(u32::from(rate_hz));
        self.ending = self
            .ending
            .filter(|(_, at)| tick.wrapping_sub(*at) < shown_ticks);
        state.ending = self.ending.map(|(cue, _)| cue);
        let cue = state.cue();
        if cue != self.cue {
            self.cue = cue;
            self.since = tick;
        }
    }

    /// The cue now.
    pub fn cue(&self) -> Cue {
        self.cue
    }

    /// Whether the LED is lit at `tick`.
    pub fn lit(&self, tick: u32, rate_hz: u16) -> bool {
        self.cue.lit(tick.wrapping_sub(self.since), rate_hz)
    }
}

/// The status LED on an `embedded-hal` output pin.
#[derive(Debug)]
pub struct StatusLed<P> {
    pin: P,
    /// The LED lights when the pin is low (the SpeedyBee F405 V4's, like most boards').
    active_low: bool,
    /// The level written last; `None` before the first write.
    lit: Option<bool>,
}

impl<P: OutputPin> StatusLed<P> {
    /// The LED on `pin`, not yet driven.
    pub fn new(pin: P, active_low: bool) -> Self {
        StatusLed {
            pin,
            active_low,
            lit: None,
        }
    }

    /// Light the LED or not; the pin is written only when that changes. A pin error is
    /// ignored (a cue is no reason to stop flying) and the write retried next time.
    pub fn show(&mut self, lit: bool) {
        if self.lit == Some(lit) {
            return;
        }
        let high = lit != self.active_low;
        let written = if high {
            self.pin.set_high()
        } else {
            self.pin.set_low()
        };
        self.lit = written.is_ok().then_some(lit);
    }

    /// The pin.
    pub fn pin(&self) -> &P {
        &self.pin
    }
}
