//! `sweephold fc servo`: the bench servo test (protocol 1.8's ServoTest frames). One
//! servo goes to its centre, its lowest or highest pulse, or a pulse, for `--hold`; the
//! host repeats the request every [`REPEAT`] with a hold of [`BOARD_HOLD_MS`], so the
//! board puts the servo back at the disarmed output within that hold when the host stops
//! asking (the command ended, the cable pulled), then asks the board to stop.
//!
//! The board refuses the test armed, without a valid parameter set and in the loop, and
//! clamps every pulse to the servo's own limits (`firmware/src/servo_test.rs`).

use std::time::{Duration, Instant};

use anyhow::{anyhow, bail};
use sweephold_protocol::{
    Frame, ServoTarget, ServoTest, ServoTestEnd, ServoTestReply, ServoTestStatus,
};

use crate::fly::frame_channel::{ByteWire, FrameChannel};

/// How often the host repeats the request while it holds a servo.
pub const REPEAT: Duration = Duration::from_millis(200);
/// The hold each request asks of the board \[ms\]: the longest a servo stays off the
/// disarmed output after the host went quiet.
pub const BOARD_HOLD_MS: u16 = 500;
/// How long an answer may take.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(5);

/// Parse a servo target: `centre` (or `center`), `min`, `max`, or a pulse `1600us` /
/// `1600`.
pub fn parse_target(text: &str) -> Result<ServoTarget, String> {
    match text {
        "centre" | "center" => return Ok(ServoTarget::Centre),
        "min" => return Ok(ServoTarget::Min),
        "max" => return Ok(ServoTarget::Max),
        _ => {}
    }
    let digits = text.strip_suffix("us").unwrap_or(text);
    digits
        .parse::<u16>()
        .map(ServoTarget::PulseUs)
        .map_err(|_| {
            format!("`{text}` is no servo target (centre, min, max or a pulse like 1600us)")
        })
}

/// Parse a duration: `2s`, `500ms` or seconds (`1.5`).
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let (number, scale) = if let Some(ms) = text.strip_suffix("ms") {
        (ms, 1e-3)
    } else if let Some(s) = text.strip_suffix('s') {
        (s, 1.0)
    } else {
        (text, 1.0)
    };
    number
        .parse::<f64>()
        .ok()
        .map(|v| v * scale)
        .filter(|s| s.is_finite() && *s >= 0.0 && *s <= 3600.0)
        .map(Duration::from_secs_f64)
        .ok_or_else(|| format!("`{text}` is no duration (e.g. 2s, 500ms, 1.5)"))
}

/// Send `request` and return the board's answer to it (telemetry read past).
fn ask<W: ByteWire>(
    channel: &mut FrameChannel<W>,
    request: ServoTest,
) -> anyhow::Result<ServoTestReply> {
    channel.send(&Frame::ServoTest(request))?;
    let mut telemetry = Vec::new();
    let frame = channel.read_until(
        ANSWER_TIMEOUT,
        "ServoTestReply (firmware older than protocol 1.8? rebuild it with `cargo fw`)",
        |frame| Some(matches!(frame, Frame::ServoTestReply(reply) if answers(reply, &request))),
        &mut telemetry,
    )?;
    match frame {
        Frame::ServoTestReply(reply) => Ok(reply),
        other => Err(anyhow!("unexpected frame {other:?}")),
    }
}

/// Whether `reply` answers `request` (and is not the end of an earlier test).
fn answers(reply: &ServoTestReply, request: &ServoTest) -> bool {
    match reply.status {
        ServoTestStatus::Moving | ServoTestStatus::Refused(_) => reply.servo == request.servo,
        ServoTestStatus::Ended(ServoTestEnd::Stopped) => request.servo == 0,
        ServoTestStatus::Ended(_) => false,
    }
}

/// What a servo test did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Held {
    /// The pulse the board put the servo at \[µs\].
    pub pulse_us: u16,
    /// Requests the board answered with Moving.
    pub requests: u32,
}

/// Hold `servo` (1–4) at `target` for `hold`, then stop the test. A refusal ends it with
/// the board's reason.
pub fn hold_servo<W: ByteWire>(
    channel: &mut FrameChannel<W>,
    servo: u8,
    target: ServoTarget,
    hold: Duration,
) -> anyhow::Result<Held> {
    let request = ServoTest {
        servo,
        target,
        hold_ms: BOARD_HOLD_MS,
    };
    let started = Instant::now();
    let mut held = Held {
        pulse_us: 0,
        requests: 0,
    };
    loop {
        let reply = ask(channel, request)?;
        match reply.status {
            ServoTestStatus::Moving => {
                held.pulse_us = reply.pulse_us;
                held.requests += 1;
            }
            ServoTestStatus::Refused(why) => {
                let hint = match why.name() {
                    "armed" => " (the servo test runs on the ground only: arm switch off)",
                    "params_invalid" => " (save a parameter set first: `fc params save`)",
                    _ => "",
                };
                bail!(
                    "the flight controller refused the servo test: {}{hint}",
                    why.name()
                );
            }
            ServoTestStatus::Ended(end) => bail!("the servo test ended: {}", end.name()),
        }
        if started.elapsed() >= hold || crate::interrupt::requested() {
            break;
        }
        std::thread::sleep(REPEAT.min(hold.saturating_sub(started.elapsed())));
    }
    let stop = ServoTest {
        servo: 0,
        target: ServoTarget::Centre,
        hold_ms: 1,
    };
    ask(channel, stop)?;
    Ok(held)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_and_durations_parse() {
        assert_eq!(parse_target("centre"), Ok(ServoTarget::Centre));
        assert_eq!(parse_target("center"), Ok(ServoTarget::Centre));
        assert_eq!(parse_target("min"), Ok(ServoTarget::Min));
        assert_eq!(parse_target("max"), Ok(ServoTarget::Max));
        assert_eq!(parse_target("1600us"), Ok(ServoTarget::PulseUs(1600)));
        assert_eq!(parse_target("760"), Ok(ServoTarget::PulseUs(760)));
        for bad in ["", "us", "-5us", "70000us", "mid", "1600 us"] {
            assert!(parse_target(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_duration("2s"), Ok(Duration::from_secs(2)));
        assert_eq!(parse_duration("500ms"), Ok(Duration::from_millis(500)));
        assert_eq!(parse_duration("1.5"), Ok(Duration::from_millis(1500)));
        for bad in ["", "s", "-1s", "NaNs", "inf", "2h"] {
            assert!(parse_duration(bad).is_err(), "{bad}");
        }
    }

    /// A reply answers the request it names, never an earlier test's end.
    #[test]
    fn only_the_matching_reply_answers() {
        let request = ServoTest {
            servo: 2,
            target: ServoTarget::Max,
            hold_ms: 500,
        };
        let reply = |servo, status| ServoTestReply {
            servo,
            pulse_us: 0,
            status,
        };
        assert!(answers(&reply(2, ServoTestStatus::Moving), &request));
        assert!(!answers(&reply(1, ServoTestStatus::Moving), &request));
        assert!(!answers(
            &reply(2, ServoTestStatus::Ended(ServoTestEnd::TimedOut)),
            &request
        ));
        let stop = ServoTest {
            servo: 0,
            ..request
        };
        assert!(answers(
            &reply(0, ServoTestStatus::Ended(ServoTestEnd::Stopped)),
            &stop
        ));
    }
}
