//! The test list `--fc board-sim` sets up on the board, and the selector position that
//! chooses a record's test from it.
//!
//! The board is set up from the aircraft file: its test list is the file's campaign, as
//! [`super::plan::plan_records`] plans it (per axis the file's two sweep bands, then one
//! doublet per axis on the first band; the flight's record length, 5 % amplitude, the
//! file's pulse width), on the selector channel [`SELECTOR_CHANNEL`] cut into twelve
//! slices. A record whose test is an entry of that list is chosen by the simulated
//! pilot's selector; the board's own single test (`TEST_*`) is then the preset's, not the
//! record's. The settings every test of a flight shares (mode, noise and its seed, fades,
//! hold) are the board's one configuration, set at each power-up from the record (one
//! record per power-up).

use sweephold_firmware::app::test_list::{TestEntry, TestList, TEST_LIST_LEN};
use sweephold_protocol::{Axis, InputKind, TestConfig};

use super::plan::PAPER_AMPLITUDE;
use crate::vehicle::Vehicle;

/// The receiver channel of the simulated transmitter's test selector: the first one the
/// default channel map leaves free.
pub const SELECTOR_CHANNEL: u8 = 9;

/// The test list of `vehicle`'s campaign with records of `t_rec_s` (see the module
/// documentation).
pub fn campaign_list(vehicle: &Vehicle, t_rec_s: f64) -> TestList {
    let [first, second] = vehicle.sweep_bands();
    let pulse_width_s = vehicle.firmware_config(Axis::Lat).test.pulse.width_s;
    let entry = |axis: Axis, input: InputKind, (omega_min, omega_max): (f64, f64)| TestEntry {
        axis: Some(axis),
        input,
        omega_min: omega_min as f32,
        omega_max: omega_max as f32,
        pulse_width_s,
        t_rec_s: t_rec_s as f32,
        amplitude: PAPER_AMPLITUDE as f32,
    };
    let mut entries = Vec::with_capacity(TEST_LIST_LEN);
    for axis in Axis::ALL {
        entries.push(entry(axis, InputKind::Sweep, first));
        entries.push(entry(axis, InputKind::Sweep, second));
    }
    for axis in Axis::ALL {
        entries.push(entry(axis, InputKind::Doublet, first));
    }
    let mut list = TestList::campaign(vehicle.preset());
    for (slot, entry) in list.entries.iter_mut().zip(entries) {
        *slot = entry;
    }
    list.slices = TEST_LIST_LEN as u8;
    list
}

/// The board's single test when the selector chooses `record`'s test: `record` with the
/// per-test fields of the preset's own test `preset` (its global settings kept).
pub fn single_test(preset: &TestConfig, record: &TestConfig) -> TestConfig {
    TestEntry::of(preset).apply(record)
}

/// The entry of `list` whose test on the board's single test `single` is `record`'s
/// (bit for bit, but the warnings the sequencer fills in), and the selector position at
/// the centre of its slice.
pub fn selection(list: &TestList, single: &TestConfig, record: &TestConfig) -> Option<(u8, f32)> {
    let same = |a: TestConfig, b: TestConfig| {
        TestConfig { warnings: 0, ..a } == TestConfig { warnings: 0, ..b }
    };
    let n = list.slices.max(1);
    (1..=n)
        .find(|&k| {
            list.get(k)
                .is_some_and(|entry| same(entry.apply(single), *record))
        })
        .map(|k| (k, -1.0 + (2.0 * f32::from(k) - 1.0) / f32::from(n)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fly::plan::plan_records;
    use crate::fly::record_config;
    use sweephold_protocol::ExcitationMode;

    /// Every record of a campaign is an entry of its list, on each preset; its slice
    /// centre selects that entry on the board.
    #[test]
    fn every_campaign_record_is_an_entry_of_the_list() {
        for name in ["bo105", "trex700l"] {
            let vehicle = Vehicle::parse(name).unwrap();
            let list = campaign_list(&vehicle, 30.0);
            let mut chosen = Vec::new();
            for input in [InputKind::Sweep, InputKind::Doublet] {
                let plans = plan_records(
                    &vehicle.sweep_bands(),
                    &Axis::ALL,
                    ExcitationMode::ConditionalAttitudeHold,
                    input,
                    30.0,
                    1,
                );
                for plan in plans {
                    let record = record_config(&vehicle, &plan, 200).test;
                    let preset = vehicle.firmware_config(plan.axis).test;
                    let single = single_test(&preset, &record);
                    let (entry, position) = selection(&list, &single, &record)
                        .unwrap_or_else(|| panic!("{name} {}", plan.file_name()));
                    assert_eq!(list.entry_at(position), Some(entry));
                    chosen.push(entry);
                }
            }
            assert_eq!(chosen, (1..=12).collect::<Vec<u8>>(), "{name}");
        }
    }

    /// A record outside the list (another length, a 3-2-1-1) has no entry.
    #[test]
    fn a_record_outside_the_list_has_no_entry() {
        let vehicle = Vehicle::parse("bo105").unwrap();
        let list = campaign_list(&vehicle, 30.0);
        let mut record = vehicle.firmware_config(Axis::Lat).test;
        record.sweep.omega_min = 0.2;
        record.sweep.omega_max = 31.4;
        record.sweep.t_rec_s = 30.0;
        let single = single_test(&vehicle.firmware_config(Axis::Lat).test, &record);
        assert!(selection(&list, &single, &record).is_some());
        record.sweep.t_rec_s = 45.0;
        assert_eq!(selection(&list, &single, &record), None);
        record.sweep.t_rec_s = 30.0;
        record.input = InputKind::ThreeTwoOneOne;
        assert_eq!(selection(&list, &single, &record), None);
    }
}
