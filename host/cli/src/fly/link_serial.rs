//! A real flight controller on a serial port: `sweephold fly --fc serial:PATH[@BAUD]`.
//!
//! The board image speaks the same lockstep protocol over its USART as it does in QEMU
//! over the emulated one (`--fc qemu-usart`): Configure → ConfigureResult (after a
//! Header), then per tick SensorIn → Events, Sample → ActuatorOut. The exchange itself
//! is [`FrameChannel`]'s; this module only opens the tty (raw 8N1, no flow control,
//! modem lines ignored) with termios through `libc`. One port is one board, so a run
//! flies its records one after the other on a single link.

use std::fs::File;
use std::io::{ErrorKind, Read, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::anyhow;
use sweephold_firmware::Config;
use sweephold_protocol::{ActuatorOut, SensorIn};

use super::frame_channel::{check_configure_answer, link_config, ByteWire, FrameChannel};
use super::link::FlightControllerLink;

/// The board image's USART rate (`firmware/src/board/usart.rs`).
pub const DEFAULT_BAUD: u32 = 460_800;

/// How long the board may take to answer one frame (a Configure or a SensorIn). A tick
/// takes well under a millisecond on the board and ~10 ms of line time at 460 800 Bd.
pub const ANSWER_TIMEOUT: Duration = Duration::from_secs(2);

/// A serial port and its line rate, as `--fc serial:PATH[@BAUD]` names them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SerialPort {
    /// The tty, e.g. `/dev/ttyUSB0`.
    pub path: PathBuf,
    /// Line rate [Bd].
    pub baud: u32,
}

impl SerialPort {
    /// Parse `PATH[@BAUD]` (the part after `serial:`).
    pub fn parse(text: &str) -> Result<SerialPort, String> {
        let (path, baud) = match text.rsplit_once('@') {
            Some((path, baud)) => {
                let baud: u32 = baud
                    .parse()
                    .map_err(|_| format!("serial:{text}: baud rate `{baud}` is not a number"))?;
                (path, baud)
            }
            None => (text, DEFAULT_BAUD),
        };
        if path.is_empty() {
            return Err(format!(
                "serial:{text}: no port (expected serial:PATH[@BAUD], e.g. serial:/dev/ttyUSB0@460800)"
            ));
        }
        if termios_speed(baud).is_none() {
            return Err(format!(
                "serial:{text}: {baud} Bd is not a rate the tty driver offers (e.g. 115200, 460800, 921600)"
            ));
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

/// The termios speed constant of `baud`, if there is one.
fn termios_speed(baud: u32) -> Option<libc::speed_t> {
    Some(match baud {
        9_600 => libc::B9600,
        19_200 => libc::B19200,
        38_400 => libc::B38400,
        57_600 => libc::B57600,
        115_200 => libc::B115200,
        230_400 => libc::B230400,
        460_800 => libc::B460800,
        500_000 => libc::B500000,
        921_600 => libc::B921600,
        1_000_000 => libc::B1000000,
        1_500_000 => libc::B1500000,
        2_000_000 => libc::B2000000,
        _ => return None,
    })
}

/// An open tty in raw mode.
pub struct SerialWire {
    file: File,
    name: String,
}

impl SerialWire {
    /// Open `port` raw, 8N1, no flow control, modem lines ignored; drop whatever the
    /// driver had buffered.
    pub fn open(port: &SerialPort) -> anyhow::Result<SerialWire> {
        let name = port.path.display().to_string();
        let fail =
            |what: &str, e: std::io::Error| anyhow!("cannot open serial port {name}: {what}{e}");
        // Non-blocking so the open does not wait for carrier detect; cleared below.
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(libc::O_NOCTTY | libc::O_NONBLOCK)
            .open(&port.path)
            .map_err(|e| fail("", e))?;
        let speed = termios_speed(port.baud)
            .ok_or_else(|| anyhow!("serial port {name}: unsupported rate {} Bd", port.baud))?;
        let fd = file.as_raw_fd();
        // SAFETY: `fd` is open for the whole block; `termios` is a plain C struct that
        // tcgetattr fills before it is read.
        unsafe {
            let mut termios: libc::termios = std::mem::zeroed();
            if libc::tcgetattr(fd, &mut termios) != 0 {
                return Err(fail("not a terminal: ", std::io::Error::last_os_error()));
            }
            libc::cfmakeraw(&mut termios);
            termios.c_cflag |= libc::CLOCAL | libc::CREAD;
            termios.c_cflag &= !(libc::CRTSCTS | libc::CSTOPB | libc::PARENB);
            termios.c_cc[libc::VMIN] = 1;
            termios.c_cc[libc::VTIME] = 0;
            if libc::cfsetispeed(&mut termios, speed) != 0
                || libc::cfsetospeed(&mut termios, speed) != 0
                || libc::tcsetattr(fd, libc::TCSANOW, &termios) != 0
            {
                return Err(fail("termios: ", std::io::Error::last_os_error()));
            }
            libc::tcflush(fd, libc::TCIOFLUSH);
            let flags = libc::fcntl(fd, libc::F_GETFL);
            if flags < 0 || libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) != 0 {
                return Err(fail("fcntl: ", std::io::Error::last_os_error()));
            }
        }
        Ok(SerialWire { file, name })
    }

    /// The port's path as shown in messages.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl ByteWire for SerialWire {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.file.write_all(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
        let mut poll = libc::pollfd {
            fd: self.file.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        let millis = libc::c_int::try_from(timeout.as_millis().max(1)).unwrap_or(1000);
        // SAFETY: one valid pollfd, count 1, for the duration of the call.
        let ready = unsafe { libc::poll(&mut poll, 1, millis) };
        match ready {
            0 => Err(ErrorKind::TimedOut.into()),
            n if n < 0 => Err(std::io::Error::last_os_error()),
            _ => self.file.read(buf),
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
            let error = SerialPort::parse(text).expect_err(text);
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
