//! The store over a RAM NOR flash that can lose power at any write or erase.

use super::*;
use crate::params::mock_flash::{MockFlash, PAGE, PAGES};
use crate::params::ParamId;

const VEHICLE: VehicleId = VehicleId::Trex700l;

fn store(flash: MockFlash) -> ParamStore<MockFlash> {
    ParamStore::new(flash, 0..(PAGE * PAGES) as u32).unwrap()
}

/// A consistent set that differs from the defaults by `n` (the swash phase and the
/// tail centre).
fn variant(n: u32) -> ParamTable {
    let mut table = ParamTable::defaults(VEHICLE);
    table
        .set(ParamId::SwashPhase, (n % 300) as f32 * 0.5 - 75.0)
        .unwrap();
    table
        .set(ParamId::TailMid, 1400.0 + (n % 100) as f32)
        .unwrap();
    table
}

/// `n` saves of variants 0..n on a fresh flash.
fn flash_after_saves(n: u32) -> MockFlash {
    let mut s = store(MockFlash::new());
    for i in 0..n {
        s.save(&variant(i)).unwrap();
    }
    s.into_flash().rebooted()
}

#[test]
fn an_empty_region_gives_the_defaults_and_says_so() {
    let loaded = store(MockFlash::new()).load(VEHICLE);
    assert_eq!(loaded.status, LoadStatus::Empty);
    assert!(!loaded.status.is_valid());
    assert_eq!(loaded.table, ParamTable::defaults(VEHICLE));
}

#[test]
fn a_saved_set_is_loaded_after_a_reboot() {
    let table = variant(3);
    let mut s = store(MockFlash::new());
    s.save(&table).unwrap();
    let loaded = store(s.into_flash().rebooted()).load(VEHICLE);
    assert_eq!(
        loaded,
        Loaded {
            table,
            status: LoadStatus::Loaded
        }
    );
}

#[test]
fn an_inconsistent_set_is_refused_before_anything_is_written() {
    let mut table = ParamTable::defaults(VEHICLE);
    table.set_by_name("SERVO1_MIN", 1600.0).unwrap();
    let mut s = store(MockFlash::new());
    assert_eq!(s.save(&table), Err(SaveError::Inconsistent));
    let flash = s.into_flash();
    assert_eq!(flash.steps, 0);
    assert!(flash.mem.iter().all(|&b| b == 0xFF));
}

#[test]
fn a_power_loss_at_every_step_of_a_save_leaves_the_old_or_the_new_set() {
    let (mut kept_old, mut got_new, mut cases) = (0, 0, 0);
    // Earlier saves put the new record at different places: on a fresh page, in the
    // middle of one, and where the save has to migrate and erase a page.
    for earlier in [1u32, 2, 3, 5, 8, 13, 21] {
        let before = flash_after_saves(earlier);
        let old = variant(earlier - 1);
        let new = variant(1000 + earlier);
        // How many steps a complete save takes from here.
        let mut probe = store(before.rebooted());
        probe.save(&new).unwrap();
        let steps = probe.into_flash().steps;
        assert!(steps > 0);
        for cut in 0..steps {
            let mut flash = before.rebooted();
            flash.cut_at = Some(cut);
            let mut s = store(flash);
            assert_eq!(s.save(&new), Err(SaveError::Flash), "cut {cut}");
            let mut s = store(s.into_flash().rebooted());
            let loaded = s.load(VEHICLE);
            assert_eq!(
                loaded.status,
                LoadStatus::Loaded,
                "{earlier} saves, cut {cut}"
            );
            if loaded.table == old {
                kept_old += 1;
            } else if loaded.table == new {
                got_new += 1;
            } else {
                panic!("{earlier} saves, cut at step {cut}: neither the old nor the new set");
            }
            // The store recovers: the next save goes through and is loaded.
            let next = variant(2000 + cut as u32);
            s.save(&next).unwrap();
            assert_eq!(store(s.into_flash().rebooted()).load(VEHICLE).table, next);
            cases += 1;
        }
    }
    // Both outcomes occur: the cut lands before and after the record's commit.
    assert!(kept_old > 0 && got_new > 0, "old {kept_old}, new {got_new}");
    assert!(cases >= 20, "{cases}");
}

#[test]
fn a_power_loss_during_the_first_save_gives_the_defaults_flagged_or_the_new_set() {
    let new = variant(7);
    let mut probe = store(MockFlash::new());
    probe.save(&new).unwrap();
    let steps = probe.into_flash().steps;
    for cut in 0..steps {
        let mut flash = MockFlash::new();
        flash.cut_at = Some(cut);
        let mut s = store(flash);
        assert!(s.save(&new).is_err());
        let loaded = store(s.into_flash().rebooted()).load(VEHICLE);
        match loaded.status {
            LoadStatus::Loaded => assert_eq!(loaded.table, new),
            status => {
                assert!(!status.is_valid());
                assert_eq!(loaded.table, ParamTable::defaults(VEHICLE));
            }
        }
    }
}

#[test]
fn a_corrupt_byte_never_loads_a_wrong_set() {
    let table = variant(11);
    let mut s = store(MockFlash::new());
    s.save(&table).unwrap();
    let clean = s.into_flash().rebooted();
    let record = encode(&table);
    let record_at = clean
        .mem
        .windows(RECORD_LEN)
        .position(|w| w == record)
        .expect("the record is in the flash as written");
    let (mut refused, mut record_bytes_refused) = (0, 0);
    for at in 0..clean.mem.len() {
        if clean.mem[at] == 0xFF {
            continue;
        }
        for bit in [0x01u8, 0x80] {
            let mut flash = clean.rebooted();
            flash.mem[at] ^= bit;
            let loaded = store(flash).load(VEHICLE);
            if loaded.status.is_valid() {
                assert_eq!(loaded.table, table, "byte {at} bit {bit:#x}");
            } else {
                assert_eq!(loaded.table, ParamTable::defaults(VEHICLE));
                refused += 1;
                if (record_at..record_at + RECORD_LEN).contains(&at) {
                    record_bytes_refused += 1;
                }
            }
        }
    }
    // Every flipped bit of the record itself is caught.
    assert_eq!(record_bytes_refused, 2 * RECORD_LEN);
    assert!(refused >= record_bytes_refused);
}

#[test]
fn a_record_of_another_version_or_layout_is_not_loaded() {
    let check = |record: &[u8], expected: LoadStatus| {
        let mut s = store(MockFlash::new());
        s.save_raw(record).unwrap();
        let loaded = store(s.into_flash().rebooted()).load(VEHICLE);
        assert_eq!(loaded.status, expected);
        assert_eq!(loaded.table, ParamTable::defaults(VEHICLE));
    };
    let with_crc = |mut record: Vec<u8>| {
        let body = record.len() - 4;
        let crc = crc32(&record[..body]);
        record[body..].copy_from_slice(&crc.to_le_bytes());
        record
    };
    let good = encode(&variant(5)).to_vec();
    // Version + 1, CRC recomputed: a record of another table.
    let mut other = good.clone();
    other[4..6].copy_from_slice(&(TABLE_VERSION + 1).to_le_bytes());
    check(&with_crc(other), LoadStatus::OtherVersion);
    // A record of table version 1 (before FRAME was appended): one value fewer,
    // version 1, CRC consistent. It boots the defaults, flagged.
    let mut version_1 = good[..RECORD_LEN - 8].to_vec();
    version_1[4..6].copy_from_slice(&1u16.to_le_bytes());
    version_1[6..8].copy_from_slice(&((COUNT - 1) as u16).to_le_bytes());
    version_1.extend_from_slice(&[0; 4]);
    check(&with_crc(version_1), LoadStatus::OtherVersion);
    // One value fewer, count and CRC consistent: not this table's layout.
    let mut shorter = good[..RECORD_LEN - 8].to_vec();
    shorter[6..8].copy_from_slice(&((COUNT - 1) as u16).to_le_bytes());
    shorter.extend_from_slice(&[0; 4]);
    check(&with_crc(shorter), LoadStatus::Corrupt);
    // Another magic.
    let mut magic = good.clone();
    magic[0] = b'X';
    check(&with_crc(magic), LoadStatus::Corrupt);
    // A CRC that does not match.
    let mut crc = good.clone();
    crc[RECORD_LEN - 1] ^= 0x40;
    check(&crc, LoadStatus::Corrupt);
    // A value out of its range (SWASH_TYPE 90), CRC fine.
    let mut out_of_range = good.clone();
    let at = 8 + 4 * ParamId::SwashType.index();
    out_of_range[at..at + 4].copy_from_slice(&90.0f32.to_le_bytes());
    check(&with_crc(out_of_range), LoadStatus::Invalid);
    // In range but inconsistent (servo 1 min above its centre).
    let mut inconsistent = good;
    let at = 8 + 4 * ParamId::Servo1Min.index();
    inconsistent[at..at + 4].copy_from_slice(&1600.0f32.to_le_bytes());
    check(&with_crc(inconsistent), LoadStatus::Invalid);
}

#[test]
fn a_failing_flash_gives_the_defaults_flagged() {
    let mut flash = flash_after_saves(2);
    flash.powered = false;
    let loaded = store(flash).load(VEHICLE);
    assert_eq!(loaded.status, LoadStatus::FlashError);
    assert_eq!(loaded.table, ParamTable::defaults(VEHICLE));
}

#[test]
fn saves_wear_every_page_equally() {
    let flash = flash_after_saves(400);
    let (min, max) = (
        *flash.erases.iter().min().unwrap(),
        *flash.erases.iter().max().unwrap(),
    );
    // About two records fit a 1 KiB page: 400 saves cycle through the four pages
    // dozens of times.
    assert!(min >= 10, "{:?}", flash.erases);
    assert!(max - min <= 1, "{:?}", flash.erases);
    assert_eq!(store(flash).load(VEHICLE).table, variant(399));
}

#[test]
fn an_unusable_region_is_refused() {
    let unaligned = ParamStore::new(MockFlash::new(), 100..(PAGE * 3) as u32);
    assert_eq!(unaligned.err(), Some(RegionError::Unusable));
    let one_page = ParamStore::new(MockFlash::new(), 0..PAGE as u32);
    assert_eq!(one_page.err(), Some(RegionError::Unusable));
}

#[test]
fn the_record_round_trips_and_fits_the_buffer() {
    let table = variant(9);
    assert_eq!(decode(&encode(&table)), Ok(*table.values()));
    assert_eq!(RECORD_LEN, 12 + 4 * COUNT);
}
