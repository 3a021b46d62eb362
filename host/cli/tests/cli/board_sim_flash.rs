//! `--fc board-sim:FLASH`: the simulated board holds its parameters in a flash file
//! through the firmware's own store, is set up by `fc params push` from an aircraft file,
//! and flies the aircraft through its real servo geometry (fbl700: 140° plate, servo 2
//! reversed, 760 µs tail servo).

use std::path::Path;

use serde_json::Value;

use crate::support;
use crate::support::sweephold;

const FBL700: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../aircraft/vehicles/fbl700.toml"
);

fn ok(args: &[&str]) -> String {
    let output = sweephold(args);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).unwrap()
}

/// The one-line error of a command that must fail.
fn refused(args: &[&str]) -> String {
    let output = sweephold(args);
    assert!(!output.status.success(), "{args:?} succeeded");
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

struct Scratch(support::Scratch);

impl Scratch {
    fn new(name: &str) -> Self {
        Scratch(support::Scratch::new(&format!("board-sim-flash-{name}")))
    }

    fn path(&self, name: &str) -> String {
        self.0.join(name).to_str().unwrap().to_string()
    }
}

/// A flash file holding the fbl700 file's parameters, saved.
fn fbl700_flash(dir: &Scratch, name: &str) -> String {
    let flash = dir.path(name);
    let fc = format!("--fc=board-sim:{flash}");
    let pushed = ok(&["fc", "params", "push", FBL700, "--save", &fc]);
    assert!(pushed.contains("(saved)"), "{pushed}");
    flash
}

/// Fly the lateral sweeps (30 s, seed 3) of fbl700 on `fc` into `out`; the summary.
fn fly(fc: &str, out: &Path) -> Value {
    ok(&[
        "fly",
        "--fc",
        fc,
        "--vehicle",
        "fbl700",
        "--axes",
        "lat",
        "--t-rec",
        "30",
        "--seed",
        "3",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn params_live_in_the_flash_file_and_a_command_is_a_power_cycle() {
    let dir = Scratch::new("power-cycle");
    let flash = fbl700_flash(&dir, "board.flash");
    let fc = format!("--fc=board-sim:{flash}");
    assert_eq!(std::fs::metadata(&flash).unwrap().len(), 32 * 1024);
    assert_eq!(ok(&["fc", "params", "get", "SWASH_TYPE", &fc]), "140\n");
    assert_eq!(ok(&["fc", "params", "get", "SERVO2_DIR", &fc]), "-1\n");
    assert_eq!(ok(&["fc", "params", "get", "TAIL_MID", &fc]), "760\n");
    assert_eq!(ok(&["fc", "params", "get", "SERVO_RATE", &fc]), "333\n");
    let diff = ok(&["fc", "params", "diff", FBL700, &fc]);
    // Only the parameters the aircraft file does not set differ (absent from it).
    assert!(
        diff.lines().all(|line| line.ends_with("not in the file")),
        "{diff}"
    );
    // A set without save is lost when the command ends, and FLASH is not touched.
    let before = std::fs::read(&flash).unwrap();
    assert_eq!(
        ok(&["fc", "params", "set", "SWASH_PHASE", "12.5", &fc]),
        "SWASH_PHASE = 12.5\n"
    );
    assert_eq!(ok(&["fc", "params", "get", "SWASH_PHASE", &fc]), "0\n");
    assert_eq!(std::fs::read(&flash).unwrap(), before);
    // With --save it stays.
    ok(&["fc", "params", "set", "SWASH_PHASE", "12.5", "--save", &fc]);
    assert_eq!(ok(&["fc", "params", "get", "SWASH_PHASE", &fc]), "12.5\n");
    // A push of an out-of-range value writes nothing.
    let bad = dir.path("bad.toml");
    std::fs::write(&bad, "[params]\nSWASH_TYPE = 140\nTAIL_MID = 3000\n").unwrap();
    let error = refused(&["fc", "params", "push", &bad, "--save", &fc]);
    assert!(error.contains("nothing was written"), "{error}");
    assert_eq!(ok(&["fc", "params", "get", "SWASH_PHASE", &fc]), "12.5\n");
    // A file that is no flash file is refused on one line.
    let short = dir.path("short.flash");
    std::fs::write(&short, [0u8; 100]).unwrap();
    let error = refused(&["fc", "params", "list", &format!("--fc=board-sim:{short}")]);
    assert!(error.contains("not a board-sim flash file"), "{error}");
}

#[test]
fn the_board_booted_from_flash_flies_as_the_board_set_up_from_the_file() {
    let dir = Scratch::new("same-flight");
    let flash = fbl700_flash(&dir, "board.flash");
    let from_flash = fly(&format!("board-sim:{flash}"), &dir.0.join("flash"));
    let from_file = fly("board-sim", &dir.0.join("file"));
    for record in ["lat-1.bin", "lat-2.bin"] {
        let a = std::fs::read(dir.0.join("flash").join(record)).unwrap();
        let b = std::fs::read(dir.0.join("file").join(record)).unwrap();
        assert!(a == b, "{record} differs");
    }
    for run in from_flash["runs"].as_array().unwrap() {
        assert!(run["abort_reason"].is_null(), "{run}");
    }
    assert_eq!(from_flash["runs"], from_file["runs"]);
}

#[test]
fn a_board_set_up_with_a_servo_direction_wrong_cannot_hold_the_hover() {
    let dir = Scratch::new("wrong-servo");
    let flash = fbl700_flash(&dir, "board.flash");
    let fc = format!("--fc=board-sim:{flash}");
    ok(&["fc", "params", "set", "SERVO2_DIR", "1", "--save", &fc]);
    let summary = fly(&format!("board-sim:{flash}"), &dir.0.join("out"));
    for run in summary["runs"].as_array().unwrap() {
        assert_eq!(run["abort_reason"], "attitude_limit", "{run}");
        assert!(run["duration_s"].as_f64().unwrap() < 1.0, "{run}");
    }
}

#[test]
fn a_flash_without_a_saved_set_is_refused_before_anything_is_flown() {
    let dir = Scratch::new("no-set");
    let absent = dir.path("absent.flash");
    let out = dir.path("out");
    let error = refused(&[
        "fly",
        "--fc",
        &format!("board-sim:{absent}"),
        "--vehicle",
        "fbl700",
        "--axes",
        "lat",
        "-q",
        "--out",
        &out,
    ]);
    assert!(error.contains("does not exist"), "{error}");
    assert!(!Path::new(&out).exists());
    let erased = dir.path("erased.flash");
    std::fs::write(&erased, vec![0xFF; 32 * 1024]).unwrap();
    let error = refused(&[
        "campaign",
        "--fc",
        &format!("board-sim:{erased}"),
        "--vehicle",
        "fbl700",
        "-q",
        "--out",
        &out,
    ]);
    assert!(
        error.contains("holds no valid parameter set (Empty)"),
        "{error}"
    );
    assert_eq!(std::fs::read(&erased).unwrap(), vec![0xFF; 32 * 1024]);
}
