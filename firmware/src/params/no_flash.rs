//! [`NoFlash`]: the flash of a board whose parameters live in RAM only (no store yet).
//! [`ParamLink`](super::link::ParamLink) is generic over its store's `NorFlash`; a
//! board without a flash driver names this type, which has no value, so
//! `ParamLink::<NoFlash>::boot(None, …)` is the only way to use it and a `Save` is
//! refused with `NoStore`.

use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};

/// A flash that does not exist: no value of this type can be made.
#[derive(Debug)]
pub enum NoFlash {}

impl ErrorType for NoFlash {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for NoFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, _offset: u32, _bytes: &mut [u8]) -> Result<(), Self::Error> {
        match *self {}
    }

    fn capacity(&self) -> usize {
        match *self {}
    }
}

impl NorFlash for NoFlash {
    const WRITE_SIZE: usize = 1;
    const ERASE_SIZE: usize = 1;

    fn erase(&mut self, _from: u32, _to: u32) -> Result<(), Self::Error> {
        match *self {}
    }

    fn write(&mut self, _offset: u32, _bytes: &[u8]) -> Result<(), Self::Error> {
        match *self {}
    }
}
