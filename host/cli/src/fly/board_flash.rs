//! The board-sim board's parameter sectors in a file (`--fc board-sim:FLASH`): a NOR
//! flash whose memory is the file ([`FileFlash`]), under the firmware library's own
//! [`ParamStore`] (sequential-storage) — the code the board runs. FLASH is two 16 KiB
//! sectors (the STM32F405's small sectors), created erased (all 0xFF) when absent.
//!
//! `fly` and `campaign` read the saved set with [`load_params`] and never write FLASH;
//! `sweephold fc params` talks to the board over it (`fc::board_sim`).

use std::path::Path;

use anyhow::{anyhow, bail};
use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use sweephold_firmware::params::store::{LoadStatus, ParamStore};
use sweephold_firmware::params::Params;
use sweephold_protocol::VehicleId;

use crate::output;

/// Erase unit of the file's flash \[bytes\] (an STM32F405 small sector).
pub const SECTOR: usize = 16 * 1024;
/// Sectors of the parameter region.
pub const SECTORS: usize = 2;
/// Bytes of a FLASH file.
pub const FLASH_LEN: usize = SECTOR * SECTORS;
/// Program unit \[bytes\] (the F405 programs 32-bit words at 2.7–3.6 V).
const WORD: usize = 4;
/// The preset whose defaults a board-sim board boots without a saved set (the board
/// image's default vehicle).
pub const BOARD_VEHICLE: VehicleId = VehicleId::Trex700l;

/// NOR flash in memory, loaded from and written back to a FLASH file: programming only
/// clears bits, erasing sets a whole sector to 0xFF.
pub struct FileFlash {
    mem: Vec<u8>,
    changed: bool,
}

/// An access outside the flash or not aligned to its units.
#[derive(Clone, Copy, Debug)]
pub struct FileFlashError(NorFlashErrorKind);

impl NorFlashError for FileFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

impl FileFlash {
    /// The flash FLASH holds; an erased one if the file does not exist.
    pub fn open(path: &Path) -> anyhow::Result<Self> {
        let mem = match std::fs::read(path) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => vec![0xFF; FLASH_LEN],
            Err(e) => bail!("cannot read {}: {}", path.display(), output::io_reason(&e)),
        };
        if mem.len() != FLASH_LEN {
            bail!(
                "{} is not a board-sim flash file: {} bytes, expected {FLASH_LEN} (two 16 KiB \
                 sectors)",
                path.display(),
                mem.len()
            );
        }
        Ok(FileFlash {
            mem,
            changed: false,
        })
    }

    /// The same memory, nothing changed since (after it was persisted).
    pub fn reopened(flash: FileFlash) -> Self {
        FileFlash {
            mem: flash.mem,
            changed: false,
        }
    }

    /// Write the memory to `path` (atomically) if anything was programmed or erased.
    pub fn persist(&self, path: &Path) -> anyhow::Result<()> {
        if self.changed {
            output::write_atomic(path, &self.mem)?;
        }
        Ok(())
    }

    fn range(&self, offset: u32, len: usize) -> Result<std::ops::Range<usize>, FileFlashError> {
        let start = offset as usize;
        match start.checked_add(len) {
            Some(end) if end <= self.mem.len() => Ok(start..end),
            _ => Err(FileFlashError(NorFlashErrorKind::OutOfBounds)),
        }
    }
}

impl ErrorType for FileFlash {
    type Error = FileFlashError;
}

impl ReadNorFlash for FileFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FileFlashError> {
        let range = self.range(offset, bytes.len())?;
        bytes.copy_from_slice(&self.mem[range]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.mem.len()
    }
}

impl NorFlash for FileFlash {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = SECTOR;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), FileFlashError> {
        let (start, end) = (from as usize, to as usize);
        if !start.is_multiple_of(SECTOR) || !end.is_multiple_of(SECTOR) || start > end {
            return Err(FileFlashError(NorFlashErrorKind::NotAligned));
        }
        let range = self.range(from, end - start)?;
        self.mem[range].fill(0xFF);
        self.changed = true;
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FileFlashError> {
        if !(offset as usize).is_multiple_of(WORD) || !bytes.len().is_multiple_of(WORD) {
            return Err(FileFlashError(NorFlashErrorKind::NotAligned));
        }
        let range = self.range(offset, bytes.len())?;
        for (cell, byte) in self.mem[range].iter_mut().zip(bytes) {
            *cell &= byte;
        }
        self.changed = true;
        Ok(())
    }
}

/// The board's parameter store over FLASH's memory.
pub fn store(flash: FileFlash) -> anyhow::Result<ParamStore<FileFlash>> {
    ParamStore::new(flash, 0..FLASH_LEN as u32)
        .map_err(|e| anyhow!("the board-sim flash region is unusable ({e:?})"))
}

/// The set saved in FLASH as the board boots it for `vehicle`'s preset, or a one-line
/// error when FLASH holds no valid set (the board would boot defaults and refuse to arm).
pub fn load_params(path: &Path, vehicle: VehicleId) -> anyhow::Result<Params> {
    if !path.exists() {
        bail!(
            "{} does not exist: the board has no saved parameters (`sweephold fc params push \
             FILE --fc board-sim:{0}` then `save`)",
            path.display()
        );
    }
    let loaded = store(FileFlash::open(path)?)?.load(vehicle);
    if loaded.status != LoadStatus::Loaded {
        bail!(
            "{} holds no valid parameter set ({:?}): the board would boot its defaults and \
             refuse to arm; push and save a set with `sweephold fc params … --fc \
             board-sim:{0}`",
            path.display(),
            loaded.status
        );
    }
    loaded.table.params().map_err(|e| {
        anyhow!(
            "{}: the saved set is refused: {}",
            path.display(),
            e.message()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_flash_programs_like_nor_flash() {
        let dir = std::env::temp_dir().join(format!("sweephold-fileflash-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("flash.bin");
        let mut flash = FileFlash::open(&path).unwrap();
        assert!(flash.mem.iter().all(|&b| b == 0xFF));
        flash.write(8, &[0x0F, 0xF0, 0x00, 0xFF]).unwrap();
        flash.write(8, &[0xFF, 0x0F, 0xFF, 0x01]).unwrap();
        let mut word = [0; 4];
        flash.read(8, &mut word).unwrap();
        assert_eq!(word, [0x0F, 0x00, 0x00, 0x01]);
        assert!(flash.write(2, &[0; 4]).is_err());
        assert!(flash.write(FLASH_LEN as u32, &[0; 4]).is_err());
        assert!(flash.erase(0, 100).is_err());
        flash.persist(&path).unwrap();
        let again = FileFlash::open(&path).unwrap();
        assert_eq!(again.mem[8..12], [0x0F, 0x00, 0x00, 0x01]);
        let mut again = again;
        again.erase(0, SECTOR as u32).unwrap();
        assert!(again.mem[..SECTOR].iter().all(|&b| b == 0xFF));
        std::fs::write(&path, [0u8; 100]).unwrap();
        let wrong = FileFlash::open(&path).err().unwrap().to_string();
        assert!(wrong.contains("not a board-sim flash file"), "{wrong}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
