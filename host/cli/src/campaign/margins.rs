//! The margins stage: `sweephold margins` on the campaign's `model9.json` with the
//! campaign's vehicle — `margins.json` (the figures and their spreads) and
//! `margins-loops.json` (the nominal loops sampled for the report's Bode plots).

use std::ffi::OsString;

use super::{verb_args, Campaign};
use crate::artifacts::files;
use crate::margins::{write_stage_files, MarginsArgs};

/// Models drawn for the spreads with `--quick`.
pub const QUICK_SAMPLES: usize = 40;

pub use crate::margins::{PLOTTED_POINTS, STAGE_SAMPLES as CAMPAIGN_SAMPLES};

impl Campaign<'_> {
    /// The margins stage: the figures of `model9.json` under the vehicle's board law
    /// ([`crate::margins::write_stage_files`]).
    pub(super) fn margins(&mut self) -> anyhow::Result<((), String)> {
        let model = self.dir().join(files::MODEL_9DOF);
        let argv: Vec<OsString> = vec![model.into()];
        // The verb's defaults (the shipped board's law, seed 1), with the campaign's
        // vehicle and fewer draws.
        let mut args: MarginsArgs = verb_args("margins", argv)?;
        args.vehicle = Some(self.args.vehicle.clone());
        args.samples = if self.args.quick {
            QUICK_SAMPLES
        } else {
            CAMPAIGN_SAMPLES
        };
        let line = write_stage_files(self.dir(), &args)?;
        Ok(((), line))
    }
}

#[cfg(test)]
mod tests {
    use super::super::{CampaignArgs, CampaignLink, CampaignTrimBalance, TrimPointsArg};
    use super::*;
    use crate::artifacts::stage::Stage;
    use crate::fly::AmplitudeArg;
    use crate::vehicle::Vehicle;

    /// The stage writes both files for a model it can take, and leaves them out with its
    /// reason, without failing the campaign, for one it cannot.
    #[test]
    fn the_stage_writes_the_figures_or_says_why_not() {
        let dir = std::env::temp_dir().join(format!("sweephold-margins-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let args = CampaignArgs {
            vehicle: Vehicle::shipped("trex700l"),
            out: dir.join("campaign"),
            seed: 1,
            quick: true,
            trim_points: TrimPointsArg::On,
            trim_balance: CampaignTrimBalance::Default,
            amplitude: AmplitudeArg::Fixed,
            fc: CampaignLink::InProcess,
            strict: false,
            quiet: true,
            priors: None,
        };
        let mut run = Campaign::new(&args);
        run.stage(Stage::Setup, Campaign::set_up).unwrap();
        let model = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../control/tests/fixtures/trex700l-quick-seed1-model9.json");
        std::fs::copy(model, run.dir().join(files::MODEL_9DOF)).unwrap();
        let ((), line) = run.margins().unwrap();
        assert!(line.contains("ADS-33 levels"), "{line}");
        let written: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(run.dir().join(files::MARGINS)).unwrap())
                .unwrap();
        assert_eq!(written["samples"], QUICK_SAMPLES);
        let loops: crate::margins::ExportedLoops = serde_json::from_str(
            &std::fs::read_to_string(run.dir().join(files::MARGINS_LOOPS)).unwrap(),
        )
        .unwrap();
        assert_eq!(loops.loops.len(), 6);
        assert!(loops.loops.iter().all(|l| l.omega.len() == PLOTTED_POINTS));

        std::fs::remove_file(run.dir().join(files::MARGINS)).unwrap();
        std::fs::write(run.dir().join(files::MODEL_9DOF), "{\"version\": 1}").unwrap();
        let ((), line) = run.margins().unwrap();
        assert!(line.starts_with("not computed: "), "{line}");
        assert!(!run.dir().join(files::MARGINS).exists());
        drop(run);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
