//! `sweephold fc watch`: a live view of the board over its link, from the telemetry it
//! streams anyway (no request of its own but one parameter List at the start).
//!
//! One status line per `--every` seconds of board time (from the Samples' ticks and the
//! Header's rate): the mode (armed or not), the sequencer's phase, the test list entry
//! and engagement of the last Header, the attitude and rates, the command, and the
//! servo pulses the command makes through the board's mixer (built from the parameters
//! listed at the start; not shown when the board refuses the List, i.e. armed). Every
//! Event is a line of its own as it arrives (the same text as `decode --events`).
//! The receiver's raw channels are not in the telemetry and are not shown.
//!
//! [`Watcher`] turns frames into lines and is tested on its own; [`watch`] runs it on a
//! frame channel until `--count` lines, `--seconds` of wall time, or Ctrl-C.

use std::io::Write;
use std::time::{Duration, Instant};

use anyhow::Context;
use sweephold_firmware::mixer::MixerConfig;
use sweephold_protocol::{Event, FlightMode, Frame, Header, InputKind, Phase, Sample};

use crate::decode::event_text;
use crate::fly::frame_channel::{ByteWire, FrameChannel};
use crate::table::phase_name;

/// How long the board may stay silent before the watch fails.
pub const SILENCE_LIMIT: Duration = Duration::from_secs(5);

/// When a watch ends.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Limits {
    /// After this many status lines.
    pub count: Option<u64>,
    /// After this much wall time.
    pub seconds: Option<f64>,
}

/// The board as the telemetry shows it, and the lines it makes.
#[derive(Clone, Debug)]
pub struct Watcher {
    /// Board seconds between two status lines.
    every_s: f64,
    /// The last Header (its rate and test).
    header: Option<Header>,
    /// The mode from the last ModeChange (Disarmed at power-up).
    mode: FlightMode,
    /// Tick of the last status line.
    last_line_tick: Option<u32>,
    /// The board's mixer, for the servo pulses.
    mixer: Option<MixerConfig>,
}

impl Watcher {
    /// A watcher printing a status line every `every_s` board seconds; servo pulses
    /// through `mixer` when given.
    pub fn new(every_s: f64, mixer: Option<MixerConfig>) -> Self {
        Watcher {
            every_s,
            header: None,
            mode: FlightMode::Disarmed,
            last_line_tick: None,
            mixer,
        }
    }

    /// The lines `frame` makes: an Event's line, a status line when one is due, or none.
    /// The second value is whether a status line is among them.
    pub fn feed(&mut self, frame: &Frame) -> (Vec<String>, bool) {
        match frame {
            Frame::Header(header) => {
                self.header = Some(*header);
                (vec![header_line(header)], false)
            }
            Frame::Event(event) => {
                if let Event::ModeChange { to, .. } = event {
                    self.mode = *to;
                }
                (vec![format!("event {}", event_text(event))], false)
            }
            Frame::Sample(sample) => {
                let rate = f64::from(self.header.map_or(200, |h| h.rate_hz).max(1));
                let every_ticks = (self.every_s * rate).round().max(1.0) as u32;
                let due = self
                    .last_line_tick
                    .is_none_or(|last| sample.tick.wrapping_sub(last) >= every_ticks);
                if !due {
                    return (Vec::new(), false);
                }
                self.last_line_tick = Some(sample.tick);
                (vec![self.status_line(sample, rate)], true)
            }
            _ => (Vec::new(), false),
        }
    }

    fn status_line(&self, sample: &Sample, rate: f64) -> String {
        let m = &sample.meas;
        let c = &sample.command;
        let armed = if self.mode == FlightMode::Disarmed {
            "disarmed"
        } else {
            "armed"
        };
        let test = match self.header.and_then(|h| h.selection) {
            Some(s) => format!("entry {} #{}", s.entry, s.engagement),
            None => "-".to_string(),
        };
        let servos = self.mixer.map_or_else(
            || "servos ? (parameters not read)".to_string(),
            |mixer| {
                let us = sweephold_firmware::mix(&mixer, c);
                format!("servos {} {} {} {} us", us[0], us[1], us[2], us[3])
            },
        );
        let hold: Vec<&str> = sample
            .hold
            .iter()
            .map(|h| match h {
                sweephold_protocol::HoldState::Released => "-",
                sweephold_protocol::HoldState::Engaged => "H",
                sweephold_protocol::HoldState::Frozen => "F",
            })
            .collect();
        format!(
            "t {:>9.3} s  {} {:<12} phase {:<12} test {:<10} hold {}  \
             att {:+6.1} {:+6.1} {:+6.1} deg  rates {:+7.1} {:+7.1} {:+7.1} deg/s  \
             cmd {:+.3} {:+.3} {:+.3} {:+.3}  {servos}",
            f64::from(sample.tick) / rate,
            armed,
            self.mode.name(),
            phase_label(sample.phase),
            test,
            hold.concat(),
            m.phi.to_degrees(),
            m.theta.to_degrees(),
            m.psi.to_degrees(),
            m.p.to_degrees(),
            m.q.to_degrees(),
            m.r.to_degrees(),
            c.lat,
            c.lon,
            c.ped,
            c.col,
        )
    }
}

fn phase_label(phase: Phase) -> &'static str {
    phase_name(phase)
}

fn input_name(input: InputKind) -> &'static str {
    match input {
        InputKind::Sweep => "sweep",
        InputKind::Doublet => "doublet",
        InputKind::ThreeTwoOneOne => "3-2-1-1",
        InputKind::AdaptiveSweep => "adaptive sweep",
        InputKind::LoopSweep => "loop sweep",
    }
}

fn header_line(header: &Header) -> String {
    let selection = header.selection.map_or(String::new(), |s| {
        format!(", entry {} engagement {}", s.entry, s.engagement)
    });
    format!(
        "header {} at {} Hz, protocol {}: {} {}{selection}",
        header.vehicle.name(),
        header.rate_hz,
        header.protocol,
        header.test.primary.name(),
        input_name(header.test.input),
    )
}

/// Write the Header and Event lines of the frames in `bytes` (telemetry read before the
/// watch began); their Samples only bring the watcher up to date (no stale status lines).
pub fn replay(bytes: &[u8], watcher: &mut Watcher, out: &mut impl Write) -> anyhow::Result<()> {
    let mut decoder = sweephold_protocol::Decoder::new();
    for frame in decoder.feed(bytes).flatten() {
        let (lines, status) = watcher.feed(&frame);
        if status {
            continue;
        }
        for line in lines {
            writeln!(out, "{line}").context("cannot write to standard output")?;
        }
    }
    Ok(())
}

/// Read frames from `channel` and write the watcher's lines to `out` until `limits` or
/// `stop()` says so. Fails when the board stays silent for [`SILENCE_LIMIT`].
pub fn watch<W: ByteWire>(
    channel: &mut FrameChannel<W>,
    watcher: &mut Watcher,
    limits: Limits,
    out: &mut impl Write,
    stop: impl Fn() -> bool,
) -> anyhow::Result<u64> {
    let started = Instant::now();
    let mut lines = 0u64;
    let mut discarded = Vec::new();
    loop {
        if stop() {
            return Ok(lines);
        }
        if limits
            .seconds
            .is_some_and(|s| started.elapsed().as_secs_f64() >= s)
        {
            return Ok(lines);
        }
        let frame =
            match channel.read_until(SILENCE_LIMIT, "telemetry", |_| Some(true), &mut discarded) {
                Ok(frame) => frame,
                // A Ctrl-C at a terminal reaches the whole process group: QEMU ends too.
                Err(_) if stop() => return Ok(lines),
                Err(error) => return Err(error),
            };
        discarded.clear();
        let (text, status) = watcher.feed(&frame);
        for line in text {
            writeln!(out, "{line}").context("cannot write to standard output")?;
        }
        out.flush().context("cannot write to standard output")?;
        if status {
            lines += 1;
            if limits.count.is_some_and(|n| lines >= n) {
                return Ok(lines);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweephold_protocol::{Controls, HoldState, Measurements, TestSelection};

    fn sample(tick: u32) -> Frame {
        Frame::Sample(Sample {
            tick,
            phase: Phase::Sweep,
            primary: sweephold_protocol::Axis::Lat,
            sweep_omega: 1.0,
            hold: [HoldState::Released, HoldState::Engaged, HoldState::Frozen],
            command: Controls {
                lat: 0.25,
                lon: 0.0,
                ped: 0.0,
                col: 0.0,
            },
            sweep: Controls::default(),
            noise: Controls::default(),
            pilot: Controls::default(),
            meas: Measurements {
                phi: 10f32.to_radians(),
                ..Measurements::default()
            },
        })
    }

    /// Status lines every `every` board seconds at the Header's rate; events at once;
    /// the mode follows the ModeChange events; servo pulses through the mixer.
    #[test]
    fn lines_follow_the_telemetry() {
        let mut header = sweephold_protocol::synthetic::header();
        header.rate_hz = 100;
        header.selection = Some(TestSelection {
            entry: 3,
            engagement: 2,
        });
        let mixer = MixerConfig::trex700l();
        let mut watcher = Watcher::new(0.5, Some(mixer));
        assert!(!watcher.feed(&Frame::Header(header)).1);
        let change = Frame::Event(Event::ModeChange {
            tick: 0,
            from: FlightMode::Disarmed,
            to: FlightMode::Test,
        });
        let (lines, status) = watcher.feed(&change);
        assert_eq!(
            (lines, status),
            (
                vec!["event tick 0: mode disarmed -> test".to_string()],
                false
            )
        );
        let mut status_ticks = Vec::new();
        let mut last = String::new();
        for tick in 0..120 {
            let (lines, status) = watcher.feed(&sample(tick));
            if status {
                status_ticks.push(tick);
                last = lines[0].clone();
            }
        }
        assert_eq!(status_ticks, [0, 50, 100]);
        assert!(last.starts_with("t     1.000 s  armed test"), "{last}");
        assert!(last.contains("phase sweep"), "{last}");
        assert!(last.contains("test entry 3 #2"), "{last}");
        assert!(last.contains("hold -HF"), "{last}");
        assert!(last.contains("att  +10.0"), "{last}");
        let expected = sweephold_firmware::mix(
            &mixer,
            &Controls {
                lat: 0.25,
                ..Controls::default()
            },
        );
        let servos = format!(
            "servos {} {} {} {} us",
            expected[0], expected[1], expected[2], expected[3]
        );
        assert!(last.ends_with(&servos), "{last}");
    }
}
