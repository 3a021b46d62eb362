//! The margins stage: `sweephold margins` on the campaign's `model9.json` with the
//! campaign's vehicle — `margins.json` (the figures and their spreads) and
//! `margins-loops.json` (the nominal loops sampled for the report's Bode plots).

use std::ffi::OsString;

use super::{verb_args, Campaign};
use crate::artifacts::files;
use crate::margins::{analyse, MarginsArgs};
use crate::output::write_json;

/// Models drawn for the spreads with `--quick` (the verb's default, 200, without it).
pub const QUICK_SAMPLES: usize = 40;

/// Frequencies of the loops sampled for the report's plots: the Bode plots need a few
/// hundred points, not the analysis grid's 2400 (the figures come from margins.json).
pub const PLOTTED_POINTS: usize = 400;

impl Campaign<'_> {
    /// The margins stage: the figures of `model9.json` under the vehicle's board law.
    pub(super) fn margins(&mut self) -> anyhow::Result<((), String)> {
        let model = self.dir().join(files::MODEL_9DOF);
        let argv: Vec<OsString> = vec![model.into()];
        // The verb's defaults (the shipped board's law, seed 1), with the campaign's
        // vehicle and, for a quick campaign, fewer draws.
        let mut args: MarginsArgs = verb_args("margins", argv)?;
        args.vehicle = Some(self.args.vehicle.clone());
        if self.args.quick {
            args.samples = QUICK_SAMPLES;
        }
        let analysis = analyse(&args)?;
        write_json(&self.dir().join(files::MARGINS), &analysis.result)?;
        write_json(
            &self.dir().join(files::MARGINS_LOOPS),
            &analysis.sampled(Some(PLOTTED_POINTS))?,
        )?;
        Ok(((), headline(&analysis.result)))
    }
}

/// The stage's progress line: the least phase and gain margins over the loops, and the
/// ADS-33 levels (tracking/other) per stick.
fn headline(result: &control::MarginsDocument) -> String {
    let least = |pick: &dyn Fn(&control::analysis::LoopFigures) -> Option<f64>| {
        result
            .loops
            .iter()
            .filter_map(|l| pick(l).map(|v| (v, l.name)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    let pm = least(&|l| l.min_phase_margin_deg.value)
        .map_or("-".to_string(), |(v, name)| format!("{v:.1} deg ({name})"));
    let gm = least(&|l| l.gain_margin_db.value)
        .map_or("-".to_string(), |(v, name)| format!("{v:.1} dB ({name})"));
    let level = |l: Option<u8>| l.map_or("-".to_string(), |l| l.to_string());
    let levels: Vec<String> = result
        .handling
        .iter()
        .map(|h| {
            format!(
                "{} {} {}/{}",
                h.axis,
                match h.mode {
                    control::law::LoopMode::Rate => "rate",
                    control::law::LoopMode::Level => "level",
                },
                level(h.level_tracking),
                level(h.level_other)
            )
        })
        .collect();
    format!(
        "least PM {pm}, least GM {gm}; ADS-33 levels T/O {}",
        levels.join(", ")
    )
}
