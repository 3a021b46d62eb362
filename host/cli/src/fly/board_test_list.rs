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
//! hold) are the board's one configuration, set at each power-up from the record that
//! powers it up (every record with `--power-up per-record`, the first of a flight with
//! `once`).

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

/// The test list of a loop-test flight (`fly --input loop`) of `vehicle` with records of
/// `t_rec_s`: entries 1, 2, 3 the loop tests of lat, lon and ped on the loop-test band of
/// the file's first band ([`super::plan::loop_test_band`]), the rest empty, three slices
/// (the firmware's `TestList::loop_tests` with that band and the flight's record length).
pub fn loop_list(vehicle: &Vehicle, t_rec_s: f64) -> TestList {
    let (omega_min, omega_max) = super::plan::loop_test_band(&vehicle.sweep_bands());
    let mut list = TestList::loop_tests(vehicle.preset());
    for entry in list.entries.iter_mut().filter(|entry| !entry.is_empty()) {
        entry.omega_min = omega_min as f32;
        entry.omega_max = omega_max as f32;
        entry.t_rec_s = t_rec_s as f32;
        entry.amplitude = PAPER_AMPLITUDE as f32;
    }
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

/// The stored set with the record's test and rate: what the campaign chooses per record
/// (the test then moves into the campaign's test list, chosen by the selector).
pub(super) fn stored_with_record(
    params: &sweephold_firmware::params::Params,
    config: &sweephold_firmware::Config,
) -> anyhow::Result<sweephold_firmware::board_stack::StackConfig> {
    let mut stack = params.stack;
    let flight = &mut stack.app.flight;
    flight.rate_hz = config.rate_hz;
    let (mine, record) = (&mut flight.test, &config.test);
    mine.primary = record.primary;
    mine.input = record.input;
    mine.mode = record.mode;
    mine.seed = record.seed;
    mine.sweep.omega_min = record.sweep.omega_min;
    mine.sweep.omega_max = record.sweep.omega_max;
    mine.sweep.t_rec_s = record.sweep.t_rec_s;
    mine.sweep.amplitude = record.sweep.amplitude;
    mine.pulse.amplitude = record.pulse.amplitude;
    flight.test.warnings = flight.validate().map_err(|e| {
        anyhow::anyhow!(
            "the board's stored set refuses this record's test: {}",
            e.message()
        )
    })?;
    Ok(stack)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fly::plan::plan_records;
    use crate::fly::record_config;
    use sweephold_protocol::{ExcitationMode, Header};

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

    /// A record chosen from the list by the selector flies exactly as the same record
    /// configured as the board's single test (the path of a record outside the list):
    /// every frame of the dumps the same but the Header's selection (entry 1 or 2 against
    /// entry 0).
    #[test]
    fn a_test_chosen_by_the_selector_flies_as_the_same_test_configured() {
        use crate::fly::link_board_sim::BoardSimLink;
        use crate::fly::{board_sim_settings, fly, FlyArgs};
        use sweephold_protocol::{Decoder, Frame};

        let dir =
            std::env::temp_dir().join(format!("sweephold-selector-same-{}", std::process::id()));
        let fly_with = |unlisted: bool, folder: &str| {
            let out = dir.join(folder);
            let argv = [
                "--vehicle",
                "trex700l",
                "--fc",
                "board-sim",
                "--axes",
                "lat",
                "--t-rec",
                "6",
                "--seed",
                "3",
                "--quiet",
                "--out",
            ]
            .map(std::ffi::OsString::from)
            .into_iter()
            .chain([out.clone().into_os_string()]);
            let args: FlyArgs = crate::campaign::verb_args("fly", argv).unwrap();
            let mut settings = board_sim_settings(&args).unwrap();
            if unlisted {
                // No entry has the records' length: each flies as the single test.
                for entry in settings.test_list.entries.iter_mut() {
                    entry.t_rec_s = 7.0;
                }
            }
            fly(&args, &|| Box::new(BoardSimLink::new(settings.clone()))).unwrap();
            out
        };
        let frames = |path: std::path::PathBuf| -> Vec<Frame> {
            let bytes = std::fs::read(path).unwrap();
            Decoder::new().feed(&bytes).map(|f| f.unwrap()).collect()
        };
        let listed = fly_with(false, "listed");
        let single = fly_with(true, "single");
        for (file, entry) in [("lat-1.bin", 1), ("lat-2.bin", 2)] {
            let (a, b) = (frames(listed.join(file)), frames(single.join(file)));
            assert_eq!(a.len(), b.len(), "{file}");
            assert!(a.len() > 1000, "{file}: a whole record");
            let mut headers = 0;
            for (x, y) in a.iter().zip(&b) {
                match (x, y) {
                    (Frame::Header(x), Frame::Header(y)) => {
                        headers += 1;
                        assert_eq!(
                            x.selection.map(|s| (s.entry, s.engagement)),
                            Some((entry, 1))
                        );
                        assert_eq!(y.selection.map(|s| (s.entry, s.engagement)), Some((0, 1)));
                        assert_eq!(
                            Header {
                                selection: None,
                                ..*x
                            },
                            Header {
                                selection: None,
                                ..*y
                            }
                        );
                    }
                    _ => assert_eq!(x, y, "{file}"),
                }
            }
            assert_eq!(headers, 1, "{file}");
        }
        let _ = std::fs::remove_dir_all(&dir);
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
