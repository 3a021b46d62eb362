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
//! the thread unwinds — and a failed record boots a fresh one for the next. SIGINT or
//! SIGTERM stops the run within a second of flight (`crate::interrupt`), which drops the
//! link; a second signal ends the run at once, killing every registered QEMU first. On
//! Ctrl-C the terminal's SIGINT reaches QEMU too (same foreground process group); over semihosting the image also asks QEMU to exit when the host's end of the
//! FIFO closes, so even a killed host leaves no emulator behind (only its FIFO folder in
//! the temporary directory, which Drop removes otherwise).
//!
//! Its parts: `image` (where the image is, and the check that a file is one), `process`
//! (one QEMU running it) and `wire` (the byte stream to it).

mod image;
mod process;
mod wire;

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{anyhow, Context};
use sweephold_firmware::Config;
use sweephold_protocol::{ActuatorOut, SensorIn};

use super::defmt_log::{write_log, DefmtTable};
use super::frame_channel::{check_configure_answer, link_config};
use super::link::FlightControllerLink;
pub use image::{check_image, default_image, IMAGE_ENV, IMAGE_IN_TARGET_DIR};
use process::CONFIGURE_TIMEOUT;
pub use process::{extra_args_from_env, qemu_available, QemuTransport, QEMU};
pub use process::{start_session, QemuProcess, Session};

/// How long the image may take to answer one SensorIn. A tick needs well under a
/// millisecond of emulated time; this only catches a dead or wedged emulator.
const TICK_TIMEOUT: Duration = Duration::from_secs(10);

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
            session.wire_mut().read_log(&mut self.log_bytes);
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
