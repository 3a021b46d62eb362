//! The board image flown in QEMU: `sweephold fly --fc qemu` (and `--fc qemu-usart`).
//!
//! [`QemuLink`] boots the flight-controller image (`cargo fw`) in
//! `qemu-system-arm -M netduinoplus2` and runs the same lockstep protocol with it as
//! over a serial cable to the real board: each tick one SensorIn out, then the tick's
//! telemetry in, closed by the ActuatorOut that answers the SensorIn's `seq`; everything
//! before that ActuatorOut is handed on as raw bytes, exactly as received. The record's
//! configuration travels in a Configure frame (protocol 1.1), so one image flies every
//! axis, vehicle and test.
//!
//! Two transports ([`QemuTransport`]). **Semihosting** (the default): two host FIFOs the
//! image reads and writes with ARM semihosting calls, a whole frame per call; ~45× real
//! time. **USART**: USART1 on a TCP socket, the board's own link; QEMU's USART model takes
//! one received byte per main-loop iteration, so it runs at about real time. For it the
//! host is the server: it listens on an ephemeral port of 127.0.0.1 first and QEMU
//! connects as a client, so no other program can take the port in between.
//!
//! **Logs**: over semihosting the image's defmt log comes through a third FIFO,
//! `sweephold-log` (firmware `board/log.rs`); the link collects it while the record
//! flies and, at the end of each record, decodes it against the ELF
//! ([`super::defmt_log`]) into `DIR/<record>.log` (`lat-1.log` beside `lat-1.bin`), one
//! line per message with the loop tick and the level. Over the USART transport the
//! image logs to RTT only (no log file).
//!
//! QEMU is killed when the link is dropped — at the end of the run, on an error, and when
//! the thread unwinds — and a failed record boots a fresh one for the next. On Ctrl-C the
//! terminal's SIGINT reaches QEMU too (same foreground process group), which terminates
//! on it; over semihosting the image also asks QEMU to exit when the host's end of the
//! FIFO closes, so even a killed host leaves no emulator behind (only its FIFO folder in
//! the temporary directory, which Drop removes otherwise).

use std::ffi::OsString;
use std::io::{ErrorKind, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context};
use sweephold_firmware::Config;
use sweephold_protocol::{ActuatorOut, SensorIn};

use super::defmt_log::{write_log, DefmtTable};
use super::frame_channel::{check_configure_answer, link_config, ByteWire, FrameChannel};
use super::link::FlightControllerLink;

/// The QEMU binary.
pub const QEMU: &str = "qemu-system-arm";

/// The image `cargo fw` builds, relative to a cargo target directory.
pub const IMAGE_IN_TARGET_DIR: &str = "thumbv7em-none-eabihf/firmware/sweephold-fc";

/// How long QEMU may take to start and connect to the host.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(20);

/// How long the image may take to answer a Configure (boot included).
const CONFIGURE_TIMEOUT: Duration = Duration::from_secs(20);

/// How long the image may take to answer one SensorIn. A tick needs well under a
/// millisecond of emulated time; this only catches a dead or wedged emulator.
const TICK_TIMEOUT: Duration = Duration::from_secs(10);

/// First bytes of QEMU's stderr kept for error messages.
const STDERR_KEEP: usize = 4096;

/// Longest part of a QEMU message quoted in an error.
const STDERR_LINE_MAX: usize = 200;

/// The environment variable naming the image when `--elf` is not given.
pub const IMAGE_ENV: &str = "SWEEPHOLD_FC_ELF";

/// ELF `e_machine` of 32-bit ARM.
const EM_ARM: u16 = 40;

/// Where the image is when `--elf` is not given: the file `$SWEEPHOLD_FC_ELF` names, if
/// that variable is set; else `target/thumbv7em-none-eabihf/firmware/sweephold-fc` in the
/// workspace this binary belongs to (the nearest folder above it whose `Cargo.toml` has a
/// `[workspace]` table: a binary of `<ws>/target/<profile>/`), under `$CARGO_TARGET_DIR`
/// when that is set, or under the current directory — the first that exists. If none
/// does, the error says where it looked and how to build the image.
pub fn default_image() -> anyhow::Result<PathBuf> {
    let exe = std::env::current_exe().ok();
    let cwd = std::env::current_dir().ok();
    find_image(
        std::env::var_os(IMAGE_ENV),
        std::env::var_os("CARGO_TARGET_DIR"),
        exe.as_deref(),
        cwd.as_deref(),
    )
}

/// [`default_image`] with its inputs given: the variable's value, `$CARGO_TARGET_DIR`, the
/// running binary and the current directory.
fn find_image(
    from_env: Option<OsString>,
    target_dir: Option<OsString>,
    exe: Option<&Path>,
    cwd: Option<&Path>,
) -> anyhow::Result<PathBuf> {
    if let Some(path) = from_env.filter(|value| !value.is_empty()) {
        let path = PathBuf::from(path);
        if path.is_file() {
            return Ok(path);
        }
        bail!(
            "{IMAGE_ENV}={}: no such file (point it at the image `cargo fw` builds, or unset it)",
            path.display()
        );
    }
    let mut candidates: Vec<PathBuf> = Vec::new();
    let workspace = exe.and_then(workspace_of);
    if let Some(workspace) = &workspace {
        candidates.push(workspace.join("target").join(IMAGE_IN_TARGET_DIR));
    }
    if let Some(dir) = target_dir.filter(|value| !value.is_empty()) {
        candidates.push(PathBuf::from(dir).join(IMAGE_IN_TARGET_DIR));
    }
    if let Some(cwd) = cwd {
        candidates.push(cwd.join("target").join(IMAGE_IN_TARGET_DIR));
    }
    candidates.dedup();
    if let Some(found) = candidates.iter().find(|path| path.is_file()) {
        return Ok(found.clone());
    }
    let build = match &workspace {
        Some(workspace) => format!("`cargo fw` in {}", workspace.display()),
        None => "`cargo fw` in the sweephold workspace".to_string(),
    };
    bail!(
        "no flight-controller image (looked for {}): build it with {build}, or pass --elf PATH \
         or set {IMAGE_ENV}",
        candidates
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The workspace `exe` belongs to: the nearest folder above it whose `Cargo.toml` has a
/// `[workspace]` table.
fn workspace_of(exe: &Path) -> Option<PathBuf> {
    exe.ancestors()
        .skip(1)
        .find(|dir| {
            std::fs::read_to_string(dir.join("Cargo.toml"))
                .is_ok_and(|text| text.lines().any(|line| line.trim() == "[workspace]"))
        })
        .map(Path::to_path_buf)
}

/// Refuse `image` unless it is a 32-bit little-endian ARM ELF file — before QEMU is
/// started, which would otherwise load anything as raw memory and report a lockup.
pub fn check_image(image: &Path) -> anyhow::Result<()> {
    let mut file = match std::fs::File::open(image) {
        Ok(file) => file,
        Err(e) if e.kind() == ErrorKind::NotFound => bail!(
            "flight-controller image {} not found: build it with `cargo fw`",
            image.display()
        ),
        Err(e) => bail!(
            "cannot read flight-controller image {}: {e}",
            image.display()
        ),
    };
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        bail!(
            "flight-controller image {} is not a file: pass the ELF `cargo fw` builds (target/{})",
            image.display(),
            IMAGE_IN_TARGET_DIR
        );
    }
    // e_ident (16 bytes), e_type (2), e_machine (2).
    let mut header = [0u8; 20];
    let mut read = 0;
    while read < header.len() {
        match file.read(&mut header[read..]) {
            Ok(0) => break,
            Ok(n) => read += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => bail!(
                "cannot read flight-controller image {}: {e}",
                image.display()
            ),
        }
    }
    let refuse = |what: &str| {
        anyhow!(
            "{} is not a flight-controller image: {what}; pass the ELF `cargo fw` builds (target/{})",
            image.display(),
            IMAGE_IN_TARGET_DIR
        )
    };
    if read < 4 || header[..4] != *b"\x7fELF" {
        return Err(refuse("not an ELF file (no \\x7fELF magic)"));
    }
    if read < header.len() {
        return Err(refuse("an ELF file cut short"));
    }
    if header[4] != 1 || header[5] != 1 {
        return Err(refuse("an ELF file, but not 32-bit little-endian"));
    }
    let machine = u16::from_le_bytes([header[18], header[19]]);
    if machine != EM_ARM {
        return Err(refuse(&format!(
            "an ELF file for machine {machine}, not 32-bit ARM ({EM_ARM})"
        )));
    }
    Ok(())
}

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

/// The board image flown in QEMU. QEMU is booted by the first record (so making the
/// link costs nothing) and killed when the link is dropped or a record fails; the next
/// record then boots a fresh one.
pub struct QemuLink {
    image: PathBuf,
    transport: QemuTransport,
    extra_args: Vec<String>,
    session: Option<Session>,
    /// ActuatorOut frames that answered no outstanding SensorIn (dropped), all sessions.
    stray_answers: u64,
    /// Where the decoded defmt log of each record goes (`None`: not kept).
    log_folder: Option<PathBuf>,
    /// The image's defmt table, read at the first record that needs it.
    defmt_table: Option<DefmtTable>,
    /// Raw defmt bytes of the record being flown.
    log_bytes: Vec<u8>,
}

impl QemuLink {
    /// A link that will boot `image`, reach it over `transport`, and add `extra_args`
    /// to QEMU's command line.
    pub fn new(image: &Path, transport: QemuTransport, extra_args: &[String]) -> Self {
        QemuLink {
            image: image.to_path_buf(),
            transport,
            extra_args: extra_args.to_vec(),
            session: None,
            stray_answers: 0,
            log_folder: None,
            defmt_table: None,
            log_bytes: Vec::new(),
        }
    }

    /// Also write each record's decoded defmt log to `folder/<record>.log` (semihosting
    /// transport only).
    pub fn with_log_folder(mut self, folder: &Path) -> Self {
        self.log_folder = Some(folder.to_path_buf());
        self
    }

    /// Move what the image has logged so far into `log_bytes`.
    fn drain_log(&mut self) {
        if let Some(session) = self.session.as_mut() {
            session.wire_mut().wire.read_log(&mut self.log_bytes);
        }
    }

    /// The image this link boots.
    pub fn image(&self) -> &Path {
        &self.image
    }

    /// ActuatorOut frames received that answered no outstanding SensorIn.
    pub fn stray_answers(&self) -> u64 {
        self.stray_answers
    }

    /// The running session, booting QEMU if there is none.
    fn session(&mut self) -> anyhow::Result<&mut Session> {
        if self.session.is_none() {
            self.session = Some(start_session(
                &self.image,
                self.transport,
                &self.extra_args,
            )?);
        }
        self.session
            .as_mut()
            .ok_or_else(|| anyhow!("QEMU session missing"))
    }

    /// Keep the session after `result` only if it is `Ok`: a failed exchange leaves the
    /// stream at an unknown point, and the next record starts from a fresh boot.
    fn keep_if_ok<T>(&mut self, result: anyhow::Result<T>) -> anyhow::Result<T> {
        // Whatever the image logged up to here belongs to this record, failed or not.
        self.drain_log();
        if result.is_err() {
            self.session = None;
        }
        result
    }
}

/// The byte stream to the image.
enum Wire {
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
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        match self {
            Wire::Tcp(stream) => stream.write_all(bytes),
            Wire::Fifo { to_image, .. } => to_image.write_all(bytes),
        }
    }

    /// Read what is there, waiting at most `timeout`; `Err(TimedOut)` when nothing came.
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
        match self {
            Wire::Tcp(stream) => {
                stream.set_read_timeout(Some(timeout.max(Duration::from_millis(1))))?;
                stream.read(buf)
            }
            Wire::Fifo { from_image, .. } => {
                use std::os::fd::AsRawFd;
                let mut poll = libc::pollfd {
                    fd: from_image.as_raw_fd(),
                    events: libc::POLLIN,
                    revents: 0,
                };
                let millis = libc::c_int::try_from(timeout.as_millis().max(1)).unwrap_or(1000);
                // SAFETY: one valid pollfd, count 1, for the duration of the call.
                let ready = unsafe { libc::poll(&mut poll, 1, millis) };
                match ready {
                    0 => Err(ErrorKind::TimedOut.into()),
                    n if n < 0 => Err(std::io::Error::last_os_error()),
                    _ => from_image.read(buf),
                }
            }
        }
    }

    /// Append the defmt bytes waiting in the log FIFO to `bytes` (nothing for TCP).
    fn read_log(&mut self, bytes: &mut Vec<u8>) {
        if let Wire::Fifo { log, .. } = self {
            let mut chunk = [0u8; 4096];
            // Non-blocking: stops at WouldBlock (empty) or an error.
            while let Ok(n @ 1..) = log.read(&mut chunk) {
                bytes.extend_from_slice(chunk.get(..n).unwrap_or(&[]));
            }
        }
    }

    fn shutdown(&mut self) {
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
fn make_fifos() -> anyhow::Result<Wire> {
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
        let c_path = std::ffi::CString::new(path.as_os_str().as_encoded_bytes())
            .map_err(|_| anyhow!("NUL in {}", path.display()))?;
        // SAFETY: a valid NUL-terminated path for the duration of the call.
        if unsafe { libc::mkfifo(c_path.as_ptr(), 0o600) } != 0 {
            let error = std::io::Error::last_os_error();
            let _ = std::fs::remove_dir_all(&folder);
            return Err(error).with_context(|| format!("mkfifo {}", path.display()));
        }
        // Read-write: Linux opens a FIFO so without waiting for the other end. The log is
        // drained between ticks, so its reads must not wait.
        use std::os::unix::fs::OpenOptionsExt;
        let flags = if name == "sweephold-log" {
            libc::O_NONBLOCK
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

/// One QEMU process running the image, and the byte stream to it.
struct QemuProcess {
    child: Child,
    wire: Wire,
    stderr: Arc<Mutex<Vec<u8>>>,
}

/// The frame exchange with one QEMU.
type Session = FrameChannel<QemuProcess>;

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
fn start_session(
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

impl FlightControllerLink for QemuLink {
    fn describe(&self) -> String {
        self.transport.link_name().to_string()
    }

    fn begin_record(&mut self, config: &Config) -> anyhow::Result<()> {
        let request = link_config(config)?;
        let answer = self
            .session()
            .and_then(|session| session.configure(request, CONFIGURE_TIMEOUT));
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
            .session()
            .and_then(|session| session.exchange(input, telemetry, &mut stray, TICK_TIMEOUT));
        self.stray_answers += stray;
        self.keep_if_ok(result)
    }

    fn end_record(&mut self, dump_name: &str) -> anyhow::Result<()> {
        self.drain_log();
        let bytes = std::mem::take(&mut self.log_bytes);
        let Some(folder) = &self.log_folder else {
            return Ok(());
        };
        if self.transport != QemuTransport::Semihosting {
            return Ok(());
        }
        let path = folder.join(Path::new(dump_name).with_extension("log"));
        if self.defmt_table.is_none() {
            match DefmtTable::from_elf(&self.image) {
                Ok(table) => self.defmt_table = Some(table),
                // The record itself is fine: say in its log why there is no text.
                Err(error) => {
                    return std::fs::write(&path, format!("(no defmt log: {error:#})\n"))
                        .with_context(|| format!("cannot write {}", path.display()));
                }
            }
        }
        let Some(table) = &self.defmt_table else {
            return Ok(());
        };
        write_log(&path, &table.decode(&bytes))
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
    use sweephold_protocol::Axis;

    /// A record's log is written even when the image's defmt table cannot be read: it
    /// says why instead of failing the record.
    #[test]
    fn an_unreadable_defmt_table_is_explained_in_the_log() {
        let dir = std::env::temp_dir().join(format!("sweephold-qemu-log-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut link = QemuLink::new(
            Path::new("/nonexistent/sweephold-fc"),
            QemuTransport::Semihosting,
            &[],
        )
        .with_log_folder(&dir);
        link.end_record("lat-1.bin").expect("the log is written");
        let text = std::fs::read_to_string(dir.join("lat-1.log")).unwrap();
        assert!(
            text.starts_with("(no defmt log: cannot read /nonexistent/sweephold-fc"),
            "{text}"
        );
        // Without a log folder nothing is written and nothing fails.
        let mut quiet = QemuLink::new(Path::new("/nonexistent"), QemuTransport::Semihosting, &[]);
        quiet.end_record("lat-2.bin").expect("no folder, no log");
        assert!(!dir.join("lat-2.log").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A scratch folder removed on drop.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str) -> Scratch {
            let dir = std::env::temp_dir()
                .join(format!("sweephold-link-qemu-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }
        fn file(&self, relative: &str, bytes: &[u8]) -> PathBuf {
            let path = self.0.join(relative);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, bytes).unwrap();
            path
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// The first 20 bytes of an ELF header: class, data, machine.
    fn elf_header(class: u8, data: u8, machine: u16) -> Vec<u8> {
        let mut bytes = vec![0x7f, b'E', b'L', b'F', class, data, 1];
        bytes.resize(16, 0);
        bytes.extend_from_slice(&2u16.to_le_bytes()); // e_type: executable
        bytes.extend_from_slice(&machine.to_le_bytes());
        bytes.resize(64, 0);
        bytes
    }

    #[test]
    fn the_default_image_is_found_in_the_binarys_workspace() {
        let scratch = Scratch::new("default");
        let ws = scratch.0.join("ws");
        scratch.file(
            "ws/Cargo.toml",
            b"[package]\nname = \"x\"\n\n[workspace]\nmembers = []\n",
        );
        // A member's Cargo.toml below it has no [workspace]: the walk goes past it.
        scratch.file("ws/host/cli/Cargo.toml", b"[package]\nname = \"y\"\n");
        let exe = ws.join("target/release/sweephold");
        let elsewhere = scratch.0.join("elsewhere");
        std::fs::create_dir_all(&elsewhere).unwrap();

        // Not built yet: the error names where it looked and how to build it.
        let error = find_image(None, None, Some(&exe), Some(&elsewhere))
            .unwrap_err()
            .to_string();
        let in_ws = ws.join("target").join(IMAGE_IN_TARGET_DIR);
        assert!(error.contains(&in_ws.display().to_string()), "{error}");
        assert!(
            error.contains(&format!("`cargo fw` in {}", ws.display())),
            "{error}"
        );
        assert!(
            error.contains(IMAGE_ENV) && !error.contains('\n'),
            "{error}"
        );

        // Built: found from the binary, whatever the current directory.
        let image = scratch.file(
            &format!("ws/target/{IMAGE_IN_TARGET_DIR}"),
            &elf_header(1, 1, EM_ARM),
        );
        assert_eq!(
            find_image(None, None, Some(&exe), Some(&elsewhere)).unwrap(),
            image
        );
        // A test binary in target/debug/deps/ belongs to the same workspace.
        let test_exe = ws.join("target/debug/deps/qemu-0123");
        assert_eq!(
            find_image(None, None, Some(&test_exe), None).unwrap(),
            image
        );
        // A binary outside any workspace: the current directory's target/.
        let installed = scratch.0.join("bin/sweephold");
        assert_eq!(
            find_image(None, None, Some(&installed), Some(&ws)).unwrap(),
            image
        );
        let error = find_image(None, None, Some(&installed), Some(&elsewhere))
            .unwrap_err()
            .to_string();
        assert!(error.contains("in the sweephold workspace"), "{error}");

        // The variable wins, and a wrong one is an error naming it.
        let other = scratch.file("other.elf", &elf_header(1, 1, EM_ARM));
        assert_eq!(
            find_image(Some(other.clone().into()), None, Some(&exe), None).unwrap(),
            other
        );
        let error = find_image(Some("/nonexistent/fc.elf".into()), None, Some(&exe), None)
            .unwrap_err()
            .to_string();
        assert!(
            error.starts_with("SWEEPHOLD_FC_ELF=/nonexistent/fc.elf: no such file"),
            "{error}"
        );
    }

    #[test]
    fn only_a_32_bit_arm_elf_is_booted() {
        let scratch = Scratch::new("elf");
        let arm = scratch.file("arm.elf", &elf_header(1, 1, EM_ARM));
        check_image(&arm).unwrap();
        for (name, bytes, reason) in [
            (
                "text.bin",
                b"hello, not an image".to_vec(),
                "not an ELF file",
            ),
            ("empty.bin", Vec::new(), "not an ELF file"),
            ("short.elf", b"\x7fELF\x01\x01".to_vec(), "cut short"),
            (
                "x86_64.elf",
                elf_header(2, 1, 62),
                "not 32-bit little-endian",
            ),
            (
                "x86.elf",
                elf_header(1, 1, 3),
                "machine 3, not 32-bit ARM (40)",
            ),
        ] {
            let path = scratch.file(name, &bytes);
            let error = check_image(&path).unwrap_err().to_string();
            assert!(
                error.starts_with(&format!(
                    "{} is not a flight-controller image",
                    path.display()
                )),
                "{error}"
            );
            assert!(error.contains(reason), "{name}: {error}");
            assert!(
                error.contains("cargo fw") && !error.contains('\n'),
                "{error}"
            );
        }
        let error = check_image(&scratch.0).unwrap_err().to_string();
        assert!(error.contains("is not a file"), "{error}");
        let error = check_image(&scratch.0.join("missing"))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("not found: build it with `cargo fw`"),
            "{error}"
        );
    }

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

    #[test]
    fn a_missing_image_is_named_with_the_command_that_builds_it() {
        let mut link = QemuLink::new(
            Path::new("/nonexistent/sweephold-fc"),
            QemuTransport::Semihosting,
            &[],
        );
        let error = link
            .begin_record(&Config::bo105_default(Axis::Lat))
            .expect_err("no image");
        let text = error.to_string();
        assert!(
            text.contains("cargo fw") || text.contains("apt-get install qemu-system-arm"),
            "{text}"
        );
    }
}
