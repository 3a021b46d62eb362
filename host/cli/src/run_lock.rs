//! One run at a time per output folder: `DIR.lock` beside `DIR`, held for the whole run
//! of `campaign --out DIR` or `fly --out DIR` (by [`crate::output::StagedFolder`]). A
//! second run on the same folder is refused before it touches anything, so two runs
//! cannot mix their files or clear each other's `DIR.partial`.
//!
//! The lock is an advisory `flock(2)` on the file (nix's `Flock`), which holds the
//! owner's pid for the message. Chosen over a file created with `O_EXCL` whose pid is
//! checked for staleness: the kernel releases a `flock` however the process ends
//! (SIGKILL, a crash), so a lock left by a dead run can never block a new one, and no pid
//! test (pids are reused) decides anything: the file a killed run left is simply locked
//! again. The file is removed while still locked when the run ends; an acquirer that
//! locked a file already removed sees that the path no longer names it and tries again.

use std::fs::{self, File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use nix::errno::Errno;
use nix::fcntl::{Flock, FlockArg};

/// The lock of one output folder, released (and its file removed) when dropped.
pub struct RunLock {
    path: PathBuf,
    /// The file, removed by a run ended at once by a signal (`interrupt`).
    _registration: crate::interrupt::Registration,
    /// Field order matters: dropped after [`Drop::drop`] removed the file.
    _lock: Flock<File>,
}

impl RunLock {
    /// Lock `lock_path` (e.g. `DIR.lock`) for the folder `destination`, or refuse with a
    /// one-line error naming the run that holds it.
    pub fn acquire(destination: &Path, lock_path: &Path) -> anyhow::Result<RunLock> {
        // The folder the results go in may not exist yet (`--out new/deep/DIR`).
        if let Some(parent) = lock_path.parent().filter(|p| !p.as_os_str().is_empty()) {
            fs::create_dir_all(parent)
                .with_context(|| format!("cannot create output folder {}", parent.display()))?;
        }
        // A few rounds at most: each lost round means another run released its lock
        // between our open and our lock.
        for _ in 0..100 {
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(lock_path)
                .with_context(|| format!("cannot create {}", lock_path.display()))?;
            let mut locked = match Flock::lock(file, FlockArg::LockExclusiveNonblock) {
                Ok(locked) => locked,
                Err((mut file, Errno::EWOULDBLOCK)) => {
                    let mut holder = String::new();
                    let _ = file.read_to_string(&mut holder);
                    let holder = match holder.trim() {
                        "" => String::new(),
                        pid => format!(" (pid {pid})"),
                    };
                    bail!(
                        "output folder {} is in use by another sweephold run{holder}: wait \
                         for it to end or choose another folder (lock {})",
                        destination.display(),
                        lock_path.display()
                    );
                }
                Err((_, errno)) => bail!("cannot lock {}: {errno}", lock_path.display()),
            };
            if !names_same_file(lock_path, &locked) {
                continue;
            }
            locked
                .set_len(0)
                .and_then(|()| locked.rewind())
                .and_then(|()| {
                    writeln!(locked, "{}", std::process::id()).and_then(|()| locked.flush())
                })
                .with_context(|| format!("cannot write {}", lock_path.display()))?;
            return Ok(RunLock {
                path: lock_path.to_path_buf(),
                _registration: crate::interrupt::register_file(lock_path),
                _lock: locked,
            });
        }
        bail!("cannot lock {}: it keeps changing", lock_path.display())
    }
}

impl Drop for RunLock {
    fn drop(&mut self) {
        // Removed while still locked: see the module doc.
        let _ = fs::remove_file(&self.path);
    }
}

/// Whether `path` still names the open `file` (same device and inode).
fn names_same_file(path: &Path, file: &File) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (fs::metadata(path), file.metadata()) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_and_a_released_one_is_taken() {
        let dir = std::env::temp_dir().join(format!("sweephold-lock-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        // Its folder is created, as the staging folder's would be.
        let deep = dir.join("new/deep/c");
        drop(RunLock::acquire(&deep, &dir.join("new/deep/c.lock")).unwrap());
        let (out, lock) = (dir.join("c"), dir.join("c.lock"));
        let first = RunLock::acquire(&out, &lock).unwrap();
        let held = fs::read_to_string(&lock).unwrap();
        assert_eq!(held.trim(), std::process::id().to_string());
        let error = RunLock::acquire(&out, &lock).err().unwrap().to_string();
        assert!(error.contains("in use by another sweephold run"), "{error}");
        assert!(
            error.contains(&format!("pid {}", std::process::id())),
            "{error}"
        );
        drop(first);
        assert!(!lock.exists(), "the lock file goes with the run");
        // A file left by a run that was killed (no lock on it) is taken over.
        fs::write(&lock, "4000000\n").unwrap();
        let again = RunLock::acquire(&out, &lock).unwrap();
        drop(again);
        fs::remove_dir_all(&dir).unwrap();
    }
}
