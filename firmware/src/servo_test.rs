//! The bench servo test (protocol 1.8's [`ServoTest`] frames): one servo put at its
//! centre, its limits or a pulse while the board is disarmed, back to the disarmed output
//! when the host stops asking. The board's runner feeds it the host's requests and,
//! every control tick, the board application's servo pulses; it overrides one of them
//! only while the application is disarmed.
//!
//! Safety rules, each tested below: nothing moves armed (a request is refused, and a
//! running test ends on the first armed tick, whose pulses are the application's); a
//! pulse never leaves the servo's own limits (the mixer's `min_us`/`max_us`); a host that
//! goes quiet gets the servo back after its hold (at most [`MAX_SERVO_HOLD_MS`]).
//!
//! No allocation, no panic path, constant time per call.

use sweephold_protocol::{
    ServoTarget, ServoTest, ServoTestEnd, ServoTestRefusal, ServoTestReply, ServoTestStatus,
    MAX_SERVO_HOLD_MS,
};

use crate::mixer::{MixerConfig, ServoConfig};

/// The servo a test holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Held {
    /// 0-based output index (swash 1, 2, 3, tail).
    index: usize,
    pulse_us: u16,
    /// Control ticks left before it times out.
    ticks_left: u32,
}

/// The servo test's state: no test, or one servo held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServoTester {
    held: Option<Held>,
}

/// The configuration of output `index` (0-based).
fn servo_config(mixer: &MixerConfig, index: usize) -> Option<&ServoConfig> {
    match index {
        0..=2 => mixer.swash.get(index),
        3 => Some(&mixer.tail),
        _ => None,
    }
}

/// The pulse `target` asks of `servo`, within its limits.
pub fn target_pulse(servo: &ServoConfig, target: ServoTarget) -> u16 {
    let (low, high) = (
        servo.min_us.min(servo.max_us),
        servo.max_us.max(servo.min_us),
    );
    match target {
        ServoTarget::Centre => servo.centre_us,
        ServoTarget::Min => servo.min_us,
        ServoTarget::Max => servo.max_us,
        ServoTarget::PulseUs(us) => us,
    }
    .clamp(low, high)
}

fn reply(servo: u8, pulse_us: u16, status: ServoTestStatus) -> ServoTestReply {
    ServoTestReply {
        servo,
        pulse_us,
        status,
    }
}

impl ServoTester {
    /// Whether a servo is held.
    pub fn active(&self) -> bool {
        self.held.is_some()
    }

    /// A host's request. `refused` is the board's reason to refuse any request (armed,
    /// no valid parameters, in the loop), checked first; the pulse comes from `mixer`'s
    /// servo limits; the hold is counted in control ticks at `rate_hz`.
    pub fn request(
        &mut self,
        request: &ServoTest,
        refused: Option<ServoTestRefusal>,
        mixer: &MixerConfig,
        rate_hz: u16,
    ) -> ServoTestReply {
        let refuse = |why| reply(request.servo, 0, ServoTestStatus::Refused(why));
        if let Some(why) = refused {
            return refuse(why);
        }
        if request.servo == 0 {
            self.held = None;
            return reply(0, 0, ServoTestStatus::Ended(ServoTestEnd::Stopped));
        }
        let index = usize::from(request.servo - 1);
        let Some(servo) = servo_config(mixer, index) else {
            return refuse(ServoTestRefusal::NoSuchServo);
        };
        if request.hold_ms == 0 || request.hold_ms > MAX_SERVO_HOLD_MS {
            return refuse(ServoTestRefusal::HoldOutOfRange);
        }
        let pulse_us = target_pulse(servo, request.target);
        let ticks = u32::from(request.hold_ms) * u32::from(rate_hz) / 1000;
        self.held = Some(Held {
            index,
            pulse_us,
            ticks_left: ticks.max(1),
        });
        reply(request.servo, pulse_us, ServoTestStatus::Moving)
    }

    /// One control tick: `servo_us` are the application's pulses of the tick; the held
    /// servo's replaces its own while `disarmed`. Returns the end of the test when it
    /// ends in this tick (timed out, or armed: then nothing is replaced).
    pub fn apply(&mut self, disarmed: bool, servo_us: &mut [u16; 4]) -> Option<ServoTestReply> {
        let held = self.held?;
        let servo = (held.index + 1) as u8;
        if !disarmed {
            self.held = None;
            return Some(reply(servo, 0, ServoTestStatus::Ended(ServoTestEnd::Armed)));
        }
        if held.ticks_left == 0 {
            self.held = None;
            return Some(reply(
                servo,
                0,
                ServoTestStatus::Ended(ServoTestEnd::TimedOut),
            ));
        }
        if let Some(pulse) = servo_us.get_mut(held.index) {
            *pulse = held.pulse_us;
        }
        self.held = Some(Held {
            ticks_left: held.ticks_left - 1,
            ..held
        });
        None
    }

    /// End a test without a word (the board leaves the board application).
    pub fn stop(&mut self) {
        self.held = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CENTRES: [u16; 4] = [1520; 4];

    fn mixer() -> MixerConfig {
        let mut mixer = MixerConfig::trex700l();
        mixer.tail.centre_us = 760;
        mixer.tail.min_us = 560;
        mixer.tail.max_us = 960;
        mixer
    }

    fn ask(
        tester: &mut ServoTester,
        servo: u8,
        target: ServoTarget,
        hold_ms: u16,
    ) -> ServoTestReply {
        tester.request(
            &ServoTest {
                servo,
                target,
                hold_ms,
            },
            None,
            &mixer(),
            200,
        )
    }

    #[test]
    fn a_servo_goes_to_its_target_within_its_limits() {
        let m = mixer();
        let mut tester = ServoTester::default();
        for (target, swash, tail) in [
            (ServoTarget::Centre, m.swash[1].centre_us, 760),
            (ServoTarget::Min, m.swash[1].min_us, 560),
            (ServoTarget::Max, m.swash[1].max_us, 960),
            (ServoTarget::PulseUs(1600), 1600, 960),
            (ServoTarget::PulseUs(3000), m.swash[1].max_us, 960),
            (ServoTarget::PulseUs(0), m.swash[1].min_us, 560),
        ] {
            let r = ask(&mut tester, 2, target, 100);
            assert_eq!(
                (r.servo, r.pulse_us, r.status),
                (2, swash, ServoTestStatus::Moving)
            );
            let mut out = CENTRES;
            assert_eq!(tester.apply(true, &mut out), None);
            assert_eq!(out, [1520, swash, 1520, 1520], "{target:?}");
            assert_eq!(
                ask(&mut tester, 4, target, 100).pulse_us,
                tail,
                "{target:?}"
            );
        }
    }

    #[test]
    fn the_servo_returns_when_the_host_goes_quiet() {
        let mut tester = ServoTester::default();
        // 100 ms at 200 Hz: 20 ticks held, the 21st is the disarmed output again.
        ask(&mut tester, 1, ServoTarget::Max, 100);
        for tick in 0..20 {
            let mut out = CENTRES;
            assert_eq!(tester.apply(true, &mut out), None, "tick {tick}");
            assert_ne!(out, CENTRES);
        }
        let mut out = CENTRES;
        let end = tester.apply(true, &mut out).expect("the end");
        assert_eq!(end.status, ServoTestStatus::Ended(ServoTestEnd::TimedOut));
        assert_eq!(out, CENTRES);
        assert!(!tester.active());
        // A repeated request starts the hold afresh.
        ask(&mut tester, 1, ServoTarget::Max, 100);
        for _ in 0..15 {
            tester.apply(true, &mut CENTRES.clone());
        }
        ask(&mut tester, 1, ServoTarget::Max, 100);
        for _ in 0..20 {
            assert_eq!(tester.apply(true, &mut CENTRES.clone()), None);
        }
    }

    #[test]
    fn nothing_moves_armed() {
        let mut tester = ServoTester::default();
        let r = tester.request(
            &ServoTest {
                servo: 1,
                target: ServoTarget::Max,
                hold_ms: 500,
            },
            Some(ServoTestRefusal::Armed),
            &mixer(),
            200,
        );
        assert_eq!(r.status, ServoTestStatus::Refused(ServoTestRefusal::Armed));
        assert!(!tester.active());
        // Armed while a test runs: the tick's pulses are the application's.
        ask(&mut tester, 1, ServoTarget::Max, 500);
        let armed_pulses = [1400, 1500, 1600, 1700];
        let mut out = armed_pulses;
        let end = tester.apply(false, &mut out).expect("the end");
        assert_eq!(end.status, ServoTestStatus::Ended(ServoTestEnd::Armed));
        assert_eq!(out, armed_pulses);
        assert_eq!(tester.apply(true, &mut out), None);
        assert_eq!(out, armed_pulses);
    }

    #[test]
    fn stops_and_refusals() {
        let mut tester = ServoTester::default();
        ask(&mut tester, 3, ServoTarget::Min, 500);
        let stop = ask(&mut tester, 0, ServoTarget::Centre, 1);
        assert_eq!(stop.status, ServoTestStatus::Ended(ServoTestEnd::Stopped));
        assert!(!tester.active());
        for (servo, hold, why) in [
            (5, 100, ServoTestRefusal::NoSuchServo),
            (255, 100, ServoTestRefusal::NoSuchServo),
            (1, 0, ServoTestRefusal::HoldOutOfRange),
            (1, MAX_SERVO_HOLD_MS + 1, ServoTestRefusal::HoldOutOfRange),
        ] {
            let r = ask(&mut tester, servo, ServoTarget::Centre, hold);
            assert_eq!(r.status, ServoTestStatus::Refused(why));
            assert!(!tester.active());
        }
    }
}
