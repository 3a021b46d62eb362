//! The parameter link: obeyed disarmed, refused armed, and the store behind it.

use super::*;
use crate::params::mock_flash::{MockFlash, PAGE, PAGES};
use crate::params::no_flash::NoFlash;
use crate::params::DEFS;
use sweephold_protocol::ParamOp;

const VEHICLE: VehicleId = VehicleId::Trex700l;

fn name(text: &str) -> ParamName {
    ParamName::new(text).unwrap()
}

fn link(flash: MockFlash) -> ParamLink<MockFlash> {
    let store = ParamStore::new(flash, 0..(PAGE * PAGES) as u32).unwrap();
    ParamLink::boot(Some(store), VEHICLE)
}

fn replies(
    link: &mut ParamLink<MockFlash>,
    request: ParamRequest,
    disarmed: bool,
) -> Vec<ParamReply> {
    let mut out = Vec::new();
    link.handle(&request, disarmed, |reply| out.push(reply));
    out
}

fn flash_of(link: ParamLink<MockFlash>) -> MockFlash {
    link.into_store().unwrap().into_flash()
}

#[test]
fn a_new_board_boots_the_defaults_and_may_not_arm() {
    let link = link(MockFlash::new());
    assert_eq!(link.load_status(), LoadStatus::Empty);
    assert!(!link.params_valid());
    assert_eq!(*link.table(), ParamTable::defaults(VEHICLE));
    assert_eq!(
        link.store_event(3),
        Event::ParamStore {
            tick: 3,
            status: ParamStoreStatus::Empty
        }
    );
}

#[test]
fn every_request_is_refused_while_armed_and_changes_nothing() {
    let mut link = link(MockFlash::new());
    let requests = [
        ParamRequest::List,
        ParamRequest::Get {
            name: name("SWASH_TYPE"),
        },
        ParamRequest::Set {
            name: name("SWASH_TYPE"),
            value: 140.0,
        },
        ParamRequest::Save,
        ParamRequest::Reset,
    ];
    let mut table = *link.table();
    table.set_by_name("SERVO2_DIR", -1.0).unwrap();
    // A RAM change made while disarmed survives the armed requests (Reset included).
    assert_eq!(
        replies(
            &mut link,
            ParamRequest::Set {
                name: name("SERVO2_DIR"),
                value: -1.0
            },
            true
        ),
        [ParamReply::Value {
            index: ParamId::Servo2Dir.index() as u16,
            count: COUNT as u16,
            name: name("SERVO2_DIR"),
            value: -1.0
        }]
    );
    for request in requests {
        let out = replies(&mut link, request, false);
        let expected_name = match request {
            ParamRequest::Get { name } | ParamRequest::Set { name, .. } => name,
            _ => ParamName::EMPTY,
        };
        assert_eq!(
            out,
            [ParamReply::Refused {
                op: request.op(),
                name: expected_name,
                reason: ParamRefusal::Armed
            }]
        );
    }
    assert_eq!(*link.table(), table);
    assert!(!link.params_valid());
    // Nothing reached the flash.
    let flash = flash_of(link);
    assert_eq!(flash.steps, 0);
    assert!(flash.mem.iter().all(|&b| b == 0xFF));
}

#[test]
fn list_gives_every_parameter_in_table_order_then_done() {
    let mut link = link(MockFlash::new());
    let out = replies(&mut link, ParamRequest::List, true);
    assert_eq!(out.len(), COUNT + 1);
    for (i, (reply, def)) in out.iter().zip(DEFS.iter()).enumerate() {
        let ParamReply::Value {
            index,
            count,
            name,
            value,
        } = *reply
        else {
            panic!("{reply:?}");
        };
        assert_eq!((usize::from(index), usize::from(count)), (i, COUNT));
        assert_eq!(name.as_str(), Some(def.name));
        assert_eq!(value, link.table().values()[i]);
    }
    assert_eq!(out[COUNT], ParamReply::Done { op: ParamOp::List });
}

#[test]
fn list_entries_one_at_a_time_are_the_list_reply() {
    let mut link = link(MockFlash::new());
    link.handle(
        &ParamRequest::Set {
            name: name("SWASH_PHASE"),
            value: 5.0,
        },
        true,
        |_| {},
    );
    let whole = replies(&mut link, ParamRequest::List, true);
    let stepped: Vec<ParamReply> = (0..).map_while(|i| link.list_entry(i)).collect();
    assert_eq!(stepped, whole);
    assert_eq!(link.list_entry(COUNT + 1), None);
}

#[test]
fn a_link_without_store_refuses_save_and_lists_the_defaults() {
    let mut link: ParamLink<NoFlash> = ParamLink::boot(None, VEHICLE);
    assert!(link.params_valid());
    assert_eq!(*link.table(), ParamTable::defaults(VEHICLE));
    let mut out = Vec::new();
    link.handle(&ParamRequest::Save, true, |reply| out.push(reply));
    assert_eq!(
        out,
        [ParamReply::Refused {
            op: ParamOp::Save,
            name: ParamName::EMPTY,
            reason: ParamRefusal::NoStore,
        }]
    );
}

#[test]
fn get_and_set_by_name_with_refusals() {
    let mut link = link(MockFlash::new());
    let value_of = |link: &mut ParamLink<MockFlash>, text: &str| match replies(
        link,
        ParamRequest::Get { name: name(text) },
        true,
    )[..]
    {
        [ParamReply::Value { value, .. }] => value,
        ref other => panic!("{other:?}"),
    };
    assert_eq!(value_of(&mut link, "SWASH_TYPE"), 120.0);
    let set = |link: &mut ParamLink<MockFlash>, text: &str, value: f32| {
        replies(
            link,
            ParamRequest::Set {
                name: name(text),
                value,
            },
            true,
        )
    };
    assert!(matches!(
        set(&mut link, "SWASH_TYPE", 140.0)[..],
        [ParamReply::Value { value, .. }] if value == 140.0
    ));
    assert_eq!(value_of(&mut link, "SWASH_TYPE"), 140.0);
    for (text, value, reason) in [
        ("NO_SUCH", 1.0, ParamRefusal::UnknownName),
        ("SWASH_TYPE", 90.0, ParamRefusal::NotAChoice),
        ("SWASH_PHASE", f32::NAN, ParamRefusal::NotFinite),
        ("SWASH_PHASE", 200.0, ParamRefusal::OutOfRange),
        ("SERVO1_MID", 1500.5, ParamRefusal::NotAnInteger),
    ] {
        assert_eq!(
            set(&mut link, text, value),
            [ParamReply::Refused {
                op: ParamOp::Set,
                name: name(text),
                reason
            }],
            "{text}"
        );
    }
    assert_eq!(value_of(&mut link, "SWASH_TYPE"), 140.0);
    // Names are exact: lower case is another name.
    assert!(matches!(
        replies(
            &mut link,
            ParamRequest::Get {
                name: name("swash_type")
            },
            true
        )[..],
        [ParamReply::Refused {
            reason: ParamRefusal::UnknownName,
            ..
        }]
    ));
}

#[test]
fn a_saved_set_boots_next_time_and_allows_arming() {
    let mut link = link(MockFlash::new());
    for (text, value) in [
        ("SWASH_TYPE", 140.0),
        ("SERVO2_DIR", -1.0),
        ("TAIL_MID", 760.0),
    ] {
        link.handle(
            &ParamRequest::Set {
                name: name(text),
                value,
            },
            true,
            |_| {},
        );
    }
    // TAIL_MID 760 lies below TAIL_MIN 1100: the set is inconsistent, nothing is saved.
    assert_eq!(
        replies(&mut link, ParamRequest::Save, true),
        [ParamReply::Refused {
            op: ParamOp::Save,
            name: ParamName::EMPTY,
            reason: ParamRefusal::Inconsistent
        }]
    );
    assert!(!link.params_valid());
    for (text, value) in [("TAIL_MIN", 560.0), ("TAIL_MAX", 960.0)] {
        link.handle(
            &ParamRequest::Set {
                name: name(text),
                value,
            },
            true,
            |_| {},
        );
    }
    assert_eq!(
        replies(&mut link, ParamRequest::Save, true),
        [ParamReply::Done { op: ParamOp::Save }]
    );
    assert!(link.params_valid());
    let saved = *link.table();
    let rebooted = self::link(flash_of(link).rebooted());
    assert_eq!(rebooted.load_status(), LoadStatus::Loaded);
    assert!(rebooted.params_valid());
    assert_eq!(*rebooted.table(), saved);
    let params = saved.params().unwrap();
    assert_eq!(params.stack.app.flight.mixer.tail.centre_us, 760);
}

#[test]
fn reset_restores_the_defaults_in_ram_only() {
    let mut link = link(MockFlash::new());
    link.handle(
        &ParamRequest::Set {
            name: name("SWASH_LEAD"),
            value: 2.0,
        },
        true,
        |_| {},
    );
    link.handle(&ParamRequest::Save, true, |_| {});
    assert_eq!(
        replies(&mut link, ParamRequest::Reset, true),
        [ParamReply::Done { op: ParamOp::Reset }]
    );
    assert_eq!(*link.table(), ParamTable::defaults(VEHICLE));
    // Not saved: the next boot has the saved set.
    let rebooted = self::link(flash_of(link).rebooted());
    assert_eq!(rebooted.table().get(ParamId::SwashLead), 2.0);
}

#[test]
fn a_failed_flash_write_is_reported_and_keeps_the_old_status() {
    let mut flash = MockFlash::new();
    flash.cut_at = Some(0);
    let mut link = link(flash);
    assert_eq!(
        replies(&mut link, ParamRequest::Save, true),
        [ParamReply::Refused {
            op: ParamOp::Save,
            name: ParamName::EMPTY,
            reason: ParamRefusal::StoreFailed
        }]
    );
    assert!(!link.params_valid());
}

#[test]
fn without_a_store_save_is_refused_and_the_defaults_count_as_valid() {
    let mut link = ParamLink::<MockFlash>::boot(None, VEHICLE);
    assert!(link.params_valid());
    assert_eq!(
        replies(&mut link, ParamRequest::Save, true),
        [ParamReply::Refused {
            op: ParamOp::Save,
            name: ParamName::EMPTY,
            reason: ParamRefusal::NoStore
        }]
    );
}

#[test]
fn accepted_changes_are_flagged_once_and_reset_keeps_the_frame() {
    let mut link = link(MockFlash::new());
    assert!(!link.take_changed());
    // Refused (armed, or out of range): nothing to rebuild.
    let frame = ParamRequest::Set {
        name: name("FRAME"),
        value: 1.0,
    };
    link.handle(&frame, false, |_| {});
    link.handle(
        &ParamRequest::Set {
            name: name("FRAME"),
            value: 3.0,
        },
        true,
        |_| {},
    );
    assert!(!link.take_changed());
    link.handle(&frame, true, |_| {});
    assert!(link.take_changed());
    assert!(!link.take_changed());
    link.handle(
        &ParamRequest::Set {
            name: name("SWASH_LEAD"),
            value: 2.0,
        },
        true,
        |_| {},
    );
    link.handle(&ParamRequest::Reset, true, |_| {});
    assert!(link.take_changed());
    // Reset: the Bo-105's defaults, FRAME still naming it.
    assert_eq!(*link.table(), ParamTable::defaults(VehicleId::Bo105));
}
