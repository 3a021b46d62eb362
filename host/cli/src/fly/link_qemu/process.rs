//! One QEMU process running the image: started with the transport's arguments, its
//! stderr kept for error messages, killed on drop.

use std::io::{ErrorKind, Read};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context};

use super::image::check_image;
use super::wire::{make_fifos, Wire};
use crate::fly::frame_channel::{ByteWire, FrameChannel};

/// The QEMU binary.
pub const QEMU: &str = "qemu-system-arm";

/// How long QEMU may take to start and connect to the host.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(20);

/// How long the image may take to answer a Configure (boot included).
pub(super) const CONFIGURE_TIMEOUT: Duration = Duration::from_secs(20);

/// First bytes of QEMU's stderr kept for error messages.
const STDERR_KEEP: usize = 4096;

/// Longest part of a QEMU message quoted in an error.
const STDERR_LINE_MAX: usize = 200;

/// `Ok` when `qemu-system-arm` can be started, else the one-line reason.
pub fn qemu_available() -> anyhow::Result<()> {
    match Command::new(QEMU)
        .arg("--version")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
    {
        Ok(status) if status.success() => Ok(()),
        Ok(status) => bail!("{QEMU} --version failed ({status})"),
        Err(e) if e.kind() == ErrorKind::NotFound => {
            bail!("{QEMU} not found: install it with `apt-get install qemu-system-arm`")
        }
        Err(e) => bail!("cannot run {QEMU}: {e}"),
    }
}

/// Extra QEMU arguments from `SWEEPHOLD_QEMU_ARGS` (split on white space), e.g.
/// `-icount shift=0,sleep=off`.
pub fn extra_args_from_env() -> Vec<String> {
    std::env::var("SWEEPHOLD_QEMU_ARGS")
        .map(|text| text.split_whitespace().map(str::to_string).collect())
        .unwrap_or_default()
}

/// How the host reaches the image in QEMU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QemuTransport {
    /// ARM semihosting: SYS_READ / SYS_WRITE on two host FIFOs, a whole frame per call
    /// (`board/semihosting.rs`). QEMU only; the fast one.
    Semihosting,
    /// USART1 on a TCP socket, as a serial cable to the board would carry it. QEMU's
    /// USART model takes one received byte per main-loop iteration: ~200 ticks/s.
    Usart,
}

impl QemuTransport {
    /// Name in `summary.json` and messages.
    pub fn link_name(self) -> &'static str {
        match self {
            QemuTransport::Semihosting => "qemu",
            QemuTransport::Usart => "qemu-usart",
        }
    }
}

/// The mailbox words that ask the image for the semihosting link (see the firmware's
/// `board/semihosting.rs`): "SHST" and its complement at 0x2001_0000.
const SEMIHOSTING_MAILBOX: [(u32, u32); 2] =
    [(0x2001_0000, 0x5348_5354), (0x2001_0004, !0x5348_5354)];

/// One QEMU process running the image, and the byte stream to it.
pub struct QemuProcess {
    child: Child,
    /// Killed by a run ended at once by a signal (`crate::interrupt`); otherwise on drop.
    _registration: crate::interrupt::Registration,
    wire: Wire,
    stderr: Arc<Mutex<Vec<u8>>>,
}

/// The frame exchange with one QEMU.
pub type Session = FrameChannel<QemuProcess>;

impl QemuProcess {
    /// Append what the image has logged since the last call to `bytes`.
    pub(super) fn read_log(&mut self, bytes: &mut Vec<u8>) {
        self.wire.read_log(bytes);
    }
}

impl ByteWire for QemuProcess {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.wire.send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
        self.wire.recv(buf, timeout)
    }

    /// An error naming `what` went wrong, with QEMU's state and the end of its stderr.
    fn failure(&mut self, what: &str) -> anyhow::Error {
        let state = match self.child.try_wait() {
            Ok(Some(status)) => format!("QEMU exited ({status})"),
            Ok(None) => "QEMU still running".to_string(),
            Err(e) => format!("QEMU state unknown ({e})"),
        };
        let stderr = stderr_text(&self.stderr);
        if stderr.is_empty() {
            anyhow!("{what}; {state}")
        } else {
            anyhow!("{what}; {state}; QEMU said: {stderr}")
        }
    }
}

/// Boot `image` in QEMU and connect to its USART1. `extra_args` go to QEMU as they
/// are (e.g. `-icount shift=0`).
pub fn start_session(
    image: &Path,
    transport: QemuTransport,
    extra_args: &[String],
) -> anyhow::Result<Session> {
    check_image(image)?;
    qemu_available()?;
    let image = std::path::absolute(image)
        .with_context(|| format!("cannot resolve {}", image.display()))?;
    let mut command = Command::new(QEMU);
    command
        .args(["-M", "netduinoplus2", "-nographic", "-monitor", "none"])
        .arg("-kernel")
        .arg(&image);
    let (listener, fifos) = match transport {
        QemuTransport::Usart => {
            let listener =
                TcpListener::bind("127.0.0.1:0").context("cannot listen on 127.0.0.1 for QEMU")?;
            let port = listener.local_addr()?.port();
            listener.set_nonblocking(true)?;
            // USART1 is the first serial port of the machine.
            command
                .arg("-chardev")
                .arg(format!(
                    "socket,id=usart1,host=127.0.0.1,port={port},server=off,nodelay=on"
                ))
                .args(["-serial", "chardev:usart1"]);
            (Some(listener), None)
        }
        QemuTransport::Semihosting => {
            let fifos = make_fifos()?;
            if let Wire::Fifo { folder, .. } = &fifos {
                // The image opens the FIFOs by relative name.
                command.current_dir(folder);
            }
            command
                .args(["-serial", "null"])
                .args(["-semihosting-config", "enable=on,target=native"]);
            for (address, word) in SEMIHOSTING_MAILBOX {
                command.arg("-device").arg(format!(
                    "loader,addr={address:#x},data={word:#x},data-len=4"
                ));
            }
            (None, Some(fifos))
        }
    };
    let mut child = command
        .args(extra_args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("cannot start {QEMU}"))?;
    let registration = crate::interrupt::register_child(child.id());
    let stderr = Arc::new(Mutex::new(Vec::new()));
    if let Some(mut pipe) = child.stderr.take() {
        let keep = Arc::clone(&stderr);
        std::thread::spawn(move || {
            // Keep the start (what went wrong first); read on so that QEMU never blocks.
            let mut chunk = [0u8; 512];
            while let Ok(n @ 1..) = pipe.read(&mut chunk) {
                let mut kept = keep.lock().unwrap_or_else(|e| e.into_inner());
                let room = STDERR_KEEP.saturating_sub(kept.len()).min(n);
                kept.extend_from_slice(chunk.get(..room).unwrap_or(&[]));
            }
        });
    }
    let wire = match (listener, fifos) {
        (Some(listener), _) => Wire::Tcp(accept(&listener, &mut child, &stderr)?),
        (None, Some(fifos)) => fifos,
        (None, None) => bail!("no transport"),
    };
    let mut session = FrameChannel::new(QemuProcess {
        _registration: registration,
        child,
        wire,
        stderr,
    });
    // QEMU's USART drops what arrives before the image has enabled it, which would
    // cut the first Configure. The image's first frame (its boot Header) comes
    // after it is enabled: wait for it.
    session.read_until(
        CONFIGURE_TIMEOUT,
        "boot frame (an image older than this host? rebuild it with `cargo fw`)",
        |_| Some(true),
        &mut Vec::new(),
    )?;
    Ok(session)
}

fn stderr_text(stderr: &Mutex<Vec<u8>>) -> String {
    let bytes = stderr.lock().unwrap_or_else(|e| e.into_inner());
    stderr_summary(&String::from_utf8_lossy(&bytes))
}

/// QEMU's stderr as one line for an error message: its first line that says `fatal` or
/// `error`, else its first non-empty line, cut at [`STDERR_LINE_MAX`] characters, and how
/// many other lines there were (a CPU lockup prints ~30 lines of registers after its
/// reason).
fn stderr_summary(text: &str) -> String {
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|line| !line.is_empty())
        .collect();
    let says = |line: &&&str| {
        let lower = line.to_lowercase();
        lower.contains("fatal") || lower.contains("error")
    };
    let Some(chosen) = lines.iter().find(says).or(lines.first()) else {
        return String::new();
    };
    let mut summary: String = chosen
        .chars()
        .filter(|c| !c.is_control())
        .take(STDERR_LINE_MAX)
        .collect();
    if chosen.chars().count() > STDERR_LINE_MAX {
        summary.push('…');
    }
    match lines.len() - 1 {
        0 => summary,
        1 => format!("{summary} (and 1 more line)"),
        more => format!("{summary} (and {more} more lines)"),
    }
}

impl Drop for QemuProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        self.wire.shutdown();
    }
}

/// Wait for QEMU to connect to `listener` (it is the client), watching that it runs.
fn accept(
    listener: &TcpListener,
    child: &mut Child,
    stderr: &Mutex<Vec<u8>>,
) -> anyhow::Result<TcpStream> {
    let deadline = Instant::now() + CONNECT_TIMEOUT;
    let stream = loop {
        match listener.accept() {
            Ok((stream, _)) => break stream,
            Err(e) if e.kind() == ErrorKind::WouldBlock => {}
            Err(e) => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(e).context("accepting QEMU's connection");
            }
        }
        if let Ok(Some(status)) = child.try_wait() {
            std::thread::sleep(Duration::from_millis(50));
            bail!(
                "{QEMU} exited ({status}) before connecting: {}",
                stderr_text(stderr)
            );
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "{QEMU} did not connect within {} s",
                CONNECT_TIMEOUT.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    stream.set_nonblocking(false)?;
    stream.set_nodelay(true)?;
    Ok(stream)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn qemus_stderr_is_summarised_in_one_line() {
        let mut lockup = String::from(
            "qemu: fatal: Lockup: can't escalate 3 to HardFault (current priority -1)\n\n",
        );
        for k in 0..27 {
            lockup.push_str(&format!("R{k:02}=00000000 R{:02}=00000000\n", k + 1));
        }
        assert_eq!(
            stderr_summary(&lockup),
            "qemu: fatal: Lockup: can't escalate 3 to HardFault (current priority -1) \
             (and 27 more lines)"
        );
        // A warning before the error: the error is the line that matters.
        assert_eq!(
            stderr_summary("qemu-system-arm: warning: x\nqemu-system-arm: error: y\n"),
            "qemu-system-arm: error: y (and 1 more line)"
        );
        assert_eq!(stderr_summary("just this"), "just this");
        assert_eq!(stderr_summary("\n \n"), "");
        let long = "x".repeat(1000);
        assert_eq!(
            stderr_summary(&long).chars().count(),
            STDERR_LINE_MAX + 1,
            "cut, with an ellipsis"
        );
    }
}
