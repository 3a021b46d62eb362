//! The STM32F405's flash as an `embedded-storage` [`NorFlash`]: the parameter store's
//! two sectors (10 and 11, [`STORE_SECTORS`]), reserved for it in `memory.x`.
//!
//! **Sequence** (RM0090 §3.6): unlock the control register (the two keys into KEYR),
//! 32-bit parallelism (PSIZE x32: the boards run at 3.3 V), then either a sector erase
//! (SER, SNB, STRT) or one word program at a time (PG, then the word stored at its
//! address), each time waiting for BSY to clear and checking the error flags (a flag
//! is an error, cleared before the next operation), and lock again whatever happened.
//! Every programmed word is read back and compared: a mismatch is an error (a flash that
//! ignores writes, as QEMU's `netduinoplus2` does, is refused at the first word, never
//! taken for saved). Reads are memory-mapped.
//!
//! **Bounds.** The driver's device is the whole 1 MiB (offsets from `0x0800_0000`), so
//! offsets are the chip's; but it erases and programs only inside the store's sectors:
//! anything else is refused `OutOfBounds`, so no bug can erase the image. Its erase unit
//! is the 128 KiB sector of the store.
//!
//! **Stalls.** While a sector is erased (up to 2 s for 128 KiB at x32, datasheet) the
//! CPU cannot fetch from flash: the loop stops. The image saves only while disarmed and
//! stretches the independent watchdog around a save
//! ([`Watchdog::stretch_for_flash`](crate::chip::watchdog::Watchdog::stretch_for_flash)).
//!
//! The registers are reached through [`FlashBus`], so the host tests drive this same
//! driver against a model of the controller; on the chip it is [`Registers`].

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Where the flash is mapped.
pub const FLASH_BASE: u32 = 0x0800_0000;
/// The device: 1 MiB.
pub const FLASH_SIZE: u32 = 1024 * 1024;
/// A store sector \[bytes\] (sectors 5 to 11 are 128 KiB).
pub const SECTOR_SIZE: u32 = 128 * 1024;
/// The store's sectors: the last two of the device.
pub const STORE_SECTORS: [u8; 2] = [10, 11];
/// The store's region, as offsets into the device: sectors 10 and 11.
pub const STORE_REGION: core::ops::Range<u32> =
    sector_offset(STORE_SECTORS[0])..sector_offset(STORE_SECTORS[1]) + SECTOR_SIZE;

/// The offset of sector `n` (5 ≤ n ≤ 11, the 128 KiB ones).
pub const fn sector_offset(n: u8) -> u32 {
    0x2_0000 + (n as u32 - 5) * SECTOR_SIZE
}

/// KEYR's unlock sequence (RM0090 §3.5.1).
pub const KEY1: u32 = 0x4567_0123;
/// Second key.
pub const KEY2: u32 = 0xCDEF_89AB;

/// CR bits (RM0090 §3.9.7).
pub mod cr {
    /// Programming.
    pub const PG: u32 = 1 << 0;
    /// Sector erase.
    pub const SER: u32 = 1 << 1;
    /// Sector number field's position (4 bits).
    pub const SNB_SHIFT: u32 = 3;
    /// Sector number field.
    pub const SNB_MASK: u32 = 0xF << SNB_SHIFT;
    /// Parallelism field's position (2 bits).
    pub const PSIZE_SHIFT: u32 = 8;
    /// Parallelism field (the tests' model checks it).
    #[cfg(test)]
    pub const PSIZE_MASK: u32 = 0b11 << PSIZE_SHIFT;
    /// Parallelism x32.
    pub const PSIZE_X32: u32 = 0b10 << PSIZE_SHIFT;
    /// Start the erase.
    pub const STRT: u32 = 1 << 16;
    /// Lock CR.
    pub const LOCK: u32 = 1 << 31;
}

/// SR bits (RM0090 §3.9.6).
pub mod sr {
    /// End of operation.
    pub const EOP: u32 = 1 << 0;
    /// Operation error.
    pub const OPERR: u32 = 1 << 1;
    /// Write protection error.
    pub const WRPERR: u32 = 1 << 4;
    /// Programming alignment error.
    pub const PGAERR: u32 = 1 << 5;
    /// Programming parallelism error.
    pub const PGPERR: u32 = 1 << 6;
    /// Programming sequence error.
    pub const PGSERR: u32 = 1 << 7;
    /// Busy.
    pub const BSY: u32 = 1 << 16;
    /// Every error flag.
    pub const ERRORS: u32 = OPERR | WRPERR | PGAERR | PGPERR | PGSERR;
}

/// The flash controller's registers and the memory-mapped flash.
pub trait FlashBus {
    /// Write KEYR.
    fn write_keyr(&mut self, key: u32);
    /// Read CR.
    fn read_cr(&self) -> u32;
    /// Write CR.
    fn write_cr(&mut self, value: u32);
    /// Read SR.
    fn read_sr(&self) -> u32;
    /// Write SR (1 clears a flag).
    fn write_sr(&mut self, value: u32);
    /// Store `word` at `address` (the program step of PG).
    fn write_word(&mut self, address: u32, word: u32);
    /// The memory at `address` (mapped reads).
    fn read_bytes(&self, address: u32, bytes: &mut [u8]);
}

/// Why a flash operation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum FlashError {
    /// Offset or length not a multiple of the write or erase unit.
    NotAligned,
    /// Outside the device, or (erase, program) outside the store's sectors.
    OutOfBounds,
    /// The control register stayed locked after the keys.
    Locked,
    /// The controller raised these SR error flags.
    Controller(u32),
    /// A programmed word read back different.
    Verify,
}

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            FlashError::NotAligned => NorFlashErrorKind::NotAligned,
            FlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            FlashError::Locked | FlashError::Controller(_) | FlashError::Verify => {
                NorFlashErrorKind::Other
            }
        }
    }
}

/// The flash over a [`FlashBus`].
pub struct F405Flash<B: FlashBus> {
    bus: B,
}

impl<B: FlashBus> F405Flash<B> {
    /// The driver over `bus`.
    pub fn new(bus: B) -> Self {
        F405Flash { bus }
    }

    /// The bus back (tests).
    #[cfg(test)]
    pub fn into_bus(self) -> B {
        self.bus
    }

    /// Unlock CR, clear stale flags, run `operation`, lock CR again whatever happened.
    fn unlocked(
        &mut self,
        operation: impl FnOnce(&mut Self) -> Result<(), FlashError>,
    ) -> Result<(), FlashError> {
        self.wait_idle();
        if self.bus.read_cr() & cr::LOCK != 0 {
            self.bus.write_keyr(KEY1);
            self.bus.write_keyr(KEY2);
        }
        let result = if self.bus.read_cr() & cr::LOCK != 0 {
            Err(FlashError::Locked)
        } else {
            self.bus.write_sr(sr::ERRORS | sr::EOP);
            operation(self)
        };
        self.bus.write_cr(cr::LOCK);
        result
    }

    /// Wait for BSY to clear (the controller always ends an operation; an erase takes
    /// up to 2 s, during which this loop's own fetches stall).
    fn wait_idle(&self) {
        while self.bus.read_sr() & sr::BSY != 0 {}
    }

    /// Wait for the operation to end; its error flags, if any, cleared and returned.
    fn finish(&mut self) -> Result<(), FlashError> {
        self.wait_idle();
        let errors = self.bus.read_sr() & sr::ERRORS;
        // PG and SER off again: the next operation starts from a clean CR.
        self.bus.write_cr(cr::PSIZE_X32);
        if errors != 0 {
            self.bus.write_sr(errors);
            return Err(FlashError::Controller(errors));
        }
        Ok(())
    }

    fn erase_sector(&mut self, sector: u8) -> Result<(), FlashError> {
        let snb = (u32::from(sector) << cr::SNB_SHIFT) & cr::SNB_MASK;
        self.bus.write_cr(cr::PSIZE_X32 | cr::SER | snb);
        self.bus.write_cr(cr::PSIZE_X32 | cr::SER | snb | cr::STRT);
        self.finish()
    }

    fn program_word(&mut self, offset: u32, word: [u8; 4]) -> Result<(), FlashError> {
        let address = FLASH_BASE + offset;
        self.bus.write_cr(cr::PSIZE_X32 | cr::PG);
        self.bus.write_word(address, u32::from_le_bytes(word));
        self.finish()?;
        let mut back = [0u8; 4];
        self.bus.read_bytes(address, &mut back);
        if back != word {
            return Err(FlashError::Verify);
        }
        Ok(())
    }
}

/// Whether `from..to` lies inside the store's region.
fn in_store(from: u32, to: u32) -> bool {
    from <= to && from >= STORE_REGION.start && to <= STORE_REGION.end
}

impl<B: FlashBus> ErrorType for F405Flash<B> {
    type Error = FlashError;
}

impl<B: FlashBus> ReadNorFlash for F405Flash<B> {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FlashError> {
        let end = offset
            .checked_add(u32::try_from(bytes.len()).map_err(|_| FlashError::OutOfBounds)?)
            .ok_or(FlashError::OutOfBounds)?;
        if end > FLASH_SIZE {
            return Err(FlashError::OutOfBounds);
        }
        self.bus.read_bytes(FLASH_BASE + offset, bytes);
        Ok(())
    }

    fn capacity(&self) -> usize {
        FLASH_SIZE as usize
    }
}

impl<B: FlashBus> NorFlash for F405Flash<B> {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR_SIZE as usize;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), FlashError> {
        if !from.is_multiple_of(SECTOR_SIZE) || !to.is_multiple_of(SECTOR_SIZE) {
            return Err(FlashError::NotAligned);
        }
        if !in_store(from, to) {
            return Err(FlashError::OutOfBounds);
        }
        self.unlocked(|flash| {
            let mut offset = from;
            while offset < to {
                let sector = 5 + ((offset - 0x2_0000) / SECTOR_SIZE) as u8;
                flash.erase_sector(sector)?;
                offset += SECTOR_SIZE;
            }
            Ok(())
        })
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FlashError> {
        let len = u32::try_from(bytes.len()).map_err(|_| FlashError::OutOfBounds)?;
        if !offset.is_multiple_of(4) || !len.is_multiple_of(4) {
            return Err(FlashError::NotAligned);
        }
        let end = offset.checked_add(len).ok_or(FlashError::OutOfBounds)?;
        if !in_store(offset, end) {
            return Err(FlashError::OutOfBounds);
        }
        self.unlocked(|flash| {
            let mut at = offset;
            for chunk in bytes.chunks_exact(4) {
                let word = [chunk[0], chunk[1], chunk[2], chunk[3]];
                flash.program_word(at, word)?;
                at += 4;
            }
            Ok(())
        })
    }
}

/// The chip's flash controller (thread mode only: the image reaches it from the loop's
/// parameter requests, never from an interrupt).
#[cfg(target_os = "none")]
pub struct Registers {
    flash: stm32f4::stm32f405::FLASH,
}

#[cfg(target_os = "none")]
impl Registers {
    /// The controller, handed over by `chip::devices`.
    pub fn new(flash: stm32f4::stm32f405::FLASH) -> Self {
        Registers { flash }
    }
}

#[cfg(target_os = "none")]
impl FlashBus for Registers {
    fn write_keyr(&mut self, key: u32) {
        self.flash.keyr().write(|w| w.key().set(key));
    }

    fn read_cr(&self) -> u32 {
        self.flash.cr().read().bits()
    }

    fn write_cr(&mut self, value: u32) {
        // SAFETY: every CR bit pattern is a valid register value; the ones written here
        // (PG, SER, SNB, PSIZE, STRT, LOCK) are the documented programming and erase
        // controls (RM0090 §3.9.7), and the driver writes them only while the
        // controller is idle.
        self.flash.cr().write(|w| unsafe { w.bits(value) });
    }

    fn read_sr(&self) -> u32 {
        self.flash.sr().read().bits()
    }

    fn write_sr(&mut self, value: u32) {
        // SAFETY: SR's flags are write-1-to-clear; writing 1 to an error or EOP flag
        // only clears it, and BSY is read-only.
        self.flash.sr().write(|w| unsafe { w.bits(value) });
    }

    fn write_word(&mut self, address: u32, word: u32) {
        // SAFETY: `address` is a word-aligned address inside the parameter store's
        // sectors (checked by `F405Flash::write`), which `memory.x` keeps out of the
        // image: no Rust object lives there. With PG set, a 32-bit store to flash is
        // the program operation itself (RM0090 §3.6.4).
        unsafe { core::ptr::write_volatile(address as *mut u32, word) };
    }

    fn read_bytes(&self, address: u32, bytes: &mut [u8]) {
        for (i, byte) in bytes.iter_mut().enumerate() {
            // SAFETY: `address + i` lies inside the 1 MiB flash (checked by
            // `F405Flash::read`), which is always mapped and readable; volatile, since
            // a program or erase changes it behind the compiler's back.
            *byte = unsafe { core::ptr::read_volatile((address as usize + i) as *const u8) };
        }
    }
}

#[cfg(test)]
#[path = "flash_tests.rs"]
mod tests;
