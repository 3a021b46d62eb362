//! A battery of generated bad or unusual inputs across the verbs that read files
//! (`decode`, `frf`, `verify`, `fit`, `report`): damaged, cut, repeated and random
//! telemetry dumps, JSON documents with each key removed or of the wrong type, cut JSON,
//! damaged CSV and trim-point files, paths that are folders, missing or devices.
//!
//! A bad input may be refused or, if it is still readable (a dump with a few damaged
//! frames, an optional key removed), used; what every case must show is the README's
//! promise: no panic and no death by a signal, a refusal as one line `error: …` with exit
//! status 1 or 2, an end within 60 s, and no input file changed (checked over the whole
//! battery). The count of cases and of exit statuses is printed (`--nocapture`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::support::Scratch;

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("battery-{name}"))
}

/// The bytes of every file below `dir`, by path.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                files.push((path.clone(), std::fs::read(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}

/// A small deterministic generator (xorshift64*) for the random bytes and positions.
struct Bytes(u64);

impl Bytes {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn fill(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next() as u8).collect()
    }
}

/// One case: its name and its command line (run in the battery's folder).
struct Case {
    name: String,
    args: Vec<String>,
}

fn case(name: impl Into<String>, args: &[&str]) -> Case {
    Case {
        name: name.into(),
        args: args.iter().map(|a| a.to_string()).collect(),
    }
}

/// Damaged copies of the dump `dump` written into `folder`; their paths (relative to the
/// battery folder) with what was done.
fn damaged_dumps(root: &Path, folder: &str, dump: &[u8]) -> Vec<(String, String)> {
    let mut rng = Bytes(0x5EED_0042);
    let mut made: Vec<(String, Vec<u8>)> = vec![
        ("empty".into(), Vec::new()),
        ("one byte".into(), vec![0xA5]),
        ("seven bytes".into(), dump[..7].to_vec()),
        ("the first 200 bytes".into(), dump[..200].to_vec()),
        ("random 10 bytes".into(), rng.fill(10)),
        ("random 1000 bytes".into(), rng.fill(1000)),
        ("random 100000 bytes".into(), rng.fill(100_000)),
        ("all zeros".into(), vec![0; 50_000]),
        ("all 0xFF".into(), vec![0xFF; 50_000]),
        ("twice over".into(), [dump, dump].concat()),
        ("reversed".into(), dump.iter().rev().copied().collect()),
        ("text".into(), b"tick,time_s\n1,0.0\n".to_vec()),
    ];
    for per_mille in [1, 10, 50, 100, 250, 500, 750, 990, 999] {
        let cut = dump.len() * per_mille / 1000;
        made.push((format!("cut at {per_mille}/1000"), dump[..cut].to_vec()));
        made.push((format!("from {per_mille}/1000 on"), dump[cut..].to_vec()));
    }
    for flips in [1, 10, 100, 1000, 10_000] {
        let mut bytes = dump.to_vec();
        for _ in 0..flips {
            let at = (rng.next() as usize) % bytes.len();
            bytes[at] ^= 1 << (rng.next() % 8);
        }
        made.push((format!("{flips} bits flipped"), bytes));
    }
    for (at, len) in [(0, 64), (1000, 5000), (dump.len() / 2, 20_000)] {
        let mut bytes = dump.to_vec();
        bytes.drain(at..(at + len).min(dump.len()));
        made.push((format!("{len} bytes cut out at {at}"), bytes));
    }
    std::fs::create_dir_all(root.join(folder)).unwrap();
    made.into_iter()
        .enumerate()
        .map(|(i, (what, bytes))| {
            let path = format!("{folder}/d{i}.bin");
            std::fs::write(root.join(&path), bytes).unwrap();
            (path, what)
        })
        .collect()
}

/// Variants of the JSON document `text`: each top-level key removed, set to null, to a
/// string, to a huge number and to an empty array; the text cut; not JSON at all.
fn damaged_json(root: &Path, folder: &str, text: &str) -> Vec<(String, String)> {
    let value: Value = serde_json::from_str(text).unwrap();
    let mut made: Vec<(String, String)> = Vec::new();
    for key in value.as_object().unwrap().keys() {
        let mut without = value.clone();
        without.as_object_mut().unwrap().remove(key);
        made.push((format!("without `{key}`"), without.to_string()));
        for (kind, replacement) in [
            ("null", Value::Null),
            ("a string", Value::from("x")),
            ("1e308", Value::from(1e308)),
            ("[]", Value::Array(Vec::new())),
        ] {
            let mut changed = value.clone();
            changed[key.as_str()] = replacement;
            made.push((format!("`{key}` = {kind}"), changed.to_string()));
        }
    }
    for per_mille in [0, 1, 100, 500, 999] {
        let cut = text.len() * per_mille / 1000;
        let cut = (0..=cut).rev().find(|&c| text.is_char_boundary(c)).unwrap();
        made.push((format!("cut at {per_mille}/1000"), text[..cut].to_string()));
    }
    made.push(("not JSON".into(), "model = 1\n".into()));
    made.push(("a JSON array".into(), "[1, 2, 3]".into()));
    made.push(("a JSON number".into(), "42".into()));
    std::fs::create_dir_all(root.join(folder)).unwrap();
    made.into_iter()
        .enumerate()
        .map(|(i, (what, text))| {
            let path = format!("{folder}/j{i}.json");
            std::fs::write(root.join(&path), text).unwrap();
            (path, what)
        })
        .collect()
}

/// Damaged CSV files (for `frf` and `fit --trim-points`), from the text `csv`.
fn damaged_csv(root: &Path, folder: &str, csv: &str) -> Vec<(String, String)> {
    let lines: Vec<&str> = csv.lines().collect();
    let header = lines[0];
    let columns = header.split(',').count();
    let row = |cell: &str| vec![cell; columns].join(",");
    let mut made: Vec<(String, String)> = vec![
        ("empty".into(), String::new()),
        ("header only".into(), format!("{header}\n")),
        ("one row".into(), format!("{header}\n{}\n", lines[1])),
        ("no header".into(), lines[1..].join("\n")),
        (
            "a row of NaN".into(),
            format!("{header}\n{}\n{}\n", lines[1], row("NaN")),
        ),
        (
            "a row of inf".into(),
            format!("{header}\n{}\n{}\n", lines[1], row("inf")),
        ),
        (
            "a row of text".into(),
            format!("{header}\n{}\n{}\n", lines[1], row("x")),
        ),
        (
            "a row of 1e308".into(),
            format!("{header}\n{}\n{}\n", lines[1], row("1e308")),
        ),
        (
            "a short row".into(),
            format!("{header}\n{}\n1,2\n", lines[1]),
        ),
        ("a long row".into(), format!("{header}\n{},9,9\n", lines[1])),
        ("semicolons".into(), csv.replace(',', ";")),
        ("a duplicated header".into(), format!("{header}\n{csv}")),
        ("CRLF".into(), csv.replace('\n', "\r\n")),
        ("a BOM".into(), format!("\u{feff}{csv}")),
        (
            "binary".into(),
            String::from_utf8_lossy(&[0, 159, 146, 150, 10]).into(),
        ),
        (
            "the rows twice".into(),
            format!("{csv}{}\n", lines[1..].join("\n")),
        ),
        (
            "columns renamed".into(),
            csv.replacen(header, &header.to_uppercase(), 1),
        ),
        (
            "the first column dropped".into(),
            lines
                .iter()
                .map(|l| l.split_once(',').map_or("", |s| s.1))
                .collect::<Vec<_>>()
                .join("\n"),
        ),
    ];
    made.push((
        "every row the same".into(),
        format!(
            "{header}\n{}\n",
            vec![lines[1]; lines.len().max(3)].join("\n")
        ),
    ));
    std::fs::create_dir_all(root.join(folder)).unwrap();
    made.into_iter()
        .enumerate()
        .map(|(i, (what, text))| {
            let path = format!("{folder}/c{i}.csv");
            std::fs::write(root.join(&path), text).unwrap();
            (path, what)
        })
        .collect()
}

#[test]
fn generated_bad_inputs_end_in_one_line_and_change_no_input() {
    let root = scratch("all");
    let campaign = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(&root)
        .args(["campaign", "--quick", "--quiet", "--out", "c"])
        .output()
        .unwrap();
    assert!(campaign.status.success());
    std::fs::create_dir_all(root.join("in")).unwrap();
    let decoded = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(&root)
        .args(["decode", "-q", "c/fly-cah/lat-1.bin", "-o", "in/lat-1.csv"])
        .output()
        .unwrap();
    assert!(decoded.status.success());
    std::fs::create_dir_all(root.join("out")).unwrap();
    std::fs::create_dir_all(root.join("in/a-folder")).unwrap();

    let dump = std::fs::read(root.join("c/fly-cah/lat-1.bin")).unwrap();
    let doublet = std::fs::read(root.join("c/verify-doublet/lat-1.bin")).unwrap();
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
    let mut cases = Vec::new();

    // Telemetry dumps.
    let mut dumps = damaged_dumps(&root, "in/dumps", &dump);
    dumps.extend([
        ("in/a-folder".to_string(), "a folder".to_string()),
        ("in/missing.bin".to_string(), "a missing file".to_string()),
        ("/dev/null".to_string(), "/dev/null".to_string()),
    ]);
    for (path, what) in &dumps {
        let p = path.as_str();
        cases.push(case(
            format!("decode: {what}"),
            &["decode", "-q", p, "-o", "out/x.csv"],
        ));
        cases.push(case(
            format!("decode jsonl: {what}"),
            &["decode", "-q", "--format", "jsonl", p, "-o", "out/x.jsonl"],
        ));
        cases.push(case(
            format!("frf: {what}"),
            &["frf", "-q", p, "--out", "out/f.json"],
        ));
        cases.push(case(
            format!("frf with a good dump: {what}"),
            &["frf", "-q", "c/fly-cah/lat-2.bin", p, "--out", "out/f.json"],
        ));
        cases.push(case(
            format!("verify: {what}"),
            &["verify", "--model", "c/model9.json", p],
        ));
    }
    for (path, what) in damaged_dumps(&root, "in/doublets", &doublet) {
        cases.push(case(
            format!("verify, doublet: {what}"),
            &[
                "verify",
                "--model",
                "c/model9.json",
                &path,
                "--segment",
                "2",
            ],
        ));
    }
    // Models for verify.
    for (path, what) in damaged_json(&root, "in/models", &read("c/model9.json")) {
        cases.push(case(
            format!("verify --model: {what}"),
            &["verify", "--model", &path, "c/verify-doublet/lat-1.bin"],
        ));
    }
    // Frequency responses for fit (bounded: one start, few points).
    for (path, what) in damaged_json(&root, "in/frfs", &read("c/frf.json")) {
        cases.push(case(
            format!("fit --frf: {what}"),
            &[
                "fit",
                "--frf",
                &path,
                "--model",
                "bo105-6dof",
                "--max-starts",
                "1",
                "--points",
                "8",
            ],
        ));
    }
    // Campaign documents for report: each damaged in a copy of the campaign folder.
    for (document, tag) in [("summary.json", "s"), ("model9.json", "m")] {
        let variants = damaged_json(&root, &format!("in/{tag}"), &read(&format!("c/{document}")));
        for (i, (path, what)) in variants.into_iter().enumerate() {
            let folder = format!("out/report-{tag}{i}");
            copy_folder(&root.join("c"), &root.join(&folder));
            std::fs::copy(root.join(&path), root.join(&folder).join(document)).unwrap();
            cases.push(case(
                format!("report, {document}: {what}"),
                &["report", &folder],
            ));
        }
    }
    // CSV for frf, trim points for fit.
    for (path, what) in damaged_csv(&root, "in/csv", &read("in/lat-1.csv")) {
        cases.push(case(
            format!("frf CSV: {what}"),
            &[
                "frf",
                "-q",
                &path,
                "--band",
                "0.5,20",
                "--out",
                "out/f.json",
            ],
        ));
    }
    for (path, what) in damaged_csv(&root, "in/trim", &read("c/trim-points.csv")) {
        cases.push(case(
            format!("fit --trim-points: {what}"),
            &[
                "fit",
                "--frf",
                "c/frf.json",
                "--model",
                "bo105-6dof",
                "--trim-points",
                &path,
                "--max-starts",
                "1",
                "--points",
                "8",
            ],
        ));
    }

    let inputs = [snapshot(&root.join("c")), snapshot(&root.join("in"))];
    let mut statuses: BTreeMap<i32, usize> = BTreeMap::new();
    let mut by_kind: BTreeMap<(&str, i32), usize> = BTreeMap::new();
    let mut failures = Vec::new();
    for case in &cases {
        match run(&root, case) {
            Ok(code) => {
                *statuses.entry(code).or_default() += 1;
                let kind = case.name.split(':').next().unwrap_or_default();
                *by_kind.entry((kind, code)).or_default() += 1;
            }
            Err(why) => failures.push(format!("{}: {why}", case.name)),
        }
    }
    for ((kind, code), n) in &by_kind {
        println!("{kind:>32}  exit {code}: {n}");
    }
    assert_eq!(
        [snapshot(&root.join("c")), snapshot(&root.join("in"))],
        inputs,
        "an input changed"
    );
    println!("{} cases, exit statuses {statuses:?}", cases.len());
    assert!(
        failures.is_empty(),
        "{} failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(cases.len() >= 300, "{} cases", cases.len());
    std::fs::remove_dir_all(&root).unwrap();
}

/// Run one case; its exit status, or what broke the promise.
fn run(root: &Path, case: &Case) -> Result<i32, String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweephold"))
        .current_dir(root)
        .args(&case.args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    let stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::Read::read_to_string(&mut { stderr }, &mut text);
        text
    });
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            break status;
        }
        if started.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            return Err("still running after 60 s".into());
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr = reader.join().unwrap();
    let stderr = stderr.trim();
    let code = status
        .code()
        .ok_or_else(|| format!("killed by a signal: {stderr}"))?;
    if stderr.contains("panicked") || code == 101 {
        return Err(format!("panic: {stderr}"));
    }
    match code {
        0 => Ok(0),
        1 | 2 if stderr.lines().count() == 1 && stderr.starts_with("error: ") => Ok(code),
        _ => Err(format!("exit {code}, stderr not one error line: {stderr}")),
    }
}

fn copy_folder(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_folder(&path, &target);
        } else {
            std::fs::copy(&path, &target).unwrap();
        }
    }
}
