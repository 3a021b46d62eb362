//! Every kind of input a user may hand the binary, one case per row: each ends in a
//! one-line error with a documented exit status (1: the work failed, 2: the command line
//! is wrong) or in the right result, and no input file is ever modified.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::Scratch;

fn sweephold(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs")
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("inputs-{name}"))
}

/// The bytes of every file below `dir` (sorted by path), to prove nothing changed.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                files.push((path, bytes));
            }
        }
    }
    files.sort();
    files
}

/// Assert a failure with exit status `code` and a one-line error containing `needle`.
fn assert_one_line_error(output: &Output, code: i32, needle: &str, case: &str) {
    let stderr = String::from_utf8_lossy(&output.stderr).trim().to_string();
    assert_eq!(output.status.code(), Some(code), "{case}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{case}: not one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{case}: {stderr}");
    assert!(
        stderr.contains(needle),
        "{case}: {stderr:?} should contain {needle:?}"
    );
    assert!(!stderr.contains("panicked"), "{case}: {stderr}");
}

/// A one-state model of roll rate (model.json layout), for verify's argument checks.
const LAG_MODEL: &str = r#"{"version": 1, "structure": "lag", "description": "",
"states": ["p"], "controls": ["lat"], "outputs": ["p"],
"matrices": {"M": {"rows": 1, "cols": 1, "data": [1.0]}, "F": {"rows": 1, "cols": 1, "data": [-2.0]},
"G": {"rows": 1, "cols": 1, "data": [3.0]}, "H0": {"rows": 1, "cols": 1, "data": [1.0]},
"H1": {"rows": 1, "cols": 1, "data": [0.0]}},
"delays": [0.0], "parameters": [], "pairs": [], "average_cost": 0.0,
"correlation": null, "starts": [], "minimum_confirmed": true, "reduction": []}"#;

/// A lateral sweep flown in process (two short records) and its frf.json, in `dir/data`.
fn flown_data(dir: &Path) -> PathBuf {
    let data = dir.join("data");
    let output = sweephold(
        dir,
        &[
            "fly", "--axes", "lat", "--t-rec", "20", "--out", "data/fly", "-q",
        ],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let output = sweephold(
        dir,
        &[
            "frf",
            "data/fly/lat-1.bin",
            "data/fly/lat-2.bin",
            "--out",
            "data/frf.json",
            "-q",
        ],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    data
}

#[test]
fn refused_command_lines_and_outputs_that_are_inputs() {
    let dir = scratch("refused");
    let data = flown_data(&dir);
    std::fs::write(dir.join("not-a-folder"), "x").unwrap();
    std::fs::write(data.join("lag.json"), LAG_MODEL).unwrap();
    // frf.json damaged two ways: another layout version, a magnitude no response has.
    let frf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data.join("frf.json")).unwrap()).unwrap();
    let mut version = frf.clone();
    version["version"] = 99.into();
    std::fs::write(data.join("frf-v99.json"), version.to_string()).unwrap();
    let mut huge = frf;
    huge["pairs"][0]["mag_db"][3] = 1e300.into();
    std::fs::write(data.join("frf-huge.json"), huge.to_string()).unwrap();
    let before = snapshot(&data);
    let cases: &[(&[&str], i32, &str)] = &[
        // An output that is one of the inputs: refused before anything is written.
        (
            &["decode", "data/fly/lat-1.bin", "-o", "data/fly/lat-1.bin"],
            1,
            "is one of the inputs",
        ),
        (
            &[
                "decode",
                "data/fly/lat-1.bin",
                "data/fly/lat-2.bin",
                "-o",
                "data/fly/lat-2.bin",
            ],
            1,
            "is one of the inputs",
        ),
        (
            &[
                "decode",
                "data/fly/lat-1.bin",
                "-o",
                "data/fly/../fly/lat-1.bin",
            ],
            1,
            "is one of the inputs",
        ),
        (
            &["frf", "data/fly/lat-1.bin", "--out", "data/fly/lat-1.bin"],
            1,
            "is one of the inputs",
        ),
        (
            &[
                "fit",
                "--frf",
                "data/frf.json",
                "--model",
                "x.toml",
                "--out",
                "data/frf.json",
            ],
            1,
            "is one of the inputs",
        ),
        // Documents that are not what they claim, named with the field at fault.
        (
            &["fit", "--frf", "data/frf-v99.json", "--model", "bo105-6dof"],
            1,
            "version 99",
        ),
        (
            &[
                "fit",
                "--frf",
                "data/frf-huge.json",
                "--model",
                "bo105-6dof",
            ],
            1,
            "mag_db",
        ),
        // Counts beyond their documented range (more below).
        (
            &[
                "fit",
                "--frf",
                "data/frf.json",
                "--model",
                "x",
                "--max-starts",
                "0",
            ],
            2,
            "from 1 to 64",
        ),
        // Numbers that start with a minus sign reach their parser and are refused with
        // the reason, not clap's tip to use `--`.
        (
            &["frf", "data/fly/lat-1.bin", "--band", "-1,10"],
            2,
            "need 0 < WMIN < WMAX",
        ),
        (
            &["fly", "--seed", "-1"],
            2,
            "expected a whole number from 0",
        ),
        (
            &["campaign", "--seed", "-1"],
            2,
            "expected a whole number from 0",
        ),
        (
            &["fly", "--pilot-override", "nan"],
            2,
            "expected a finite number >= 0",
        ),
        (
            &["fly", "--pilot-override", "-1"],
            2,
            "expected a finite number >= 0",
        ),
        (
            &["fly", "--pilot-override", "500", "--out", "o"],
            1,
            "the end of the shortest record",
        ),
        (
            &["fly", "--gust", "inf"],
            2,
            "expected a finite number >= 0",
        ),
        (
            &["fly", "--sensor-dropout", "1.5"],
            2,
            "probability from 0 to 1",
        ),
        (&["fly", "--rate", "10"], 2, "50..=1000"),
        (&["fly", "--t-rec", "1"], 2, "from 5 to 1000 s"),
        (
            &["verify", "--model", "m.json", "--segment", "-2", "x.bin"],
            2,
            "seconds > 0",
        ),
        (
            &["fly", "--axes", "lat,lat", "--out", "o"],
            1,
            "names lat twice",
        ),
        (&["fly", "--bogus"], 2, "unexpected argument '--bogus'"),
        // A board image that is not one: refused at once, before QEMU is looked for.
        (
            &["fly", "--fc", "qemu", "--elf", "not-a-folder", "--out", "o"],
            1,
            "not an ELF file",
        ),
        (&["fit"], 2, "--frf <FILE>"),
        // Folders where files are expected, and files where folders are.
        (&["decode", "data"], 1, "is a folder"),
        (
            &["verify", "--model", "data/lag.json", "data/fly"],
            1,
            "is a folder",
        ),
        (
            &["verify", "--model", "data/fly", "data/fly/lat-1.bin"],
            1,
            "is a folder",
        ),
        (&["frf", "data/fly", "--out", "x.json"], 1, "is a folder"),
        (
            &[
                "frf",
                "data/fly/lat-1.bin",
                "data/fly/lat-2.bin",
                "--out",
                "new.json",
                "--plots",
                "not-a-folder",
            ],
            1,
            "exists and is not a folder",
        ),
        (
            &[
                "verify",
                "--model",
                "data/lag.json",
                "--plots",
                "not-a-folder",
                "data/fly/lat-1.bin",
            ],
            1,
            "exists and is not a folder",
        ),
    ];
    for points in ["18446744073709551615", "4294967296", "1e9", "100000", "1"] {
        let args = [
            "fit",
            "--frf",
            "data/frf.json",
            "--model",
            "x",
            "--points",
            points,
        ];
        let output = sweephold(&dir, &args);
        assert_one_line_error(&output, 2, "from 2 to 200", &args.join(" "));
    }
    for (args, code, needle) in cases {
        let output = sweephold(&dir, args);
        assert_one_line_error(&output, *code, needle, &args.join(" "));
    }
    // Nothing was written by a refused command, and no input changed.
    assert_eq!(snapshot(&data), before);
    for absent in ["new.json", "x.json", "o"] {
        assert!(!dir.join(absent).exists(), "{absent} was written");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_fly_folder_is_replaced_whole() {
    let dir = scratch("fly-folder");
    let fly = |args: &[&str]| {
        let mut all = vec!["fly", "--t-rec", "10", "--out", "run", "-q"];
        all.extend_from_slice(args);
        let output = sweephold(&dir, &all);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    fly(&["--axes", "lat,lon", "--seed", "2"]);
    fly(&["--axes", "ped", "--seed", "3"]);
    let mut names: Vec<String> = std::fs::read_dir(dir.join("run"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    // No dump of the earlier run is left beside the new ones.
    assert_eq!(names, ["ped-1.bin", "ped-2.bin", "summary.json"]);
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(leftovers, ["run"], "no staging folder left behind");

    // A folder holding files of its own is not replaced.
    std::fs::create_dir_all(dir.join("mine")).unwrap();
    std::fs::write(dir.join("mine/notes.txt"), "mine").unwrap();
    let output = sweephold(
        &dir,
        &[
            "fly", "--t-rec", "10", "--axes", "lat", "--out", "mine", "-q",
        ],
    );
    assert_one_line_error(
        &output,
        1,
        "not a sweephold run",
        "fly into a foreign folder",
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("mine/notes.txt")).unwrap(),
        "mine"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn decode_to_a_file_writes_it_whole_or_not_at_all() {
    let dir = scratch("decode-atomic");
    flown_data(&dir);
    std::fs::write(dir.join("rows.csv"), "earlier rows\n").unwrap();
    std::fs::write(dir.join("noise.bin"), [7u8; 300]).unwrap();
    // A dump without a frame fails; the earlier output stays as it was.
    let output = sweephold(&dir, &["decode", "noise.bin", "-o", "rows.csv", "-q"]);
    assert_one_line_error(&output, 1, "no valid frame", "decode noise");
    assert_eq!(
        std::fs::read_to_string(dir.join("rows.csv")).unwrap(),
        "earlier rows\n"
    );
    // A good dump replaces it.
    let output = sweephold(
        &dir,
        &["decode", "data/fly/lat-1.bin", "-o", "rows.csv", "-q"],
    );
    assert!(output.status.success());
    let rows = std::fs::read_to_string(dir.join("rows.csv")).unwrap();
    assert!(
        rows.starts_with("tick,") || rows.lines().count() > 100,
        "{}",
        &rows[..80]
    );
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(names.is_empty(), "temporary files left: {names:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn frf_reads_the_swept_axis_from_its_own_decoded_csv() {
    let dir = scratch("decoded-csv");
    flown_data(&dir);
    let decode = |dumps: &[&str], csv: &str| {
        let mut args = vec!["decode"];
        args.extend_from_slice(dumps);
        args.extend(["-o", csv, "-q"]);
        let output = sweephold(&dir, &args);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    // Two dumps decoded into one file: their times restart, which frf names.
    decode(&["data/fly/lat-1.bin", "data/fly/lat-2.bin"], "both.csv");
    let output = sweephold(
        &dir,
        &["frf", "both.csv", "--band", "0.2,31.4", "--out", "x.json"],
    );
    assert_one_line_error(
        &output,
        1,
        "decode each dump to its own file",
        "frf both.csv",
    );
    // One file per dump.
    decode(&["data/fly/lat-1.bin"], "lat-1.csv");
    decode(&["data/fly/lat-2.bin"], "lat-2.csv");
    let csv = std::fs::read(dir.join("lat-1.csv")).unwrap();
    let args = [
        "frf",
        "lat-1.csv",
        "lat-2.csv",
        "--band",
        "0.2,31.4",
        "--out",
        "csv-frf.json",
    ];
    let output = sweephold(&dir, &args);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let document: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("csv-frf.json")).unwrap()).unwrap();
    let pairs = document["pairs"].as_array().expect("pairs");
    assert!(!pairs.is_empty());
    // Every response is to the lateral stick the `primary` column names.
    for pair in pairs {
        assert_eq!(pair["input"], "lat", "{}", pair["output"]);
    }
    assert_eq!(
        std::fs::read(dir.join("lat-1.csv")).unwrap(),
        csv,
        "the CSV is unchanged"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A named pipe (like `/dev/null` or `/dev/stdout`) as output is written in place: a
/// rename over it would leave a plain file where the pipe or device was.
#[cfg(unix)]
#[test]
fn a_pipe_as_output_is_written_in_place() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("pipe");
    flown_data(&dir);
    let pipe = dir.join("rows.pipe");
    let made = Command::new("mkfifo")
        .arg(&pipe)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    // A second name for the pipe, to release the reader should the output replace it.
    let keep = dir.join("keep.pipe");
    std::fs::hard_link(&pipe, &keep).unwrap();
    let reader = {
        let pipe = pipe.clone();
        std::thread::spawn(move || std::fs::read(pipe).expect("the pipe reads"))
    };
    let output = sweephold(
        &dir,
        &["decode", "data/fly/lat-1.bin", "-o", "rows.pipe", "-q"],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let still_a_pipe = std::fs::symlink_metadata(&pipe)
        .unwrap()
        .file_type()
        .is_fifo();
    if !still_a_pipe {
        drop(std::fs::OpenOptions::new().write(true).open(&keep));
    }
    let rows = reader.join().unwrap();
    assert!(still_a_pipe, "the pipe was replaced by a file");
    assert!(
        rows.starts_with(b"tick,time_s,"),
        "the rows came through the pipe"
    );
    std::fs::remove_dir_all(&dir).ok();
}
