//! The flying stages: the sweeps of each excitation mode and the held-out doublets, each
//! flown as `sweephold fly` flies them (its arguments, in process), and the sweeps kept as
//! `fly` decoded them.

use std::ffi::OsString;
use std::path::PathBuf;

use clap::ValueEnum;
use sysid::frf::Record;

use super::{verb_args, Campaign, CampaignLink};
use crate::artifacts::files;
use crate::artifacts::flown::LATERAL;
use crate::artifacts::summary::{ModeSummary, PeakAttitudeDeg};
use crate::fly::link::InProcessLink;
use crate::fly::summary::{FlySummary, MaxAbsDeg};
use crate::fly::{self, AmplitudeArg, FlyArgs, FlyOutcome, InputArg, ModeArg};
use truth::TrimAttitude;

/// The records of one mode that did not abort: their dumps and their sweeps, decoded.
pub struct FlownMode {
    /// The mode flown.
    pub mode: ModeArg,
    /// The dumps, in flying order.
    pub dumps: Vec<PathBuf>,
    /// Their sweeps, in the same order; `source` is the dump's path.
    pub records: Vec<Record>,
    /// The trim attitude each dump's flight controller captured, in the same order as
    /// `dumps`, as the telemetry streamed.
    pub trims: Vec<Option<[f32; 2]>>,
}

impl FlownMode {
    /// The lateral sweeps, in flying order.
    pub fn lateral(&self) -> impl Iterator<Item = &Record> {
        self.records.iter().filter(|r| r.primary == LATERAL)
    }

    /// The sweeps, taken out (the dumps stay).
    pub fn take_records(&mut self) -> Vec<Record> {
        std::mem::take(&mut self.records)
    }

    /// The mean trim attitude the flight controller captured over the records, or None
    /// when no record has one: what the flight-test engineer has, the aircraft's own trim
    /// rather than the simulator's.
    pub fn captured_trim(&self) -> Option<TrimAttitude> {
        let captured: Vec<[f32; 2]> = self.trims.iter().flatten().copied().collect();
        let mut sum = [0.0; 2];
        for [phi, theta] in &captured {
            sum[0] += f64::from(*phi);
            sum[1] += f64::from(*theta);
        }
        let count = captured.len() as f64;
        (!captured.is_empty()).then(|| TrimAttitude {
            phi: sum[0] / count,
            theta: sum[1] / count,
        })
    }

    /// The same with the lateral sweeps alone.
    pub fn lateral_only(mut self) -> FlownMode {
        self.records.retain(|r| r.primary == LATERAL);
        self
    }
}

/// The name clap knows a value of `T` by on the command line.
fn value_name<T: ValueEnum>(value: T) -> OsString {
    value
        .to_possible_value()
        .map_or_else(OsString::new, |v| v.get_name().into())
}

impl Campaign<'_> {
    /// `sweephold fly` for this campaign: every axis, `input` in `mode` with `seed`, into
    /// `folder` of the campaign folder; the sweeps with the campaign's `--amplitude` (the
    /// doublets are never shaped).
    fn fly_args(
        &self,
        mode: ModeArg,
        input: InputArg,
        seed: u64,
        folder: &str,
    ) -> anyhow::Result<FlyArgs> {
        let amplitude = if input == InputArg::Sweep {
            self.args.amplitude
        } else {
            AmplitudeArg::Fixed
        };
        let mut argv: Vec<OsString> = vec![
            "--vehicle".into(),
            self.args.vehicle.given().into(),
            "--mode".into(),
            value_name(mode),
            "--input".into(),
            value_name(input),
            "--amplitude".into(),
            value_name(amplitude),
            "--seed".into(),
            seed.to_string().into(),
            "--t-rec".into(),
            self.args.t_rec_s().to_string().into(),
            "--fc".into(),
            self.args.fc.name().into(),
            "--out".into(),
            self.dir().join(folder).into(),
            "--quiet".into(),
        ];
        if matches!(self.args.fc, CampaignLink::BoardSim(_)) && amplitude == AmplitudeArg::Fixed {
            // A flight as the board flies it: every test of the stage on one power-up,
            // chosen from the test list by the transmitter's selector, in one log. An
            // adaptive sweep is no entry of the list: a power-up per record.
            argv.extend(["--power-up".into(), "once".into()]);
        }
        verb_args("fly", argv)
    }

    /// A fly stage: the sweeps of `mode` (summary section and progress line), the records
    /// that did not abort kept with their sweeps as `fly` decoded them.
    pub(super) fn fly_sweeps(&mut self, mode: ModeArg) -> anyhow::Result<(FlownMode, String)> {
        let folder = files::fly_folder(mode.name());
        let outcome =
            self.fly(&self.fly_args(mode, InputArg::Sweep, self.args.seed, &folder)?)?;
        let summary = mode_summary(&outcome.summary, &folder);
        let line = format!(
            "{} records, {} abort(s), lat–lon coherence {}",
            summary.records,
            summary.aborts,
            summary
                .cross_coherence_lat_lon
                .map_or("-".to_string(), |c| format!("{c:.3}"))
        );
        let slot = match mode {
            ModeArg::Cah => &mut self.summary.modes.cah,
            ModeArg::Standard => &mut self.summary.modes.standard,
            ModeArg::Noise => &mut self.summary.modes.noise,
        };
        *slot = Some(summary);
        let mut flown = FlownMode {
            mode,
            dumps: Vec::new(),
            records: Vec::new(),
            trims: Vec::new(),
        };
        for (((run, dump), record), trim) in outcome
            .summary
            .runs
            .iter()
            .zip(outcome.dumps)
            .zip(outcome.records)
            .zip(outcome.trims)
        {
            if run.aborted {
                continue;
            }
            if let Some(mut record) = record {
                // Named by its path, as a dump loaded from its file is.
                record.source = dump.display().to_string();
                flown.records.push(record);
            }
            flown.dumps.push(dump);
            flown.trims.push(trim);
        }
        Ok((flown, line))
    }

    /// The verification's fly stage: the held-out doublets (another seed), their files
    /// relative to the campaign folder, those that aborted left out.
    pub(super) fn fly_doublets(&mut self) -> anyhow::Result<(Vec<String>, String)> {
        let seed = self.args.verification_seed();
        let args = self.fly_args(
            ModeArg::Cah,
            InputArg::Doublet,
            seed,
            files::VERIFICATION_FOLDER,
        )?;
        let outcome = self.fly(&args)?;
        let doublets: Vec<String> = outcome
            .summary
            .runs
            .iter()
            .filter(|r| !r.aborted)
            .map(|r| format!("{}/{}", files::VERIFICATION_FOLDER, r.file))
            .collect();
        let line = format!("{} doublets, seed {seed}", doublets.len());
        Ok((doublets, line))
    }
}

impl Campaign<'_> {
    /// The steady flights' stage (`--fc board-sim`): `fly --steady-flights` with the
    /// flight's settings into `fly-steady/` (the board's log and `gnss.csv`).
    pub(super) fn fly_steady(&mut self) -> anyhow::Result<((), String)> {
        let mut args = self.fly_args(
            ModeArg::Cah,
            InputArg::Sweep,
            self.args.seed,
            files::STEADY_FOLDER,
        )?;
        args.steady_flights = true;
        let fixes = fly::fly_steady_flights(&args, &args.out)?;
        Ok((
            (),
            format!(
                "{} steady flights, {fixes} GNSS fixes",
                crate::sim::TRIM_FLIGHTS.len()
            ),
        ))
    }

    /// Fly `args` on the campaign's flight controller (`--fc`).
    fn fly(&self, args: &FlyArgs) -> anyhow::Result<FlyOutcome> {
        match self.args.fc {
            CampaignLink::InProcess => fly::fly(args, &|| Box::new(InProcessLink::new())),
            CampaignLink::BoardSim(_) => fly::fly_board_sim(args),
        }
    }
}

/// The mode's figures from `fly`'s summary of its records written into `folder`.
pub fn mode_summary(summary: &FlySummary, folder: &str) -> ModeSummary {
    let peak = |value: fn(&MaxAbsDeg) -> f64| {
        summary
            .runs
            .iter()
            .map(|run| value(&run.max_abs_deg))
            .fold(0.0, f64::max)
    };
    ModeSummary {
        cross_coherence_lat_lon: summary.mean_cross_coherence("lat", "lon"),
        max_abs_deg: PeakAttitudeDeg {
            phi: peak(|m| m.phi),
            theta: peak(|m| m.theta),
        },
        max_from_trim_deg: summary
            .runs
            .iter()
            .filter_map(|run| run.max_from_trim_deg)
            .fold(None, |peak: Option<PeakAttitudeDeg>, run| {
                let peak = peak.unwrap_or_default();
                Some(PeakAttitudeDeg {
                    phi: peak.phi.max(run.phi),
                    theta: peak.theta.max(run.theta),
                })
            }),
        aborts: summary.runs.iter().filter(|run| run.aborted).count(),
        records: summary.runs.len(),
        folder: folder.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fly::summary::{FromTrimDeg, HoldFraction, RunSummary};

    fn run(axis: &str, phi: f64, aborted: bool, lon: Option<f64>) -> RunSummary {
        RunSummary {
            axis: axis.into(),
            index: 1,
            file: format!("{axis}-1.bin"),
            omega_min: 0.2,
            omega_max: 31.4,
            duration_s: 90.0,
            frames: 1,
            aborted,
            abort_reason: aborted.then(|| "attitude_limit".into()),
            max_abs_deg: MaxAbsDeg {
                phi,
                theta: phi / 2.0,
                psi: 0.0,
            },
            // A trim rolled 4° to the left: the excursions from it are the absolute
            // attitude shifted.
            max_from_trim_deg: Some(FromTrimDeg {
                phi: phi - 4.0,
                theta: phi / 4.0,
            }),
            hold_fraction: HoldFraction::default(),
            cross_coherence: lon.map(|c| ("lon".to_string(), c)).into_iter().collect(),
            estimator: None,
            after: None,
        }
    }

    #[test]
    fn mode_summary_takes_peaks_aborts_and_lateral_coherence() {
        let fly = FlySummary {
            vehicle: "bo105".into(),
            mode: "cah".into(),
            rate_hz: 200,
            seed: 1,
            link: "in-process".into(),
            plant: "nonlinear".into(),
            runs: vec![
                run("lat", 3.0, false, Some(0.1)),
                run("lat", 5.0, false, Some(0.3)),
                run("lon", 9.0, true, Some(0.9)),
            ],
        };
        let mode = mode_summary(&fly, "fly-cah");
        let mut no_capture = fly.clone();
        for run in &mut no_capture.runs {
            run.max_from_trim_deg = None;
        }
        assert_eq!(mode_summary(&no_capture, "fly-cah").max_from_trim_deg, None);
        assert!((mode.cross_coherence_lat_lon.unwrap() - 0.2).abs() < 1e-12);
        assert_eq!(mode.max_abs_deg.phi, 9.0);
        assert_eq!(mode.max_abs_deg.theta, 4.5);
        let from_trim = mode.max_from_trim_deg.unwrap();
        assert_eq!((from_trim.phi, from_trim.theta), (5.0, 2.25));
        assert_eq!(mode.aborts, 1);
        assert_eq!(mode.records, 3);
    }

    /// The fly stages run `fly` on its defaults but for the campaign's settings: those the
    /// campaign's dumps were flown with.
    #[test]
    fn the_fly_stages_take_the_verbs_defaults() {
        use super::super::{CampaignArgs, CampaignLink, TrimPointsArg, QUICK_T_REC_S};
        use crate::vehicle::Vehicle;
        use std::path::Path;
        let args = CampaignArgs {
            vehicle: Vehicle::shipped("trex700l"),
            out: PathBuf::from("campaign"),
            seed: 7,
            quick: true,
            trim_points: TrimPointsArg::On,
            trim_balance: super::super::CampaignTrimBalance::Default,
            amplitude: AmplitudeArg::Adaptive,
            fc: CampaignLink::InProcess,
            strict: false,
            quiet: true,
            priors: None,
        };
        let run = Campaign::new(&args);
        let sweeps = run
            .fly_args(ModeArg::Standard, InputArg::Sweep, 7, "fly-standard")
            .unwrap();
        assert_eq!(sweeps.vehicle, Vehicle::shipped("trex700l"));
        assert_eq!(sweeps.mode, ModeArg::Standard);
        assert_eq!(sweeps.amplitude, AmplitudeArg::Adaptive);
        assert_eq!((sweeps.seed, sweeps.t_rec_s), (7, QUICK_T_REC_S));
        assert_eq!(sweeps.axes, sweephold_protocol::Axis::ALL.to_vec());
        assert_eq!(sweeps.rate_hz, 200);
        assert_eq!(sweeps.fc, crate::fly::FcArg::InProcess);
        assert_eq!(sweeps.out, Path::new("campaign/fly-standard"));
        assert!(sweeps.quiet && !sweeps.perfect_sensors && !sweeps.linearized_plant);
        assert_eq!(
            (
                sweeps.gust,
                sweeps.sensor_dropout,
                sweeps.sensor_spike,
                sweeps.pilot_noise
            ),
            (0.0, 0.0, 0.0, 0.0)
        );
        assert!(sweeps.pilot_override_at_s.is_none() && sweeps.elf.is_none());
        let board = CampaignArgs {
            fc: CampaignLink::BoardSim(None),
            ..args.clone()
        };
        let on_the_board = Campaign::new(&board)
            .fly_args(ModeArg::Cah, InputArg::Sweep, 7, "fly-cah")
            .unwrap();
        assert_eq!(on_the_board.fc, crate::fly::FcArg::BoardSim(None));
        // The board-sim link's own flags keep fly's defaults (vibration on, no faults);
        // the stage is one power-up.
        assert!(on_the_board.vibration.is_none() && on_the_board.imu_fault.is_none());
        // An adaptive sweep is no entry of the test list: a power-up per record; fixed
        // sweeps and the doublets fly each stage on one power-up.
        assert_eq!(on_the_board.power_up, None);
        assert_eq!(sweeps.power_up, None);
        let fixed = CampaignArgs {
            amplitude: AmplitudeArg::Fixed,
            ..board.clone()
        };
        let fixed = Campaign::new(&fixed);
        for input in [InputArg::Sweep, InputArg::Doublet] {
            let stage = fixed.fly_args(ModeArg::Cah, input, 7, "fly-cah").unwrap();
            assert_eq!(stage.power_up, Some(crate::fly::PowerUpArg::Once));
        }
        let doublets = run
            .fly_args(ModeArg::Cah, InputArg::Doublet, 8, "verify-doublet")
            .unwrap();
        assert_eq!(doublets.amplitude, AmplitudeArg::Fixed);
    }

    fn flown(trims: Vec<Option<[f32; 2]>>) -> FlownMode {
        FlownMode {
            mode: ModeArg::Cah,
            dumps: trims.iter().map(|_| PathBuf::from("x.bin")).collect(),
            records: Vec::new(),
            trims,
        }
    }

    #[test]
    fn the_captured_trim_is_the_mean_over_the_records_that_captured_one() {
        let trim = flown(vec![Some([-0.04, 0.03]), None, Some([-0.06, 0.05])])
            .captured_trim()
            .unwrap();
        assert!((trim.phi + 0.05).abs() < 1e-7, "{trim:?}");
        assert!((trim.theta - 0.04).abs() < 1e-7, "{trim:?}");
        assert_eq!(flown(vec![None, None]).captured_trim(), None);
        assert_eq!(flown(Vec::new()).captured_trim(), None);
    }
}
