//! `sweephold fly`: the paper's test campaign, flown on the host with the flight
//! controller in the loop and the nonlinear simulator as the aircraft.

mod args;
pub mod board_flash;
pub mod board_test_list;
pub mod defmt_log;
pub mod frame_channel;
pub mod gust_pulse;
pub mod imu_fault;
pub mod link;
pub mod link_board_sim;
pub mod link_qemu;
pub mod link_serial;
pub mod pilot_collective;
pub mod plan;
pub mod record;
pub mod servo_plant;
pub mod summary;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Mutex;

use anyhow::{bail, Context};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use sweephold_firmware::Config;
use sysid::frf::Record;

use crate::output::{write_atomic, write_json, StagedFolder};
use crate::vehicle::Vehicle;
use link::{FlightControllerLink, InProcessLink};
use plan::RecordPlan;
use record::{fly_record, Disturbances};
use summary::{FlySummary, RunSummary};

pub use args::{
    parse_fc, AmplitudeArg, FcArg, FcArgError, FlyArgs, InputArg, ModeArg, PowerUpArg,
    VibrationArg, MAX_FLY_ON_S, MAX_T_REC_S, MIN_T_REC_S,
};

/// The firmware configuration of one record.
pub fn record_config(vehicle: &Vehicle, plan: &RecordPlan, rate_hz: u16) -> Config {
    let mut config = vehicle.firmware_config(plan.axis);
    config.rate_hz = rate_hz;
    config.test.mode = plan.mode;
    config.test.input = plan.input;
    config.test.primary = plan.axis;
    config.test.seed = plan.seed;
    config.test.sweep.omega_min = plan.omega_min as f32;
    config.test.sweep.omega_max = plan.omega_max as f32;
    config.test.sweep.t_rec_s = plan.t_rec_s as f32;
    config.test.sweep.amplitude = plan.amplitude as f32;
    config.test.pulse.amplitude = plan.amplitude as f32;
    config
}

/// Result of a whole `fly` run.
pub struct FlyOutcome {
    /// The summary written to `summary.json`.
    pub summary: FlySummary,
    /// Dump paths, in flying order.
    pub dumps: Vec<PathBuf>,
    /// The sweep record of each dump as decoded for its cross-control coherence, in
    /// flying order (`None` for an aborted record or another input than a sweep), so that
    /// a caller needs not decode the dumps again. Its `source` is the dump's file name.
    pub records: Vec<Option<Record>>,
    /// The trim attitude φ, θ \[rad\] each record's flight controller captured, in flying
    /// order, as the telemetry streamed (`None` where it captured none).
    pub trims: Vec<Option<[f32; 2]>>,
}

/// Run `sweephold fly`: the records are flown into `OUT.partial`, which replaces OUT
/// only when every record was written (see [`crate::output::StagedFolder`]).
pub fn run(args: &FlyArgs) -> anyhow::Result<()> {
    validate(args)?;
    if args.steady_flights {
        return run_steady_flights(args);
    }
    // The board image is found (and checked) before anything is written.
    let image = match (&args.fc, &args.elf) {
        (FcArg::Qemu | FcArg::QemuUsart, elf) => {
            let image = match elf {
                Some(path) => path.clone(),
                None => link_qemu::default_image()?,
            };
            link_qemu::check_image(&image)?;
            link_qemu::qemu_available()?;
            Some(image)
        }
        _ => None,
    };
    let staged = StagedFolder::begin(&args.out)?;
    // The test hook's first point: the lock held and the staging folder made, nothing flown.
    crate::interrupt::pause_point("setup");
    let mut staged_args = args.clone();
    staged_args.out = staged.path().to_path_buf();
    let flown = fly_on_link(&staged_args, image.as_deref()).and_then(|outcome| {
        // The last safe point: a signal up to here leaves DIR as it was.
        crate::interrupt::pause_point("complete");
        crate::interrupt::check().map(|()| outcome)
    });
    let outcome = match flown {
        Ok(outcome) => {
            staged.complete()?;
            outcome
        }
        Err(error) => {
            let kept = match staged.fail() {
                Ok(failed) => format!("its files are in {}", failed.display()),
                Err(e) => format!("{e:#}"),
            };
            return Err(error.context(format!(
                "fly failed ({kept}; {} is unchanged)",
                args.out.display()
            )));
        }
    };
    if !args.quiet {
        for run in &outcome.summary.runs {
            let coherence: Vec<String> = run
                .cross_coherence
                .iter()
                .map(|(k, v)| format!("{k} {v:.2}"))
                .collect();
            crate::note!(
                "{:>9}  {:6.1} s  {}  max |phi| {:4.1} deg, |theta| {:4.1} deg  cross-coherence: {}",
                run.file,
                run.duration_s,
                run.abort_reason.as_deref().map_or("ok     ".to_string(), |r| format!("ABORT {r}")),
                run.max_abs_deg.phi,
                run.max_abs_deg.theta,
                if coherence.is_empty() { "-".to_string() } else { coherence.join(", ") }
            );
            if let Some(estimator) = &run.estimator {
                let e = estimator.max_error_deg;
                crate::note!(
                    "{:>9}  board estimate: max error phi {:.2} deg, theta {:.2} deg",
                    "",
                    e.phi,
                    e.theta
                );
            }
            if let Some(after) = &run.after {
                crate::note!(
                    "{:>9}  after the test: {:.1} s in {}, max |phi| {:4.1} deg, |theta| {:4.1} deg",
                    "", after.duration_s, after.mode, after.max_abs_deg.phi, after.max_abs_deg.theta
                );
                if let Some(gust) = &after.gust_pulse {
                    let [u, v, w] = gust.body_wind_m_s;
                    crate::note!(
                        "{:>9}  gust ({u}, {v}, {w}) m/s at {} s: peak excursion phi {:.2} deg, theta {:.2} deg",
                        "", gust.at_s, gust.peak_excursion_deg.phi, gust.peak_excursion_deg.theta
                    );
                }
            }
        }
        crate::note!(
            "wrote {} records and summary.json to {}",
            outcome.dumps.len(),
            args.out.display()
        );
    }
    Ok(())
}

/// The simulated GNSS's file in the output folder of `fly --steady-flights`.
pub const GNSS_FILE: &str = "gnss.csv";

/// `fly --steady-flights`: the steady flights into `OUT.partial`, swapped in when done.
fn run_steady_flights(args: &FlyArgs) -> anyhow::Result<()> {
    let staged = StagedFolder::begin(&args.out)?;
    match fly_steady_flights(args, staged.path()) {
        Ok(fixes) => {
            staged.complete()?;
            if !args.quiet {
                crate::note!(
                    "wrote {}/{} and {GNSS_FILE} ({fixes} fixes) to {}",
                    link_board_sim::LOG_FOLDER,
                    link_board_sim::power_up_log_name(1),
                    args.out.display()
                );
            }
            Ok(())
        }
        Err(error) => {
            let kept = match staged.fail() {
                Ok(failed) => format!("its files are in {}", failed.display()),
                Err(e) => format!("{e:#}"),
            };
            Err(error.context(format!(
                "fly failed ({kept}; {} is unchanged)",
                args.out.display()
            )))
        }
    }
}

/// Fly the steady flights of `sim trim-points` on the board-sim link set up for `args`
/// (the first record's configuration powers it up) and write the board's log and the
/// GNSS file into `folder`; returns the number of fixes.
pub fn fly_steady_flights(args: &FlyArgs, folder: &std::path::Path) -> anyhow::Result<usize> {
    let settings = board_sim_settings(args)?;
    let plans = args.plans();
    let plan = plans
        .first()
        .ok_or_else(|| anyhow::anyhow!("no record to power the board up for"))?;
    let config = record_config(&args.vehicle, plan, args.rate_hz);
    let flights = link_board_sim::fly_steady_flights(
        &settings,
        &config,
        &crate::sim::TRIM_FLIGHTS,
        args.gust,
    )?;
    let logs = folder.join(link_board_sim::LOG_FOLDER);
    std::fs::create_dir_all(&logs).with_context(|| format!("cannot create {}", logs.display()))?;
    write_atomic(
        &logs.join(link_board_sim::power_up_log_name(1)),
        &flights.log,
    )?;
    write_atomic(
        &folder.join(GNSS_FILE),
        sysid::steady::gnss_csv(&flights.fixes).as_bytes(),
    )?;
    Ok(flights.fixes.len())
}

/// Fly `args` into `args.out` over the link `args.fc` names.
fn fly_on_link(args: &FlyArgs, image: Option<&std::path::Path>) -> anyhow::Result<FlyOutcome> {
    match &args.fc {
        FcArg::InProcess => fly(args, &|| Box::new(InProcessLink::new())),
        FcArg::Qemu | FcArg::QemuUsart => {
            let image = image.ok_or_else(|| anyhow::anyhow!("no board image"))?;
            let extra = link_qemu::extra_args_from_env();
            let transport = if args.fc == FcArg::Qemu {
                link_qemu::QemuTransport::Semihosting
            } else {
                link_qemu::QemuTransport::Usart
            };
            fly(args, &|| {
                Box::new(
                    link_qemu::QemuLink::new(image, transport, &extra).with_log_folder(&args.out),
                )
            })
        }
        // One port, one board: the records are flown one after the other.
        FcArg::Serial(port) => fly_with_workers(
            args,
            &|| Box::new(link_serial::SerialLink::new(port.clone())),
            1,
        ),
        FcArg::BoardSim(_) => fly_board_sim(args),
    }
}

/// Fly `args` into `args.out` on the board-sim link (one per worker).
pub fn fly_board_sim(args: &FlyArgs) -> anyhow::Result<FlyOutcome> {
    let settings = board_sim_settings(args)?;
    // One power-up flies its records one after the other, on one board.
    let workers = match settings.power_up {
        link_board_sim::PowerUp::Once => 1,
        link_board_sim::PowerUp::PerRecord => usize::MAX,
    };
    fly_with_workers(
        args,
        &|| Box::new(link_board_sim::BoardSimLink::new(settings.clone())),
        workers,
    )
}

/// The board-sim link's settings for `args`.
pub fn board_sim_settings(args: &FlyArgs) -> anyhow::Result<link_board_sim::BoardSimSettings> {
    let heli = args.vehicle.helicopter();
    let trim = rotorsim::trim(&heli, 0.0)
        .map_err(|e| anyhow::anyhow!("{} does not trim in hover: {e}", args.vehicle.name()))?;
    Ok(link_board_sim::BoardSimSettings {
        heli,
        trim,
        sim_options: sim_options(args),
        vibration: args.vibration != Some(VibrationArg::None),
        rc_loss_at_s: args.rc_loss_at_s,
        imu_fault: args.imu_fault,
        swash: args.vehicle.aircraft().swash,
        rotor_rpm: servo_plant::board_rotor_rpm(args.vehicle.aircraft()),
        test_list: if args.input == InputArg::Loop {
            board_test_list::loop_list(&args.vehicle, args.t_rec_s)
        } else {
            board_test_list::campaign_list(&args.vehicle, args.t_rec_s)
        },
        setup: match &args.fc {
            FcArg::BoardSim(Some(flash)) => link_board_sim::BoardSetup::Stored(Box::new(
                board_flash::load_params(flash, args.vehicle.preset())?,
            )),
            _ => link_board_sim::BoardSetup::FromAircraft,
        },
        power_up: PowerUpArg::link(args.power_up),
        log_folder: Some(args.out.join(link_board_sim::LOG_FOLDER)),
    })
}

/// The simulator's options for `args` (before the seed and the disturbances).
fn sim_options(args: &FlyArgs) -> rotorsim::SimOptions {
    let mut sim_options = rotorsim::SimOptions {
        actuator: args.vehicle.servos(),
        ..rotorsim::SimOptions::default()
    };
    if args.perfect_sensors {
        // Sensors only: the actuators keep their servo dynamics and delay.
        sim_options.sensor_noise = rotorsim::SensorNoise::perfect();
    }
    sim_options.linearized_plant = args.linearized_plant;
    sim_options
}

/// Refuse a bad command line or a configuration the firmware would refuse, before
/// anything is flown or written.
pub fn validate(args: &FlyArgs) -> anyhow::Result<()> {
    args.check()?;
    if let FcArg::BoardSim(Some(flash)) = &args.fc {
        board_flash::load_params(flash, args.vehicle.preset())?;
    }
    let plans = args.plans();
    for plan in &plans {
        let config = record_config(&args.vehicle, plan, args.rate_hz);
        sweephold_firmware::FlightController::new(config).map_err(|e| {
            anyhow::anyhow!(
                "record {}: the firmware refuses this configuration: {}",
                plan.file_name(),
                e.message()
            )
        })?;
    }
    Ok(())
}

/// Fly every record of `args` with links made by `make_link` (one per worker thread),
/// write the dumps and `summary.json`, and return the summary.
pub fn fly(
    args: &FlyArgs,
    make_link: &(dyn Fn() -> Box<dyn FlightControllerLink> + Sync),
) -> anyhow::Result<FlyOutcome> {
    fly_with_workers(args, make_link, usize::MAX)
}

/// [`fly`] with at most `max_workers` worker threads (links): 1 for a link that cannot
/// be shared, such as a board on a serial port.
pub fn fly_with_workers(
    args: &FlyArgs,
    make_link: &(dyn Fn() -> Box<dyn FlightControllerLink> + Sync),
    max_workers: usize,
) -> anyhow::Result<FlyOutcome> {
    validate(args)?;
    let heli = args.vehicle.helicopter();
    let trim = rotorsim::trim(&heli, 0.0)
        .map_err(|e| anyhow::anyhow!("{} does not trim in hover: {e}", args.vehicle.name()))?;
    let plans = args.plans();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output folder {}", args.out.display()))?;

    let sim_options = sim_options(args);
    let disturbances = Disturbances {
        gust_level: args.gust,
        sensor_dropout: args.sensor_dropout,
        sensor_spike: args.sensor_spike,
        pilot_override_at_s: args.pilot_override_at_s,
        pilot_stick_noise: args.pilot_noise,
        collective_step: args.collective_step,
        fly_on_s: args.fly_on_s.unwrap_or(0.0),
        gust_pulse: args.gust_pulse,
    };

    let bars = MultiProgress::with_draw_target(if args.quiet {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    });
    let style = ProgressStyle::with_template("{prefix:>9} [{bar:30}] {pos:>4}/{len} s {msg}")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");

    let next = Mutex::new(0usize);
    let flight_errors: Mutex<Vec<anyhow::Error>> = Mutex::new(Vec::new());
    let results: Mutex<Vec<Option<anyhow::Result<FinishedRecord>>>> =
        Mutex::new(plans.iter().map(|_| None).collect());
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(plans.len())
        .min(max_workers)
        .max(1);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                let mut link = make_link();
                loop {
                    let i = {
                        let mut next = next.lock().unwrap_or_else(|e| e.into_inner());
                        let i = *next;
                        *next += 1;
                        i
                    };
                    let Some(plan) = plans.get(i) else { break };
                    let config = record_config(&args.vehicle, plan, args.rate_hz);
                    let max_s = expected_duration_s(&config) + 10.0;
                    let bar = bars.add(ProgressBar::new(max_s as u64));
                    bar.set_style(style.clone());
                    bar.set_prefix(plan.file_name());
                    let mut options = sim_options;
                    options.seed = args.seed ^ u64::from(plan.seed).rotate_left(17);
                    let aircraft = record::Aircraft {
                        heli: &heli,
                        trim: &trim,
                        options,
                    };
                    let result = fly_record(
                        link.as_mut(),
                        &config,
                        aircraft,
                        &disturbances,
                        max_s,
                        |t| bar.set_position(t as u64),
                    );
                    // The link's own record of it (the image's log), even for a failed one.
                    let logged = link.end_record(&plan.file_name());
                    let result = result
                        .and_then(|flown| logged.map(|()| flown))
                        .and_then(|flown| finish_record(args, plan, &config, flown));
                    bar.finish_and_clear();
                    results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(result);
                }
                if let Err(error) = link.end_flight() {
                    flight_errors
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push(error);
                }
            });
        }
    });

    if let Some(error) = flight_errors
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .next()
    {
        return Err(error.context("writing the board's log"));
    }
    let mut runs = Vec::new();
    let mut records = Vec::new();
    let mut trims = Vec::new();
    for (plan, result) in plans
        .iter()
        .zip(results.into_inner().unwrap_or_else(|e| e.into_inner()))
    {
        let run = result.unwrap_or_else(|| Err(anyhow::anyhow!("not flown")));
        let (run, record, trim) = run.with_context(|| format!("record {}", plan.file_name()))?;
        runs.push(run);
        records.push(record);
        trims.push(trim);
    }
    let link = make_link().describe();
    let summary = FlySummary {
        vehicle: args.vehicle.name().to_string(),
        mode: args.mode.name().to_string(),
        rate_hz: u32::from(args.rate_hz),
        seed: args.seed,
        link,
        plant: if args.linearized_plant {
            "linearized"
        } else {
            "nonlinear"
        }
        .to_string(),
        runs,
    };
    let path = args.out.join("summary.json");
    // The test hook: every record written, the summary not yet.
    crate::interrupt::pause_point("summary");
    write_json(&path, &summary)?;
    let dumps = plans.iter().map(|p| args.out.join(p.file_name())).collect();
    Ok(FlyOutcome {
        summary,
        dumps,
        records,
        trims,
    })
}

/// Seconds from arming to the end of the excitation for `config` (trim capture, fades,
/// the ω_min hold and the record).
pub fn expected_duration_s(config: &Config) -> f64 {
    let excitation = sweephold_firmware::excitation::Excitation::from_test(&config.test);
    f64::from(config.trim_capture_s) + excitation.duration_s()
}

/// A record written: its summary, its sweep as decoded for the summary (if a sweep that
/// did not abort) and the trim attitude its flight controller captured.
type FinishedRecord = (RunSummary, Option<Record>, Option<[f32; 2]>);

fn finish_record(
    args: &FlyArgs,
    plan: &RecordPlan,
    config: &Config,
    flown: record::FlownRecord,
) -> anyhow::Result<FinishedRecord> {
    write_atomic(&args.out.join(plan.file_name()), &flown.dump)?;
    if !flown.began {
        if let Some(refusal) = &flown.test_refused {
            bail!("the flight controller refused the test ({refusal}): no test started");
        }
        if let Some(fault) = args.board_fault() {
            let mode = flown
                .first_mode_change
                .map_or_else(String::new, |change| format!(": the board went {change}"));
            bail!("{fault} ended the record before it began (no test started{mode})");
        }
    }
    let record = if plan.input.is_sweep() && flown.abort.is_none() {
        Some(sysid::frf::load_dump_bytes(&flown.dump, &plan.file_name())?)
    } else {
        None
    };
    let cross_coherence = match &record {
        Some(record) => record_cross_coherence(record)?,
        None => BTreeMap::new(),
    };
    let run = RunSummary {
        axis: plan.axis.name().to_string(),
        index: plan.index,
        file: plan.file_name(),
        omega_min: plan.omega_min,
        omega_max: plan.omega_max,
        duration_s: flown.ticks as f64 / f64::from(config.rate_hz),
        frames: flown.frames,
        aborted: flown.abort.is_some(),
        abort_reason: flown.abort.map(|r| r.name().to_string()),
        max_abs_deg: flown.max_abs_deg,
        max_from_trim_deg: flown.max_from_trim_deg,
        hold_fraction: flown.hold_fraction,
        cross_coherence,
        estimator: matches!(args.fc, FcArg::BoardSim(_)).then_some(summary::EstimatorSummary {
            max_error_deg: flown.attitude_error_deg,
        }),
        after: flown.after,
    };
    Ok((run, record, flown.trim_captured))
}

/// Mean coherence between the primary control and each other excited control over the
/// sweep band of one record (sysid's cross-control coherence).
pub fn record_cross_coherence(record: &Record) -> anyhow::Result<BTreeMap<String, f64>> {
    let primary = record.primary.clone();
    let pairs = sysid::frf::cross_control_coherence(record, &sysid::frf::FrfOptions::default())?;
    Ok(pairs
        .into_iter()
        .map(|c| (if c.a == primary { c.b } else { c.a }, c.mean))
        .collect())
}
