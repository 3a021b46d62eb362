//! `sweephold verify`: simulate an identified model (`model.json`) on the inputs recorded
//! in telemetry dumps or CSV logs and score its prediction of the recorded outputs with Theil's
//! inequality coefficient (the time-domain check of CIFER's VERIFID; method in
//! `sysid::fit::verify`).

use std::fmt::Write as _;
use std::fs;
use std::path::PathBuf;

use crate::csv_args::CsvArgs;
use crate::dump_tests::TestListing;
use crate::output::{check_input_file, check_output_folder, write_files_into};
use anyhow::{anyhow, Context};
use clap::Args;
use sysid::fit::verify::{verify_record_in_segments, BiasMode, Verification, VerifyError};
use sysid::fit::ModelDocument;
use sysid::records::{load_csv_records, Record};

/// Arguments of `sweephold verify`.
#[derive(Args, Debug)]
#[command(
    after_help = "Inputs are the applied commands lat lon ped col, outputs every model output \
the dump records, both as perturbations from trim. With --bias trim (the default) the trim \
of each input and the bias b of each output is its mean over the dump's trim-capture samples \
before the excitation; a dump without them is refused. With --bias fitted b is fitted by \
least squares, b = mean(y - ŷ), and the inputs are taken from their first sample (this also \
removes any constant error of the prediction). TIC = rms(y - b - ŷ) / (rms(y - b) + rms(ŷ)): \
0 perfect, 1 worst; <= 0.25-0.3 is the usual acceptance guideline.\n\nFiles ending in .csv \
are read as frf reads them (--time, --inputs, --outputs, --units, --window; see \
`sweephold frf --help`), with the inputs and outputs named as the model names its controls \
and outputs; a CSV log has no trim-capture samples, so it needs --bias fitted. The reader's \
notes (resampling, gaps, units) are printed under the record's table."
)]
pub struct VerifyArgs {
    /// The identified model (`model.json` as `sweephold fit --out` writes it).
    #[arg(long, value_name = "model.json")]
    pub model: PathBuf,
    /// Telemetry dumps (every test of each) or CSV logs to verify against (ideally
    /// records not used in the fit): any test the firmware flies — doublet, 3-2-1-1 or sweep (`sweephold fly
    /// --input doublet`).
    #[arg(value_name = "DUMP|CSV", required = true)]
    pub dumps: Vec<PathBuf>,
    /// Write one SVG per dump and output (measured vs predicted) into this folder. A plot's
    /// name there that is a symbolic link to the model or a dump is refused; any other link
    /// is replaced, never written through.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Restart the simulation every SECONDS (> 0) from the measured state (states named like
    /// recorded outputs; others at 0). Without it the model runs open loop over the whole
    /// record, which an unstable hover model cannot survive.
    #[arg(long, value_name = "SECONDS", value_parser = crate::arg_values::positive_seconds, allow_hyphen_values = true)]
    pub segment: Option<f64>,
    /// Where each output's bias comes from: its mean over the trim samples before the
    /// excitation (`trim`), or least squares over the record (`fitted`).
    #[arg(long, value_enum, default_value_t = BiasArg::Trim)]
    pub bias: BiasArg,
    /// Also replay the tests that aborted. Every test of a dump (a file per power-up
    /// holds several) is replayed and, when the file holds several or one is left out,
    /// listed on stderr with what became of it; tests cut off by the end of the file are
    /// replayed, aborted ones left out by default.
    #[arg(long)]
    pub include_aborted: bool,
    /// How to read CSV logs.
    #[command(flatten)]
    pub csv: CsvArgs,
}

/// `--bias`: the values of [`BiasMode`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BiasArg {
    /// Each output's mean over the dump's trim-capture samples before the excitation.
    Trim,
    /// Least squares over the record, b = mean(y − ŷ).
    Fitted,
}

impl BiasArg {
    /// The mode `sysid` takes.
    pub fn mode(self) -> BiasMode {
        match self {
            BiasArg::Trim => BiasMode::Trim,
            BiasArg::Fitted => BiasMode::Fitted,
        }
    }
}

/// The report's line saying where the biases come from.
fn bias_line(bias: BiasMode) -> &'static str {
    match bias {
        BiasMode::Trim => {
            "bias: trim (each output's and input's mean over the trim samples before the \
             excitation)"
        }
        BiasMode::Fitted => {
            "bias: fitted (least squares, b = mean(y - ŷ) per output; inputs from their first \
             sample)"
        }
    }
}

/// Run `sweephold verify`: the report on stdout.
pub fn run(args: &VerifyArgs) -> anyhow::Result<()> {
    let report = report(args)?;
    crate::output::print(&report)
}

/// Verify and write the plots; the report's text.
fn report(args: &VerifyArgs) -> anyhow::Result<String> {
    check_input_file("--model", &args.model)?;
    let text = fs::read_to_string(&args.model)
        .with_context(|| format!("cannot read {}", args.model.display()))?;
    let document: ModelDocument = serde_json::from_str(&text)
        .with_context(|| format!("{} is not a model.json", args.model.display()))?;
    let model = document.model().ok_or_else(|| {
        anyhow!(
            "{}: the matrices do not match its states, controls and outputs",
            args.model.display()
        )
    })?;
    // Check every file before simulating anything.
    for dump in &args.dumps {
        check_input_file("dump", dump)?;
    }
    if let Some(dir) = &args.plots {
        check_output_folder("--plots", dir)?;
    }
    let mut report = String::new();
    let _ = writeln!(
        report,
        "model {} ({}), {} states, controls {}, delays {} s",
        document.structure,
        args.model.display(),
        model.states.len(),
        model.controls.join(" "),
        model
            .delays
            .iter()
            .map(|d| format!("{d:.4}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    let bias = args.bias.mode();
    let _ = writeln!(report, "{}", bias_line(bias));
    let mut all_theil = Vec::new();
    let columns = args.csv.columns(None)?;
    let mut records: Vec<(&PathBuf, Record)> = Vec::new();
    let mut columns_read = false;
    let mut test_lines = Vec::new();
    for file in &args.dumps {
        let is_csv = file
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        columns_read |= is_csv;
        if is_csv {
            let read = load_csv_records(file, &columns).map_err(|e| anyhow!("{e}"))?;
            records.extend(read.into_iter().map(|record| (file, record)));
        } else {
            // Every test of the file (a logger's file per power-up holds several), each
            // listed on stderr with what became of it when the file holds several or one
            // was left out (a dump of one test used says nothing, as before).
            // A test cut off by the end of the file is still a record of the inputs
            // and outputs, and is replayed; an aborted one (the pilot took over) only
            // with --include-aborted.
            let tests = crate::dump_tests::excitation_records(file, args.include_aborted, true)?;
            records.extend(tests.used.into_iter().map(|test| (file, test.record)));
            if tests.listing.len() > 1 || tests.listing.iter().any(|t| t.verdict != "used") {
                test_lines.extend(tests.listing.iter().map(TestListing::line));
            }
        }
    }
    for line in &test_lines {
        crate::note!("{line}");
    }
    for (dump, record) in &records {
        let verification =
            verify_record_in_segments(&model, record, args.segment, bias).map_err(|e| {
                // Record errors name the dump already; model errors get it in front.
                let message = e.to_string();
                if let VerifyError::NoTrim { record: source } = &e {
                    anyhow!(
                        "{source}: no trim samples before the excitation to take the output \
                         bias from; --bias fitted fits it instead"
                    )
                } else if message.contains(&record.source) {
                    anyhow!(message)
                } else {
                    anyhow!("{}: {message}", dump.display())
                }
            })?;
        write_verification(&mut report, &verification);
        for note in &record.notes {
            let _ = writeln!(report, "note: {note}");
        }
        all_theil.extend(verification.outputs.iter().map(|o| o.theil));
        if let (Some(dir), None) = (&args.plots, verification.diverged_at_s) {
            let mut inputs = vec![args.model.as_path()];
            inputs.extend(args.dumps.iter().map(PathBuf::as_path));
            let written = write_files_into(
                "--plots",
                dir,
                &crate::plot::verification::verification_plots(&verification)?,
                &inputs,
            )?;
            let _ = writeln!(report, "wrote {written} plots to {}", dir.display());
        }
    }
    if records.len() > 1 && !all_theil.is_empty() {
        // A dump gives one record per test, a CSV log one per part (split at long gaps).
        let what = if records.len() == args.dumps.len() && !columns_read {
            "dumps"
        } else {
            "records"
        };
        let _ = writeln!(
            report,
            "\nmean TIC over {} {what}: {:.4}",
            records.len(),
            all_theil.iter().sum::<f64>() / all_theil.len() as f64
        );
    }
    Ok(report)
}

/// The table of one record: per output TIC, RMS of error, measurement, prediction, bias.
fn write_verification(out: &mut String, verification: &Verification) {
    let _ = writeln!(
        out,
        "\n{}: {} samples at {} Hz ({:.1} s)",
        verification.source,
        verification.samples,
        verification.sample_rate_hz,
        verification.samples as f64 / verification.sample_rate_hz
    );
    if verification.bias == BiasMode::Trim {
        let _ = writeln!(
            out,
            "trim: the first {} samples ({:.2} s), before the excitation",
            verification.trim_samples,
            verification.trim_samples as f64 / verification.sample_rate_hz
        );
    }
    if let Some(at) = verification.diverged_at_s {
        let _ = writeln!(
            out,
            "the model diverged (overflow) at t = {at:.2} s: an unstable mode ran away; \
             every output scores TIC 1 (try --segment)"
        );
        return;
    }
    let _ = writeln!(
        out,
        "{:<8} {:>8} {:>12} {:>12} {:>12} {:>12}",
        "output", "TIC", "rms error", "rms meas.", "rms pred.", "bias"
    );
    // A prediction that ran away without overflowing the state still overflows the sums.
    let cell = |value: f64| {
        if value.is_finite() && value.abs() < 1e9 {
            format!("{value:.5}")
        } else {
            "-".to_string()
        }
    };
    for score in &verification.outputs {
        let _ = writeln!(
            out,
            "{:<8} {:>8.4} {:>12} {:>12} {:>12} {:>12}",
            score.output,
            score.theil,
            cell(score.rms_error),
            cell(score.rms_measured),
            cell(score.rms_predicted),
            cell(score.bias)
        );
    }
    let _ = writeln!(out, "{:<8} {:>8.4}", "mean", verification.theil_mean);
    if !verification.not_measured.is_empty() {
        let _ = writeln!(
            out,
            "not measured (not scored, not in the mean): {}",
            verification.not_measured.join(" ")
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(model: PathBuf, dumps: Vec<PathBuf>) -> VerifyArgs {
        VerifyArgs {
            model,
            dumps,
            plots: None,
            segment: None,
            bias: BiasArg::Trim,
            include_aborted: false,
            csv: CsvArgs::default(),
        }
    }

    #[test]
    fn error_paths_are_one_line_messages() {
        let directory =
            std::env::temp_dir().join(format!("sweephold-verify-{}", std::process::id()));
        fs::create_dir_all(&directory).unwrap();
        let missing = directory.join("missing.json");
        let error = run(&args(missing, vec![directory.join("x.bin")])).unwrap_err();
        assert!(format!("{error:#}").contains("cannot read"), "{error:#}");

        let not_json = directory.join("bad.json");
        fs::write(&not_json, "{").unwrap();
        let error = run(&args(not_json, vec![directory.join("x.bin")])).unwrap_err();
        assert!(
            format!("{error:#}").contains("not a model.json"),
            "{error:#}"
        );

        // A model document whose matrices do not fit its names.
        let mut document = serde_json::json!({
            "version": 1, "structure": "lag", "description": "",
            "states": ["p"], "controls": ["lat"], "outputs": ["p"],
            "matrices": {
                "M": {"rows": 1, "cols": 1, "data": [1.0]},
                "F": {"rows": 1, "cols": 1, "data": [-2.0]},
                "G": {"rows": 1, "cols": 1, "data": [3.0]},
                "H0": {"rows": 1, "cols": 1, "data": [1.0]},
                "H1": {"rows": 1, "cols": 1, "data": [0.0]}
            },
            "delays": [0.0], "parameters": [], "pairs": [], "average_cost": 0.0,
            "correlation": null, "starts": [], "minimum_confirmed": true, "reduction": []
        });
        let good = directory.join("model.json");
        fs::write(&good, document.to_string()).unwrap();
        document["matrices"]["F"]["rows"] = serde_json::json!(2);
        let mismatched = directory.join("mismatched.json");
        fs::write(&mismatched, document.to_string()).unwrap();
        let error = run(&args(mismatched, vec![directory.join("x.bin")])).unwrap_err();
        assert!(format!("{error:#}").contains("do not match"), "{error:#}");

        // A missing dump is refused before anything is simulated.
        let error = run(&args(good.clone(), vec![directory.join("x.bin")])).unwrap_err();
        assert!(format!("{error:#}").contains("no such file"), "{error:#}");

        // A synthetic dump (smooth made-up telemetry): the model runs on it and its
        // mismatches are named.
        use sweephold_protocol::{codec, synthetic, Frame};
        let dump = directory.join("lat-1.bin");
        let mut bytes = codec::encode_to_vec(&Frame::Header(synthetic::header()))
            .unwrap()
            .to_vec();
        for tick in 0..2000 {
            bytes.extend(
                codec::encode_to_vec(&Frame::Sample(synthetic::sample(tick)))
                    .unwrap()
                    .to_vec(),
            );
        }
        fs::write(&dump, bytes).unwrap();
        // Every Sample of it is in the Sweep phase: no trim to take the bias from.
        let error = run(&args(good.clone(), vec![dump.clone()])).unwrap_err();
        let message = format!("{error:#}");
        assert!(
            message.contains("lat-1.bin: no trim samples") && message.contains("--bias fitted"),
            "{message}"
        );
        assert!(!message.contains('\n'), "{message}");
        let fitted = |model: &PathBuf| VerifyArgs {
            bias: BiasArg::Fitted,
            ..args(model.clone(), vec![dump.clone()])
        };
        run(&fitted(&good)).unwrap();
        let plots = directory.join("plots");
        let with_plots = VerifyArgs {
            plots: Some(plots.clone()),
            segment: Some(2.0),
            ..fitted(&good)
        };
        run(&with_plots).unwrap();
        assert!(plots.join("lat-1-p.svg").is_file());
        document["matrices"]["F"]["rows"] = serde_json::json!(1);
        document["controls"] = serde_json::json!(["cyc"]);
        let other_control = directory.join("cyc.json");
        fs::write(&other_control, document.to_string()).unwrap();
        let error = run(&args(other_control, vec![dump.clone()])).unwrap_err();
        let message = format!("{error:#}");
        assert!(
            message.contains("`cyc`") && message.contains("lat-1.bin"),
            "{message}"
        );
        assert!(!message.contains('\n'), "{message}");
        document["controls"] = serde_json::json!(["lat"]);
        document["outputs"] = serde_json::json!(["roll_rate"]);
        let other_output = directory.join("roll_rate.json");
        fs::write(&other_output, document.to_string()).unwrap();
        let error = run(&args(other_output, vec![dump])).unwrap_err();
        assert!(format!("{error:#}").contains("roll_rate"), "{error:#}");

        // A file that is not a dump.
        let garbage = directory.join("garbage.bin");
        fs::write(&garbage, [1u8, 2, 3, 0, 7, 7, 0]).unwrap();
        let error = run(&args(good, vec![garbage])).unwrap_err();
        let message = format!("{error:#}");
        assert!(message.contains("garbage.bin"), "{message}");
        assert!(!message.contains('\n'), "{message}");
        fs::remove_dir_all(&directory).ok();
    }

    /// A model (a lag from `lat` to `p`, seen in `p` and `q`) and a dump of synthetic
    /// telemetry whose first 200 Samples (1 s) are trim capture and the next 1200 the
    /// excitation, in `directory`.
    fn trimmed_files(directory: &std::path::Path) -> (PathBuf, PathBuf) {
        use sweephold_protocol::{codec, synthetic, Frame, Phase};
        fs::create_dir_all(directory).unwrap();
        let model = directory.join("model.json");
        let document = serde_json::json!({
            "version": 1, "structure": "lag", "description": "",
            "states": ["p"], "controls": ["lat"], "outputs": ["p", "q"],
            "matrices": {
                "M": {"rows": 1, "cols": 1, "data": [1.0]},
                "F": {"rows": 1, "cols": 1, "data": [-2.0]},
                "G": {"rows": 1, "cols": 1, "data": [3.0]},
                "H0": {"rows": 2, "cols": 1, "data": [1.0, 0.5]},
                "H1": {"rows": 2, "cols": 1, "data": [0.0, 0.0]}
            },
            "delays": [0.013], "parameters": [], "pairs": [], "average_cost": 0.0,
            "correlation": null, "starts": [], "minimum_confirmed": true, "reduction": []
        });
        fs::write(&model, document.to_string()).unwrap();
        let dump = directory.join("lat-1.bin");
        let mut bytes = codec::encode_to_vec(&Frame::Header(synthetic::header()))
            .unwrap()
            .to_vec();
        for tick in 0..1400 {
            let mut sample = synthetic::sample(tick);
            if tick < 200 {
                sample.phase = Phase::TrimCapture;
            }
            bytes.extend(
                codec::encode_to_vec(&Frame::Sample(sample))
                    .unwrap()
                    .to_vec(),
            );
        }
        fs::write(&dump, bytes).unwrap();
        (model, dump)
    }

    /// `sweephold verify --model DIR/model.json DIR/lat-1.bin` on [`trimmed_files`] as the
    /// code printed it before `--bias` existed (the fitted bias), `DIR` for the folder.
    const FITTED_BEFORE: &str = "\
model lag (DIR/model.json), 1 states, controls lat, delays 0.0130 s

DIR/lat-1.bin: 1400 samples at 200 Hz (7.0 s)
output        TIC    rms error    rms meas.    rms pred.         bias
p          0.7191      0.08355      0.07061      0.04556      0.00761
q          0.7189      0.04168      0.03519      0.02278      0.00145
mean       0.7190
";

    /// The same with `--segment 0.5` and the dump given twice.
    const FITTED_SEGMENTED_BEFORE: &str = "\
model lag (DIR/model.json), 1 states, controls lat, delays 0.0130 s

DIR/lat-1.bin: 1400 samples at 200 Hz (7.0 s)
output        TIC    rms error    rms meas.    rms pred.         bias
p          0.3836      0.05505      0.07939      0.06413      0.04532
q          0.3440      0.02465      0.03959      0.03207      0.02030
mean       0.3638

DIR/lat-1.bin: 1400 samples at 200 Hz (7.0 s)
output        TIC    rms error    rms meas.    rms pred.         bias
p          0.3836      0.05505      0.07939      0.06413      0.04532
q          0.3440      0.02465      0.03959      0.03207      0.02030
mean       0.3638

mean TIC over 2 dumps: 0.3638
";

    #[test]
    fn the_fitted_bias_prints_what_verify_printed_before_and_trim_is_the_default() {
        let directory =
            std::env::temp_dir().join(format!("sweephold-verify-bias-{}", std::process::id()));
        let (model, dump) = trimmed_files(&directory);
        let text = |bias: BiasArg, segment: Option<f64>, copies: usize| {
            report(&VerifyArgs {
                bias,
                segment,
                ..args(model.clone(), vec![dump.clone(); copies])
            })
            .unwrap()
            .replace(directory.to_str().unwrap(), "DIR")
        };
        // The fitted bias: the report of before, with the bias named in its second line.
        for (segment, copies, before) in [
            (None, 1, FITTED_BEFORE),
            (Some(0.5), 2, FITTED_SEGMENTED_BEFORE),
        ] {
            let fitted = text(BiasArg::Fitted, segment, copies);
            let mut lines: Vec<&str> = fitted.lines().collect();
            assert_eq!(lines.remove(1), bias_line(BiasMode::Fitted));
            assert_eq!(lines.join("\n") + "\n", before);
        }
        // The default: the trim bias, named, with the trim samples it averaged.
        #[derive(clap::Parser)]
        struct Command {
            #[command(flatten)]
            verify: VerifyArgs,
        }
        let parsed = <Command as clap::Parser>::try_parse_from(["verify", "--model", "m", "d"]);
        assert_eq!(parsed.unwrap().verify.bias, BiasArg::Trim);
        let parsed = <Command as clap::Parser>::try_parse_from([
            "verify", "--bias", "fitted", "--model", "m", "d",
        ]);
        assert_eq!(parsed.unwrap().verify.bias, BiasArg::Fitted);
        let trim = text(BiasArg::Trim, None, 1);
        assert_eq!(trim.lines().nth(1), Some(bias_line(BiasMode::Trim)));
        assert!(
            trim.contains("trim: the first 200 samples (1.00 s), before the excitation"),
            "{trim}"
        );
        assert!(!trim.contains("p          0.7191"), "{trim}");
        fs::remove_dir_all(&directory).ok();
    }

    /// The score table of a report: (output, TIC, rms error, rms meas., rms pred., bias).
    fn table(report: &str) -> Vec<(String, Vec<f64>)> {
        report
            .lines()
            .skip_while(|l| !l.starts_with("output"))
            .skip(1)
            .take_while(|l| !l.starts_with("mean"))
            .map(|l| {
                let mut cells = l.split_whitespace();
                let name = cells.next().unwrap().to_string();
                (name, cells.map(|c| c.parse().unwrap()).collect())
            })
            .collect()
    }

    /// A dump decoded to CSV verifies as the dump does (fitted bias: a CSV log has no
    /// trim samples), and the CSV with the default trim bias is refused with the remedy.
    #[test]
    fn a_decoded_csv_verifies_as_its_dump() {
        use sweephold_protocol::{codec, synthetic, Frame};
        let directory =
            std::env::temp_dir().join(format!("sweephold-verify-csv-{}", std::process::id()));
        let (model, _) = trimmed_files(&directory);
        let dump = directory.join("sweep.bin");
        let mut bytes = codec::encode_to_vec(&Frame::Header(synthetic::header()))
            .unwrap()
            .to_vec();
        for tick in 0..2000 {
            bytes.extend(
                codec::encode_to_vec(&Frame::Sample(synthetic::sample(tick)))
                    .unwrap()
                    .to_vec(),
            );
        }
        fs::write(&dump, bytes).unwrap();
        let csv = directory.join("sweep.csv");
        crate::decode::run(&crate::decode::DecodeArgs {
            dumps: vec![dump.clone()],
            format: crate::decode::Format::Csv,
            output: Some(csv.clone()),
            quiet: true,
            topic: None,
        })
        .unwrap();
        let fitted = |file: &PathBuf| {
            report(&VerifyArgs {
                bias: BiasArg::Fitted,
                segment: Some(2.0),
                ..args(model.clone(), vec![file.clone()])
            })
            .unwrap()
        };
        let (from_dump, from_csv) = (fitted(&dump), fitted(&csv));
        assert!(
            from_csv.contains("sweep.csv: 2000 samples at 200"),
            "{from_csv}"
        );
        let (a, b) = (table(&from_dump), table(&from_csv));
        assert_eq!(a.len(), 2, "{from_dump}");
        for ((name_a, a), (name_b, b)) in a.iter().zip(&b) {
            assert_eq!(name_a, name_b);
            for (x, y) in a.iter().zip(b) {
                // Decode prints the dump's f32 values in their shortest form.
                assert!((x - y).abs() <= 1e-5, "{name_a}: {x} vs {y}");
            }
        }
        let error = report(&args(model.clone(), vec![csv.clone()])).unwrap_err();
        let message = format!("{error:#}");
        assert!(
            message.contains("sweep.csv: no trim samples") && message.contains("--bias fitted"),
            "{message}"
        );
        fs::remove_dir_all(&directory).ok();
    }
}
