//! Everything the report draws, read from the campaign folder: `summary.json`, `frf.json`,
//! `model9.json`, `truth-model9.json`, `verify.json`, `margins.json` and
//! `margins-loops.json`, and what it draws from the dumps (the
//! sweep time history and the cross-control coherence curves): handed over by the
//! campaign, or decoded from the dumps when the report is made from the folder alone.
//!
//! A folder `sweephold identify` wrote is told apart by its `summary.json`
//! ([`FolderSummary`]): it holds `tests` (every test of the logs read) where a
//! campaign's holds `modes`. Such a folder has neither truth nor flights of its own: the
//! report reads only its documents, and nothing from the dumps.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use sysid::document::FrfDocument;
use sysid::fit::report::ModelMatrices;
use sysid::fit::{Model, PairFit};
use sysid::records::{load_dump, Record};

use crate::artifacts::files;
use crate::artifacts::flown::{lateral_coherence, FlownRecords, ModeCoherence, LATERAL};
use crate::artifacts::identify_summary::IdentifySummary;
use crate::artifacts::summary::{CampaignSummary, FitSummary, VerifySummary};
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

/// The `summary.json` of the folder, which says what kind of folder it is.
#[derive(Clone, Debug)]
pub enum FolderSummary {
    /// Written by `sweephold campaign`: flights in the simulator, scored against its truth.
    Campaign(CampaignSummary),
    /// Written by `sweephold identify`: logs alone, no truth.
    Identify(IdentifySummary),
}

impl FolderSummary {
    /// The final fit's section, once fitted.
    pub fn fit(&self) -> Option<&FitSummary> {
        match self {
            FolderSummary::Campaign(s) => s.fit.as_ref(),
            FolderSummary::Identify(s) => s.fit.as_ref(),
        }
    }

    /// The verification's section, once verified.
    pub fn verify(&self) -> Option<&VerifySummary> {
        match self {
            FolderSummary::Campaign(s) => s.verify.as_ref(),
            FolderSummary::Identify(s) => s.verify.as_ref(),
        }
    }

    /// The campaign's summary; `None` for an identify folder.
    pub fn campaign(&self) -> Option<&CampaignSummary> {
        match self {
            FolderSummary::Campaign(s) => Some(s),
            FolderSummary::Identify(_) => None,
        }
    }

    /// Whether the folder's model is compared with a truth (a campaign's, whether or not
    /// its truth stage completed): the sections draw their truth columns, curves and
    /// notes only then.
    pub fn has_truth(&self) -> bool {
        matches!(self, FolderSummary::Campaign(_))
    }

    /// Read `summary.json` at `path`: an identify folder's when it holds `tests` and no
    /// `modes`, else a campaign's.
    fn read(path: &Path) -> Result<FolderSummary, ReportError> {
        let text = std::fs::read_to_string(path).map_err(|e| ReportError::Unreadable {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let parse_error = |e: serde_json::Error| ReportError::Corrupt {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let is_identify = serde_json::from_str::<serde_json::Value>(&text)
            .ok()
            .and_then(|value| {
                value
                    .as_object()
                    .map(|o| o.contains_key("tests") && !o.contains_key("modes"))
            })
            .unwrap_or(false);
        if is_identify {
            serde_json::from_str(&text)
                .map(FolderSummary::Identify)
                .map_err(parse_error)
        } else {
            serde_json::from_str(&text)
                .map(FolderSummary::Campaign)
                .map_err(parse_error)
        }
    }
}

/// The report's inputs. Files of stages that did not complete are `None` (the sections
/// say so); files that exist but do not parse are an error.
#[derive(Clone, Debug)]
pub struct ReportInputs {
    /// The campaign (or identify) folder.
    pub dir: PathBuf,
    /// `summary.json`.
    pub summary: FolderSummary,
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
        let summary = FolderSummary::read(&dir.join(files::SUMMARY))?;
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
        // An identify folder's report draws only what identify writes.
        let campaign = summary.has_truth();
        let truth_model: Option<TruthModelDocument> = if campaign {
            read_optional(&dir.join(files::TRUTH_MODEL_9DOF))?
        } else {
            None
        };
        if let Some(truth) = &truth_model {
            if truth.model().is_none() {
                return Err(corrupt(
                    &dir.join(files::TRUTH_MODEL_9DOF),
                    "the matrices do not match its states, controls and outputs",
                ));
            }
        }
        let verify = read_optional(&dir.join(files::VERIFY))?;
        // Both campaign and identify folders have the margins stage's files.
        let margins: Option<MarginsFile> = read_optional(&dir.join(files::MARGINS))?;
        if let Some(Err(why)) = margins.as_ref().map(MarginsFile::check) {
            return Err(corrupt(&dir.join(files::MARGINS), why));
        }
        let margins_loops = read_optional(&dir.join(files::MARGINS_LOOPS))?;
        let flown = match (flown, &summary) {
            (Some(flown), _) => flown,
            (None, FolderSummary::Campaign(campaign)) => decode_flown(dir, campaign)?,
            // Nothing is drawn from an identify folder's dumps: they lie outside it.
            (None, FolderSummary::Identify(_)) => FlownRecords::default(),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The kind of a folder is read from its summary.json: `tests` without `modes` is an
    /// identify folder's; anything else is read as a campaign's, with its errors.
    #[test]
    fn the_summary_tells_an_identify_folder_from_a_campaign() {
        let dir =
            std::env::temp_dir().join(format!("sweephold-folder-kind-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("summary.json");
        let read = |text: &str| {
            std::fs::write(&path, text).unwrap();
            FolderSummary::read(&path)
        };
        let identify = r#"{"vehicle": "trex700l", "seed": 1, "tests": [], "sweeps": [],
            "held_out": [], "captured_trim_rad": null, "trim_points": null, "notes": [],
            "fit": null, "verify": null, "timings_s": {}, "error": null}"#;
        assert!(matches!(read(identify), Ok(FolderSummary::Identify(_))));
        let campaign = r#"{"vehicle": "bo105", "link": "in-process", "seed": 1,
            "verification_seed": 2, "t_rec_s": 90.0, "quick": false,
            "modes": {"cah": null, "standard": null, "noise": null},
            "fit": null, "verify": null, "timings_s": {}, "error": null}"#;
        let read_campaign = read(campaign).unwrap();
        assert!(matches!(read_campaign, FolderSummary::Campaign(_)));
        assert!(read_campaign.has_truth());
        // Broken either way: the kind's own parse error.
        let error = read(r#"{"tests": 3}"#).unwrap_err().to_string();
        assert!(
            error.contains("is corrupt") && error.contains("sequence"),
            "{error}"
        );
        let error = read(r#"{"modes": 3}"#).unwrap_err().to_string();
        assert!(error.contains("is corrupt"), "{error}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
