//! A test's own folder, removed when the test is done with it.
//!
//! Each scratch path is `TMP/sweephold-NAME-XXXXXX/NAME`: the outer folder has a unique
//! name made by the `tempfile` crate (already a dependency of the CLI; unique also when
//! the tests of one binary run in parallel, where the process id no longer tells them
//! apart), and is the test's alone. Everything a run puts beside its `--out` (the
//! `OUT.failed` folder a failed run keeps by design, a staging folder, a lock) lands in it,
//! so removing it leaves nothing behind. A test that panics keeps it, and says where, for
//! a look at what the run left.

use std::ops::Deref;
use std::path::{Path, PathBuf};

/// A folder path of one test's own; the folder around it is removed on drop.
pub struct Scratch {
    /// The unique folder holding `path` and its siblings.
    root: PathBuf,
    path: PathBuf,
}

impl Scratch {
    /// An empty folder made for the test.
    pub fn new(name: &str) -> Scratch {
        let scratch = Scratch::unmade(name);
        std::fs::create_dir(&scratch.path).unwrap();
        scratch
    }

    /// A path where nothing is yet, for a folder a run makes (its `--out`).
    pub fn unmade(name: &str) -> Scratch {
        let root = tempfile::Builder::new()
            .prefix(&format!("sweephold-{name}-"))
            .tempdir()
            .unwrap()
            .keep();
        // The real path: a run's folder is compared with the working folders of the
        // processes found running (`fly_signals`), which the system gives resolved.
        let root = root.canonicalize().unwrap();
        let path = root.join(name);
        Scratch { root, path }
    }
}

impl Deref for Scratch {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept for a look: {}", self.root.display());
        } else {
            // A run killed by a test may still be writing there for a moment: a failure to
            // remove is not the test's failure.
            let _ = std::fs::remove_dir_all(&self.root);
        }
    }
}
