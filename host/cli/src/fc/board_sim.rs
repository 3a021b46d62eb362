//! `--fc board-sim:FLASH` for `sweephold fc params`: a simulated board that holds its
//! parameters like a board, in FLASH ([`board_flash`]).
//!
//! Every command is a power cycle: the board boots from FLASH ([`ParamLink::boot`]: the
//! saved set, or the TREX 700L preset's defaults when FLASH holds none, as the board
//! image), obeys the command's parameter frames — encoded and decoded with the protocol's
//! codec, as over a serial line — and is switched off when the command ends. What a
//! `set`, `push` or `reset` changed in RAM is then lost unless `save` wrote it to FLASH:
//! a save writes the file back at once (atomically, replacing it whole).

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::anyhow;
use sweephold_firmware::params::link::ParamLink;
use sweephold_firmware::params::store::ParamStore;
use sweephold_protocol::codec::encode_to_vec;
use sweephold_protocol::decoder::Decoder;
use sweephold_protocol::{Frame, ParamOp, ParamReply};

use crate::fly::board_flash::{self, FileFlash, BOARD_VEHICLE};

/// A board-sim board on the other end of a byte stream: frames sent to it are decoded
/// and its parameter requests obeyed (it is disarmed: on the ground); its replies are
/// read back as bytes.
pub struct BoardSimWire {
    path: PathBuf,
    link: Option<ParamLink<FileFlash>>,
    decoder: Decoder,
    replies: Vec<u8>,
}

impl BoardSimWire {
    /// Power the board on: boot from FLASH at `path`.
    pub fn boot(path: &Path) -> anyhow::Result<Self> {
        let store = board_flash::store(FileFlash::open(path)?)?;
        Ok(BoardSimWire {
            path: path.to_path_buf(),
            link: Some(ParamLink::boot(Some(store), BOARD_VEHICLE)),
            decoder: Decoder::new(),
            replies: Vec::new(),
        })
    }

    /// A save wrote the store: the flash's memory goes to FLASH at once, as a board's
    /// flash holds what it was programmed with. The set in RAM is the saved one, so the
    /// board carries on with the store reopened on the same memory.
    fn write_back(&mut self) -> anyhow::Result<()> {
        let flash = self
            .link
            .take()
            .and_then(ParamLink::into_store)
            .map(ParamStore::into_flash)
            .ok_or_else(|| anyhow!("the board-sim board has no store"))?;
        flash.persist(&self.path)?;
        self.link = Some(ParamLink::boot(
            Some(board_flash::store(FileFlash::reopened(flash))?),
            BOARD_VEHICLE,
        ));
        Ok(())
    }
}

impl crate::fly::frame_channel::ByteWire for BoardSimWire {
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let mut requests = Vec::new();
        self.decoder.feed_with(bytes, |frame| {
            if let Ok(Frame::ParamRequest(request)) = frame {
                requests.push(request);
            }
        });
        for request in requests {
            let Some(link) = self.link.as_mut() else {
                return Err(std::io::Error::other("the board is off"));
            };
            let replies = &mut self.replies;
            let mut saved = false;
            link.handle(&request, true, |reply| {
                saved |= reply == ParamReply::Done { op: ParamOp::Save };
                if let Ok(encoded) = encode_to_vec(&Frame::ParamReply(reply)) {
                    replies.extend_from_slice(encoded.as_bytes());
                }
            });
            if saved {
                self.write_back()
                    .map_err(|e| std::io::Error::other(format!("{e:#}")))?;
            }
        }
        Ok(())
    }

    fn recv(&mut self, buf: &mut [u8], _timeout: Duration) -> std::io::Result<usize> {
        if self.replies.is_empty() {
            return Err(std::io::ErrorKind::TimedOut.into());
        }
        let n = buf.len().min(self.replies.len());
        buf[..n].copy_from_slice(&self.replies[..n]);
        self.replies.drain(..n);
        Ok(n)
    }

    fn failure(&mut self, what: &str) -> anyhow::Error {
        anyhow!("{what} (board-sim, flash {})", self.path.display())
    }
}
