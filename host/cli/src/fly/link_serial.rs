//! A real flight controller on a serial port: `sweephold fly --fc serial:PATH[@BAUD]`.
//!
//! The board image speaks the same lockstep protocol over its USART as it does in QEMU
//! over the emulated one (`--fc qemu-usart`): Configure → ConfigureResult (after a
//! Header), then per tick SensorIn → Events, Sample → ActuatorOut. The exchange itself
//! is [`FrameChannel`]'s; this module only opens the tty (raw 8N1, no flow control,
//! modem lines ignored) through the `serialport` crate. One port is one board, so a run
//! flies its records one after the other on a single link.

use std::io::{ErrorKind, IsTerminal, Read, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::anyhow;
use nix::errno::Errno;
use nix::fcntl::OFlag;
use sweephold_firmware::Config;
use sweephold_protocol::{ActuatorOut, SensorIn};

use super::frame_channel::{check_configure_answer, link_config, ByteWire, FrameChannel};
use super::link::FlightControllerLink;

/// The board image's USART rate (`firmware/board/src/usart.rs`).
pub const DEFAULT_BAUD: u32 = 460_800;

/// How long the board may take to answer one frame (a Configure or a SensorIn). A tick
/// takes well under a millisecond on the board and ~10 ms of line time at 460 800 Bd.
pub const ANSWER_TIMEOUT: Duration = Duration::from_secs(2);

/// The line rates a tty driver offers (the termios `B…` speeds from 9600 Bd up): the
/// rates `serial:PATH@BAUD` accepts.
const OFFERED_RATES: [u32; 12] = [
    9_600, 19_200, 38_400, 57_600, 115_200, 230_400, 460_800, 500_000, 921_600, 1_000_000,
    1_500_000, 2_000_000,
];

/// A serial port and its line rate, as `--fc serial:PATH[@BAUD]` names them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SerialPort {
    /// The tty, e.g. `/dev/ttyUSB0`.
    pub path: PathBuf,
    /// Line rate \[Bd\].
    pub baud: u32,
}

/// Why `serial:PATH[@BAUD]` names no usable port; `text` is the part after `serial:`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SerialPortError {
    /// The part after `@` is not a number.
    #[error("serial:{text}: baud rate `{baud}` is not a number")]
    BaudNotANumber {
        /// The value after `serial:`.
        text: String,
        /// The part after `@`.
        baud: String,
    },
    /// Nothing before the `@` (or nothing at all).
    #[error(
        "serial:{text}: no port (expected serial:PATH[@BAUD], e.g. serial:/dev/ttyUSB0@460800)"
    )]
    NoPort {
        /// The value after `serial:`.
        text: String,
    },
    /// A rate that is not one of the tty driver's.
    #[error(
        "serial:{text}: {baud} Bd is not a rate the tty driver offers (e.g. 115200, 460800, 921600)"
    )]
    UnofferedRate {
        /// The value after `serial:`.
        text: String,
        /// The rate asked for \[Bd\].
        baud: u32,
    },
}

impl SerialPort {
    /// Parse `PATH[@BAUD]` (the part after `serial:`).
    pub fn parse(text: &str) -> Result<SerialPort, SerialPortError> {
        let (path, baud) = match text.rsplit_once('@') {
            Some((path, baud)) => {
                let rate: u32 = baud.parse().map_err(|_| SerialPortError::BaudNotANumber {
                    text: text.to_string(),
                    baud: baud.to_string(),
                })?;
                (path, rate)
            }
            None => (text, DEFAULT_BAUD),
        };
        if path.is_empty() {
            return Err(SerialPortError::NoPort {
                text: text.to_string(),
            });
        }
        if !OFFERED_RATES.contains(&baud) {
            return Err(SerialPortError::UnofferedRate {
                text: text.to_string(),
                baud,
            });
        }
        Ok(SerialPort {
            path: PathBuf::from(path),
            baud,
        })
    }
}

impl std::fmt::Display for SerialPort {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "serial:{}@{}", self.path.display(), self.baud)
    }
}

/// An open tty in raw mode.
pub struct SerialWire {
    port: Box<dyn serialport::SerialPort>,
    name: String,
}

impl SerialWire {
    /// Open `port` raw, 8N1, no flow control, modem lines ignored; drop whatever the
    /// driver had buffered. Not exclusive: like any tty, the port stays open to others
    /// (a monitor, say).
    pub fn open(port: &SerialPort) -> anyhow::Result<SerialWire> {
        let name = port.path.display().to_string();
        if !OFFERED_RATES.contains(&port.baud) {
            return Err(anyhow!(
                "serial port {name}: unsupported rate {} Bd",
                port.baud
            ));
        }
        // Opened here first, without waiting for carrier detect: the open errors read as
        // for any file, and a file that is no terminal is refused before any terminal
        // setting. It stays open until serialport has the port, so that closing it is not
        // the tty's last close (which would drop the modem lines).
        let probe = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags((OFlag::O_NOCTTY | OFlag::O_NONBLOCK).bits())
            .open(&port.path)
            .map_err(|e| anyhow!("cannot open serial port {name}: {e}"))?;
        if !probe.is_terminal() {
            let why = std::io::Error::from(Errno::ENOTTY);
            return Err(anyhow!(
                "cannot open serial port {name}: not a terminal: {why}"
            ));
        }
        let path = port
            .path
            .to_str()
            .ok_or_else(|| anyhow!("cannot open serial port {name}: the path is not UTF-8"))?;
        // serialport sets raw mode with the receiver on and the modem lines ignored, then
        // the frame format and the rate.
        let opened = serialport::new(path, port.baud)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .exclusive(false)
            .timeout(ANSWER_TIMEOUT)
            .open()
            .map_err(|e| anyhow!("cannot open serial port {name}: termios: {e}"))?;
        opened
            .clear(serialport::ClearBuffer::All)
            .map_err(|e| anyhow!("cannot open serial port {name}: termios: {e}"))?;
        drop(probe);
        Ok(SerialWire { port: opened, name })
    }

    /// The port's path as shown in messages.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl ByteWire for SerialWire {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        // A write waits for room in the driver's buffer at most one answer's time.
        self.port.set_timeout(ANSWER_TIMEOUT)?;
        self.port.write_all(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
        self.port
            .set_timeout(timeout.max(Duration::from_millis(1)))?;
        match self.port.read(buf) {
            // serialport reports the other end's hang-up before reading: the stream's end.
            Err(e) if e.kind() == ErrorKind::BrokenPipe => Ok(0),
            other => other,
        }
    }

    fn failure(&mut self, what: &str) -> anyhow::Error {
        anyhow!(
            "serial port {}: {what} (is the board connected, running sweephold-fc and at this baud rate?)",
            self.name
        )
    }
}

/// A flight controller on a serial port. The port is opened by the first record and
/// closed when a record fails (the stream is then at an unknown point) or the link is
/// dropped; the next record opens it again.
pub struct SerialLink {
    port: SerialPort,
    channel: Option<FrameChannel<SerialWire>>,
    /// ActuatorOut frames that answered no outstanding SensorIn (dropped).
    stray_answers: u64,
}

impl SerialLink {
    /// A link to the board on `port`; nothing is opened yet.
    pub fn new(port: SerialPort) -> Self {
        SerialLink {
            port,
            channel: None,
            stray_answers: 0,
        }
    }

    /// The port of this link.
    pub fn path(&self) -> &Path {
        &self.port.path
    }

    /// ActuatorOut frames received that answered no outstanding SensorIn.
    pub fn stray_answers(&self) -> u64 {
        self.stray_answers
    }

    fn channel(&mut self) -> anyhow::Result<&mut FrameChannel<SerialWire>> {
        if self.channel.is_none() {
            self.channel = Some(FrameChannel::new(SerialWire::open(&self.port)?));
        }
        self.channel
            .as_mut()
            .ok_or_else(|| anyhow!("serial port {} not open", self.port.path.display()))
    }

    fn keep_if_ok<T>(&mut self, result: anyhow::Result<T>) -> anyhow::Result<T> {
        if result.is_err() {
            self.channel = None;
        }
        result
    }
}

impl FlightControllerLink for SerialLink {
    fn describe(&self) -> String {
        self.port.to_string()
    }

    fn begin_record(&mut self, config: &Config) -> anyhow::Result<()> {
        let request = link_config(config)?;
        let answer = self
            .channel()
            .and_then(|channel| channel.configure(request, ANSWER_TIMEOUT));
        let answer = self.keep_if_ok(answer)?;
        check_configure_answer(config, answer)
    }

    fn exchange(
        &mut self,
        input: &SensorIn,
        telemetry: &mut Vec<u8>,
    ) -> anyhow::Result<ActuatorOut> {
        let mut stray = 0;
        let result = self
            .channel()
            .and_then(|channel| channel.exchange(input, telemetry, &mut stray, ANSWER_TIMEOUT));
        self.stray_answers += stray;
        self.keep_if_ok(result)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_port_without_rate_gets_the_board_rate() {
        let port = SerialPort::parse("/dev/ttyUSB0").expect("valid");
        assert_eq!(port.path, Path::new("/dev/ttyUSB0"));
        assert_eq!(port.baud, DEFAULT_BAUD);
        let port = SerialPort::parse("/dev/ttyACM1@115200").expect("valid");
        assert_eq!(
            (port.path.to_str(), port.baud),
            (Some("/dev/ttyACM1"), 115_200)
        );
    }

    #[test]
    fn malformed_ports_are_refused_with_the_reason() {
        for (text, reason) in [
            ("", "no port"),
            ("@115200", "no port"),
            ("/dev/ttyUSB0@fast", "not a number"),
            ("/dev/ttyUSB0@12345", "not a rate"),
        ] {
            let error = SerialPort::parse(text).expect_err(text).to_string();
            assert!(error.contains(reason), "{text}: {error}");
        }
    }

    #[test]
    fn a_regular_file_is_not_a_serial_port() {
        let path = std::env::temp_dir().join(format!("sweephold-not-a-tty-{}", std::process::id()));
        std::fs::write(&path, b"x").expect("scratch file");
        let error = SerialWire::open(&SerialPort {
            path: path.clone(),
            baud: DEFAULT_BAUD,
        })
        .err()
        .expect("a file is no tty");
        let _ = std::fs::remove_file(&path);
        assert!(error.to_string().contains("not a terminal"), "{error}");
    }
}
