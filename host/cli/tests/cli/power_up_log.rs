//! `fly --fc board-sim --power-up once`: every record of a run flown on one power-up of
//! the board, each test chosen from its test list by the transmitter's selector, and the
//! board's log of the power-up written as one file that `frf` reads test by test.

use std::path::Path;
use std::process::Output;

use sweephold_protocol::{Decoder, Frame, Header};

use crate::support::{sweephold, Scratch};

fn ok(args: &[&str]) -> String {
    let output = sweephold(args);
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert!(output.status.success(), "{args:?}: {stderr}");
    stderr
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// `fly --vehicle trex700l --fc board-sim --power-up once --seed 2 -q --out DIR` plus `args`.
fn fly_once(dir: &Path, args: &[&str]) -> Output {
    let mut all = vec![
        "fly",
        "--vehicle",
        "trex700l",
        "--fc",
        "board-sim",
        "--power-up",
        "once",
        "--seed",
        "2",
        "-q",
        "--out",
    ];
    all.push(s(dir));
    all.extend_from_slice(args);
    sweephold(&all)
}

fn headers(bytes: &[u8]) -> Vec<Header> {
    Decoder::new()
        .feed(bytes)
        .filter_map(|frame| match frame {
            Ok(Frame::Header(header)) => Some(header),
            _ => None,
        })
        .collect()
}

/// Where `part` lies in `whole`, if it is a contiguous slice of it at or after `from`.
fn find(whole: &[u8], part: &[u8], from: usize) -> Option<usize> {
    (from..=whole.len().saturating_sub(part.len())).find(|&i| whole[i..].starts_with(part))
}

#[test]
fn one_power_up_flies_every_record_and_logs_them_in_one_file() {
    let dir = Scratch::unmade("power-up-once");
    let output = fly_once(&dir, &["--axes", "lat,lon", "--t-rec", "12"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let log = std::fs::read(dir.join("log").join("power-up-1.bin")).unwrap();
    assert!(
        !dir.join("log").join("power-up-2.bin").exists(),
        "one power-up for the whole run"
    );

    // Four tests, engaged one after the other on one power-up, each its list entry (lat
    // on bands 1 and 2 are entries 1 and 2, lon entries 3 and 4) and its own noise seed.
    let sent = headers(&log);
    let chosen: Vec<(u8, u16)> = sent
        .iter()
        .map(|h| h.selection.map_or((0, 0), |s| (s.entry, s.engagement)))
        .collect();
    assert_eq!(chosen, [(1, 1), (2, 2), (3, 3), (4, 4)]);
    let mut seeds: Vec<u32> = sent.iter().map(|h| h.test.seed).collect();
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), 4, "each test its own noise seed");

    // Each record's dump is the log's stretch of its test, in flying order; the log holds
    // more: the power-up, the hovers between the tests.
    let mut at = 0;
    let mut recorded = 0;
    for name in ["lat-1", "lat-2", "lon-1", "lon-2"] {
        let dump = std::fs::read(dir.join(format!("{name}.bin"))).unwrap();
        assert_eq!(headers(&dump).len(), 1, "{name}");
        let start = find(&log, &dump, at).unwrap_or_else(|| panic!("{name} is not in the log"));
        at = start + dump.len();
        recorded += dump.len();
    }
    assert!(
        log.len() > recorded,
        "the log keeps the ticks between the tests"
    );

    // `frf` on the log uses every test and gives the responses of the four dumps.
    let (from_log, from_dumps) = (dir.join("log.json"), dir.join("dumps.json"));
    let listing = ok(&[
        "frf",
        s(&dir.join("log").join("power-up-1.bin")),
        "--out",
        s(&from_log),
    ]);
    for (number, axis) in [(1, "lat"), (2, "lat"), (3, "lon"), (4, "lon")] {
        let line = format!("power-up-1.bin: test {number}: {axis} Sweep, ");
        assert!(
            listing
                .lines()
                .any(|l| l.contains(&line) && l.ends_with("completed: used")),
            "{line} in\n{listing}"
        );
    }
    let dumps: Vec<String> = ["lat-1", "lat-2", "lon-1", "lon-2"]
        .iter()
        .map(|name| dir.join(format!("{name}.bin")).display().to_string())
        .collect();
    let mut separate = vec!["frf", "-q", "--out", s(&from_dumps)];
    separate.extend(dumps.iter().map(String::as_str));
    ok(&separate);
    assert_eq!(
        std::fs::read(&from_log).unwrap(),
        std::fs::read(&from_dumps).unwrap(),
        "frf of the log against frf of the dumps"
    );
}

#[test]
fn a_record_that_leaves_the_pilot_mode_ends_the_power_up() {
    // The receiver lost 4 s into each record: the board goes to its receiver failsafe and
    // the next record powers it up again, into a log of its own.
    let dir = Scratch::unmade("power-up-rc-loss");
    let output = fly_once(&dir, &["--axes", "lat", "--t-rec", "10", "--rc-loss", "4"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for n in [1, 2] {
        let log = std::fs::read(dir.join("log").join(format!("power-up-{n}.bin"))).unwrap();
        let sent = headers(&log);
        assert_eq!(sent.len(), 1, "power-up {n}");
        assert_eq!(
            sent[0].selection.map(|s| (s.entry, s.engagement)),
            Some((n as u8, 1)),
            "power-up {n}: its first engagement"
        );
    }
    assert!(!dir.join("log").join("power-up-3.bin").exists());
}

#[test]
fn one_power_up_refuses_a_test_outside_its_list_and_other_links() {
    let dir = Scratch::unmade("power-up-refused");
    // A 3-2-1-1 is no entry of the campaign's list: no selector position chooses it.
    let output = fly_once(&dir, &["--axes", "lat", "--input", "3211", "--t-rec", "10"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        stderr.contains("not an entry of the board's test list"),
        "{stderr}"
    );
    assert!(!dir.exists(), "a failed run leaves no output folder");
    let output = sweephold(&["fly", "--power-up", "once", "--out", s(&dir)]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        stderr.contains("--power-up is for --fc board-sim only"),
        "{stderr}"
    );
}
