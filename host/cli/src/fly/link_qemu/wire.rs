//! The byte stream between the host and the image in QEMU: USART1's TCP socket, or the
//! semihosting FIFOs (and the FIFO of the image's defmt log).

use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::os::fd::AsFd;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{anyhow, Context};
use nix::fcntl::OFlag;
use nix::poll::{PollFd, PollFlags, PollTimeout};
use nix::sys::stat::Mode;

/// The byte stream to the image.
pub(super) enum Wire {
    /// USART1's TCP socket.
    Tcp(TcpStream),
    /// The semihosting FIFOs, both opened read-write (so neither open blocks and the
    /// host never sees end of file), in a scratch folder removed on drop.
    Fifo {
        to_image: std::fs::File,
        from_image: std::fs::File,
        /// The image's defmt frames (`sweephold-log`), read without blocking.
        log: std::fs::File,
        folder: PathBuf,
    },
}

impl Wire {
    pub(super) fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        match self {
            Wire::Tcp(stream) => stream.write_all(bytes),
            Wire::Fifo { to_image, .. } => to_image.write_all(bytes),
        }
    }

    /// Read what is there, waiting at most `timeout`; `Err(TimedOut)` when nothing came.
    pub(super) fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
        match self {
            Wire::Tcp(stream) => {
                stream.set_read_timeout(Some(timeout.max(Duration::from_millis(1))))?;
                stream.read(buf)
            }
            Wire::Fifo { from_image, .. } => {
                let wait = PollTimeout::try_from(timeout.max(Duration::from_millis(1)))
                    .unwrap_or(PollTimeout::from(1000u16));
                let mut fds = [PollFd::new(from_image.as_fd(), PollFlags::POLLIN)];
                match nix::poll::poll(&mut fds, wait) {
                    Ok(0) => Err(ErrorKind::TimedOut.into()),
                    Ok(_) => from_image.read(buf),
                    Err(errno) => Err(errno.into()),
                }
            }
        }
    }

    /// Append the defmt bytes waiting in the log FIFO to `bytes` (nothing for TCP).
    pub(super) fn read_log(&mut self, bytes: &mut Vec<u8>) {
        if let Wire::Fifo { log, .. } = self {
            let mut chunk = [0u8; 4096];
            // Non-blocking: stops at WouldBlock (empty) or an error.
            while let Ok(n @ 1..) = log.read(&mut chunk) {
                bytes.extend_from_slice(chunk.get(..n).unwrap_or(&[]));
            }
        }
    }

    pub(super) fn shutdown(&mut self) {
        match self {
            Wire::Tcp(stream) => {
                let _ = stream.shutdown(std::net::Shutdown::Both);
            }
            Wire::Fifo { folder, .. } => {
                let _ = std::fs::remove_dir_all(folder);
            }
        }
    }
}

/// A fresh scratch folder with the three FIFOs the image opens (`sweephold-in`,
/// `sweephold-out`, `sweephold-log`), all opened read-write, the log one non-blocking.
pub(super) fn make_fifos() -> anyhow::Result<Wire> {
    use std::sync::atomic::{AtomicU32, Ordering};
    static COUNT: AtomicU32 = AtomicU32::new(0);
    let folder = std::env::temp_dir().join(format!(
        "sweephold-qemu-{}-{}",
        std::process::id(),
        COUNT.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder)
        .with_context(|| format!("cannot create {}", folder.display()))?;
    let mut files = Vec::new();
    for name in ["sweephold-in", "sweephold-out", "sweephold-log"] {
        let path = folder.join(name);
        if let Err(errno) = nix::unistd::mkfifo(&path, Mode::S_IRUSR | Mode::S_IWUSR) {
            let _ = std::fs::remove_dir_all(&folder);
            return Err(std::io::Error::from(errno))
                .with_context(|| format!("mkfifo {}", path.display()));
        }
        // Read-write: Linux opens a FIFO so without waiting for the other end. The log is
        // drained between ticks, so its reads must not wait.
        use std::os::unix::fs::OpenOptionsExt;
        let flags = if name == "sweephold-log" {
            OFlag::O_NONBLOCK.bits()
        } else {
            0
        };
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(flags)
            .open(&path)
            .with_context(|| format!("cannot open {}", path.display()))?;
        files.push(file);
    }
    let log = files.pop().ok_or_else(|| anyhow!("FIFO missing"))?;
    let from_image = files.pop().ok_or_else(|| anyhow!("FIFO missing"))?;
    let to_image = files.pop().ok_or_else(|| anyhow!("FIFO missing"))?;
    Ok(Wire::Fifo {
        to_image,
        from_image,
        log,
        folder,
    })
}
