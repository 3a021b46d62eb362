//! The lockstep frame exchange with a flight controller over any byte stream: the part
//! of the protocol the QEMU links (`link_qemu`) and the serial link (`link_serial`)
//! share.
//!
//! Per record: Configure → (Header) ConfigureResult. Per tick: SensorIn → the tick's
//! Events and Sample → the ActuatorOut answering the SensorIn's `seq`. Everything before
//! that ActuatorOut is handed on as raw bytes, exactly as received.

use std::io::ErrorKind;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail};
use sweephold_firmware::{Config, FlightController};
use sweephold_protocol::codec::{encode_to_vec, DELIMITER};
use sweephold_protocol::decoder::decode_frame;
use sweephold_protocol::{
    ActuatorOut, ConfigureResult, Event, Frame, FrameError, LinkConfig, SensorIn,
};

/// A byte stream to a flight controller.
pub trait ByteWire {
    /// Write all of `bytes`.
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()>;

    /// Read what is there, waiting at most `timeout`; `Err(TimedOut)` (or `WouldBlock`)
    /// when nothing came, `Ok(0)` when the other end closed.
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize>;

    /// A one-line error saying `what` went wrong, with whatever this wire knows about
    /// its other end (the emulator's state, the port's name).
    fn failure(&mut self, what: &str) -> anyhow::Error;
}

/// What a flight controller can be told at run time: a configuration the Configure
/// frame carries exactly, i.e. the vehicle's preset for the primary axis with another
/// rate and test (what the board image builds from it, `board/runner.rs`).
pub fn link_config(config: &Config) -> anyhow::Result<LinkConfig> {
    let mut preset = Config::preset(config.vehicle, config.test.primary);
    preset.rate_hz = config.rate_hz;
    preset.test = config.test;
    if preset != *config {
        bail!(
            "the link can only change the vehicle, rate and test of the image's preset; \
             this configuration differs in other settings (gains, mixer, limits, trim \
             capture): build an image with them"
        );
    }
    Ok(LinkConfig {
        vehicle: config.vehicle,
        rate_hz: config.rate_hz,
        test: config.test,
    })
}

/// `Ok` when the flight controller accepted `config`, else an error naming why it
/// refused (found by validating the same configuration with this host's firmware library).
pub fn check_configure_answer(config: &Config, answer: ConfigureResult) -> anyhow::Result<()> {
    if answer.accepted {
        return Ok(());
    }
    let reason = FlightController::new(*config)
        .err()
        .map_or("a reason this host's firmware library does not see", |e| {
            e.message()
        });
    bail!(
        "the flight controller refused the configuration (ConfigError #{}): {reason}",
        answer.refusal
    )
}

/// A [`ByteWire`] and the bytes received from it not yet handed out.
pub struct FrameChannel<W> {
    wire: W,
    /// Bytes received and not yet handed out (the start of a frame, or frames after the
    /// one that closed the last exchange).
    pending: Vec<u8>,
    /// Where in `pending` the search for the next delimiter resumes.
    scanned: usize,
}

impl<W: ByteWire> FrameChannel<W> {
    /// A channel over `wire`, nothing received yet.
    pub fn new(wire: W) -> Self {
        FrameChannel {
            wire,
            pending: Vec::with_capacity(4096),
            scanned: 0,
        }
    }

    /// The wire.
    pub fn wire_mut(&mut self) -> &mut W {
        &mut self.wire
    }

    /// The same channel (bytes received and not handed out kept) over the wire `wrap`
    /// makes of this one's.
    pub fn map_wire<V>(self, wrap: impl FnOnce(W) -> V) -> FrameChannel<V> {
        FrameChannel {
            wire: wrap(self.wire),
            pending: self.pending,
            scanned: self.scanned,
        }
    }

    /// Encode and send `frame`.
    pub fn send(&mut self, frame: &Frame) -> anyhow::Result<()> {
        let bytes = encode_to_vec(frame).map_err(|e| anyhow!("cannot encode {e:?}"))?;
        let result = self.wire.send(bytes.as_bytes());
        result.map_err(|e| {
            self.wire
                .failure(&format!("sending to the flight controller: {e}"))
        })
    }

    /// Read until a frame for which `closes` returns `true` arrives; return the bytes of
    /// every frame before it (the delimiters included, exactly as received) and that frame.
    /// Frames for which `closes` returns `None` are dropped from the returned bytes. A
    /// Header of another protocol major version ends the wait with an error.
    pub fn read_until(
        &mut self,
        timeout: Duration,
        what: &str,
        mut closes: impl FnMut(&Frame) -> Option<bool>,
        before: &mut Vec<u8>,
    ) -> anyhow::Result<Frame> {
        let deadline = Instant::now() + timeout;
        let mut start = 0;
        loop {
            while let Some(offset) = self
                .pending
                .get(self.scanned..)
                .and_then(|rest| rest.iter().position(|&b| b == DELIMITER))
            {
                let end = self.scanned + offset + 1;
                self.scanned = end;
                let body = self.pending.get(start..end - 1).unwrap_or(&[]);
                let decoded = decode_frame(body);
                if let Err(FrameError::VersionMismatch { found, expected }) = decoded {
                    return Err(self.wire.failure(&format!(
                        "the flight controller speaks protocol {found}, this host {expected} \
                         (major versions differ): flash a matching sweephold-fc"
                    )));
                }
                match decoded.as_ref().ok().map(&mut closes) {
                    Some(Some(true)) => {
                        let frame = decoded.map_err(|e| anyhow!("{e:?}"))?;
                        before.extend_from_slice(self.pending.get(..start).unwrap_or(&[]));
                        self.pending.drain(..end);
                        self.scanned = 0;
                        return Ok(frame);
                    }
                    Some(None) => {
                        // Not telemetry of this exchange: cut it out.
                        self.pending.drain(start..end);
                        self.scanned = start;
                    }
                    // Telemetry (or a corrupt frame, which the decoder of the dump
                    // reports): keep it in place.
                    Some(Some(false)) | None => start = end,
                }
            }
            let now = Instant::now();
            if now >= deadline {
                let what = format!(
                    "no {what} from the flight controller within {} s ({} bytes received meanwhile)",
                    timeout.as_secs_f64(),
                    self.pending.len()
                );
                return Err(self.wire.failure(&what));
            }
            let mut chunk = [0u8; 4096];
            match self.wire.recv(&mut chunk, deadline - now) {
                Ok(0) => return Err(self.wire.failure("the other end closed the connection")),
                Ok(n) => self
                    .pending
                    .extend_from_slice(chunk.get(..n).unwrap_or(&[])),
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(self
                        .wire
                        .failure(&format!("reading from the flight controller: {e}")))
                }
            }
        }
    }

    /// Send `request` and wait at most `timeout` for its answer. A board that reports the
    /// frame ignored (it is armed) ends the wait with an error saying so.
    pub fn configure(
        &mut self,
        request: LinkConfig,
        timeout: Duration,
    ) -> anyhow::Result<ConfigureResult> {
        self.send(&Frame::Configure(request))?;
        // Everything before the answer belongs to the previous configuration (boot
        // Header, standalone Samples, the watchdog's own steps): discarded.
        let mut discarded = Vec::new();
        let answer = self.read_until(
            timeout,
            "ConfigureResult (firmware older than protocol 1.1? rebuild it with `cargo fw`)",
            |frame| {
                Some(matches!(
                    frame,
                    Frame::ConfigureResult(_) | Frame::Event(Event::HostLinkIgnored { .. })
                ))
            },
            &mut discarded,
        )?;
        match answer {
            Frame::ConfigureResult(result) => Ok(result),
            Frame::Event(Event::HostLinkIgnored { .. }) => Err(armed()),
            other => bail!("unexpected answer to Configure: {other:?}"),
        }
    }

    /// One lockstep tick, waiting at most `timeout` for the answer; ActuatorOut frames
    /// answering another seq are dropped and counted in `stray`.
    pub fn exchange(
        &mut self,
        input: &SensorIn,
        telemetry: &mut Vec<u8>,
        stray: &mut u64,
        timeout: Duration,
    ) -> anyhow::Result<ActuatorOut> {
        self.send(&Frame::SensorIn(*input))?;
        let seq = input.seq;
        let answer = self.read_until(
            timeout,
            "ActuatorOut",
            |frame| match frame {
                Frame::ActuatorOut(out) if out.seq == seq => Some(true),
                Frame::ActuatorOut(_) => {
                    *stray += 1;
                    None
                }
                Frame::ConfigureResult(_) => None,
                Frame::Event(Event::HostLinkIgnored { .. }) => Some(true),
                _ => Some(false),
            },
            telemetry,
        )?;
        match answer {
            Frame::ActuatorOut(out) => Ok(out),
            Frame::Event(Event::HostLinkIgnored { .. }) => Err(armed()),
            other => bail!("unexpected frame closing the tick: {other:?}"),
        }
    }
}

/// The error of a board that ignores the host because it is armed.
fn armed() -> anyhow::Error {
    anyhow!(
        "the flight controller is armed and ignores the host: hardware in the loop is entered \
         on the ground only (arm switch off)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use sweephold_protocol::{Axis, VehicleId};

    /// A wire that answers with the bytes it was given, whatever is sent.
    struct Replay(Vec<u8>);

    impl ByteWire for Replay {
        fn send(&mut self, _bytes: &[u8]) -> std::io::Result<()> {
            Ok(())
        }

        fn recv(&mut self, buf: &mut [u8], _timeout: Duration) -> std::io::Result<usize> {
            let n = self.0.len().min(buf.len());
            buf[..n].copy_from_slice(&self.0[..n]);
            self.0.drain(..n);
            if n == 0 {
                return Err(ErrorKind::TimedOut.into());
            }
            Ok(n)
        }

        fn failure(&mut self, what: &str) -> anyhow::Error {
            anyhow!("{what}")
        }
    }

    #[test]
    fn an_armed_board_that_ignores_the_host_is_named() {
        use sweephold_protocol::HostFrame;
        let ignored = |frame| {
            let event = Frame::Event(Event::HostLinkIgnored { tick: 9, frame });
            encode_to_vec(&event).unwrap().as_bytes().to_vec()
        };
        let request = link_config(&Config::bo105_default(Axis::Lat)).unwrap();
        let mut channel = FrameChannel::new(Replay(ignored(HostFrame::Configure)));
        let error = channel
            .configure(request, Duration::from_millis(50))
            .expect_err("ignored");
        assert!(error.to_string().contains("armed"), "{error}");
        let mut channel = FrameChannel::new(Replay(ignored(HostFrame::SensorIn)));
        let error = channel
            .exchange(
                &SensorIn::default(),
                &mut Vec::new(),
                &mut 0,
                Duration::from_millis(50),
            )
            .expect_err("ignored");
        assert!(error.to_string().contains("armed"), "{error}");
        // Without the event the wait ends at its timeout, naming what it waited for.
        let mut channel = FrameChannel::new(Replay(Vec::new()));
        let error = channel
            .configure(request, Duration::from_millis(50))
            .expect_err("silent");
        assert!(error.to_string().contains("no ConfigureResult"), "{error}");
    }

    #[test]
    fn a_preset_with_another_test_travels_in_a_configure_frame() {
        let mut config = Config::bo105_default(Axis::Lon);
        config.rate_hz = 250;
        config.test.seed = 77;
        config.test.sweep.t_rec_s = 12.0;
        let request = link_config(&config).expect("representable");
        assert_eq!(request.vehicle, VehicleId::Bo105);
        assert_eq!(request.rate_hz, 250);
        assert_eq!(request.test, config.test);
    }

    #[test]
    fn settings_outside_the_configure_frame_are_refused() {
        let mut config = Config::trex700l_default(Axis::Lat);
        config.trim_capture_s += 0.5;
        let error = link_config(&config).expect_err("not representable");
        assert!(error.to_string().contains("build an image"), "{error}");
    }

    #[test]
    fn a_refusal_is_named_with_the_firmware_library() {
        let mut config = Config::bo105_default(Axis::Ped);
        config.rate_hz = 20;
        let answer = ConfigureResult {
            accepted: false,
            refusal: 3,
        };
        let error = check_configure_answer(&config, answer).expect_err("refused");
        assert!(
            error.to_string().contains("tick rate outside 50-1000 Hz"),
            "{error}"
        );
        let accepted = ConfigureResult {
            accepted: true,
            refusal: 0,
        };
        assert!(check_configure_answer(&Config::bo105_default(Axis::Ped), accepted).is_ok());
    }
}
