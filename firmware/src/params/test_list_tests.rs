//! The test list in the table (`TEST_SEL_CH`, `TEST_SEL_N`, `TEST1_*` … `TEST12_*`):
//! the defaults are each preset's campaign, the list round trips through the table, the
//! typed view and the store, its fields are refused out of range, and a store of table
//! version 4 boots the defaults.

use super::store::{encode, ParamStore, RECORD_LEN};
use super::*;
use crate::app::test_list::{TestEntry, TEST_LIST_LEN};
use crate::app::AppConfigError;
use crate::params::link::ParamLink;
use crate::params::mock_flash::{MockFlash, PAGE, PAGES};
use crate::params::store::LoadStatus;
use crate::receiver::ChannelMapError;
use sweephold_protocol::codec::crc32;
use sweephold_protocol::{Axis, Event, InputKind, ParamStoreStatus};

const FIELDS: [&str; 7] = ["AXIS", "INPUT", "WMIN", "WMAX", "WIDTH", "TREC", "AMP"];

fn name(entry: usize, field: &str) -> String {
    format!("TEST{entry}_{field}")
}

#[test]
fn the_entries_are_named_in_order_and_fit_the_name_limit() {
    let first = ParamId::TestSelCh.index();
    assert_eq!(DEFS[first].name, "TEST_SEL_CH");
    assert_eq!(DEFS[first + 1].name, "TEST_SEL_N");
    for entry in 1..=TEST_LIST_LEN {
        for (f, field) in FIELDS.iter().enumerate() {
            let def = &DEFS[first + 2 + (entry - 1) * FIELDS.len() + f];
            assert_eq!(def.name, name(entry, field));
            assert!(def.name.len() <= MAX_NAME_LEN, "{}", def.name);
        }
    }
    // The list ends the table's version 5; version 6 appended the three hold slews.
    assert_eq!(
        ParamId::HoldSlewLat.index(),
        first + 2 + TEST_LIST_LEN * FIELDS.len()
    );
}

/// The host's campaign per axis: two sweep bands, then one doublet per axis on the first
/// band (`host/cli/src/fly/plan.rs`: `PAPER_BANDS`, `TREX700L_BANDS`, 90 s, 5 %).
#[test]
fn the_default_list_is_each_presets_campaign() {
    for (vehicle, bands, width) in [
        (VehicleId::Bo105, [(0.2, 31.4), (0.01, 18.85)], 1.0),
        (VehicleId::Trex700l, [(0.2, 62.8), (0.01, 18.85)], 0.3),
    ] {
        let table = ParamTable::defaults(vehicle);
        assert_eq!(table.get(ParamId::TestSelCh), 0.0, "no selector by default");
        assert_eq!(table.get(ParamId::TestSelN), 12.0);
        let get = |entry: usize, field: &str| table.get_by_name(&name(entry, field)).unwrap();
        for axis in 1..=4 {
            for (band, (wmin, wmax)) in bands.iter().enumerate() {
                let entry = 2 * (axis - 1) + band + 1;
                assert_eq!(get(entry, "AXIS"), axis as f32, "entry {entry}");
                assert_eq!(get(entry, "INPUT"), 0.0, "entry {entry}: sweep");
                assert_eq!((get(entry, "WMIN"), get(entry, "WMAX")), (*wmin, *wmax));
                assert_eq!(get(entry, "TREC"), 90.0);
                assert_eq!(get(entry, "AMP"), 0.05);
            }
            let doublet = 8 + axis;
            assert_eq!(get(doublet, "AXIS"), axis as f32);
            assert_eq!(get(doublet, "INPUT"), 1.0, "entry {doublet}: doublet");
            assert_eq!(get(doublet, "WIDTH"), width);
            assert_eq!(
                (get(doublet, "WMIN"), get(doublet, "WMAX")),
                bands[0],
                "on the first band"
            );
        }
        let list = table.params().unwrap().stack.app.tests;
        assert_eq!(list.entries[0].axis, Some(Axis::Lat));
        assert_eq!(list.entries[7].axis, Some(Axis::Col));
        assert_eq!(list.entries[11].input, InputKind::Doublet);
        assert!(list.entries.iter().all(|e| !e.is_empty()));
    }
}

#[test]
fn a_changed_list_round_trips_through_the_table_the_typed_view_and_the_store() {
    let mut table = ParamTable::defaults(VehicleId::Trex700l);
    for (key, value) in [
        ("TEST_SEL_CH", 9.0),
        ("TEST_SEL_N", 6.0),
        ("TEST3_AXIS", 3.0),
        ("TEST3_INPUT", 2.0),
        ("TEST3_WIDTH", 0.7),
        ("TEST3_TREC", 20.0),
        ("TEST3_AMP", 0.08),
        ("TEST5_WMIN", 0.5),
        ("TEST5_WMAX", 40.0),
        ("TEST12_AXIS", 0.0),
    ] {
        table.set_by_name(key, value).unwrap();
    }
    let params = table.params().unwrap();
    assert_eq!(params.stack.channel_map.selector.channel, 9);
    let list = params.stack.app.tests;
    assert_eq!(list.slices, 6);
    assert_eq!(
        list.entries[2],
        TestEntry {
            axis: Some(Axis::Ped),
            input: InputKind::ThreeTwoOneOne,
            omega_min: 0.2,
            omega_max: 62.8,
            pulse_width_s: 0.7,
            t_rec_s: 20.0,
            amplitude: 0.08,
        }
    );
    assert_eq!(
        (list.entries[4].omega_min, list.entries[4].omega_max),
        (0.5, 40.0)
    );
    assert!(list.entries[11].is_empty());
    assert_eq!(list.get(12), None);
    // Back to the same values, and through the stored record.
    assert_eq!(typed::values_of(&params), *table.values());
    assert_eq!(
        ParamTable::from_values(typed::values_of(&params)),
        Ok(table)
    );
    let mut store = ParamStore::new(MockFlash::new(), 0..(PAGE * PAGES) as u32).unwrap();
    store.save(&table).unwrap();
    let mut store =
        ParamStore::new(store.into_flash().rebooted(), 0..(PAGE * PAGES) as u32).unwrap();
    let loaded = store.load(VehicleId::Trex700l);
    assert_eq!(loaded.status, LoadStatus::Loaded);
    assert_eq!(loaded.table, table);
}

#[test]
fn entry_fields_out_of_range_are_refused() {
    let base = ParamTable::defaults(VehicleId::Bo105);
    for entry in [1, 7, 12] {
        for (field, below, above) in [
            ("AXIS", -1.0, 5.0),
            ("INPUT", -1.0, 5.0),
            ("WMIN", 0.0, 101.0),
            ("WMAX", 0.0, 401.0),
            ("WIDTH", 0.0, 61.0),
            ("TREC", -1.0, 3601.0),
            ("AMP", 0.0, 0.51),
        ] {
            let key = name(entry, field);
            for (value, error) in [
                (below, SetError::OutOfRange),
                (above, SetError::OutOfRange),
                (f32::NAN, SetError::NotFinite),
            ] {
                let mut table = base;
                assert_eq!(
                    table.set_by_name(&key, value),
                    Err(error),
                    "{key} = {value}"
                );
                assert_eq!(table, base, "{key}: a refused value changes nothing");
            }
        }
        let mut table = base;
        assert_eq!(
            table.set_by_name(&name(entry, "AXIS"), 1.5),
            Err(SetError::NotAnInteger)
        );
    }
    let mut table = base;
    for (key, value) in [
        ("TEST_SEL_CH", 17.0),
        ("TEST_SEL_N", 0.0),
        ("TEST_SEL_N", 13.0),
    ] {
        assert_eq!(
            table.set_by_name(key, value),
            Err(SetError::OutOfRange),
            "{key}"
        );
    }
}

#[test]
fn a_list_the_sequencer_refuses_is_refused_as_a_whole() {
    let base = ParamTable::defaults(VehicleId::Trex700l);
    // Entry 4's band upside down: each value in range, the test not.
    let mut table = base;
    table.set_by_name("TEST4_WMIN", 20.0).unwrap();
    table.set_by_name("TEST4_WMAX", 10.0).unwrap();
    assert!(matches!(
        table.params(),
        Err(ParamsError::App(AppConfigError::TestList(
            crate::app::test_list::TestListError::Entry { entry: 4, .. }
        )))
    ));
    // The same entry emptied (no axis, or no record length) is not a test: accepted.
    table.set_by_name("TEST4_AXIS", 0.0).unwrap();
    assert!(table.params().is_ok());
    table.set_by_name("TEST4_AXIS", 2.0).unwrap();
    table.set_by_name("TEST4_TREC", 0.0).unwrap();
    assert!(table.params().is_ok());
    // A sweep past the loop's 0.4·Nyquist (251 rad/s at 200 Hz) is refused too.
    let mut table = base;
    table.set_by_name("TEST2_WMAX", 300.0).unwrap();
    assert!(table.params().is_err());
    // The selector on a channel another function reads.
    let mut table = base;
    table.set_by_name("TEST_SEL_CH", 7.0).unwrap();
    assert_eq!(
        table.params(),
        Err(ParamsError::ChannelMap(ChannelMapError::DuplicateChannel))
    );
}

/// A board whose store holds a table of version 4 (before the list): it boots the
/// defaults, the list included, says so with the `param_store` event and may not arm.
#[test]
fn a_version_4_store_boots_the_defaults_and_says_so() {
    let vehicle = VehicleId::Trex700l;
    let mut table = ParamTable::defaults(vehicle);
    table.set_by_name("SWASH_PHASE", 10.0).unwrap();
    // The version-4 record: its 105 values (everything before TEST_SEL_CH), version 4,
    // its own count and a consistent CRC.
    let old_count = ParamId::TestSelCh.index();
    let mut record = encode(&table)[..8 + 4 * old_count].to_vec();
    record[4..6].copy_from_slice(&4u16.to_le_bytes());
    record[6..8].copy_from_slice(&(old_count as u16).to_le_bytes());
    let crc = crc32(&record);
    record.extend_from_slice(&crc.to_le_bytes());
    assert_eq!(record.len(), RECORD_LEN - 4 * (COUNT - old_count));
    let mut store = ParamStore::new(MockFlash::new(), 0..(PAGE * PAGES) as u32).unwrap();
    store.save_raw(&record).unwrap();
    let store = ParamStore::new(store.into_flash().rebooted(), 0..(PAGE * PAGES) as u32).unwrap();
    let link = ParamLink::boot(Some(store), vehicle);
    assert_eq!(link.load_status(), LoadStatus::OtherVersion);
    assert!(!link.params_valid());
    assert_eq!(*link.table(), ParamTable::defaults(vehicle));
    assert_eq!(
        link.store_event(0),
        Event::ParamStore {
            tick: 0,
            status: ParamStoreStatus::OtherVersion
        }
    );
}
