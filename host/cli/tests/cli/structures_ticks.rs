//! Malformed inputs as a user meets them: dumps whose ticks step back, structure files with numbers
//! that are not finite or parameters nothing uses, shipped structures by name, and a
//! board image that is not one. Each ends in the right result or a one-line error, never
//! a panic, and no input file is modified.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sweephold_protocol::{codec, synthetic, Frame, Phase};
use sysid::document::FrfDocument;
use sysid::fit::synthetic::{exact_frf_document, SyntheticGrid};
use sysid::fit::PairBand;

use crate::support::Scratch;

struct TempDir(Scratch);

impl TempDir {
    fn new(name: &str) -> Self {
        TempDir(Scratch::new(&format!("issue19-{name}")))
    }
    fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }
}

/// Run the binary in `dir` with `env` set (an empty value removes the variable).
fn sweephold_in(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_sweephold"));
    command.args(args).current_dir(dir);
    for (name, value) in env {
        if value.is_empty() {
            command.env_remove(name);
        } else {
            command.env(name, value);
        }
    }
    command.output().expect("run sweephold")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The contents of `inputs`, to compare after the run.
fn snapshot<P: AsRef<Path>>(inputs: &[P]) -> Vec<Vec<u8>> {
    inputs
        .iter()
        .map(|path| std::fs::read(path).unwrap())
        .collect()
}

fn assert_unchanged<P: AsRef<Path>>(inputs: &[P], before: &[Vec<u8>]) {
    assert_eq!(inputs.len(), before.len());
    for (path, bytes) in inputs.iter().zip(before) {
        let path = path.as_ref();
        assert_eq!(
            &std::fs::read(path).unwrap(),
            bytes,
            "{} was modified",
            path.display()
        );
    }
}

/// Exit status 1, stderr exactly one line `error: …` containing every needle, no panic.
fn assert_one_line_error(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert_eq!(err.lines().count(), 1, "one line: {err:?}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for needle in needles {
        assert!(err.contains(needle), "{err:?} should mention {needle:?}");
    }
}

fn encode(frames: &[Frame]) -> Vec<u8> {
    frames
        .iter()
        .flat_map(|f| codec::encode_to_vec(f).unwrap().to_vec())
        .collect()
}

/// A Header (200 Hz lateral sweep) and one sweep Sample per tick.
fn dump_with_ticks(ticks: impl IntoIterator<Item = u32>) -> Vec<u8> {
    let mut frames = vec![Frame::Header(synthetic::header())];
    frames.extend(ticks.into_iter().map(|tick| {
        let mut sample = synthetic::sample(tick);
        sample.phase = Phase::Sweep;
        Frame::Sample(sample)
    }));
    encode(&frames)
}

/// A model.json of p/lat (first order) for `verify`.
const ROLL_MODEL: &str = r#"{"version":1,"structure":"roll","description":"",
"states":["p"],"controls":["lat"],"outputs":["p"],
"matrices":{"M":{"rows":1,"cols":1,"data":[1.0]},"F":{"rows":1,"cols":1,"data":[-2.0]},
"G":{"rows":1,"cols":1,"data":[1.0]},"H0":{"rows":1,"cols":1,"data":[1.0]},
"H1":{"rows":1,"cols":1,"data":[0.0]}},
"delays":[0.0],"parameters":[],"pairs":[],"average_cost":0.0,"correlation":null,
"starts":[],"minimum_confirmed":true,"reduction":[]}"#;

// ---------------------------------------------------------------------------------------
// 1. Ticks that step back.

#[test]
fn ticks_that_step_back_are_reported_by_decode_and_refused_by_frf_and_verify() {
    let dir = TempDir::new("ticks");
    let back = dir.file("back.bin", &dump_with_ticks([100, 101, 102, 50, 51]));
    let reversed = dir.file("reversed.bin", &dump_with_ticks((0..=1000).rev()));
    let good = dir.file("good.bin", &dump_with_ticks(0..400));
    let model = dir.file("model.json", ROLL_MODEL.as_bytes());
    let inputs = [back.as_path(), reversed.as_path(), good.as_path(), &model];
    let before = snapshot(&inputs);
    let path = |p: &Path| p.display().to_string();

    // decode: counted as steps back, not gaps; the duration counts forward steps only.
    let out = sweephold_in(&dir.0, &["decode", &path(&back)], &[]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("0 tick gaps, 1 tick steps back"), "{err}");
    assert!(err.contains("duration 0.015 s"), "{err}");
    let csv = String::from_utf8(out.stdout).unwrap();
    let times: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|row| row.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(times, [0.0, 0.005, 0.01, 0.01, 0.015]);

    let out = sweephold_in(&dir.0, &["decode", &path(&reversed)], &[]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("0 tick gaps, 1000 tick steps back"), "{err}");
    assert!(err.contains("duration 0.000 s"), "{err}");
    assert!(!err.contains("4294"), "no wrapped count: {err}");

    // frf and verify refuse the record, naming the dump, the sample and the ticks.
    let frf_out = dir.0.join("frf.json");
    let out = sweephold_in(
        &dir.0,
        &["frf", &path(&back), "--out", &path(&frf_out)],
        &[],
    );
    assert_one_line_error(
        &out,
        &[&format!(
            "{}: ticks step back at sample 3 (tick 102 → 50)",
            path(&back)
        )],
    );
    assert!(!frf_out.exists(), "nothing written");
    let out = sweephold_in(
        &dir.0,
        &["frf", &path(&reversed), "--out", &path(&frf_out)],
        &[],
    );
    assert_one_line_error(
        &out,
        &["reversed.bin: ticks step back at sample 1 (tick 1000 → 999)"],
    );

    let verify = |dump: &Path, bias: &str| {
        sweephold_in(
            &dir.0,
            &[
                "verify",
                "--model",
                &path(&model),
                &path(dump),
                "--bias",
                bias,
            ],
            &[],
        )
    };
    let out = verify(&back, "fitted");
    assert_one_line_error(
        &out,
        &["back.bin: ticks step back at sample 3 (tick 102 → 50)"],
    );
    // The same model on a dump whose ticks move forward verifies (with the fitted bias:
    // these dumps have no trim-capture samples to take the trim bias from).
    let out = verify(&good, "fitted");
    assert!(out.status.success(), "{}", stderr(&out));
    let out = verify(&good, "trim");
    assert_one_line_error(
        &out,
        &[
            "good.bin: no trim samples before the excitation",
            "--bias fitted",
        ],
    );

    assert_unchanged(&inputs, &before);
}

// ---------------------------------------------------------------------------------------
// 2. Structure files: numbers that are not finite, parameters nothing uses.

const ROLL_STRUCTURE: &str = r#"name = "roll"
states = ["p"]
controls = ["lat"]
outputs = ["p"]
pairs = [{ output = "p", input = "lat", range = [0.5, 20.0] }]

[parameters]
Lp = -2.0
Llat = { start = 1.0, min = 0.0, max = 10.0 }

[F.p]
p = "Lp"

[G.p]
lat = "Llat"
"#;

fn roll_frf() -> FrfDocument {
    let structure: sysid::fit::ModelStructure = ROLL_STRUCTURE.parse().unwrap();
    let model = structure.model(&[-3.0, 2.0]).unwrap();
    let band = PairBand {
        input: "lat".into(),
        output: "p".into(),
        range: [0.5, 20.0],
    };
    exact_frf_document(&model, &[band], SyntheticGrid::FitPoints(20))
}

#[test]
fn structure_files_with_non_finite_numbers_or_unused_parameters_are_refused() {
    let dir = TempDir::new("structures");
    let frf = dir.file(
        "frf.json",
        serde_json::to_string(&roll_frf()).unwrap().as_bytes(),
    );
    let cases = [
        (
            ROLL_STRUCTURE.replace("Lp = -2.0", "Lp = nan"),
            "nan.toml, line 8: parameter `Lp` = NaN is not a finite number",
        ),
        (
            ROLL_STRUCTURE.replace("Lp = -2.0", "Lp = -inf"),
            "line 8: parameter `Lp` = -inf is not a finite number",
        ),
        (
            ROLL_STRUCTURE.replace("max = 10.0", "max = inf"),
            "line 9: parameter `Llat`: max = inf is not a finite number",
        ),
        (
            ROLL_STRUCTURE.replace("min = 0.0, max = 10.0", "min = 5.0, max = 1.0"),
            "line 9: parameter `Llat`: `min` must be below `max`",
        ),
        (
            ROLL_STRUCTURE.replace("start = 1.0", "start = 20.0"),
            "line 9: parameter `Llat`: the value lies outside [min, max]",
        ),
        (
            ROLL_STRUCTURE.replace("Lp = -2.0", "Lp = -2.0\nFoo = 0.5"),
            "line 9: parameter `Foo` is declared but used in no matrix entry or delay",
        ),
    ];
    for (k, (text, message)) in cases.iter().enumerate() {
        let name = if k == 0 {
            "nan.toml".to_string()
        } else {
            format!("case-{k}.toml")
        };
        let structure = dir.file(&name, text.as_bytes());
        let inputs = [structure.as_path(), frf.as_path()];
        let before = snapshot(&inputs);
        let out = sweephold_in(
            &dir.0,
            &[
                "fit",
                "--frf",
                "frf.json",
                "--model",
                &structure.display().to_string(),
            ],
            &[],
        );
        assert_one_line_error(&out, &[&name, message]);
        assert_unchanged(&inputs, &before);
    }

    // The file as it is fits (the exact data's values).
    let structure = dir.file("roll.toml", ROLL_STRUCTURE.as_bytes());
    let out = sweephold_in(
        &dir.0,
        &[
            "fit",
            "--frf",
            "frf.json",
            "--model",
            "roll.toml",
            "--out",
            "model.json",
        ],
        &[],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let model: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.0.join("model.json")).unwrap()).unwrap();
    let value = |name: &str| {
        model["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap()["value"]
            .as_f64()
            .unwrap()
    };
    assert!((value("Lp") + 3.0).abs() < 1e-6 && (value("Llat") - 2.0).abs() < 1e-6);
    assert_eq!(std::fs::read_to_string(&structure).unwrap(), ROLL_STRUCTURE);
}

// ---------------------------------------------------------------------------------------
// 3. Shipped structures by name.

#[test]
fn fit_model_takes_a_shipped_name_a_file_wins_and_an_unknown_name_lists_them() {
    let dir = TempDir::new("names");
    // The TREX hybrid's exact responses at its start values: a fit of that name is
    // already at its minimum.
    let trex = sweephold::structures::shipped("trex700l-9dof-hybrid", &Default::default())
        .unwrap()
        .unwrap();
    let model = trex.model(&trex.values()).unwrap();
    let band = |output: &str, input: &str| PairBand {
        input: input.to_string(),
        output: output.to_string(),
        range: [0.5, 12.0],
    };
    let mut bands: Vec<PairBand> = trex
        .pairs
        .iter()
        .map(|pair| band(&pair.output, &pair.input))
        .collect();
    // The 6-DOF fitted below also takes ay/col, which the TREX hybrid leaves out.
    assert!(!bands
        .iter()
        .any(|b| (b.output.as_str(), b.input.as_str()) == ("ay", "col")));
    bands.push(band("ay", "col"));
    let frf = dir.file(
        "frf.json",
        serde_json::to_string(&exact_frf_document(
            &model,
            &bands,
            SyntheticGrid::FitPoints(20),
        ))
        .unwrap()
        .as_bytes(),
    );
    let before = snapshot(&[&frf]);

    let out = sweephold_in(
        &dir.0,
        &[
            "fit",
            "--frf",
            "frf.json",
            "--model",
            "trex700l-9dof-hybrid",
            "--max-starts",
            "1",
            "--out",
            "model.json",
        ],
        &[],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let document: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.0.join("model.json")).unwrap()).unwrap();
    assert_eq!(document["structure"], "trex700l-9dof-hybrid");
    // Its servos are known actuators, written into model.json.
    assert_eq!(document["actuators"][0]["natural_frequency_rad_s"], 60.0);
    assert!(
        document["average_cost"].as_f64().unwrap() < 1e-6,
        "{}",
        document["average_cost"]
    );
    // F[b1c, p] = Kpq = hub_height·Lfu and F[b1c, v] = Mfv = Lfu: their ratio is the
    // hub height the name put in, the TREX's.
    let states: Vec<&str> = document["states"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    let n = states.len();
    let at = |row: &str, column: &str| {
        let i = states.iter().position(|s| *s == row).unwrap();
        let j = states.iter().position(|s| *s == column).unwrap();
        document["matrices"]["F"]["data"][i * n + j]
            .as_f64()
            .unwrap()
    };
    let hub_height = -rotorsim::Helicopter::trex700l().main_rotor.hub[2];
    let ratio = at("b1c", "p") / at("b1c", "v");
    assert!((ratio - hub_height).abs() < 1e-9, "{ratio} vs {hub_height}");

    // Another name resolves to its own structure: the 6-DOF's pairs are in the data too,
    // but it has no flapping, so it reports on its own terms (no file needed). From one
    // start on the TREX hybrid's exact responses it lands in a degenerate minimum (M_q of
    // 10⁶) that holding those parameters does not cure: refused naming the structure.
    let out = sweephold_in(
        &dir.0,
        &[
            "fit",
            "--frf",
            "frf.json",
            "--model",
            "bo105-6dof",
            "--max-starts",
            "1",
        ],
        &[],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("of bo105-6dof on frf.json lie orders of magnitude outside"),
        "{}",
        stderr(&out)
    );

    // A file of that name in the current directory wins over the shipped structure.
    let local = dir.file(
        "bo105-6dof",
        ROLL_STRUCTURE
            .replace("name = \"roll\"", "name = \"local-roll\"")
            .as_bytes(),
    );
    let local_before = snapshot(&[&local]);
    let out = sweephold_in(
        &dir.0,
        &["fit", "--frf", "frf.json", "--model", "bo105-6dof"],
        &[],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let report = String::from_utf8(out.stdout).unwrap();
    assert!(
        report.starts_with("structure local-roll (1 states"),
        "{report}"
    );
    assert_unchanged(&[&local], &local_before);

    // An unknown name: one line listing the shipped ones.
    let out = sweephold_in(
        &dir.0,
        &["fit", "--frf", "frf.json", "--model", "bo105-12dof"],
        &[],
    );
    assert_one_line_error(
        &out,
        &[
            "--model bo105-12dof: no such file, and no shipped structure of that name",
            "bo105-6dof, bo105-9dof-hybrid, trex700l-6dof, trex700l-9dof-hybrid",
        ],
    );
    assert_unchanged(&[&frf], &before);

    // --help lists the names and no repository paths.
    let out = sweephold_in(&dir.0, &["fit", "--help"], &[]);
    let help = String::from_utf8(out.stdout).unwrap();
    for name in [
        "bo105-6dof",
        "bo105-9dof-hybrid",
        "trex700l-6dof",
        "trex700l-9dof-hybrid",
    ] {
        assert!(help.contains(name), "help lists {name}");
    }
    assert!(!help.contains("host/sysid/models/"), "{help}");
}

// ---------------------------------------------------------------------------------------
// 4. The board image: found from the binary or $SWEEPHOLD_FC_ELF, and checked to be an
// ARM ELF before QEMU boots it.

#[test]
fn fly_qemu_refuses_an_image_that_is_not_an_arm_elf_in_one_line() {
    let dir = TempDir::new("elf");
    let junk: Vec<u8> = (0..3000u32).map(|k| (k * 7919 % 251) as u8).collect();
    let not_elf = dir.file("not-an-elf.bin", &junk);
    let before = snapshot(&[&not_elf]);
    let fly = |extra: &[&str], env: &[(&str, &str)]| {
        let mut args = vec![
            "fly", "--fc", "qemu", "--axes", "lat", "--t-rec", "5", "--quiet", "--out", "out",
        ];
        args.extend_from_slice(extra);
        let started = std::time::Instant::now();
        let out = sweephold_in(&dir.0, &args, env);
        (out, started.elapsed())
    };
    let not_elf_text = not_elf.display().to_string();
    // The image is checked before QEMU is looked for: the answer is the same on a machine
    // without QEMU.
    let expected = "is not a flight-controller image: not an ELF file";

    // --elf FILE, and $SWEEPHOLD_FC_ELF when --elf is not given.
    for (extra, env) in [
        (vec!["--elf", not_elf_text.as_str()], vec![]),
        (vec![], vec![("SWEEPHOLD_FC_ELF", not_elf_text.as_str())]),
    ] {
        let (out, took) = fly(&extra, &env);
        assert_one_line_error(&out, &[expected]);
        assert!(stderr(&out).contains(&not_elf_text), "{}", stderr(&out));
        assert!(
            took.as_secs() < 10,
            "refused at once, not after a timeout: {took:?}"
        );
    }
    // A variable naming no file says so.
    let (out, _) = fly(&[], &[("SWEEPHOLD_FC_ELF", "/nonexistent/fc.elf")]);
    assert_one_line_error(
        &out,
        &["SWEEPHOLD_FC_ELF=/nonexistent/fc.elf: no such file"],
    );
    assert_unchanged(&[&not_elf], &before);
}
