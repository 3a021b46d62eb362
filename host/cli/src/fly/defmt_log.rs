//! The board image's defmt log, decoded on the host.
//!
//! The image logs with defmt: each log call sends a compact binary frame (an index into
//! the format strings the ELF keeps in its `.defmt` section, the timestamp and the
//! arguments, rzCOBS-framed). Under `sweephold fly --fc qemu` those frames reach the host
//! through the semihosting file `sweephold-log` (firmware `board/log.rs`); this module
//! turns them back into text with `defmt-decoder` against the ELF that produced them,
//! one line per message: the timestamp (the loop tick of the Sample the message belongs
//! to), the level and the message.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{anyhow, Context};
use defmt_decoder::{DecodeError, Table};

/// The format-string table of one image.
pub struct DefmtTable {
    table: Table,
}

/// The text of a stretch of log bytes.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct DecodedLog {
    /// One line per message, `"<tick> <LEVEL> <message>"`.
    pub lines: Vec<String>,
    /// Frames that did not decode (skipped).
    pub malformed: usize,
}

impl DefmtTable {
    /// The table of the ELF at `elf`; an error when the file cannot be read, is not an
    /// ELF, has no `.defmt` section or was built with another defmt wire version.
    pub fn from_elf(elf: &Path) -> anyhow::Result<DefmtTable> {
        let bytes = std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
        let table = Table::parse(&bytes)
            .map_err(|e| anyhow!("{}: defmt table unreadable: {e}", elf.display()))?
            .ok_or_else(|| anyhow!("{}: no .defmt section (not a defmt image)", elf.display()))?;
        Ok(DefmtTable { table })
    }

    /// Decode `bytes`, a sequence of whole defmt frames. A frame that does not decode is
    /// counted and skipped (the stream resynchronises on the next frame delimiter).
    pub fn decode(&self, bytes: &[u8]) -> DecodedLog {
        let mut decoder = self.table.new_stream_decoder();
        decoder.received(bytes);
        let mut log = DecodedLog::default();
        // Every successful or malformed decode consumes at least one byte: bounded.
        for _ in 0..=bytes.len() {
            match decoder.decode() {
                Ok(frame) => {
                    let mut line = String::new();
                    if let Some(timestamp) = frame.display_timestamp() {
                        // (Its Display ignores width: pad the text.)
                        let _ = write!(line, "{:>8} ", timestamp.to_string());
                    }
                    let level = frame
                        .level()
                        .map_or("PRINT".to_string(), |level| level.as_str().to_uppercase());
                    let _ = write!(line, "{level:<5} {}", frame.display_message());
                    log.lines.push(line);
                }
                Err(DecodeError::UnexpectedEof) => break,
                Err(DecodeError::Malformed) => log.malformed += 1,
            }
        }
        log
    }
}

/// Write `log` to `path`, one message per line (an empty file when there was none; a
/// last line says how many frames did not decode, if any).
pub fn write_log(path: &Path, log: &DecodedLog) -> anyhow::Result<()> {
    let mut text = String::new();
    for line in &log.lines {
        text.push_str(line);
        text.push('\n');
    }
    if log.malformed > 0 {
        let _ = writeln!(text, "({} malformed defmt frames skipped)", log.malformed);
    }
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_that_is_not_an_elf_is_refused_with_its_name() {
        let dir = std::env::temp_dir().join(format!("sweephold-defmt-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("not-an-elf");
        std::fs::write(&path, b"hello").unwrap();
        let error = DefmtTable::from_elf(&path).err().expect("refused");
        assert!(error.to_string().contains("not-an-elf"), "{error}");
        let missing = DefmtTable::from_elf(&dir.join("missing"))
            .err()
            .expect("refused");
        assert!(missing.to_string().contains("cannot read"), "{missing}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_log_file_has_one_line_per_message_and_counts_bad_frames() {
        let dir = std::env::temp_dir().join(format!("sweephold-defmtw-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("lat-1.log");
        let log = DecodedLog {
            lines: vec!["       0 INFO  a".into(), "       5 WARN  b".into()],
            malformed: 2,
        };
        write_log(&path, &log).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            "       0 INFO  a\n       5 WARN  b\n(2 malformed defmt frames skipped)\n"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
