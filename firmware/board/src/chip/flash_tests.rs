//! The flash driver against a model of the STM32F405's flash controller (RM0090 §3):
//! CR locked until the two keys, writes to a locked CR ignored, PSIZE checked, a program
//! only clears bits, a sector erase sets its 128 KiB to 0xFF, BSY for a few polls after
//! each operation, error flags injected; and the parameter store over it.

use super::*;
use sweephold_firmware::params::store::{LoadStatus, ParamStore};
use sweephold_firmware::params::{ParamId, ParamTable};
use sweephold_protocol::VehicleId;

/// The controller and its memory (1 MiB, initially erased).
struct Model {
    mem: Vec<u8>,
    cr: u32,
    sr: u32,
    /// Keys accepted so far in the unlock sequence.
    key_stage: u8,
    /// A wrong key was written: locked until reset.
    key_error: bool,
    /// SR polls left that read BSY.
    busy_polls: core::cell::Cell<u32>,
    /// Error flags the next operation raises (and does not carry out).
    fail_next: Option<u32>,
    /// Programs are dropped (QEMU: the flash ignores writes).
    ignore_writes: bool,
    erased_sectors: Vec<u8>,
    programs: usize,
}

impl Model {
    fn new() -> Model {
        Model {
            mem: vec![0xFF; FLASH_SIZE as usize],
            cr: cr::LOCK,
            sr: 0,
            key_stage: 0,
            key_error: false,
            busy_polls: core::cell::Cell::new(0),
            fail_next: None,
            ignore_writes: false,
            erased_sectors: Vec::new(),
            programs: 0,
        }
    }

    fn locked(&self) -> bool {
        self.cr & cr::LOCK != 0
    }

    /// An operation starts: BSY for three polls; an injected failure instead of it.
    fn operate(&mut self) -> bool {
        self.busy_polls.set(3);
        if let Some(errors) = self.fail_next.take() {
            self.sr |= errors;
            return false;
        }
        true
    }

    /// The range of a 128 KiB sector in `mem`.
    fn sector_range(sector: u8) -> core::ops::Range<usize> {
        let start = sector_offset(sector) as usize;
        start..start + SECTOR_SIZE as usize
    }
}

impl FlashBus for Model {
    fn write_keyr(&mut self, key: u32) {
        match (self.key_stage, key) {
            (0, KEY1) => self.key_stage = 1,
            (1, KEY2) if !self.key_error => {
                self.key_stage = 0;
                self.cr &= !cr::LOCK;
            }
            _ => {
                self.key_error = true;
                self.key_stage = 0;
            }
        }
    }

    fn read_cr(&self) -> u32 {
        self.cr
    }

    fn write_cr(&mut self, value: u32) {
        assert_eq!(self.busy_polls.get(), 0, "CR written while busy");
        if self.locked() {
            return;
        }
        self.cr = value;
        if value & cr::STRT != 0 {
            self.cr &= !cr::STRT;
            if value & cr::SER == 0 || value & cr::PSIZE_MASK != cr::PSIZE_X32 {
                self.sr |= sr::PGSERR;
                return;
            }
            if !self.operate() {
                return;
            }
            let sector = ((value & cr::SNB_MASK) >> cr::SNB_SHIFT) as u8;
            assert!((5..=11).contains(&sector), "erase of sector {sector}");
            self.mem[Model::sector_range(sector)].fill(0xFF);
            self.erased_sectors.push(sector);
            self.sr |= sr::EOP;
        }
    }

    fn read_sr(&self) -> u32 {
        let busy = self.busy_polls.get();
        if busy > 0 {
            self.busy_polls.set(busy - 1);
            return self.sr | sr::BSY;
        }
        self.sr
    }

    fn write_sr(&mut self, value: u32) {
        self.sr &= !(value & (sr::ERRORS | sr::EOP));
    }

    fn write_word(&mut self, address: u32, word: u32) {
        assert_eq!(self.busy_polls.get(), 0, "programmed while busy");
        if self.locked() || self.cr & cr::PG == 0 {
            self.sr |= sr::PGSERR;
            return;
        }
        if self.cr & cr::PSIZE_MASK != cr::PSIZE_X32 {
            self.sr |= sr::PGPERR;
            return;
        }
        if !address.is_multiple_of(4) {
            self.sr |= sr::PGAERR;
            return;
        }
        if !self.operate() {
            return;
        }
        self.programs += 1;
        if self.ignore_writes {
            return;
        }
        let at = (address - FLASH_BASE) as usize;
        for (cell, byte) in self.mem[at..at + 4].iter_mut().zip(word.to_le_bytes()) {
            // A program only clears bits.
            *cell &= byte;
        }
        self.sr |= sr::EOP;
    }

    fn read_bytes(&self, address: u32, bytes: &mut [u8]) {
        let at = (address - FLASH_BASE) as usize;
        bytes.copy_from_slice(&self.mem[at..at + bytes.len()]);
    }
}

fn flash() -> F405Flash<Model> {
    F405Flash::new(Model::new())
}

#[test]
fn the_store_is_the_last_two_sectors() {
    assert_eq!(STORE_REGION, 0xC_0000..0x10_0000);
    assert_eq!(sector_offset(10), 0xC_0000);
    assert_eq!(sector_offset(11), 0xE_0000);
    assert_eq!(STORE_REGION.start, sector_offset(STORE_SECTORS[0]));
    assert_eq!(
        STORE_REGION.end,
        sector_offset(STORE_SECTORS[1]) + SECTOR_SIZE
    );
    assert_eq!(FLASH_BASE + STORE_REGION.start, 0x080C_0000);
}

#[test]
fn a_word_is_programmed_read_back_and_the_controller_locked_again() {
    let mut f = flash();
    let at = STORE_REGION.start + 8;
    f.write(at, &[1, 2, 3, 4, 5, 6, 7, 8]).unwrap();
    let mut back = [0u8; 8];
    f.read(at, &mut back).unwrap();
    assert_eq!(back, [1, 2, 3, 4, 5, 6, 7, 8]);
    let model = f.into_bus();
    assert!(model.locked());
    assert_eq!(model.programs, 2);
    assert_eq!(model.sr & sr::ERRORS, 0);
    assert!(!model.key_error);
}

#[test]
fn a_program_only_clears_bits_and_a_mismatch_is_an_error() {
    let mut f = flash();
    let at = STORE_REGION.start;
    f.write(at, &[0x0F, 0xFF, 0xFF, 0xFF]).unwrap();
    // Clearing more bits of the same word is a valid second program.
    f.write(at, &[0x05, 0xFF, 0xFF, 0xFF]).unwrap();
    // Setting a bit again is not: the read-back differs.
    assert_eq!(
        f.write(at, &[0xF0, 0xFF, 0xFF, 0xFF]),
        Err(FlashError::Verify)
    );
    assert!(f.into_bus().locked());
}

#[test]
fn an_erase_sets_whole_sectors_to_ff() {
    let mut f = flash();
    let region = STORE_REGION;
    f.write(region.start, &[0; 4]).unwrap();
    f.write(region.end - 4, &[0; 4]).unwrap();
    f.erase(region.start, region.start + SECTOR_SIZE).unwrap();
    let mut back = [0u8; 4];
    f.read(region.start, &mut back).unwrap();
    assert_eq!(back, [0xFF; 4]);
    f.read(region.end - 4, &mut back).unwrap();
    assert_eq!(back, [0; 4]);
    f.erase(region.start, region.end).unwrap();
    f.read(region.end - 4, &mut back).unwrap();
    assert_eq!(back, [0xFF; 4]);
    let model = f.into_bus();
    assert_eq!(model.erased_sectors, [10, 10, 11]);
    assert!(model.locked());
}

#[test]
fn nothing_outside_the_store_is_erased_or_programmed() {
    let mut f = flash();
    let start = STORE_REGION.start;
    assert_eq!(f.erase(0, SECTOR_SIZE), Err(FlashError::OutOfBounds));
    assert_eq!(
        f.erase(start - SECTOR_SIZE, start),
        Err(FlashError::OutOfBounds)
    );
    assert_eq!(f.write(start - 4, &[0; 4]), Err(FlashError::OutOfBounds));
    assert_eq!(f.write(start - 4, &[0; 8]), Err(FlashError::OutOfBounds));
    assert_eq!(f.write(FLASH_SIZE, &[0; 4]), Err(FlashError::OutOfBounds));
    assert_eq!(f.write(start + 2, &[0; 4]), Err(FlashError::NotAligned));
    assert_eq!(f.write(start, &[0; 3]), Err(FlashError::NotAligned));
    assert_eq!(
        f.erase(start + 4, start + SECTOR_SIZE),
        Err(FlashError::NotAligned)
    );
    let mut buffer = [0u8; 8];
    assert_eq!(
        f.read(FLASH_SIZE - 4, &mut buffer),
        Err(FlashError::OutOfBounds)
    );
    // The image's flash reads fine.
    f.read(0, &mut buffer).unwrap();
    let model = f.into_bus();
    assert_eq!(model.programs, 0);
    assert!(model.erased_sectors.is_empty());
    assert!(model.locked());
}

#[test]
fn controller_errors_are_reported_cleared_and_the_controller_locked() {
    for flag in [sr::WRPERR, sr::PGAERR, sr::PGPERR, sr::PGSERR, sr::OPERR] {
        let mut model = Model::new();
        model.fail_next = Some(flag);
        let mut f = F405Flash::new(model);
        assert_eq!(
            f.write(STORE_REGION.start, &[0; 4]),
            Err(FlashError::Controller(flag))
        );
        // Cleared: the next operation succeeds.
        f.write(STORE_REGION.start, &[0; 4]).unwrap();
        let mut model = f.into_bus();
        assert!(model.locked());
        model.fail_next = Some(flag);
        let mut f = F405Flash::new(model);
        assert_eq!(
            f.erase(STORE_REGION.start, STORE_REGION.start + SECTOR_SIZE),
            Err(FlashError::Controller(flag))
        );
        assert!(f.into_bus().locked());
    }
}

#[test]
fn a_flash_that_ignores_writes_is_refused_not_saved() {
    // QEMU's netduinoplus2: programs do nothing, erases neither.
    let mut model = Model::new();
    model.ignore_writes = true;
    let mut store = ParamStore::new(F405Flash::new(model), STORE_REGION).unwrap();
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    table.set(ParamId::SwashPhase, 12.5).unwrap();
    assert!(store.save(&table).is_err());
    let model = store.into_flash().into_bus();
    assert!(model.locked());
}

#[test]
fn the_parameter_store_saves_and_loads_over_the_driver() {
    let mut store = ParamStore::new(flash(), STORE_REGION).unwrap();
    assert_eq!(store.load(VehicleId::Trex700l).status, LoadStatus::Empty);
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    table.set(ParamId::SwashPhase, 12.5).unwrap();
    table.set(ParamId::TailMid, 760.0).unwrap();
    table.set(ParamId::TailMin, 560.0).unwrap();
    table.set(ParamId::TailMax, 960.0).unwrap();
    store.save(&table).unwrap();
    // The bytes as the chip would hold them after a reset.
    let model = store.into_flash().into_bus();
    let mut rebooted = Model::new();
    rebooted.mem = model.mem;
    let mut store = ParamStore::new(F405Flash::new(rebooted), STORE_REGION).unwrap();
    let loaded = store.load(VehicleId::Trex700l);
    assert_eq!(loaded.status, LoadStatus::Loaded);
    assert_eq!(loaded.table, table);
}
