//! Where results go, by three rules every verb follows:
//!
//! 1. **No input is ever an output.** [`refuse_inputs_as_outputs`] runs before any work:
//!    an output path that names one of the inputs (by path, symbolic link or hard link)
//!    is refused, naming both, so `decode X.bin -o X.bin` cannot truncate the telemetry
//!    it reads. The files a verb names itself inside an output folder (`--plots DIR`,
//!    `report DIR`'s report.html) are checked the same way ([`write_files_into`],
//!    [`write_file_in_folder`]), and are never written *through* a symbolic link: the
//!    rename replaces a link found there, never its target. A path given on the command
//!    line (`-o FILE`, `--out FILE`) that is a link is written through, to its target (so
//!    `-o /dev/stdout` and a link to another disk work), once that target was checked
//!    against the inputs.
//! 2. **Files appear whole or not at all.** [`AtomicFile`] writes into a temporary file
//!    in the destination's folder and renames it over the destination only when
//!    everything was written and synced; a failure or an interruption leaves the earlier
//!    file as it was and no half file.
//! 3. **A folder of results is replaced whole.** [`StagedFolder`] builds a run's folder
//!    beside the destination (`DIR.partial`) and swaps it in only when the run completes,
//!    so a failed run leaves the previous complete one readable; the failed run's files
//!    are kept as `DIR.failed` for inspection.
//!
//! Standard output takes one path too: [`print()`] or [`StdoutWriter`], whose write
//! errors [`stdout_outcome`] (applied by `crate::run` to every verb) turns into a
//! one-line `cannot write to standard output: …` (exit 1), never a panic. A reader that
//! went away (`| head`, a broken pipe) is not a failure of the work: the verb stops
//! writing and exits 0, as `head` expects.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

mod staged;

pub(crate) use staged::sibling;
pub use staged::StagedFolder;

/// A write to standard output failed. Kept apart from the other I/O errors (reading an
/// input is one too) so that [`stdout_outcome`] can recognise it under any context.
#[derive(Debug)]
pub struct StdoutFailed(io::Error);

impl std::fmt::Display for StdoutFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot write to standard output: {}", io_reason(&self.0))
    }
}

impl std::error::Error for StdoutFailed {}

/// Standard output, locked, with its write errors marked as [`StdoutFailed`]. Every byte
/// a verb sends to standard output goes through one of these (or [`print()`]).
pub struct StdoutWriter(io::StdoutLock<'static>);

impl StdoutWriter {
    /// Lock standard output for this writer.
    pub fn lock() -> StdoutWriter {
        StdoutWriter(io::stdout().lock())
    }
}

impl Write for StdoutWriter {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf).map_err(mark_stdout)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.0.flush().map_err(mark_stdout)
    }
}

fn mark_stdout(error: io::Error) -> io::Error {
    io::Error::new(error.kind(), StdoutFailed(error))
}

/// `eprintln!` that never panics: progress and warnings on standard error are best
/// effort, and a standard error that cannot be written (full, closed) loses the line
/// instead of ending the run with a panic (exit 101). The crate denies `eprintln!`
/// (`clippy::print_stderr` in `lib.rs`) so that every line goes through here.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// [`note!`] without the line end (`eprint!`).
#[macro_export]
macro_rules! note_text {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stderr(), $($arg)*);
    }};
}

/// Write `text` to standard output and flush it.
pub fn print(text: &str) -> anyhow::Result<()> {
    let mut out = StdoutWriter::lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(anyhow::Error::from)
}

/// A verb's result with its standard-output failures made plain: a closed reader (broken
/// pipe) is success, any other write error becomes the one line `cannot write to
/// standard output: …` whatever context was added above it; other errors pass as they are.
pub fn stdout_outcome(result: anyhow::Result<()>) -> anyhow::Result<()> {
    let Err(error) = result else {
        return Ok(());
    };
    let failed = error.chain().find_map(|cause| {
        cause.downcast_ref::<StdoutFailed>().or_else(|| {
            cause
                .downcast_ref::<io::Error>()
                .and_then(|e| e.get_ref())
                .and_then(|inner| inner.downcast_ref::<StdoutFailed>())
        })
    });
    match failed {
        Some(failed) if failed.0.kind() == io::ErrorKind::BrokenPipe => Ok(()),
        Some(failed) => Err(anyhow::anyhow!("{failed}")),
        None => Err(error),
    }
}

/// Refuse, before anything is written, an output that is one of the inputs.
///
/// `inputs` and `outputs` are `(role, path)` pairs, e.g. `("--output", path)`; the
/// message names the output's role. Outputs that do not exist yet cannot be an input
/// (every input is opened before this is called) and are compared by their would-be
/// canonical path. Hard links are caught by device and inode number.
pub fn refuse_inputs_as_outputs(inputs: &[&Path], outputs: &[(&str, &Path)]) -> anyhow::Result<()> {
    let inputs: Vec<(&Path, PathBuf, Option<FileId>)> = inputs
        .iter()
        .map(|p| (*p, absolute(p), FileId::of(p)))
        .collect();
    for (role, output) in outputs {
        let (path, id) = (absolute(output), FileId::of(output));
        for (given, input, input_id) in &inputs {
            let same_id = matches!((&id, input_id), (Some(a), Some(b)) if a == b);
            if *input == path || same_id {
                let is_link = fs::symlink_metadata(output).is_ok_and(|m| m.is_symlink());
                if is_link {
                    bail!(
                        "{role} {} is a symbolic link to {}, one of the inputs: refusing to \
                         write through it",
                        output.display(),
                        given.display()
                    );
                }
                bail!(
                    "{role} {} is one of the inputs ({}): refusing to overwrite it",
                    output.display(),
                    given.display()
                );
            }
        }
    }
    Ok(())
}

/// `path` made absolute with every existing part resolved (links followed): its
/// deepest existing ancestor canonicalized, the rest appended.
fn absolute(path: &Path) -> PathBuf {
    let joined = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().map_or_else(|_| path.to_path_buf(), |cwd| cwd.join(path))
    };
    let mut missing = Vec::new();
    let mut existing = joined.as_path();
    loop {
        if let Ok(canonical) = existing.canonicalize() {
            return missing
                .iter()
                .rev()
                .fold(canonical, |acc: PathBuf, part| acc.join(part));
        }
        match (existing.parent(), existing.file_name()) {
            (Some(parent), Some(name)) => {
                missing.push(name.to_os_string());
                existing = parent;
            }
            _ => return joined,
        }
    }
}

/// The identity of an existing file: device and inode on Unix (hard links share it).
#[derive(PartialEq, Eq)]
struct FileId(u64, u64);

impl FileId {
    #[cfg(unix)]
    fn of(path: &Path) -> Option<FileId> {
        use std::os::unix::fs::MetadataExt;
        fs::metadata(path).ok().map(|m| FileId(m.dev(), m.ino()))
    }

    #[cfg(not(unix))]
    fn of(_path: &Path) -> Option<FileId> {
        None
    }
}

/// A file written atomically: bytes go to a temporary file in the destination's folder
/// (same file system, so the final rename is atomic) and replace the destination only on
/// [`AtomicFile::commit`]. Dropped without a commit, the temporary file is removed and
/// the destination is untouched. A destination that is a symbolic link has its target
/// replaced, the link staying ([`AtomicFile::create`]), or the link itself replaced
/// ([`AtomicFile::create_not_through_links`]); one that is a device, pipe or socket (`/dev/null`,
/// `/dev/stdout`, a FIFO) is written in place, since a rename would put a plain file
/// where the device was.
pub struct AtomicFile {
    destination: PathBuf,
    file: BufWriter<Output>,
    /// The temporary file, removed by a run ended at once by a signal (`interrupt`).
    _registration: Option<crate::interrupt::Registration>,
}

/// Where an [`AtomicFile`]'s bytes go until the commit.
enum Output {
    /// A temporary file renamed over the destination on commit.
    Temporary(tempfile::NamedTempFile),
    /// The destination itself (not a regular file: written in place).
    InPlace(fs::File),
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            Output::Temporary(file) => file.write(buf),
            Output::InPlace(file) => file.write(buf),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self {
            Output::Temporary(file) => file.flush(),
            Output::InPlace(file) => file.flush(),
        }
    }
}

/// How a destination path is written.
#[derive(Debug, PartialEq, Eq)]
enum Destination {
    /// A regular file, or nothing yet, at this path (links resolved): replaced by rename.
    Replace(PathBuf),
    /// A device, pipe or socket: written in place.
    InPlace,
}

impl Destination {
    /// Classify `path` without touching it. With `Links::Replace` a symbolic link is
    /// itself the destination (the rename replaces the link, not its target).
    fn of(path: &Path, links: Links) -> anyhow::Result<Destination> {
        if links == Links::Replace && fs::symlink_metadata(path).is_ok_and(|m| m.is_symlink()) {
            return Ok(Destination::Replace(path.to_path_buf()));
        }
        match fs::metadata(path) {
            Ok(meta) if meta.is_dir() => bail!("cannot write {}: it is a folder", path.display()),
            Ok(meta) if meta.is_file() => Ok(Destination::Replace(
                fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
            )),
            Ok(_) => Ok(Destination::InPlace),
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                Ok(Destination::Replace(path.to_path_buf()))
            }
            Err(e) => Err(e).with_context(|| format!("cannot write {}", path.display())),
        }
    }
}

/// What an [`AtomicFile`] does with a destination that is a symbolic link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Links {
    /// Write the link's target (a path the user named: `-o /dev/stdout`).
    Follow,
    /// Replace the link itself (a file the verb names inside an output folder).
    Replace,
}

impl AtomicFile {
    /// Start writing `destination` (its folder must exist); a symbolic link there has its
    /// target written (for paths given on the command line, checked by
    /// [`refuse_inputs_as_outputs`]).
    pub fn create(destination: &Path) -> anyhow::Result<AtomicFile> {
        AtomicFile::create_with(destination, Links::Follow)
    }

    /// Start writing `destination`, never through a link: a symbolic link at that path is
    /// replaced by the new file on commit, its target left alone.
    pub fn create_not_through_links(destination: &Path) -> anyhow::Result<AtomicFile> {
        AtomicFile::create_with(destination, Links::Replace)
    }

    fn create_with(destination: &Path, links: Links) -> anyhow::Result<AtomicFile> {
        let target = match Destination::of(destination, links)? {
            Destination::InPlace => {
                let file = fs::OpenOptions::new()
                    .write(true)
                    .open(destination)
                    .with_context(|| format!("cannot write {}", destination.display()))?;
                return Ok(AtomicFile {
                    destination: destination.to_path_buf(),
                    file: BufWriter::with_capacity(256 * 1024, Output::InPlace(file)),
                    _registration: None,
                });
            }
            Destination::Replace(target) => target,
        };
        let folder = match target.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent,
            _ => Path::new("."),
        };
        let name = target
            .file_name()
            .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // The mode a plain `File::create` gives (0666 less the umask), not the private
        // 0600 of a temporary file: the result is an ordinary output file.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(fs::Permissions::from_mode(0o666));
        }
        let file = builder
            .tempfile_in(folder)
            .with_context(|| format!("cannot create {}", destination.display()))?;
        let registration = crate::interrupt::register_file(file.path());
        Ok(AtomicFile {
            destination: target,
            file: BufWriter::with_capacity(256 * 1024, Output::Temporary(file)),
            _registration: Some(registration),
        })
    }

    /// Flush, sync and rename over the destination (or, in place, flush).
    pub fn commit(self) -> anyhow::Result<()> {
        crate::interrupt::pause_point("write");
        let destination = self.destination;
        let context = || format!("cannot write {}", destination.display());
        let output = self
            .file
            .into_inner()
            .map_err(|e| e.into_error())
            .with_context(context)?;
        match output {
            Output::Temporary(file) => {
                file.as_file().sync_all().with_context(context)?;
                file.persist(&destination)
                    .map_err(|e| e.error)
                    .with_context(context)?;
            }
            Output::InPlace(mut file) => file.flush().with_context(context)?,
        }
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

/// Write `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)
        .with_context(|| format!("cannot write {}", path.display()))?;
    file.commit()
}

/// Write `value` as pretty JSON (and a final newline) to `path`, atomically.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    let mut text = serde_json::to_string_pretty(value)?;
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// Write `files` (`(name, text)`, e.g. rendered plots) into the folder `dir`, creating it;
/// each file atomically and never through a symbolic link. Before anything is written, a
/// file that would land on one of `inputs` (a link to an input placed in `dir`) is
/// refused, naming both. Returns how many were written.
pub fn write_files_into(
    role: &str,
    dir: &Path,
    files: &[(String, String)],
    inputs: &[&Path],
) -> anyhow::Result<usize> {
    check_output_folder(role, dir)?;
    let paths: Vec<PathBuf> = files.iter().map(|(name, _)| dir.join(name)).collect();
    let outputs: Vec<(&str, &Path)> = paths.iter().map(|p| (role, p.as_path())).collect();
    refuse_inputs_as_outputs(inputs, &outputs)?;
    fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (path, (_, text)) in paths.iter().zip(files) {
        write_file_in_folder(path, text.as_bytes())?;
    }
    Ok(files.len())
}

/// Write `bytes` to `path`, a file a verb names inside an output folder: atomically, and
/// never through a symbolic link (a link at `path` is replaced, its target untouched).
pub fn write_file_in_folder(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let mut file = AtomicFile::create_not_through_links(path)?;
    file.write_all(bytes)
        .with_context(|| format!("cannot write {}", path.display()))?;
    file.commit()
}

/// Refuse a `--plots`-style output folder that exists as something else than a folder,
/// before any work is done.
pub fn check_output_folder(role: &str, dir: &Path) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{role} {}: exists and is not a folder", dir.display());
    }
    Ok(())
}

/// Refuse an input that is missing, a folder or unreadable, with a one-line message
/// naming its role (e.g. `--model`).
pub fn check_input_file(role: &str, path: &Path) -> anyhow::Result<()> {
    match fs::metadata(path) {
        Ok(meta) if meta.is_dir() => bail!("{role} {} is a folder, not a file", path.display()),
        Ok(_) => Ok(()),
        Err(e) => bail!("cannot read {role} {}: {}", path.display(), io_reason(&e)),
    }
}

/// An I/O error's reason without the "(os error N)" suffix.
pub fn io_reason(error: &io::Error) -> String {
    match error.kind() {
        io::ErrorKind::NotFound => "no such file".to_string(),
        io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        _ => {
            let text = error.to_string();
            text.split(" (os error").next().unwrap_or(&text).to_string()
        }
    }
}

#[cfg(test)]
mod tests;
