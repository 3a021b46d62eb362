//! `sweephold identify`: from a flight's logs to a model, with no simulator — every test
//! of every telemetry dump (split at its Headers, as `frf` and `verify` read them), the
//! frequency responses of the sweeps, the 6-DOF then the 9-DOF hybrid fit of the aircraft
//! file's structure reduced to the outputs the logs hold, with the file's a-priori
//! constants and trim balance, the verification on the held-out tests (doublets,
//! 3-2-1-1), the loop margins of the model with the logs' loop tests measured beside them,
//! `summary.json`, and last `report.html` drawn from the folder's files (the report's page
//! of an identify folder: no truth in it).
//!
//! The stages are the campaign's own ([`stages`]: `campaign` runs them on what it flew):
//! one pipeline. Where the campaign asks the simulator — its steady flights for the trim
//! points — identify takes a file (`--trim-points`), the steady flights of a log with a
//! GNSS file ([`flight_trim`]), or, without either, fits the hybrid's `trim_derived`
//! parameters like the others and flags it in `summary.json` and the report. Nothing in
//! this folder imports the simulator (`rotorsim`) or its truth (`truth`); CI checks it
//! (`cargo xtask import-cycles`).

pub mod flight_trim;
pub mod stages;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Context};
use clap::Args;
use sweephold_protocol::{Axis, Decoder, Event, Frame};
use sysid::fit::trim::TrimPoints;
use sysid::frf::Record;
use sysid::records::check_one_origin;

use crate::artifacts::files;
use crate::artifacts::identify_summary::{stage, IdentifySummary};
use crate::artifacts::summary::StageFailure;
use crate::dump_tests::{identify_records, UsedTest};
use crate::fit::TrimBalanceArg;
use crate::output::{check_input_file, refuse_inputs_as_outputs, write_json, StagedFolder};
use crate::structures::TrimAttitude;
use crate::vehicle::Vehicle;
use stages::Pipeline;

/// Arguments of `sweephold identify`.
#[derive(Args, Debug, Clone)]
#[command(
    after_help = "Reads telemetry dumps (a logger's file per power-up holds several tests; \
each test is listed on stderr and in summary.json with what became of it). A folder stands \
for the dumps (*.bin) directly in it. Sweep tests give the frequency responses (in the \
order lat, lon, ped, col, each axis's tests in the order given), every other test (doublet, \
3-2-1-1) is held out for the verification (in the same order), every loop test (fly --input \
loop) is measured beside the model's predicted loop in margins.json. Aborted tests and tests \
cut off by the end of a file are left out unless --include-aborted. Writes into DIR: \
frf.json, model6.json, model9.json, verify.json (when there are held-out tests), \
margins.json and margins-loops.json, trim-points.csv (with \
--steady-flights), summary.json (layout in \
docs/formats.md) and last report.html, drawn from these files alone (`sweephold report DIR` \
redraws it byte for byte). The run is built in DIR.partial and replaces DIR only when it completes; \
a failing stage leaves DIR as it was, keeps the failed run's files in DIR.failed and exits \
with status 1. DIR must be new, empty or an earlier run's folder."
)]
pub struct IdentifyArgs {
    /// Telemetry dumps, or folders of them.
    #[arg(value_name = "LOG|DIR", required = true)]
    pub inputs: Vec<PathBuf>,
    /// The aircraft flown: a shipped one (bo105, trex700l, fbl700) or the path of an
    /// aircraft file (docs/formats.md, "Aircraft files"): its 9-DOF structure, a-priori
    /// constants, trim balance and valid-range source.
    #[arg(long, value_name = "NAME|FILE", value_parser = Vehicle::parse)]
    pub vehicle: Vehicle,
    /// Output folder (built in DIR.partial, swapped in when complete; DIR.lock held
    /// meanwhile).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Seed of the fits' random restarts (`fit --seed`).
    #[arg(long, default_value_t = 1, value_parser = crate::arg_values::seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Trim points (`trim-points.csv`, as `fit --trim-points` reads them) to derive the
    /// hybrid's `trim_derived` parameters from; without them they are fitted like the
    /// others.
    #[arg(long, value_name = "CSV", conflicts_with = "steady_flights")]
    pub trim_points: Option<PathBuf>,
    /// A log holding steady flights (`fly --fc board-sim --steady-flights`, or a pilot's):
    /// its steady segments (the rule in docs/cli.md), with the velocities of --gnss, are
    /// averaged into trim points, written as DIR/trim-points.csv with their standard
    /// errors and used as --trim-points is.
    #[arg(long, value_name = "LOG", requires = "gnss")]
    pub steady_flights: Option<PathBuf>,
    /// The GNSS velocities and heading of the --steady-flights log, on its clock
    /// (`gnss.csv`, docs/formats.md).
    #[arg(long, value_name = "CSV", requires = "steady_flights")]
    pub gnss: Option<PathBuf>,
    /// How the trim points enter the 9-DOF fit (as `fit --trim-balance`); default the
    /// aircraft file's `identification.trim_balance`.
    #[arg(long, value_enum, value_name = "HOW")]
    pub trim_balance: Option<TrimBalanceArg>,
    /// Also use the tests that aborted or were cut off by the end of their file.
    #[arg(long)]
    pub include_aborted: bool,
    /// Exit with status 1 (`error: …`) when the model written is degenerate (parameters
    /// outside their physical range, or free ones on a range bound of the structure file,
    /// after the fit's restarts elsewhere); without it, a warning line on stderr.
    #[arg(long)]
    pub strict: bool,
    /// No progress on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Run `sweephold identify`: the model, then the folder's path on stdout.
pub fn run(args: &IdentifyArgs) -> anyhow::Result<()> {
    let summary = identify(args)?;
    if !args.quiet {
        if let Some(fit) = &summary.fit {
            crate::note!("fit       {}: J_ave {:.1}", fit.structure, fit.cost_ave);
        }
        if let Some(verify) = &summary.verify {
            crate::note!("verify    TIC {}", verify.headline());
        }
    }
    crate::output::print(&format!(
        "model: {}\n",
        args.out.join(files::MODEL_9DOF).display()
    ))?;
    stages::judge_degenerate(summary.fit.as_ref(), &args.out, args.strict)
}

/// The dumps `inputs` stand for: files as given, folders by the `*.bin` files directly in
/// them, in name order. A missing input, or a folder without dumps, is an error.
pub fn dump_files(inputs: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(input)
                .with_context(|| format!("cannot read {}", input.display()))?
                .filter_map(|entry| entry.ok().map(|e| e.path()))
                .filter(|path| path.is_file() && path.extension().is_some_and(|e| e == "bin"))
                .collect();
            if found.is_empty() {
                bail!(
                    "{}: no telemetry dump (*.bin) in the folder",
                    input.display()
                );
            }
            found.sort();
            files.extend(found);
        } else {
            check_input_file("log", input)?;
            files.push(input.clone());
        }
    }
    Ok(files)
}

/// The trim attitude φ, θ \[rad\] each test of the dump `path` captured (its first
/// `TrimCaptured` event), by test number − 1.
fn captured_trims(path: &Path) -> anyhow::Result<Vec<Option<[f32; 2]>>> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut trims: Vec<Option<[f32; 2]>> = Vec::new();
    for frame in Decoder::new().feed(&bytes).flatten() {
        match frame {
            Frame::Header(_) => trims.push(None),
            Frame::Event(Event::TrimCaptured { phi, theta, .. }) => {
                if let Some(trim) = trims.last_mut() {
                    trim.get_or_insert([phi, theta]);
                }
            }
            _ => {}
        }
    }
    Ok(trims)
}

/// The order the frequency responses take the sweep axes in, and the verification its
/// held-out tests: the order `fly` flies them (so that a campaign's records give the
/// campaign's figures, summed in the same order).
fn axis_rank(record: &Record) -> usize {
    Axis::ALL
        .iter()
        .position(|axis| axis.name() == record.primary)
        .unwrap_or(Axis::ALL.len())
}

/// What the logs give: the sweeps, the held-out tests, the mean captured trim, the dumps
/// holding loop tests.
struct Tests {
    sweeps: Vec<Record>,
    held_out: Vec<(String, Record)>,
    trim: Option<TrimAttitude>,
    loop_dumps: Vec<PathBuf>,
}

/// Read every test of `dumps` into `summary` and [`Tests`].
fn read_tests(
    dumps: &[PathBuf],
    include_aborted: bool,
    summary: &mut IdentifySummary,
) -> anyhow::Result<Tests> {
    let mut origins = Vec::new();
    let mut sweeps = Vec::new();
    let mut held_out = Vec::new();
    let mut captured: Vec<[f32; 2]> = Vec::new();
    let mut loop_dumps = Vec::new();
    for path in dumps {
        if crate::logs::log_format(path).is_some() {
            bail!(
                "{}: a PX4 or ArduPilot log; identify reads the board's telemetry dumps",
                path.display()
            );
        }
        let tests = identify_records(path, include_aborted)?;
        summary.tests.extend(tests.listing);
        if tests.loop_tests > 0 {
            loop_dumps.push(path.clone());
        }
        let trims = captured_trims(path)?;
        for UsedTest {
            number,
            record,
            origin,
            is_sweep,
        } in tests.used
        {
            origins.push(origin);
            if is_sweep {
                captured.extend(trims.get(number - 1).copied().flatten());
                sweeps.push(record);
            } else {
                held_out.push((record.source.clone(), record));
            }
        }
    }
    // Dumps of two vehicles (or flight controllers, or rates) are not one aircraft's.
    check_one_origin(&origins)?;
    if sweeps.is_empty() {
        if !loop_dumps.is_empty() {
            bail!(
                "no completed sweep test in the logs, only loop tests: nothing to identify \
                 (`sweephold margins MODEL --measured DUMP` measures them against a model)"
            );
        }
        bail!("no completed sweep test in the logs: nothing to identify");
    }
    // A stable sort: each axis's tests keep the order they were given in.
    sweeps.sort_by_key(axis_rank);
    held_out.sort_by_key(|(_, record)| axis_rank(record));
    summary.sweeps = sweeps.iter().map(|r| r.source.clone()).collect();
    summary.held_out = held_out.iter().map(|(name, _)| name.clone()).collect();
    // The mean of f32 values summed in f64 is exact, so independent of the order.
    let trim = (!captured.is_empty()).then(|| {
        let count = captured.len() as f64;
        TrimAttitude {
            phi: captured.iter().map(|t| f64::from(t[0])).sum::<f64>() / count,
            theta: captured.iter().map(|t| f64::from(t[1])).sum::<f64>() / count,
        }
    });
    summary.captured_trim_rad = trim.map(|t| [t.phi, t.theta]);
    if trim.is_none() {
        summary.notes.push(
            "no sweep test captured a trim attitude: the structure is written about its \
             file's"
                .to_string(),
        );
    }
    Ok(Tests {
        sweeps,
        held_out,
        trim,
        loop_dumps,
    })
}

/// Read `--trim-points`, when given.
fn read_trim_points(path: Option<&Path>) -> anyhow::Result<Option<TrimPoints>> {
    let Some(path) = path else { return Ok(None) };
    check_input_file("--trim-points", path)?;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let points = TrimPoints::parse_csv(&text).map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(Some(points))
}

/// One run of `identify`: the summary as it stands and the folder it builds.
struct Run<'a> {
    args: &'a IdentifyArgs,
    summary: IdentifySummary,
    started: Instant,
    staged: Option<StagedFolder>,
}

impl Run<'_> {
    /// Run `work` as the stage `name`: progress and timing; on failure the error in
    /// `summary.json` and the run kept in DIR.failed.
    fn stage<T>(
        &mut self,
        name: &str,
        work: impl FnOnce(&mut Self) -> anyhow::Result<(T, String)>,
    ) -> anyhow::Result<T> {
        let began = Instant::now();
        match work(self) {
            Ok((value, line)) => {
                let seconds = began.elapsed().as_secs_f64();
                if !self.args.quiet {
                    crate::note!("{name:<9} {line} ({seconds:.1} s)");
                }
                self.summary.timings_s.insert(name.to_string(), seconds);
                Ok(value)
            }
            Err(error) => {
                let message = format!("{error:#}").replace('\n', " ");
                self.summary.error = Some(StageFailure {
                    stage: name.to_string(),
                    message: message.clone(),
                });
                let mut kept = String::new();
                if let Some(staged) = self.staged.take() {
                    // Best effort: the folder may be what failed.
                    let _ = write_json(&staged.path().join(files::SUMMARY), &self.summary);
                    if let Ok(failed) = staged.fail() {
                        kept = format!(" (its files are in {})", failed.display());
                    }
                }
                Err(anyhow!("{name}: {message}{kept}"))
            }
        }
    }

    fn dir(&self) -> &Path {
        self.staged
            .as_ref()
            .map_or(self.args.out.as_path(), StagedFolder::path)
    }

    fn pipeline(&self) -> Pipeline<'_> {
        let args = self.args;
        Pipeline {
            dir: self.dir(),
            vehicle: &args.vehicle,
            seed: args.seed,
            trim_balance: args
                .trim_balance
                .unwrap_or_else(|| TrimBalanceArg::of_vehicle(&args.vehicle)),
        }
    }
}

/// Run the whole identification of `args` (see the module documentation).
pub fn identify(args: &IdentifyArgs) -> anyhow::Result<IdentifySummary> {
    // Every input checked, and read, before the output folder is touched.
    let dumps = dump_files(&args.inputs)?;
    let mut inputs: Vec<&Path> = args.inputs.iter().map(PathBuf::as_path).collect();
    inputs.extend(dumps.iter().map(PathBuf::as_path));
    inputs.extend(args.trim_points.as_deref());
    inputs.extend(args.steady_flights.as_deref());
    inputs.extend(args.gnss.as_deref());
    refuse_inputs_as_outputs(&inputs, &[("--out", &args.out)])?;
    let mut summary = IdentifySummary {
        vehicle: args.vehicle.name().to_string(),
        seed: args.seed,
        tests: Vec::new(),
        sweeps: Vec::new(),
        held_out: Vec::new(),
        captured_trim_rad: None,
        trim_points: args.trim_points.as_ref().map(|p| p.display().to_string()),
        trim_points_source: "none".to_string(),
        steady_segments: Vec::new(),
        hover_derivatives_unanchored: false,
        notes: Vec::new(),
        fit: None,
        verify: None,
        timings_s: BTreeMap::new(),
        error: None,
    };
    let tests = read_tests(&dumps, args.include_aborted, &mut summary)?;
    let mut trim_points = read_trim_points(args.trim_points.as_deref())?;
    let mut flight_csv = None;
    if trim_points.is_some() {
        summary.trim_points_source = "file".to_string();
    }
    if let (Some(log), Some(gnss)) = (&args.steady_flights, &args.gnss) {
        let rate_hz = tests.sweeps[0].sample_rate_hz;
        let flight = flight_trim::flight_trim_points(log, gnss, rate_hz)?;
        summary.trim_points_source = "flight".to_string();
        summary.trim_points = Some(files::TRIM_POINTS.to_string());
        summary.steady_segments = flight.segments;
        trim_points = Some(flight.points);
        flight_csv = Some(flight.csv);
    }
    if !args.quiet {
        for listing in &summary.tests {
            crate::note!("{}", listing.line());
        }
        if !summary.steady_segments.is_empty() {
            crate::note!(
                "trim points: {} steady segments of {}",
                summary.steady_segments.len(),
                args.steady_flights
                    .as_deref()
                    .map_or(String::new(), |p| p.display().to_string())
            );
        }
    }
    if trim_points.is_none() {
        summary.hover_derivatives_unanchored = true;
        summary.notes.push(
            "no trim points (--trim-points) and no steady flights with a velocity source \
             (--steady-flights with --gnss): the hybrid's trim_derived parameters (the hover \
             derivatives) are fitted like the others, unanchored"
                .to_string(),
        );
    }
    if tests.held_out.is_empty() {
        summary
            .notes
            .push("no held-out test (doublet, 3-2-1-1) in the logs: not verified".to_string());
    }
    let mut run = Run {
        args,
        summary,
        started: Instant::now(),
        staged: Some(StagedFolder::begin(&args.out)?),
    };
    if let Some(csv) = &flight_csv {
        crate::output::write_atomic(&run.dir().join(files::TRIM_POINTS), csv.as_bytes())?;
    }
    let Tests {
        sweeps,
        held_out,
        trim,
        loop_dumps,
    } = tests;
    let frf = run.stage(stage::FRF, |run| run.pipeline().frequency_responses(sweeps))?;
    let six = run.stage(stage::FIT_6DOF, |run| {
        run.pipeline().fit_6dof(&frf.document)
    })?;
    let nine = run.stage(stage::FIT_9DOF, |run| {
        let (result, fit, line) =
            run.pipeline()
                .fit_9dof(trim, &frf.document, &six, &trim_points)?;
        run.summary.fit = Some(fit);
        Ok((result, line))
    })?;
    if !held_out.is_empty() {
        run.stage(stage::VERIFY, |run| {
            let (verify, line) = run.pipeline().verify(&nine.model, &held_out)?;
            run.summary.verify = Some(verify);
            Ok(((), line))
        })?;
    }
    run.stage(stage::MARGINS, |run| {
        Ok(((), run.pipeline().margins(&loop_dumps)?))
    })?;
    // The report is drawn from the folder's files, the summary included: written first
    // and not again, so that `sweephold report DIR` redraws the same page.
    run.stage(stage::REPORT, |run| {
        let total = run.started.elapsed().as_secs_f64();
        run.summary.timings_s.insert("total".to_string(), total);
        write_json(&run.dir().join(files::SUMMARY), &run.summary)?;
        crate::report::write_report(run.dir())?;
        Ok(((), files::REPORT.to_string()))
    })?;
    run.stage("complete", |run| {
        let staged = run
            .staged
            .take()
            .ok_or_else(|| anyhow!("the output folder was not set up"))?;
        staged.complete()?;
        Ok(((), run.args.out.display().to_string()))
    })?;
    Ok(run.summary)
}
