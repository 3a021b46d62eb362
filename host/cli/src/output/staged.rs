//! Rule 3 of [`crate::output`]: a folder of results is built beside its destination and
//! replaced whole ([`StagedFolder`]).

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

/// A results folder built beside its destination and swapped in whole.
///
/// `DIR.partial` is where the run writes ([`StagedFolder::path`]). On
/// [`StagedFolder::complete`] the previous `DIR` (if any) is moved aside, `DIR.partial`
/// renamed to `DIR`, and the previous one removed. On [`StagedFolder::fail`] the staging
/// folder becomes `DIR.failed` (replacing an older one) and `DIR` is left as it was.
/// One run at a time per destination: `DIR.lock` ([`crate::run_lock`]) is taken before
/// anything is touched, so a second run on DIR is refused while the first runs; a
/// staging folder left by a run that was killed is cleared by the next run.
///
/// Only a folder that holds a previous run (its `summary.json`) or nothing is replaced:
/// a destination holding other files is refused, so a mistyped `--out ~` cannot remove
/// a home folder.
pub struct StagedFolder {
    destination: PathBuf,
    staging: PathBuf,
    /// `DIR.partial`, removed by a run ended at once by a signal (`interrupt`).
    _registration: crate::interrupt::Registration,
    /// `DIR.lock`, held until the run is swapped in or kept as failed.
    _lock: crate::run_lock::RunLock,
}

/// The file whose presence marks a folder as a previous run's.
pub(super) const RUN_MARKER: &str = "summary.json";

impl StagedFolder {
    /// Prepare `DIR.partial` (empty) for a run whose results go to `destination`.
    pub fn begin(destination: &Path) -> anyhow::Result<StagedFolder> {
        let lock = crate::run_lock::RunLock::acquire(destination, &sibling(destination, "lock")?)?;
        if destination.exists() {
            if !destination.is_dir() {
                bail!(
                    "output folder {}: exists and is not a folder",
                    destination.display()
                );
            }
            let empty = fs::read_dir(destination)
                .with_context(|| format!("cannot read output folder {}", destination.display()))?
                .next()
                .is_none();
            if !empty && !destination.join(RUN_MARKER).is_file() {
                bail!(
                    "output folder {} holds files that are not a sweephold run (no {RUN_MARKER}): \
                     choose a new or empty folder",
                    destination.display()
                );
            }
        }
        let staging = sibling(destination, "partial")?;
        remove_if_present(&staging)?;
        fs::create_dir_all(&staging)
            .with_context(|| format!("cannot create output folder {}", staging.display()))?;
        Ok(StagedFolder {
            destination: destination.to_path_buf(),
            _registration: crate::interrupt::register_folder(&staging),
            staging,
            _lock: lock,
        })
    }

    /// Where the run writes its files.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The folder the results end up in.
    pub fn destination(&self) -> &Path {
        &self.destination
    }

    /// Swap the completed run in for the previous one.
    pub fn complete(self) -> anyhow::Result<()> {
        let previous = sibling(&self.destination, "previous")?;
        remove_if_present(&previous)?;
        let had_previous = self.destination.exists();
        if had_previous {
            fs::rename(&self.destination, &previous).with_context(|| {
                format!(
                    "cannot move the previous {} aside",
                    self.destination.display()
                )
            })?;
        }
        if let Err(error) = fs::rename(&self.staging, &self.destination) {
            if had_previous {
                // Put the previous results back: the run's stay in DIR.partial.
                let _ = fs::rename(&previous, &self.destination);
            }
            return Err(error).with_context(|| {
                format!(
                    "cannot move {} to {}",
                    self.staging.display(),
                    self.destination.display()
                )
            });
        }
        if had_previous {
            remove_if_present(&previous)?;
        }
        Ok(())
    }

    /// Keep the failed run's files as `DIR.failed`; returns that path.
    pub fn fail(self) -> anyhow::Result<PathBuf> {
        let failed = sibling(&self.destination, "failed")?;
        remove_if_present(&failed)?;
        fs::rename(&self.staging, &failed).with_context(|| {
            format!(
                "cannot move {} to {}",
                self.staging.display(),
                failed.display()
            )
        })?;
        Ok(failed)
    }
}

/// `DIR.<suffix>` beside `dir`.
pub(crate) fn sibling(dir: &Path, suffix: &str) -> anyhow::Result<PathBuf> {
    let name = dir
        .file_name()
        .filter(|n| !n.is_empty() && *n != "." && *n != "..")
        .ok_or_else(|| anyhow::anyhow!("output folder {}: needs a folder name", dir.display()))?;
    let mut sibling = name.to_os_string();
    sibling.push(format!(".{suffix}"));
    Ok(dir.with_file_name(sibling))
}

fn remove_if_present(dir: &Path) -> anyhow::Result<()> {
    match fs::remove_dir_all(dir) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("cannot remove {}", dir.display()))
        }
        _ => Ok(()),
    }
}
