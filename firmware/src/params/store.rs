//! The parameter set in flash: a dedicated region, one versioned and CRC-checked record
//! per save, wear-levelled, and a load that never fails (a missing, corrupt, foreign or
//! inconsistent store gives the defaults and says why).
//!
//! # Why sequential-storage
//!
//! [`sequential_storage`] (Tweede golf, 8.x, `no_std`, no allocation, in production
//! use, builds for `thumbv7em-none-eabihf`) keeps a key-value map in a range of NOR
//! flash pages over `embedded-storage`'s `NorFlash`: it only appends, cycles through
//! the pages (every page is erased equally often), protects each item's header and data
//! with a CRC and is written to survive a power loss at any point (an interrupted item
//! is ignored; an interrupted page migration is repaired on the next operation). That is
//! exactly the store the board needs; writing and proving one by hand would duplicate
//! it. Its API is async: [`embassy_futures::block_on`] runs each call to completion
//! over the board's blocking flash driver (wrapped by [`BlockingFlash`], which never
//! returns `Pending`, so `block_on` polls each future once). The flash layout is its
//! 8.x format; a major version of the crate may change it, which [`TABLE_VERSION`]
//! does not cover, so such an update must be treated like a table change.
//!
//! # Record
//!
//! The whole set is one item (key [`RECORD_KEY`]), so a save replaces all values at
//! once: after a power loss at any step the load sees the complete old set or the
//! complete new one (tested with a power loss injected at every write and erase of a
//! save). Its bytes, little-endian:
//!
//! ```text
//! magic "SWPP" | table version u16 | count u16 | count × f32 | CRC-32 of all before
//! ```
//!
//! The CRC-32 (the wire protocol's) is on top of the crate's own item CRC: it checks
//! the record end to end as this firmware wrote it.
//!
//! # Region
//!
//! The region must be at least two erase pages, page-aligned, and used by nothing
//! else. On the STM32F405 the erase unit is a sector (16, 64 or 128 KiB); the board
//! integration picks two sectors the image does not occupy.

use core::ops::Range;

use embedded_storage::nor_flash::{ErrorType, NorFlash, ReadNorFlash};
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapStorage};
use sweephold_protocol::codec::crc32;
use sweephold_protocol::VehicleId;

use super::table::{COUNT, TABLE_VERSION};
use super::ParamTable;

/// The map key of the parameter record.
pub const RECORD_KEY: u8 = 1;
/// The record's first four bytes.
pub const MAGIC: [u8; 4] = *b"SWPP";
/// Bytes of one record.
pub const RECORD_LEN: usize = 4 + 2 + 2 + 4 * COUNT + 4;
/// The work buffer: key, record and the crate's rounding to a flash word (up to 32
/// bytes on any flash it supports).
const BUFFER_LEN: usize = RECORD_LEN + 1 + 32;

/// Why a load fell back to the defaults (or that it did not).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadStatus {
    /// The stored set was loaded.
    Loaded,
    /// No record in the region (new board, or an erased region).
    Empty,
    /// A record or the region is damaged (CRC, length or magic wrong).
    Corrupt,
    /// The record was written for another table version.
    OtherVersion,
    /// The record holds values the table refuses, or a set that is inconsistent.
    Invalid,
    /// The flash driver reported an error.
    FlashError,
}

impl LoadStatus {
    /// Whether the stored set is in use; anything else means defaults, an event and no
    /// arming until a valid set is saved.
    pub const fn is_valid(self) -> bool {
        matches!(self, LoadStatus::Loaded)
    }
}

/// Why a save was refused or failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SaveError {
    /// The set is inconsistent ([`ParamTable::params`] refuses it): saving it would boot
    /// the defaults next time.
    Inconsistent,
    /// The flash driver failed, or the region is damaged beyond the crate's repair.
    Flash,
}

/// Why a store could not be created.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RegionError {
    /// Not page-aligned, fewer than two pages, or pages too small for the flash.
    Unusable,
}

/// A blocking `embedded-storage` flash seen through the async traits
/// sequential-storage takes; every call completes at once.
#[derive(Debug)]
pub struct BlockingFlash<F>(pub F);

impl<F: ErrorType> ErrorType for BlockingFlash<F> {
    type Error = F::Error;
}

impl<F: ReadNorFlash> embedded_storage_async::nor_flash::ReadNorFlash for BlockingFlash<F> {
    const READ_SIZE: usize = F::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.0.read(offset, bytes)
    }

    fn capacity(&self) -> usize {
        self.0.capacity()
    }
}

impl<F: NorFlash> embedded_storage_async::nor_flash::NorFlash for BlockingFlash<F> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.0.erase(from, to)
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.0.write(offset, bytes)
    }
}

type Map<F> = MapStorage<u8, BlockingFlash<F>, Cache<Uncached, Uncached, Uncached, u8>>;

/// The parameter store over `F`'s `region`.
pub struct ParamStore<F: NorFlash> {
    map: Map<F>,
    buffer: [u8; BUFFER_LEN],
}

/// What a load gives: the table to use and whether it is the stored one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Loaded {
    /// The stored set, or the defaults.
    pub table: ParamTable,
    /// Why the defaults, if they are.
    pub status: LoadStatus,
}

impl<F: NorFlash> ParamStore<F> {
    /// A store over `region` of `flash` (byte offsets within the flash device).
    pub fn new(flash: F, region: Range<u32>) -> Result<Self, RegionError> {
        let config = MapConfig::try_new(region).map_err(|_| RegionError::Unusable)?;
        Ok(ParamStore {
            map: MapStorage::new(BlockingFlash(flash), config, Cache::new_uncached()),
            buffer: [0; BUFFER_LEN],
        })
    }

    /// The flash back (for a test, or to hand it to something else).
    pub fn into_flash(self) -> F {
        let (flash, _) = self.map.destroy();
        flash.0
    }

    /// The stored set for `vehicle`, or its defaults and why.
    pub fn load(&mut self, vehicle: VehicleId) -> Loaded {
        let defaults = |status| Loaded {
            table: ParamTable::defaults(vehicle),
            status,
        };
        let fetched =
            embassy_futures::block_on(self.map.fetch_item::<&[u8]>(&mut self.buffer, &RECORD_KEY));
        let bytes = match fetched {
            Ok(Some(bytes)) => bytes,
            Ok(None) => return defaults(LoadStatus::Empty),
            Err(sequential_storage::Error::Storage { .. }) => {
                return defaults(LoadStatus::FlashError)
            }
            Err(_) => return defaults(LoadStatus::Corrupt),
        };
        match decode(bytes) {
            Ok(values) => match ParamTable::from_values(values) {
                Ok(table) if table.params().is_ok() => Loaded {
                    table,
                    status: LoadStatus::Loaded,
                },
                _ => defaults(LoadStatus::Invalid),
            },
            Err(status) => defaults(status),
        }
    }

    /// Save `table` (all values at once); an inconsistent set is refused before
    /// anything is written.
    pub fn save(&mut self, table: &ParamTable) -> Result<(), SaveError> {
        table.params().map_err(|_| SaveError::Inconsistent)?;
        let record = encode(table);
        embassy_futures::block_on(self.map.store_item(
            &mut self.buffer,
            &RECORD_KEY,
            &record.as_slice(),
        ))
        .map_err(|_| SaveError::Flash)
    }

    /// Store raw record bytes (tests of foreign and damaged records).
    #[cfg(test)]
    pub(crate) fn save_raw(&mut self, record: &[u8]) -> Result<(), SaveError> {
        embassy_futures::block_on(self.map.store_item(&mut self.buffer, &RECORD_KEY, &record))
            .map_err(|_| SaveError::Flash)
    }
}

/// The record of `table`.
pub fn encode(table: &ParamTable) -> [u8; RECORD_LEN] {
    let mut record = [0u8; RECORD_LEN];
    let mut at = 0;
    let mut put = |bytes: &[u8]| {
        if let Some(slot) = record.get_mut(at..at + bytes.len()) {
            slot.copy_from_slice(bytes);
        }
        at += bytes.len();
    };
    put(&MAGIC);
    put(&TABLE_VERSION.to_le_bytes());
    put(&(COUNT as u16).to_le_bytes());
    for value in table.values() {
        put(&value.to_le_bytes());
    }
    let body = RECORD_LEN - 4;
    let crc = crc32(record.get(..body).unwrap_or(&[]));
    if let Some(slot) = record.get_mut(body..) {
        slot.copy_from_slice(&crc.to_le_bytes());
    }
    record
}

/// The values in `bytes`, or why they cannot be used.
pub fn decode(bytes: &[u8]) -> Result<[f32; COUNT], LoadStatus> {
    let word = |at: usize| -> Option<[u8; 4]> { bytes.get(at..at + 4)?.try_into().ok() };
    let half = |at: usize| -> Option<u16> {
        Some(u16::from_le_bytes(bytes.get(at..at + 2)?.try_into().ok()?))
    };
    if bytes.get(..4) != Some(MAGIC.as_slice()) || bytes.len() < 12 {
        return Err(LoadStatus::Corrupt);
    }
    let body = bytes.len() - 4;
    let stored_crc = word(body).map(u32::from_le_bytes);
    if stored_crc != Some(crc32(bytes.get(..body).unwrap_or(&[]))) {
        return Err(LoadStatus::Corrupt);
    }
    // The CRC holds: version and count are as written.
    if half(4) != Some(TABLE_VERSION) {
        return Err(LoadStatus::OtherVersion);
    }
    if half(6) != Some(COUNT as u16) || bytes.len() != RECORD_LEN {
        return Err(LoadStatus::Corrupt);
    }
    let mut values = [0.0f32; COUNT];
    for (i, value) in values.iter_mut().enumerate() {
        *value = f32::from_le_bytes(word(8 + 4 * i).ok_or(LoadStatus::Corrupt)?);
    }
    Ok(values)
}

#[cfg(test)]
#[path = "store_tests.rs"]
mod tests;
