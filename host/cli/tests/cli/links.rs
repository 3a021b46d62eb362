//! Outputs that are symbolic links to inputs: refused with both paths named, the input's
//! bytes unchanged — for files a verb names inside an output folder (`verify --plots`,
//! `frf --plots`, `report DIR`'s report.html) as for paths on the command line. A link
//! inside an output folder that leads elsewhere is replaced, its target left alone.

use std::os::unix::fs::symlink;
use std::path::Path;
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
    Scratch::new(&format!("links-{name}"))
}

/// A quick campaign in `dir/c`.
fn campaign(dir: &Path) {
    let output = sweephold(dir, &["campaign", "--quick", "--quiet", "--out", "c"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Exit 1, one line naming `output` and `input`; `input`'s bytes as before.
fn assert_refused(dir: &Path, args: &[&str], output: &str, input: &str) {
    let before = std::fs::read(dir.join(input)).unwrap();
    let result = sweephold(dir, args);
    let stderr = String::from_utf8_lossy(&result.stderr).trim().to_string();
    let case = args.join(" ");
    assert_eq!(result.status.code(), Some(1), "{case}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{case}: {stderr}");
    assert!(stderr.starts_with("error: "), "{case}: {stderr}");
    assert!(stderr.contains(output), "{case}: {stderr} names {output}");
    let input_name = Path::new(input).file_name().unwrap().to_str().unwrap();
    assert!(
        stderr.contains(input_name),
        "{case}: {stderr} names {input}"
    );
    assert!(stderr.contains("symbolic link"), "{case}: {stderr}");
    assert_eq!(
        std::fs::read(dir.join(input)).unwrap(),
        before,
        "{case}: {input} changed"
    );
}

#[test]
fn plot_files_linked_to_inputs_are_refused() {
    let dir = scratch("plots");
    campaign(&dir);
    // verify --plots: a plot's name in the folder links to the model, then to the dump.
    std::fs::create_dir_all(dir.join("p")).unwrap();
    let verify = [
        "verify",
        "--model",
        "c/model9.json",
        "c/verify-doublet/lat-1.bin",
        "--plots",
        "p",
    ];
    symlink(dir.join("c/model9.json"), dir.join("p/lat-1-p.svg")).unwrap();
    assert_refused(&dir, &verify, "p/lat-1-p.svg", "c/model9.json");
    std::fs::remove_file(dir.join("p/lat-1-p.svg")).unwrap();
    // A relative link, to the dump.
    symlink("../c/verify-doublet/lat-1.bin", dir.join("p/lat-1-q.svg")).unwrap();
    assert_refused(&dir, &verify, "p/lat-1-q.svg", "c/verify-doublet/lat-1.bin");
    std::fs::remove_file(dir.join("p/lat-1-q.svg")).unwrap();
    // frf --plots: a plot's name links to one of the dumps.
    std::fs::create_dir_all(dir.join("fp")).unwrap();
    symlink(
        dir.join("c/fly-cah/lat-2.bin"),
        dir.join("fp/frf_lat_p.svg"),
    )
    .unwrap();
    assert_refused(
        &dir,
        &[
            "frf",
            "c/fly-cah/lat-1.bin",
            "c/fly-cah/lat-2.bin",
            "--out",
            "f.json",
            "--plots",
            "fp",
            "-q",
        ],
        "fp/frf_lat_p.svg",
        "c/fly-cah/lat-2.bin",
    );
    assert!(
        !dir.join("f.json").exists(),
        "nothing written before the refusal"
    );
    // frf --out on the command line, a link to a dump.
    symlink(dir.join("c/fly-cah/lat-1.bin"), dir.join("out.json")).unwrap();
    assert_refused(
        &dir,
        &[
            "frf",
            "c/fly-cah/lat-1.bin",
            "c/fly-cah/lat-2.bin",
            "--out",
            "out.json",
            "-q",
        ],
        "out.json",
        "c/fly-cah/lat-1.bin",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_report_linked_to_a_campaign_file_is_refused() {
    let dir = scratch("report");
    campaign(&dir);
    for input in ["model9.json", "frf.json", "summary.json"] {
        let report = dir.join("c/report.html");
        std::fs::remove_file(&report).unwrap();
        symlink(dir.join("c").join(input), &report).unwrap();
        assert_refused(
            &dir,
            &["report", "c"],
            "c/report.html",
            &format!("c/{input}"),
        );
        // A relative link too.
        std::fs::remove_file(&report).unwrap();
        symlink(input, &report).unwrap();
        assert_refused(
            &dir,
            &["report", "c"],
            "c/report.html",
            &format!("c/{input}"),
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_link_inside_an_output_folder_is_replaced_not_written_through() {
    let dir = scratch("replace");
    campaign(&dir);
    let elsewhere = dir.join("elsewhere.txt");
    std::fs::write(&elsewhere, b"keep me").unwrap();
    std::fs::remove_file(dir.join("c/report.html")).unwrap();
    symlink(&elsewhere, dir.join("c/report.html")).unwrap();
    let output = sweephold(&dir, &["report", "c"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let meta = std::fs::symlink_metadata(dir.join("c/report.html")).unwrap();
    assert!(meta.is_file(), "the link was replaced by the report");
    assert_eq!(std::fs::read(&elsewhere).unwrap(), b"keep me");
    std::fs::remove_dir_all(&dir).unwrap();
}
