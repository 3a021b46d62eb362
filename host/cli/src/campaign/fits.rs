//! The identification stages of the campaign: the trim points (the simulator's steady
//! flights, optional), then the stages it shares with `sweephold identify`
//! ([`crate::identify::stages`]: frequency responses, 6-DOF and 9-DOF fits,
//! verification) on what the fly stages handed over.

use anyhow::anyhow;
use sysid::document::FrfDocument;
use sysid::fit::trim::TrimPoints;
use sysid::fit::{FitResult, Model};
use sysid::frf::Record;
use sysid::records::load_test_dump;

use super::{Campaign, TrimPointsArg};
use crate::artifacts::files;
use crate::artifacts::stage::Stage;
use crate::campaign::error::CampaignError;
use crate::identify::stages::{Pipeline, Responses};
use crate::output::write_atomic;
use truth::TrimAttitude;

impl Campaign<'_> {
    /// The shared stages for this campaign: its folder, aircraft, seed and trim balance.
    fn pipeline(&self) -> Pipeline<'_> {
        Pipeline {
            dir: self.dir(),
            vehicle: self.args.priors_vehicle(),
            seed: self.args.seed,
            trim_balance: self
                .args
                .trim_balance
                .for_vehicle(self.args.priors_vehicle()),
        }
    }

    /// The frf stage: the responses of `records` (the `cah` sweeps), `frf.json`.
    pub(super) fn frequency_responses(
        &mut self,
        records: Vec<Record>,
    ) -> anyhow::Result<(Responses, String)> {
        if records.is_empty() {
            return Err(anyhow!("every cah record aborted: nothing to identify"));
        }
        self.pipeline().frequency_responses(records)
    }

    /// The trim points stage, when the campaign uses them (`--trim-points`): the
    /// simulator's steady flights, `trim-points.csv`.
    pub(super) fn trim_points(&mut self) -> Result<Option<TrimPoints>, CampaignError> {
        if self.args.trim_points == TrimPointsArg::Off {
            return Ok(None);
        }
        self.stage(Stage::TrimPoints, |run| {
            let vehicle = &run.args.vehicle;
            let points = crate::sim::simulator_trim_points(&vehicle.helicopter(), vehicle.name())?;
            write_atomic(
                &run.dir().join(files::TRIM_POINTS),
                points.to_csv().as_bytes(),
            )?;
            let line = format!("{} steady flights", points.points.len());
            Ok((Some(points), line))
        })
    }

    /// The 6-DOF stage, `model6.json`.
    pub(super) fn fit_6dof(&mut self, frf: &FrfDocument) -> anyhow::Result<(FitResult, String)> {
        self.pipeline().fit_6dof(frf)
    }

    /// The 9-DOF stage, `model9.json` and the summary's `fit` section.
    pub(super) fn fit_9dof(
        &mut self,
        trim: Option<TrimAttitude>,
        frf: &FrfDocument,
        six: &FitResult,
        trim_points: &Option<TrimPoints>,
    ) -> anyhow::Result<(FitResult, String)> {
        let (result, summary, line) = self.pipeline().fit_9dof(trim, frf, six, trim_points)?;
        self.summary.fit = Some(summary);
        Ok((result, line))
    }

    /// The verify stage: `model` (the final fit) on the `doublets` (files relative to the
    /// campaign folder), `verify.json` and the summary's `verify` section.
    pub(super) fn verify(
        &mut self,
        model: &Model,
        doublets: &[String],
    ) -> anyhow::Result<((), String)> {
        let records = doublets
            .iter()
            .map(|file| {
                let record = load_test_dump(self.dir().join(file)).map_err(|e| anyhow!("{e}"))?;
                Ok((file.clone(), record))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let (summary, line) = self.pipeline().verify(model, &records)?;
        self.summary.verify = Some(summary);
        Ok(((), line))
    }
}
