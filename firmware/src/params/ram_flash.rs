//! A NOR flash in RAM with a chosen write and erase size, and the bytes a store region
//! holds after a save (host only): the QEMU tests preload a board's store sectors with
//! what this library's own [`ParamStore`] writes, so a stored set is made by the same
//! code as on the board, not by a second encoder.

use core::ops::Range;

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

use super::store::{ParamStore, RegionError, SaveError};
use super::ParamTable;

/// Why a region image could not be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageError {
    /// The region is not usable for the store.
    Region(RegionError),
    /// The save failed.
    Save(SaveError),
}

/// Out of bounds or misaligned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RamFlashError(NorFlashErrorKind);

impl NorFlashError for RamFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

const OUT_OF_BOUNDS: RamFlashError = RamFlashError(NorFlashErrorKind::OutOfBounds);

/// Erased NOR flash in RAM: writes only clear bits, erases set pages to 0xFF.
#[derive(Clone, Debug)]
pub struct RamFlash<const WRITE: usize, const ERASE: usize> {
    /// The memory, from offset 0.
    pub mem: Vec<u8>,
}

impl<const WRITE: usize, const ERASE: usize> RamFlash<WRITE, ERASE> {
    /// `capacity` erased bytes.
    pub fn new(capacity: usize) -> Self {
        RamFlash {
            mem: vec![0xFF; capacity],
        }
    }

    fn span(&self, offset: u32, len: usize, unit: usize) -> Result<Range<usize>, RamFlashError> {
        let start = offset as usize;
        if !start.is_multiple_of(unit) || !len.is_multiple_of(unit) {
            return Err(RamFlashError(NorFlashErrorKind::NotAligned));
        }
        if start + len > self.mem.len() {
            return Err(OUT_OF_BOUNDS);
        }
        Ok(start..start + len)
    }
}

impl<const WRITE: usize, const ERASE: usize> ErrorType for RamFlash<WRITE, ERASE> {
    type Error = RamFlashError;
}

impl<const WRITE: usize, const ERASE: usize> ReadNorFlash for RamFlash<WRITE, ERASE> {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), RamFlashError> {
        let span = self.span(offset, bytes.len(), 1)?;
        bytes.copy_from_slice(self.mem.get(span).ok_or(OUT_OF_BOUNDS)?);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.mem.len()
    }
}

impl<const WRITE: usize, const ERASE: usize> NorFlash for RamFlash<WRITE, ERASE> {
    const WRITE_SIZE: usize = WRITE;
    const ERASE_SIZE: usize = ERASE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), RamFlashError> {
        let len = (to as usize).saturating_sub(from as usize);
        let span = self.span(from, len, ERASE)?;
        self.mem.get_mut(span).ok_or(OUT_OF_BOUNDS)?.fill(0xFF);
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), RamFlashError> {
        let span = self.span(offset, bytes.len(), WRITE)?;
        for (cell, byte) in self
            .mem
            .get_mut(span)
            .ok_or(OUT_OF_BOUNDS)?
            .iter_mut()
            .zip(bytes)
        {
            *cell &= byte;
        }
        Ok(())
    }
}

/// The bytes of `region` (offsets in a flash of `region.end` bytes with WRITE-byte
/// words and ERASE-byte pages) after `table` was saved into an erased store there.
pub fn saved_region<const WRITE: usize, const ERASE: usize>(
    table: &ParamTable,
    region: Range<u32>,
) -> Result<Vec<u8>, ImageError> {
    let flash = RamFlash::<WRITE, ERASE>::new(region.end as usize);
    let mut store = ParamStore::new(flash, region.clone()).map_err(ImageError::Region)?;
    store.save(table).map_err(ImageError::Save)?;
    let flash = store.into_flash();
    let bytes = flash.mem.get(region.start as usize..region.end as usize);
    Ok(bytes.unwrap_or_default().to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::store::LoadStatus;
    use crate::params::ParamId;
    use sweephold_protocol::VehicleId;

    #[test]
    fn a_saved_region_loads_back_where_it_is_placed() {
        let mut table = ParamTable::defaults(VehicleId::Trex700l);
        table.set(ParamId::SwashPhase, 7.5).unwrap();
        let region = 0x4000..0xC000;
        let bytes = saved_region::<4, 0x4000>(&table, region.clone()).unwrap();
        assert_eq!(bytes.len(), 0x8000);
        let mut flash = RamFlash::<4, 0x4000>::new(0xC000);
        flash.mem[0x4000..].copy_from_slice(&bytes);
        let mut store = ParamStore::new(flash, region).unwrap();
        let loaded = store.load(VehicleId::Trex700l);
        assert_eq!(loaded.status, LoadStatus::Loaded);
        assert_eq!(loaded.table, table);
        // Misaligned or foreign regions are refused, not panicked on.
        assert!(saved_region::<4, 0x4000>(&table, 0x100..0x8100).is_err());
    }
}
