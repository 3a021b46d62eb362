//! `sweephold frf`: telemetry dumps or CSV logs → composite, MISO-conditioned frequency
//! responses (`frf.json`) and, optionally, SVG Bode and cross-control coherence plots.

use std::path::{Path, PathBuf};

use crate::csv_args::CsvArgs;
use crate::output::{
    check_input_file, check_output_folder, refuse_inputs_as_outputs, write_files_into, write_json,
};
use clap::Args;
use sysid::frf::{
    analyse, group_by_primary, FrfAnalysis, FrfOptions, ResponseEstimator, ResponseInputs,
};
use sysid::records::{check_one_origin, load_csv_records, Record};

/// Arguments of `sweephold frf`.
#[derive(Args, Debug)]
#[command(
    after_help = "Records of the same swept axis are joined (each detrended, tapered \
to zero at the joins). The response of output y to control x comes from the records in \
which x is swept (or, see --excited, in which x moves with the swept control), conditioned \
on the other controls excited there. Files ending in .csv \
are read as CSV (columns chosen with --time, --inputs, --outputs, --reference, by header \
name or by position, 1 = first; a file whose first row is all numbers has no header); \
flight logs (PX4 ULog, ArduPilot DataFlash, recognised by their first bytes) with \
--inputs/--outputs as NAME=TOPIC.FIELD (`p=vehicle_angular_velocity.xyz[0]`, `p=RATE.R`; \
`TOPIC[k]` for instance k), resampled onto one time base (see --log-rate, --log-window, \
--log-sweep; ArduPilot fields in degrees become radians; docs/formats.md); \
anything else as a telemetry dump.\n\nCSV rows: --window keeps the rows in a time span; \
a row with an empty or non-finite field is a missing sample. Timestamps within 5 % of a \
step of a uniform grid are used as they are; jittered ones are resampled onto a uniform \
grid by linear interpolation; gaps of up to 5 missing samples are filled the same way; a \
longer gap splits the file into records of the same axis, joined as records are (parts \
under 20 samples left out). Each is said in a note. Units (--units): time in s, ms or us \
(not given: a median step above 0.5 is read as ms, above 500 as us, with a note); \
channels in rad/s, deg/s, rad or deg, converted to rad/s and rad; a body-rate channel \
(p, q, r, gx, gy, gz, or a name holding `rate` or `gyro`) without a unit that peaks above \
15 gets a note that it looks like deg/s.\n\nThe swept input of a CSV file is, in this order: \
--swept; else the value of its --primary-column (as `sweephold decode` writes it), which \
must be the same on every row kept; else the input with the largest RMS about its trend \
line. A dump's Header names its swept axis.\n\nA dump holds one test per Header (a logger's \
file per power-up, or records concatenated): each test is listed on stderr (number, axis, \
input, mode, duration, how it ended) and every completed sweep is used; tests that are not \
sweeps or never started are left out, and so are aborted and partial (cut-off) ones unless \
--include-aborted.\n\nWhich inputs get responses \
(--excited): `swept`, the swept input of each group; `all`, also every other input whose \
RMS is at least 10 % of the group's largest input RMS (all from the same MISO solve, each \
with its partial coherence; the pairs carry `group` and the output's \
`multiple_coherence`); `auto` (default), `all` for CSV files whose swept input nothing \
names (no --swept, no primary column) and `swept` otherwise (dumps, decoded CSV). When two \
groups give the same pair, the one from the group that sweeps its input is kept, else the \
one with the higher mean partial coherence.\n\nExit status: 0 when frf.json was written; 1 on an \
unreadable file, a dump without a sweep, a record too short for the band, a swept input \
without excitation; 2 on an option out of range (checked before any file is read); 130 on \
SIGINT or SIGTERM (ended at once, the temporary file removed, an earlier frf.json untouched)."
)]
pub struct FrfArgs {
    /// Telemetry dumps, CSV files or flight logs (PX4 ULog, ArduPilot DataFlash).
    #[arg(required = true, value_name = "DUMP|CSV|LOG")]
    pub files: Vec<PathBuf>,
    /// Where to write the frequency-response document.
    #[arg(long, value_name = "FILE", default_value = "frf.json")]
    pub out: PathBuf,
    /// Also write SVG plots (one Bode plot per pair, one cross-control coherence plot per
    /// swept axis) into this directory. A plot's name there that is a symbolic link to an
    /// input is refused; any other link is replaced, never written through.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Frequency band [rad/s] of the grid; default: the sweep band of the dump Header
    /// (required for CSV).
    #[arg(long, value_name = "WMIN,WMAX", value_parser = parse_band, allow_hyphen_values = true)]
    pub band: Option<Band>,
    /// Coherence γ² at or above which a frequency is valid, 0–1.
    #[arg(
        long,
        value_name = "G2",
        default_value_t = 0.6,
        allow_hyphen_values = true,
        value_parser = crate::arg_values::unit_interval
    )]
    pub coherence_threshold: f64,
    /// Largest random error ε_r = √(1−γ²)/(|γ|·√(2·n_d)) a valid frequency may have, besides
    /// the coherence threshold; `none`: the coherence alone decides. The
    /// coherence does not see how few independent windows an estimate rests on: at the
    /// bottom of the band only the longest window resolves a frequency, and γ² = 0.65 there
    /// scatters three times as much as from the shorter windows. What it does to a fit is
    /// measured in docs/decisions/2026-11-21-random-error-bound.md.
    #[arg(long, value_name = "E|none", default_value = "0.15", value_parser = parse_max_random_error, allow_hyphen_values = true)]
    pub max_random_error: MaxRandomError,
    /// Number of window lengths (from 20π/ω_max to half the record), 1–20.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 5,
        allow_hyphen_values = true,
        value_parser = crate::arg_values::count::<1, 20>
    )]
    pub windows: usize,
    /// Overlap of consecutive windows, 0–0.95.
    #[arg(
        long,
        value_name = "FRACTION",
        default_value_t = 0.8,
        allow_hyphen_values = true,
        value_parser = crate::arg_values::window_overlap
    )]
    pub overlap: f64,
    /// Number of log-spaced frequencies, 2–100000.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 200,
        allow_hyphen_values = true,
        value_parser = crate::arg_values::count::<2, 100_000>
    )]
    pub points: usize,
    /// How the conditioned responses are estimated.
    #[arg(long, value_enum, default_value_t = EstimatorArg::Cross)]
    pub estimator: EstimatorArg,
    /// Which inputs get responses (see below).
    #[arg(long, value_enum, default_value_t = ExcitedArg::Auto)]
    pub excited: ExcitedArg,
    /// The CSV options.
    #[command(flatten)]
    pub csv: CsvArgs,
    /// Flight-log options.
    #[command(flatten)]
    pub log: crate::logs::LogFrfArgs,
    /// Also analyse the sweeps of dump tests that were aborted or cut off (partial); by
    /// default they are listed and left out.
    #[arg(long)]
    pub include_aborted: bool,
    /// No summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--estimator`: see [`ResponseEstimator`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EstimatorArg {
    /// Cross-spectral H = Guu⁻¹·Guy (CIFER's MISOSA)
    Cross,
    /// The recorded sweep as instrument of the swept control: free of the bias an engaged
    /// hold puts into the cross-spectral estimate by feeding sensor noise into the stick,
    /// but more scattered (see docs/cli.md, frf); dumps, or CSV with --reference
    SweepReference,
}

impl From<EstimatorArg> for ResponseEstimator {
    fn from(arg: EstimatorArg) -> ResponseEstimator {
        match arg {
            EstimatorArg::Cross => ResponseEstimator::CrossSpectral,
            EstimatorArg::SweepReference => ResponseEstimator::SweepReference,
        }
    }
}

/// `--excited`: see [`ResponseInputs`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ExcitedArg {
    /// `all` for CSV files whose swept input nothing names, `swept` otherwise
    Auto,
    /// The swept input of each group only
    Swept,
    /// Every input with RMS ≥ 10 % of the group's largest (cross estimator only)
    All,
}

impl From<ExcitedArg> for ResponseInputs {
    fn from(arg: ExcitedArg) -> ResponseInputs {
        match arg {
            ExcitedArg::Auto => ResponseInputs::Auto,
            ExcitedArg::Swept => ResponseInputs::Swept,
            ExcitedArg::All => ResponseInputs::Excited,
        }
    }
}

/// A frequency band [rad/s] as given on the command line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band(pub [f64; 2]);

fn parse_band(text: &str) -> Result<Band, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [lo, hi] = parts.as_slice() else {
        return Err(format!("`{text}`: expected WMIN,WMAX"));
    };
    let number = |s: &str| {
        s.parse::<f64>()
            .map_err(|_| format!("`{s}` is not a number"))
    };
    let (lo, hi) = (number(lo)?, number(hi)?);
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Err(format!("`{text}`: need 0 < WMIN < WMAX"));
    }
    Ok(Band([lo, hi]))
}

/// `--max-random-error`: a bound, or none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaxRandomError(pub Option<f64>);

fn parse_max_random_error(text: &str) -> Result<MaxRandomError, String> {
    if text.trim() == "none" {
        return Ok(MaxRandomError(None));
    }
    match text.trim().parse::<f64>() {
        Ok(bound) if bound.is_finite() && bound > 0.0 => Ok(MaxRandomError(Some(bound))),
        _ => Err(format!(
            "`{text}`: expected a random error > 0 (e.g. 0.15) or `none`"
        )),
    }
}

impl FrfArgs {
    /// The analysis options these arguments give.
    pub fn options(&self) -> FrfOptions {
        FrfOptions {
            band: self.band.map(|b| b.0),
            points: self.points,
            windows: self.windows,
            overlap: self.overlap,
            coherence_threshold: self.coherence_threshold,
            max_random_error: self.max_random_error.0,
            estimator: self.estimator.into(),
            responses: self.excited.into(),
            ..FrfOptions::default()
        }
    }
}

fn is_csv(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
}

/// Run `sweephold frf`.
pub fn run(args: &FrfArgs) -> anyhow::Result<()> {
    let opts = args.options();
    opts.validate()?;
    let columns = args.csv.columns(args.band.map(|b| b.0))?;
    let inputs: Vec<&Path> = args.files.iter().map(PathBuf::as_path).collect();
    refuse_inputs_as_outputs(&inputs, &[("--out", &args.out)])?;
    if let Some(dir) = &args.plots {
        check_output_folder("--plots", dir)?;
    }
    for path in &inputs {
        check_input_file("input", path)?;
    }
    let mut records: Vec<Record> = Vec::new();
    let mut origins = Vec::new();
    let mut test_lines = Vec::new();
    for path in &args.files {
        if crate::logs::log_format(path).is_some() {
            let (inputs, outputs) = (columns.inputs.clone(), columns.outputs.clone());
            let (swept, band) = (args.csv.swept.clone(), columns.sweep_band);
            records.push(crate::logs::frf_record(
                path, inputs, outputs, swept, band, &args.log,
            )?);
        } else if is_csv(path) {
            records.extend(load_csv_records(path, &columns)?);
        } else {
            let sweeps = crate::dump_tests::sweep_records(path, args.include_aborted)?;
            for (record, origin) in sweeps.records {
                records.push(record);
                origins.push(origin);
            }
            test_lines.extend(sweeps.lines);
        }
    }
    // Before any work: dumps of two vehicles (or flight controllers, or rates) are not
    // one aircraft's responses.
    check_one_origin(&origins)?;
    if !args.quiet {
        for line in &test_lines {
            crate::note!("{line}");
        }
    }
    let groups = group_by_primary(records)?;
    let analysis = analyse(&groups, &opts)?;

    // Plots first: the document is the result, written last and whole.
    let plots = match &args.plots {
        Some(dir) => write_files_into(
            "--plots",
            dir,
            &crate::plot::frf::frf_plots(&analysis)?,
            &inputs,
        )?,
        None => 0,
    };
    write_json(&args.out, &analysis.document)?;
    if !args.quiet {
        crate::note_text!("{}", summary(&analysis, &args.out, plots));
    }
    Ok(())
}

/// The stderr summary: groups, valid ranges, cross-control coherence, notes.
fn summary(analysis: &FrfAnalysis, out: &Path, plots: usize) -> String {
    let mut text = String::new();
    let document = &analysis.document;
    for group in &analysis.groups {
        let windows: Vec<String> = group.windows.iter().map(|w| format!("{w:.1}")).collect();
        let responses = if group.responses.len() > 1 {
            format!(", responses to {}", group.responses.join(", "))
        } else {
            String::new()
        };
        text += &format!(
            "{} sweep: {} record(s), {:.1} s, {:.3}–{:.2} rad/s, windows {} s, conditioned on {}{responses}\n",
            group.axis,
            group.records,
            group.seconds,
            group.band[0],
            group.band[1],
            windows.join(" "),
            group.conditioned_on.join(", ")
        );
    }
    for pair in &document.pairs {
        let range = match pair.valid_range {
            Some([lo, hi]) => format!("{lo:.2}–{hi:.2} rad/s"),
            None => "none".to_string(),
        };
        let from = match &pair.group {
            Some(group) if *group != pair.input => format!(" ({group} records)"),
            _ => String::new(),
        };
        text += &format!(
            "  {:>4} → {:<5} valid (γ² ≥ {}): {range}{from}\n",
            pair.input, pair.output, document.coherence_threshold
        );
    }
    for cc in &document.cross_coherence {
        let verdict = if cc.mean <= 0.5 {
            "ok"
        } else {
            "above the 0.5 guideline"
        };
        text += &format!(
            "  cross-control coherence ({} sweep) {}–{}: {:.2} ({verdict})\n",
            cc.axis, cc.a, cc.b, cc.mean
        );
    }
    for note in &document.notes {
        text += &format!("note: {note}\n");
    }
    text += &format!("wrote {}", out.display());
    if plots > 0 {
        text += &format!(" and {plots} plots");
    }
    text += "\n";
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use sweephold_protocol::{
        encode, Axis, Controls, ExcitationMode, FirmwareVersion, Frame, Header, HoldState,
        InputKind, Measurements, Phase, PulseSettings, Sample, SweepSettings, TestConfig,
        VehicleId, MAX_FRAME_LEN, PROTOCOL_VERSION,
    };

    #[derive(Parser)]
    struct Harness {
        #[command(flatten)]
        args: FrfArgs,
    }

    fn parse(argv: &[&str]) -> FrfArgs {
        Harness::try_parse_from(std::iter::once("frf").chain(argv.iter().copied()))
            .expect("arguments parse")
            .args
    }

    fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("sweephold-frf-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A dump of a lateral sweep (ω 0.5–12 rad/s, 50 Hz, `seconds` long, its last Sample
    /// in the done phase) where the roll rate is a discrete first-order lag of the lateral
    /// command; `sweep` false gives a dump that never leaves the idle phase.
    fn dump(seconds: f64, sweep: bool) -> Vec<u8> {
        dump_with_pedal(seconds, sweep, 0.0)
    }

    /// [`dump`] with the pedal moving as a 0.7 rad/s sine of `pedal` amplitude (not
    /// reaching the roll rate).
    fn dump_with_pedal(seconds: f64, sweep: bool, pedal: f64) -> Vec<u8> {
        let rate = 50u16;
        let header = Header {
            protocol: PROTOCOL_VERSION,
            firmware: FirmwareVersion {
                major: 0,
                minor: 1,
                patch: 0,
            },
            vehicle: VehicleId::Trex700l,
            rate_hz: rate,
            test: TestConfig {
                mode: ExcitationMode::ConditionalAttitudeHold,
                primary: Axis::Lat,
                input: InputKind::Sweep,
                sweep: SweepSettings {
                    t_rec_s: seconds as f32,
                    amplitude: 0.05,
                    omega_min: 0.5,
                    omega_max: 12.0,
                    fade_s: 0.0,
                    start_hold_cycles: 0,
                },
                pulse: PulseSettings {
                    amplitude: 0.05,
                    width_s: 0.5,
                },
                noise_rms: 0.0,
                noise_cutoff_rad_s: 10.0,
                seed: 0,
                hold_engage_rad: 0.105,
                hold_release_rad: 0.07,
                freeze_in_band: false,
                warnings: 0,
            },
            selection: None,
        };
        let mut bytes = Vec::new();
        let mut push = |frame: Frame| {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let n = encode(&frame, &mut buf).unwrap();
            bytes.extend_from_slice(&buf[..n]);
        };
        push(Frame::Header(header));
        let len = (seconds * f64::from(rate)) as usize;
        let (c1, t) = (4.0f64, seconds);
        let c2 = 1.0 / (c1.exp() - 1.0);
        let mut p = 0.0f64;
        for k in 0..len {
            let time = k as f64 / f64::from(rate);
            let theta = 0.5 * time + 11.5 * c2 * ((t / c1) * ((c1 * time / t).exp() - 1.0) - time);
            let lat = if sweep { 0.05 * theta.sin() } else { 0.0 };
            p = 0.9 * p + 0.1 * 2.0 * lat;
            push(Frame::Sample(Sample {
                tick: k as u32,
                // The last Sample in the done phase: the test completed, as the
                // firmware's do (a test cut off in its sweep is left out).
                phase: match (sweep, k + 1 == len) {
                    (false, _) => Phase::Idle,
                    (true, false) => Phase::Sweep,
                    (true, true) => Phase::Done,
                },
                primary: Axis::Lat,
                sweep_omega: 0.0,
                hold: [HoldState::Released; 3],
                command: Controls {
                    lat: lat as f32,
                    ped: (pedal * (0.7 * time).sin()) as f32,
                    ..Controls::default()
                },
                sweep: Controls::default(),
                noise: Controls::default(),
                pilot: Controls::default(),
                meas: Measurements {
                    p: p as f32,
                    ..Measurements::default()
                },
            }));
        }
        bytes
    }

    #[test]
    fn writes_the_document_and_plots() {
        let dir = scratch_dir("ok");
        let dump_path = dir.join("lat.dump");
        std::fs::write(&dump_path, dump(60.0, true)).unwrap();
        let out = dir.join("frf.json");
        let plots = dir.join("plots");
        let args = parse(&[
            dump_path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--plots",
            plots.to_str().unwrap(),
            "--points",
            "60",
            "-q",
        ]);
        run(&args).unwrap();
        let document: sysid::document::FrfDocument =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let pair = document.pair("lat", "p").expect("lat → p");
        assert_eq!(pair.omega.len(), 60);
        assert_eq!(document.max_random_error, Some(0.15));
        // p/lat = 0.2/(1 − 0.9 z⁻¹): 6 dB (gain 2) at low frequency.
        assert!((pair.mag_db[0] - 6.02).abs() < 0.5, "{}", pair.mag_db[0]);
        assert!(plots.join("frf_lat_p.svg").exists());
        let svg = std::fs::read_to_string(plots.join("frf_lat_p.svg")).unwrap();
        assert!(svg.starts_with("<svg") || svg.contains("<svg"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The swept axes of a document's pairs, in order, without repeats.
    fn swept_inputs(out: &Path) -> Vec<String> {
        let document: sysid::document::FrfDocument =
            serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
        let mut inputs: Vec<String> = document.pairs.iter().map(|p| p.input.clone()).collect();
        inputs.dedup();
        inputs
    }

    #[test]
    fn a_decoded_csv_is_analysed_for_the_axis_its_primary_column_names() {
        let dir = scratch_dir("csv-primary");
        // A lateral sweep during which the pedal moves more than the lateral stick.
        let dump_path = dir.join("lat.dump");
        std::fs::write(&dump_path, dump_with_pedal(60.0, true, 0.2)).unwrap();
        let csv = dir.join("lat.csv");
        crate::decode::run(&crate::decode::DecodeArgs {
            dumps: vec![dump_path],
            topic: None,
            format: crate::decode::Format::Csv,
            output: Some(csv.clone()),
            quiet: true,
        })
        .unwrap();
        let out = dir.join("frf.json");
        let frf = |extra: &[&str]| {
            let mut argv = vec![csv.to_str().unwrap(), "--out", out.to_str().unwrap()];
            argv.extend_from_slice(&["--band", "0.5,12", "--points", "40", "-q"]);
            argv.extend_from_slice(extra);
            run(&parse(&argv))
        };
        frf(&[]).unwrap();
        assert_eq!(swept_inputs(&out), ["lat"]);
        // Without its primary column the file would be read as a pedal sweep (and, with
        // nothing naming the swept input, give responses to the lateral stick as well).
        frf(&["--primary-column", "no_such_column"]).unwrap();
        assert_eq!(swept_inputs(&out), ["ped", "lat"]);
        // --swept (and its alias --primary) overrides the column.
        for flag in ["--swept", "--primary"] {
            frf(&[flag, "ped"]).unwrap();
            assert_eq!(swept_inputs(&out), ["ped"], "{flag}");
        }
        let message = format!("{:#}", frf(&["--swept", "roll"]).unwrap_err());
        assert_eq!(
            message,
            "--swept `roll`: not one of the --inputs names (lat, lon, ped, col)"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn one_line_errors() {
        let dir = scratch_dir("err");
        let idle = dir.join("idle.dump");
        std::fs::write(&idle, dump(10.0, false)).unwrap();
        let short = dir.join("short.dump");
        std::fs::write(&short, dump(3.0, true)).unwrap();
        let out = dir.join("frf.json");
        for (file, expected) in [(&idle, "no sweep"), (&short, "too short")] {
            let args = parse(&[file.to_str().unwrap(), "--out", out.to_str().unwrap(), "-q"]);
            let message = format!("{:#}", run(&args).unwrap_err());
            assert!(message.contains(expected), "{message}");
            assert!(!message.contains('\n'), "{message}");
        }
        assert!(!out.exists());
        assert!(parse_band("3,1").is_err() && parse_band("0.5,20").is_ok());
        assert_eq!(parse_max_random_error("none"), Ok(MaxRandomError(None)));
        assert_eq!(
            parse_max_random_error("0.15"),
            Ok(MaxRandomError(Some(0.15)))
        );
        for bad in ["0", "-0.1", "NaN", "inf", "x"] {
            assert!(parse_max_random_error(bad).is_err(), "{bad}");
        }
        assert_eq!(
            parse(&["a.dump"]).max_random_error,
            MaxRandomError(Some(0.15))
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
