//! Everything the report draws, read from the campaign folder: `summary.json`, `frf.json`,
//! `model9.json`, `truth-model9.json`, `verify.json`, `margins.json` and
//! `margins-loops.json`, and what it draws from the dumps (the
//! sweep time history and the cross-control coherence curves): handed over by the
//! campaign, or decoded from the dumps when the report is made from the folder alone.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use sysid::document::FrfDocument;
use sysid::fit::report::ModelMatrices;
use sysid::fit::{Model, PairFit};
use sysid::records::{load_dump, Record};

use crate::artifacts::files;
use crate::artifacts::flown::{lateral_coherence, FlownRecords, ModeCoherence, LATERAL};
use crate::artifacts::summary::CampaignSummary;
use crate::artifacts::truth_model::TruthModelDocument;
use crate::artifacts::verification::VerifyDocument;
use crate::margins::ExportedLoops;
use crate::report::margins_file::MarginsFile;

/// Why the report cannot be made.
#[derive(Debug)]
pub enum ReportError {
    /// A file the report needs is missing or unreadable.
    Unreadable {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
    /// A file exists but is not what the campaign writes.
    Corrupt {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
    /// `report.html` cannot be written.
    Write {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
}

impl fmt::Display for ReportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReportError::Unreadable { path, message } => {
                write!(f, "cannot read {}: {message}", path.display())
            }
            ReportError::Corrupt { path, message } => {
                write!(f, "{} is corrupt: {message}", path.display())
            }
            ReportError::Write { path, message } => {
                write!(f, "cannot write {}: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for ReportError {}

/// What the report needs of `model9.json`: the model and its fitted pairs.
///
/// Read through this narrow type rather than `ScoredModelDocument`: that one uses
/// `#[serde(flatten)]` (and its flags an internally tagged enum), which cannot read
/// numbers when serde_json's `arbitrary_precision` feature is on somewhere in the build.
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
pub struct FittedModel {
    /// Structure name.
    pub structure: String,
    /// State names.
    pub states: Vec<String>,
    /// Control names.
    pub controls: Vec<String>,
    /// Output names.
    pub outputs: Vec<String>,
    /// M F G H0 H1, row-major.
    pub matrices: ModelMatrices,
    /// Delay per control \[s\].
    pub delays: Vec<f64>,
    /// Known actuator per control (absent: none).
    #[serde(default)]
    pub actuators: Vec<Option<sysid::fit::model::Actuator>>,
    /// J per fitted pair, with its range.
    pub pairs: Vec<PairFit>,
}

impl FittedModel {
    /// The numeric model; `None` when a matrix does not fit the names.
    pub fn model(&self) -> Option<Model> {
        self.matrices.to_model(
            &self.states,
            &self.controls,
            &self.outputs,
            &self.delays,
            &self.actuators,
        )
    }
}

/// The report's inputs. Files of stages that did not complete are `None` (the sections
/// say so); files that exist but do not parse are an error.
#[derive(Clone, Debug)]
pub struct ReportInputs {
    /// The campaign folder.
    pub dir: PathBuf,
    /// `summary.json`.
    pub summary: CampaignSummary,
    /// `frf.json`.
    pub frf: Option<FrfDocument>,
    /// `model9.json` (the parts drawn).
    pub model: Option<FittedModel>,
    /// `truth-model9.json`.
    pub truth_model: Option<TruthModelDocument>,
    /// `verify.json`.
    pub verify: Option<VerifyDocument>,
    /// `margins.json` (absent in campaigns from before the margins stage).
    pub margins: Option<MarginsFile>,
    /// `margins-loops.json`.
    pub margins_loops: Option<ExportedLoops>,
    /// The sweep time history and the cross-control coherence curves.
    pub flown: FlownRecords,
}

fn read_json<T: DeserializeOwned>(path: &Path) -> Result<T, ReportError> {
    let text = std::fs::read_to_string(path).map_err(|e| ReportError::Unreadable {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    serde_json::from_str(&text).map_err(|e| ReportError::Corrupt {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// `read_json` for a file that may legitimately be absent (its stage did not run).
fn read_optional<T: DeserializeOwned>(path: &Path) -> Result<Option<T>, ReportError> {
    if path.exists() {
        read_json(path).map(Some)
    } else {
        Ok(None)
    }
}

fn corrupt(path: &Path, error: impl fmt::Display) -> ReportError {
    ReportError::Corrupt {
        path: path.to_path_buf(),
        message: error.to_string().replace('\n', " "),
    }
}

/// The lateral sweep dumps of a mode folder, in file-name order.
fn lateral_dumps(folder: &Path) -> Vec<PathBuf> {
    let prefix = format!("{LATERAL}-");
    let mut dumps: Vec<PathBuf> = std::fs::read_dir(folder)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with(&prefix) && n.ends_with(".bin"))
                })
                .collect()
        })
        .unwrap_or_default();
    dumps.sort();
    dumps
}

impl ReportInputs {
    /// Read the campaign folder `dir`, decoding its dumps.
    pub fn load(dir: &Path) -> Result<ReportInputs, ReportError> {
        ReportInputs::read(dir, None)
    }

    /// Read the documents of the campaign folder `dir`; the dump-derived inputs are
    /// `flown` when given, else decoded from its dumps.
    pub fn read(dir: &Path, flown: Option<FlownRecords>) -> Result<ReportInputs, ReportError> {
        let summary: CampaignSummary = read_json(&dir.join(files::SUMMARY))?;
        let frf = read_optional(&dir.join(files::FRF))?;
        let model: Option<FittedModel> = read_optional(&dir.join(files::MODEL_9DOF))?;
        if let Some(fitted) = &model {
            if fitted.model().is_none() {
                return Err(corrupt(
                    &dir.join(files::MODEL_9DOF),
                    "the matrices do not match its states, controls and outputs",
                ));
            }
        }
        let truth_model: Option<TruthModelDocument> =
            read_optional(&dir.join(files::TRUTH_MODEL_9DOF))?;
        if let Some(truth) = &truth_model {
            if truth.model().is_none() {
                return Err(corrupt(
                    &dir.join(files::TRUTH_MODEL_9DOF),
                    "the matrices do not match its states, controls and outputs",
                ));
            }
        }
        let verify = read_optional(&dir.join(files::VERIFY))?;
        let margins: Option<MarginsFile> = read_optional(&dir.join(files::MARGINS))?;
        if let Some(Err(why)) = margins.as_ref().map(MarginsFile::check) {
            return Err(corrupt(&dir.join(files::MARGINS), why));
        }
        let margins_loops = read_optional(&dir.join(files::MARGINS_LOOPS))?;
        let flown = match flown {
            Some(flown) => flown,
            None => decode_flown(dir, &summary)?,
        };
        Ok(ReportInputs {
            dir: dir.to_path_buf(),
            summary,
            frf,
            model,
            truth_model,
            verify,
            margins,
            margins_loops,
            flown,
        })
    }
}

/// The dump-derived inputs of the campaign folder `dir`: its lateral sweeps decoded, the
/// first `cah` one kept, each mode's joined into coherence curves.
fn decode_flown(dir: &Path, summary: &CampaignSummary) -> Result<FlownRecords, ReportError> {
    let mut flown = FlownRecords::default();
    let modes = [
        ("cah", summary.modes.cah.as_ref()),
        ("standard", summary.modes.standard.as_ref()),
        ("noise", summary.modes.noise.as_ref()),
    ];
    for (mode, done) in modes {
        let Some(done) = done else { continue };
        let dumps = lateral_dumps(&dir.join(&done.folder));
        if dumps.is_empty() {
            continue;
        }
        let records = dumps
            .iter()
            .map(|path| load_dump(path).map_err(|e| corrupt(path, e)))
            .collect::<Result<Vec<Record>, _>>()?;
        if mode == "cah" {
            flown.sweep = records.first().cloned();
        }
        let folder = dir.join(&done.folder);
        flown.coherence.push(ModeCoherence {
            mode: mode.to_string(),
            curves: lateral_coherence(records).map_err(|e| corrupt(&folder, e))?,
        });
    }
    Ok(flown)
}
