//! A NOR flash in RAM for the tests of the parameter store and its users: it can lose
//! power at any write or erase.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Erase page \[bytes\].
pub const PAGE: usize = 1024;
/// Pages in the device.
pub const PAGES: usize = 4;
/// Write unit \[bytes\].
pub const WORD: usize = 4;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MockError(NorFlashErrorKind);

impl NorFlashError for MockError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

/// NOR flash in RAM: writes only clear bits, erases set whole pages to 0xFF. A word
/// may be programmed at most twice between erases: sequential-storage's own tests
/// allow that (`WriteCountCheck::Twice`; it rewrites a page marker a torn write left
/// half done), and the STM32F405's flash, which has no ECC, takes a second program
/// that only clears bits. `cut_at` makes the write or erase with that step
/// number (0-based, counted over both) the last: it is torn (the first half of its
/// words or of its pages done, one word after them half written) and from then on every
/// operation fails, as after a power loss.
#[derive(Clone, Debug)]
pub struct MockFlash {
    pub mem: Vec<u8>,
    pub steps: usize,
    pub cut_at: Option<usize>,
    pub powered: bool,
    pub erases: [u32; PAGES],
    /// Programs of each word since its page was erased.
    programs: Vec<u8>,
}

impl MockFlash {
    /// Erased, powered, no cut.
    pub fn new() -> Self {
        MockFlash {
            mem: vec![0xFF; PAGE * PAGES],
            steps: 0,
            cut_at: None,
            powered: true,
            erases: [0; PAGES],
            programs: vec![0; PAGE * PAGES / WORD],
        }
    }

    /// The same memory after a power cycle.
    pub fn rebooted(&self) -> Self {
        MockFlash {
            steps: 0,
            cut_at: None,
            powered: true,
            ..self.clone()
        }
    }

    fn step(&mut self) -> Result<bool, MockError> {
        if !self.powered {
            return Err(MockError(NorFlashErrorKind::Other));
        }
        let cut = self.cut_at == Some(self.steps);
        self.steps += 1;
        Ok(cut)
    }
}

impl ErrorType for MockFlash {
    type Error = MockError;
}

impl ReadNorFlash for MockFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), MockError> {
        if !self.powered {
            return Err(MockError(NorFlashErrorKind::Other));
        }
        let start = offset as usize;
        let source = self
            .mem
            .get(start..start + bytes.len())
            .ok_or(MockError(NorFlashErrorKind::OutOfBounds))?;
        bytes.copy_from_slice(source);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.mem.len()
    }
}

impl NorFlash for MockFlash {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), MockError> {
        let (from, to) = (from as usize, to as usize);
        if from % PAGE != 0 || to % PAGE != 0 || to > self.mem.len() || from > to {
            return Err(MockError(NorFlashErrorKind::NotAligned));
        }
        let cut = self.step()?;
        let pages = (to - from) / PAGE;
        let done = if cut { pages / 2 } else { pages };
        for page in 0..done {
            let start = from + page * PAGE;
            self.mem[start..start + PAGE].fill(0xFF);
            self.programs[start / WORD..(start + PAGE) / WORD].fill(0);
            self.erases[start / PAGE] += 1;
        }
        if cut {
            // The interrupted page: its first half erased, the rest as it was.
            let start = from + done * PAGE;
            if start < to {
                self.mem[start..start + PAGE / 2].fill(0xFF);
            }
            self.powered = false;
            return Err(MockError(NorFlashErrorKind::Other));
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), MockError> {
        let start = offset as usize;
        if !start.is_multiple_of(WORD)
            || !bytes.len().is_multiple_of(WORD)
            || start + bytes.len() > self.mem.len()
        {
            return Err(MockError(NorFlashErrorKind::NotAligned));
        }
        let cut = self.step()?;
        for programs in &mut self.programs[start / WORD..(start + bytes.len()) / WORD] {
            *programs += 1;
            assert!(*programs <= 2, "a word programmed a third time at {start}");
        }
        let words = bytes.len() / WORD;
        let done = if cut { words / 2 } else { words };
        for (slot, byte) in self.mem[start..start + done * WORD].iter_mut().zip(bytes) {
            *slot &= byte;
        }
        if cut {
            // One more word half written: its first two bytes only.
            let at = start + done * WORD;
            if done < words {
                for i in 0..WORD / 2 {
                    self.mem[at + i] &= bytes[done * WORD + i];
                }
            }
            self.powered = false;
            return Err(MockError(NorFlashErrorKind::Other));
        }
        Ok(())
    }
}
