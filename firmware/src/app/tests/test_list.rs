//! Tests chosen by the selector channel: each slice engages its entry, the Header names
//! the entry and counts the engagements, a selector moved during a test changes nothing,
//! an empty entry is refused, and without a selector the single test flies as before.

use super::*;
use crate::app::test_list::{engagement_seed, TestEntry, TestList, TEST_LIST_LEN};
use sweephold_protocol::{Header, InputKind, RefusedCheck, TestConfig, TestSelection};

/// The TREX 700L campaign list with 3 s records (the tests' short runs).
fn short_list_config() -> AppConfig {
    let mut config = test_config();
    for entry in config.tests.entries.iter_mut() {
        entry.t_rec_s = 3.0;
    }
    config
}

/// The centre of slice `entry` (1-based) of `n` equal slices of [−1, 1].
fn slice_centre(entry: usize, n: usize) -> f32 {
    -1.0 + (2.0 * entry as f32 - 1.0) / n as f32
}

/// The Headers the application sent so far.
fn headers(rig: &Rig) -> Vec<Header> {
    rig.frames
        .iter()
        .filter_map(|frame| match frame {
            Frame::Header(header) => Some(*header),
            _ => None,
        })
        .collect()
}

/// Engage a test with the selector at `position`, wait for its Header, then release the
/// switch and wait until the sequencer is idle again; the Header.
fn engage(rig: &mut Rig, position: Option<f32>) -> Header {
    rig.rc.selector = position;
    let before = headers(rig).len();
    rig.start_test();
    rig.tick();
    let sent = headers(rig);
    assert_eq!(sent.len(), before + 1, "one Header per engagement");
    rig.rc.test_switch = false;
    let out = rig.ticks(3);
    assert_eq!((out.mode, out.phase), (Mode::Pilot, Phase::Idle));
    sent[before]
}

#[test]
fn the_selector_at_each_slice_engages_that_entry_and_counts_the_engagements() {
    let config = short_list_config();
    let mut rig = Rig::armed(config);
    for entry in 1..=TEST_LIST_LEN {
        let header = engage(&mut rig, Some(slice_centre(entry, TEST_LIST_LEN)));
        let chosen = config.tests.entries[entry - 1];
        assert_eq!(
            header.selection,
            Some(TestSelection {
                entry: entry as u8,
                engagement: entry as u16
            }),
            "entry {entry}"
        );
        assert_eq!(Some(header.test.primary), chosen.axis, "entry {entry}");
        assert_eq!(header.test.input, chosen.input);
        assert_eq!(header.test.sweep.omega_min, chosen.omega_min);
        assert_eq!(header.test.sweep.omega_max, chosen.omega_max);
        assert_eq!(header.test.sweep.t_rec_s, chosen.t_rec_s);
        assert_eq!(header.test.pulse.width_s, chosen.pulse_width_s);
        assert_eq!(header.test.sweep.amplitude, chosen.amplitude);
        // What stays global: the mode and the noise; its seed is the engagement's.
        assert_eq!(header.test.mode, config.flight.test.mode);
        assert_eq!(header.test.noise_rms, config.flight.test.noise_rms);
        assert_eq!(
            header.test.seed,
            engagement_seed(config.flight.test.seed, entry as u16)
        );
        assert_eq!(header.protocol, ProtocolVersion::BOARD_APPLICATION);
    }
    // The ends of the travel select the first and the last entry.
    assert_eq!(engage(&mut rig, Some(-1.0)).selection.unwrap().entry, 1);
    assert_eq!(engage(&mut rig, Some(1.0)).selection.unwrap().entry, 12);
}

#[test]
fn a_three_or_six_position_switch_selects_its_slices() {
    let mut list = TestList::campaign(VehicleId::Trex700l);
    list.slices = 3;
    let three: Vec<_> = [-1.0, 0.0, 1.0].map(|p| list.entry_at(p)).into();
    assert_eq!(three, [Some(1), Some(2), Some(3)]);
    list.slices = 6;
    let six: Vec<_> = [-1.0, -0.6, -0.2, 0.2, 0.6, 1.0]
        .map(|p| list.entry_at(p))
        .into();
    assert_eq!(six, [1, 2, 3, 4, 5, 6].map(Some));
    // A few counts of jitter around each position selects the same entry (one SBUS count
    // is 1/819 of half the travel).
    for (position, entry) in [(-0.6, 2), (-0.2, 3), (0.2, 4), (0.6, 5)] {
        for jitter in [-5.0 / 819.0, 5.0 / 819.0] {
            assert_eq!(list.entry_at(position + jitter), Some(entry));
        }
    }
    assert_eq!(list.entry_at(f32::NAN), None);
    assert_eq!(list.entry_at(7.0), Some(6), "beyond the travel: clamped");
}

#[test]
fn the_selector_moved_during_a_test_changes_nothing() {
    let config = short_list_config();
    // Entry 3: the longitudinal sweep on the first band.
    let position = slice_centre(3, TEST_LIST_LEN);
    let run = |move_knob: bool| {
        let mut rig = Rig::armed(config);
        rig.rc.selector = Some(position);
        rig.start_test();
        let mut outputs = Vec::new();
        for k in 0..2_000 {
            if move_knob {
                // Through every other slice and back, several times.
                rig.rc.selector = Some(-1.0 + (k % 41) as f32 * 0.05);
            }
            let out = rig.tick();
            outputs.push(out);
            if out.mode == Mode::Pilot {
                break;
            }
        }
        (rig, outputs)
    };
    let (still, still_out) = run(false);
    let (moved, moved_out) = run(true);
    assert_eq!(moved_out, still_out, "the same test, tick for tick");
    assert!(moved_out.iter().any(|o| o.phase == Phase::Sweep));
    // Flown to its end (Done, then the pilot mode), never aborted.
    assert!(moved_out.iter().any(|o| o.phase == Phase::Done));
    assert!(moved_out.iter().all(|o| o.abort.is_none()));
    let headers = headers(&moved);
    assert_eq!(headers, self::headers(&still));
    assert_eq!(headers.len(), 1);
    assert_eq!(headers[0].selection.map(|s| s.entry), Some(3));
    assert_eq!(headers[0].test.primary, Axis::Lon);
    // Every Sample of the test excites the entry's axis.
    let excited: Vec<Axis> = moved
        .frames
        .iter()
        .filter_map(|frame| match frame {
            Frame::Sample(s) if is_excitation(s.phase) => Some(s.primary),
            _ => None,
        })
        .collect();
    assert!(!excited.is_empty());
    assert!(excited.iter().all(|axis| *axis == Axis::Lon));
}

#[test]
fn an_empty_entry_is_refused_and_nothing_is_excited() {
    let mut config = short_list_config();
    config.tests.entries[4] = TestEntry::EMPTY;
    let mut rig = Rig::armed(config);
    rig.rc.selector = Some(slice_centre(5, TEST_LIST_LEN));
    rig.rc.test_switch = false;
    rig.tick();
    rig.rc.test_switch = true;
    let out = rig.tick();
    assert_eq!(
        out.refused,
        Some(Refusal::Test(CheckFailure::NoTestSelected))
    );
    assert_eq!((out.mode, out.phase), (Mode::Pilot, Phase::Idle));
    assert!(rig.tick_events().iter().any(|e| matches!(
        e,
        Event::Refused {
            check: RefusedCheck::NoTestSelected,
            ..
        }
    )));
    assert!(headers(&rig).is_empty());
    // The neighbouring entry engages, as the first engagement of the power-up.
    let header = engage(&mut rig, Some(slice_centre(6, TEST_LIST_LEN)));
    assert_eq!(
        header.selection,
        Some(TestSelection {
            entry: 6,
            engagement: 1
        })
    );
}

#[test]
fn without_a_selector_the_single_test_flies_as_entry_zero() {
    let config = short_list_config();
    let mut rig = Rig::armed(config);
    for engagement in 1..=3 {
        let header = engage(&mut rig, None);
        assert_eq!(
            header.selection,
            Some(TestSelection {
                entry: 0,
                engagement
            })
        );
        // The configured test, its warnings as the sequencer filled them in and the
        // engagement's noise seed.
        let mut expected = config.flight.test;
        expected.warnings = header.test.warnings;
        expected.seed = engagement_seed(config.flight.test.seed, engagement);
        assert_eq!(header.test, expected);
        assert_eq!(header.test.input, InputKind::Sweep);
    }
    // After a list test, entry 0 is the configured test again.
    let listed = engage(&mut rig, Some(slice_centre(8, TEST_LIST_LEN)));
    assert_eq!(listed.test.primary, Axis::Col);
    let single = engage(&mut rig, None);
    assert_eq!(single.test.primary, config.flight.test.primary);
    assert_eq!(single.test.sweep.t_rec_s, config.flight.test.sweep.t_rec_s);
    assert_eq!(
        single.selection.map(|s| (s.entry, s.engagement)),
        Some((0, 5))
    );
}

/// Each test of a flight gets its own noise seed: the stored one for the first (a flight
/// of one test flies as before), a different one for every later engagement, and so
/// another noise sequence on the same entry.
#[test]
fn every_engagement_of_a_flight_has_its_own_noise_seed() {
    let seed = 0xDEAD_BEEF;
    assert_eq!(engagement_seed(seed, 1), seed);
    assert_eq!(engagement_seed(seed, 0), seed);
    let mut seeds: Vec<u32> = (1..=1000).map(|n| engagement_seed(seed, n)).collect();
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), 1000);
    assert_eq!(
        engagement_seed(u32::MAX, u16::MAX),
        u32::MAX.wrapping_add(65_534u32.wrapping_mul(0x9E37_79B9))
    );

    // The same entry engaged twice: the same test but its seed, and other noise on the
    // off-axes during the sweep.
    let config = short_list_config();
    let mut rig = Rig::armed(config);
    let position = Some(slice_centre(1, TEST_LIST_LEN));
    let fly = |rig: &mut Rig| {
        rig.rc.selector = position;
        rig.start_test();
        let first = rig.outputs.len();
        for _ in 0..400 {
            rig.tick();
            if matches!(rig.outputs.last().map(|o| o.phase), Some(Phase::Done)) {
                break;
            }
        }
        let commands: Vec<Controls> = rig.outputs[first..].iter().map(|o| o.command).collect();
        rig.rc.test_switch = false;
        rig.ticks(3);
        commands
    };
    let first = fly(&mut rig);
    let second = fly(&mut rig);
    let sent = headers(&rig);
    assert_eq!(sent.len(), 2);
    assert_eq!(sent[0].test.seed, config.flight.test.seed);
    assert_eq!(
        sent[1].test.seed,
        engagement_seed(config.flight.test.seed, 2)
    );
    assert_eq!(
        Header {
            test: TestConfig {
                seed: 0,
                ..sent[0].test
            },
            selection: None,
            ..sent[0]
        },
        Header {
            test: TestConfig {
                seed: 0,
                ..sent[1].test
            },
            selection: None,
            ..sent[1]
        },
    );
    let off_axis_differs = first
        .iter()
        .zip(&second)
        .any(|(a, b)| a.lon != b.lon || a.ped != b.ped);
    assert!(
        off_axis_differs,
        "the second engagement repeats the first one's noise"
    );
}
