//! `fly --fc board-sim` flies the tests of the board's test list chosen by the simulated
//! pilot's selector channel: each dump's Header names the entry the selector chose and
//! the engagement (one record per power-up: the first), and its test is that entry's.
//! A record outside the list is the board's single test, entry 0.

use std::path::{Path, PathBuf};
use std::process::Command;

use sweephold_protocol::{Axis, Decoder, Frame, Header, InputKind, ProtocolVersion};

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("sweephold-test-list-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// `fly --fc board-sim --t-rec 6 -q --out DIR` with `args`.
fn fly(dir: &Path, args: &[&str]) {
    let out = dir.to_str().unwrap();
    let mut all = vec![
        "fly",
        "--fc",
        "board-sim",
        "--t-rec",
        "6",
        "-q",
        "--out",
        out,
    ];
    all.extend_from_slice(args);
    let output = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .args(&all)
        .output()
        .expect("the binary runs");
    assert!(
        output.status.success(),
        "{all:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The Headers of a dump.
fn headers(path: &Path) -> Vec<Header> {
    let bytes = std::fs::read(path).unwrap();
    Decoder::new()
        .feed(&bytes)
        .filter_map(|frame| match frame {
            Ok(Frame::Header(header)) => Some(header),
            _ => None,
        })
        .collect()
}

/// The one Header of `file`: entry, engagement, axis, input and band.
fn test_of(dir: &Path, file: &str) -> (u8, u16, Axis, InputKind, f32, f32) {
    let headers = headers(&dir.join(file));
    assert_eq!(headers.len(), 1, "{file}: one test per record");
    let header = headers[0];
    assert_eq!(
        header.protocol,
        ProtocolVersion::BOARD_APPLICATION,
        "{file}"
    );
    let selection = header
        .selection
        .expect("a board Header names its selection");
    let test = header.test;
    (
        selection.entry,
        selection.engagement,
        test.primary,
        test.input,
        test.sweep.omega_min,
        test.sweep.omega_max,
    )
}

/// The Bo-105's list: lat, lon, ped, col sweeps on 0.2–31.4 and 0.01–18.85 rad/s
/// (entries 1–8), then one doublet per axis (9–12). The two longitudinal sweeps are
/// entries 3 and 4, the pedal doublet entry 11.
#[test]
fn the_pilots_selector_chooses_each_records_entry_and_the_headers_name_it() {
    let dir = scratch("bo105");
    fly(
        &dir,
        &["--vehicle", "bo105", "--axes", "lon", "--seed", "1"],
    );
    assert_eq!(
        test_of(&dir, "lon-1.bin"),
        (3, 1, Axis::Lon, InputKind::Sweep, 0.2, 31.4)
    );
    assert_eq!(
        test_of(&dir, "lon-2.bin"),
        (4, 1, Axis::Lon, InputKind::Sweep, 0.01, 18.85)
    );
    let doublets = dir.join("doublets");
    fly(
        &doublets,
        &["--vehicle", "bo105", "--axes", "ped", "--input", "doublet"],
    );
    assert_eq!(
        test_of(&doublets, "ped-1.bin"),
        (11, 1, Axis::Ped, InputKind::Doublet, 0.2, 31.4)
    );
    // A 3-2-1-1 is not in the list: the board flies it as its single test, entry 0.
    let other = dir.join("3211");
    fly(
        &other,
        &["--vehicle", "bo105", "--axes", "lat", "--input", "3211"],
    );
    let (entry, engagement, axis, input, ..) = test_of(&other, "lat-1.bin");
    assert_eq!(
        (entry, engagement, axis, input),
        (0, 1, Axis::Lat, InputKind::ThreeTwoOneOne)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The TREX 700L's first band reaches 62.8 rad/s: its lateral sweeps are entries 1 and 2.
#[test]
fn the_trex_list_holds_its_own_bands() {
    let dir = scratch("trex");
    fly(
        &dir,
        &["--vehicle", "trex700l", "--axes", "lat", "--seed", "2"],
    );
    assert_eq!(
        test_of(&dir, "lat-1.bin"),
        (1, 1, Axis::Lat, InputKind::Sweep, 0.2, 62.8)
    );
    assert_eq!(
        test_of(&dir, "lat-2.bin"),
        (2, 1, Axis::Lat, InputKind::Sweep, 0.01, 18.85)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
