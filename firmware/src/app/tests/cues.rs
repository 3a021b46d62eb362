//! The status LED through the whole application, on a mock pin: in every phase the
//! pilot must tell apart, the pattern seen over two seconds of ticks is that phase's
//! (flashes and lit time as `docs/board-application.md` lists them), and no two phases
//! look alike.

use super::*;
use crate::app::cues::{Cue, StatusLed, END_CUE_S};
use embedded_hal::digital::{ErrorType, OutputPin};

/// A pin that remembers its level and counts its writes.
#[derive(Debug, Default)]
struct MockPin {
    high: Option<bool>,
    writes: u32,
}

impl ErrorType for MockPin {
    type Error = core::convert::Infallible;
}

impl OutputPin for MockPin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.high = Some(false);
        self.writes += 1;
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.high = Some(true);
        self.writes += 1;
        Ok(())
    }
}

/// What the pilot sees in one 2 s window: flashes (off → on changes) and lit time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Seen {
    flashes: u32,
    lit_ms: u32,
}

/// The documented pattern of each phase (docs/board-application.md, "Pilot cues"),
/// written out here rather than taken from the masks: flashes per 2 s, lit ms per 2 s.
fn documented(cue: Cue) -> Seen {
    let (flashes, lit_ms) = match cue {
        Cue::Disarmed => (1, 100),
        Cue::ParamsInvalid => (2, 200),
        Cue::Pilot => (0, 2000),
        Cue::TrimCapture => (1, 1000),
        Cue::Sweep => (4, 1000),
        Cue::HoldEngaged => (4, 1600),
        Cue::Done => (3, 300),
        Cue::Aborted => (20, 1000),
    };
    Seen { flashes, lit_ms }
}

/// Ticks of one 2 s window at the tests' 200 Hz.
const WINDOW: usize = 400;

/// Tick `rig` for one window plus one tick with the LED (active low) on a mock pin,
/// `keep` run before each tick to hold the phase; returns what was seen and the cues
/// the application reported meanwhile.
fn watch(rig: &mut Rig, mut keep: impl FnMut(&mut Rig)) -> (Seen, Vec<Cue>) {
    let mut led = StatusLed::new(MockPin::default(), true);
    let mut lit = Vec::new();
    let mut cues = Vec::new();
    for _ in 0..=WINDOW {
        keep(rig);
        rig.tick();
        led.show(rig.app.status_led());
        // Active low: lit while the pin is low.
        lit.push(led.pin().high == Some(false));
        cues.push(rig.app.cue());
    }
    let flashes = lit.windows(2).filter(|w| !w[0] && w[1]).count() as u32;
    let changes = lit.windows(2).filter(|w| w[0] != w[1]).count() as u32;
    assert!(
        led.pin().writes <= changes + 1,
        "the pin is written only when the level changes: {} writes, {changes} changes",
        led.pin().writes
    );
    let lit_ms = lit[..WINDOW].iter().filter(|on| **on).count() as u32 * 5;
    cues.dedup();
    (Seen { flashes, lit_ms }, cues)
}

/// A rig in the state whose cue is `cue`, and what keeps it there.
fn rig_showing(cue: Cue) -> (Rig, fn(&mut Rig)) {
    fn nothing(_: &mut Rig) {}
    fn tilted(rig: &mut Rig) {
        // Off-axis pitch beyond the 6° engage angle, inside the 20° abort limit.
        rig.imu.theta = 8.0 * DEG;
    }
    match cue {
        Cue::Disarmed => (Rig::in_mode(Mode::Disarmed), nothing),
        Cue::ParamsInvalid => {
            let mut rig = Rig::in_mode(Mode::Disarmed);
            rig.app.set_params_valid(false);
            rig.tick();
            (rig, nothing)
        }
        Cue::Pilot => (Rig::in_mode(Mode::Pilot), nothing),
        Cue::TrimCapture => {
            let mut config = test_config();
            config.flight.trim_capture_s = 5.0;
            let mut rig = Rig::armed(config);
            rig.start_test();
            (rig, nothing)
        }
        Cue::Sweep => (Rig::in_phase(Phase::Sweep), nothing),
        Cue::HoldEngaged => {
            let mut rig = Rig::in_phase(Phase::Sweep);
            tilted(&mut rig);
            rig.tick();
            assert!(rig
                .app
                .flight_controller()
                .hold_states()
                .contains(&HoldState::Engaged));
            (rig, tilted)
        }
        Cue::Done => (Rig::after_test(Phase::Done), nothing),
        Cue::Aborted => (Rig::after_test(Phase::Aborted), nothing),
    }
}

#[test]
fn every_phase_shows_its_own_pattern_on_the_led() {
    let mut seen_by_cue = Vec::new();
    for cue in Cue::ALL {
        let (mut rig, keep) = rig_showing(cue);
        assert_eq!(rig.app.cue(), cue, "set up for {}", cue.name());
        let (seen, cues) = watch(&mut rig, keep);
        assert_eq!(cues, [cue], "the cue held for the window: {}", cue.name());
        assert_eq!(seen, documented(cue), "{}", cue.name());
        seen_by_cue.push((cue, seen));
    }
    for (i, (a, seen_a)) in seen_by_cue.iter().enumerate() {
        for (b, seen_b) in &seen_by_cue[i + 1..] {
            assert_ne!(seen_a, seen_b, "{} and {} look alike", a.name(), b.name());
        }
    }
}

/// A refused arm request and both failsafes show the abort's flicker; a test's end
/// gives way to the mode's pattern after `END_CUE_S`.
#[test]
fn refusals_and_failsafes_flicker_and_ends_time_out() {
    let mut rig = Rig::in_mode(Mode::Disarmed);
    rig.rc.throttle = 0.5;
    rig.rc.arm = false;
    rig.tick();
    rig.rc.arm = true;
    assert!(rig.tick().refused.is_some());
    assert_eq!(rig.app.cue(), Cue::Aborted);
    rig.ticks(END_CUE_S as usize * 200);
    assert_eq!(rig.app.cue(), Cue::Disarmed);

    for mode in [Mode::RcFailsafe, Mode::ImuFailsafe] {
        let mut rig = Rig::in_mode(mode);
        let keep: fn(&mut Rig) = |_| {};
        let (seen, _) = watch(&mut rig, keep);
        assert_eq!(rig.app.mode(), mode);
        assert_eq!(seen, documented(Cue::Aborted), "{mode:?}");
    }

    let mut rig = Rig::after_test(Phase::Done);
    rig.ticks(END_CUE_S as usize * 200 - 2);
    assert_eq!(rig.app.cue(), Cue::Done);
    rig.ticks(2);
    assert_eq!(rig.app.cue(), Cue::Pilot);
}

/// The pattern starts with its cue: a Done's first flash is lit on the tick the test
/// ends.
#[test]
fn a_pattern_starts_with_its_cue() {
    let mut rig = Rig::in_phase(Phase::Sweep);
    let out = rig.run_until_phase(Phase::Done);
    assert_eq!(out.mode, Mode::Test);
    assert_eq!(rig.app.cue(), Cue::Done);
    assert!(rig.app.status_led());
}
