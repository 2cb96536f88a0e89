//! Output files that appear complete or not at all: written under a
//! temporary name in the target's directory (so the final rename stays on
//! one file system) and renamed into place only when finished. A pending
//! file that is dropped without [`PendingFile::commit`] is removed.
//!
//! Every temporary file of the process is also in a registry, so that a
//! process ended by a signal can remove them first
//! ([`remove_pending_files`]; the binary does it on SIGINT and SIGTERM):
//! only a process killed outright (SIGKILL, a crash) leaves `.NAME.partial-*`
//! files behind, and the next run writing the same target reports them
//! ([`unfinished_temporaries`]).
//!
//! A target that exists and is not a regular file (`/dev/null`, a named
//! pipe, a terminal) is written directly: renaming a file over it would
//! replace the device. A target that is a symbolic link is resolved, so the
//! link keeps pointing at the finished file.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{self, BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The temporary files of this process not yet renamed or removed, by
/// registration number.
static PENDING: Mutex<BTreeMap<u64, PathBuf>> = Mutex::new(BTreeMap::new());
static NEXT_REGISTRATION: AtomicU64 = AtomicU64::new(0);

fn registry() -> MutexGuard<'static, BTreeMap<u64, PathBuf>> {
    // The map stays consistent even if a holder panicked.
    PENDING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes every temporary file of this process that is not finished yet,
/// and keeps them from being renamed into place afterwards (a pending file
/// committed from now on waits forever): for a process about to exit on a
/// signal. Returns the files removed.
pub fn remove_pending_files() -> Vec<PathBuf> {
    let guard = registry();
    let mut removed = Vec::new();
    for path in guard.values() {
        if std::fs::remove_file(path).is_ok() {
            removed.push(path.clone());
        }
    }
    // Held until the process exits: no rename can follow the removal.
    std::mem::forget(guard);
    removed
}

/// The temporary files of this process not yet finished (for tests and
/// diagnostics).
pub fn pending_files() -> Vec<PathBuf> {
    registry().values().cloned().collect()
}

/// A file being written next to its target.
#[derive(Debug)]
pub struct PendingFile {
    /// `None` when the target is written directly (not a regular file).
    temp: Option<tempfile::TempPath>,
    target: PathBuf,
    /// Its number in the registry of pending files, when it has a temporary file.
    registration: Option<u64>,
}

impl Drop for PendingFile {
    /// Removes the temporary file (an unfinished output) and its registration.
    fn drop(&mut self) {
        let mut pending = registry();
        if let Some(temp) = self.temp.take() {
            let _ = temp.close();
        }
        if let Some(n) = self.registration.take() {
            pending.remove(&n);
        }
    }
}

impl PendingFile {
    /// Creates the temporary file next to `target` and opens it for writing.
    pub fn create(target: &Path) -> io::Result<(PendingFile, File)> {
        if let Ok(meta) = std::fs::metadata(target)
            && !meta.is_file()
            && !meta.is_dir()
        {
            let file = std::fs::OpenOptions::new().write(true).open(target)?;
            let pending = PendingFile {
                temp: None,
                target: target.to_path_buf(),
                registration: None,
            };
            return Ok((pending, file));
        }
        let resolved;
        let target = match std::fs::symlink_metadata(target) {
            Ok(meta) if meta.file_type().is_symlink() => {
                resolved = std::fs::canonicalize(target)?;
                resolved.as_path()
            }
            _ => target,
        };
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let prefix = temporary_prefix(&name);
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix);
        // An ordinary file once renamed (temporary files are private by default).
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
        // Created and registered with the registry held: a signal handled
        // meanwhile waits for it, then finds the file.
        let mut pending_files = registry();
        let (file, temp) = builder
            .tempfile_in(dir_of(target))
            .map_err(one_message)?
            .into_parts();
        let registration = NEXT_REGISTRATION.fetch_add(1, Ordering::Relaxed);
        pending_files.insert(registration, temp.to_path_buf());
        drop(pending_files);
        let pending = PendingFile {
            temp: Some(temp),
            target: target.to_path_buf(),
            registration: Some(registration),
        };
        Ok((pending, file))
    }

    /// Like [`PendingFile::create`], for formats whose writer seeks (MCAP):
    /// a target that exists and is not a regular file (a device, a pipe)
    /// is refused with [`io::ErrorKind::InvalidInput`] instead of being
    /// written directly.
    pub fn create_seekable(target: &Path) -> io::Result<(PendingFile, File)> {
        if let Ok(meta) = std::fs::metadata(target)
            && !meta.is_file()
        {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "not a regular file: an MCAP trace is written with seeks, so it needs one",
            ));
        }
        PendingFile::create(target)
    }

    /// Creates the temporary file next to `target`, for writers that open
    /// it by its path ([`PendingFile::path`]).
    pub fn new(target: &Path) -> io::Result<PendingFile> {
        let (pending, _file) = PendingFile::create(target)?;
        Ok(pending)
    }

    /// The path to write to: the temporary file's, or the target's when it
    /// is written directly.
    pub fn path(&self) -> &Path {
        self.temp.as_deref().unwrap_or(&self.target)
    }

    /// The final path.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Finishes the file written through `file` and renames it to its
    /// target: [`PendingFile::seal`], then [`PendingFile::commit`]. The one
    /// way an output file is finished; a caller that writes several files
    /// seals each one before committing any (so that an error finishing one
    /// leaves none of them).
    pub fn finish(self, file: BufWriter<File>) -> Result<(), FinishError> {
        self.seal(file)?;
        self.commit().map_err(FinishStep::Renaming.with())
    }

    /// Makes the file written through `file` complete and durable under
    /// its temporary name: flushes the buffer, syncs the file to the disk
    /// ([`sync`]) and closes it. The file is renamed into place by
    /// [`PendingFile::commit`].
    pub fn seal(&self, file: BufWriter<File>) -> Result<(), FinishError> {
        seal(file)
    }

    /// Renames the finished file to its target. The registry is held
    /// during the rename, so a signal either removes the temporary file
    /// before it or finds it renamed.
    pub fn commit(mut self) -> io::Result<()> {
        let mut pending = registry();
        if let Some(n) = self.registration.take() {
            pending.remove(&n);
        }
        match self.temp.take() {
            // On an error the temporary file is removed (dropped).
            Some(temp) => temp.persist(&self.target).map(|_| ()).map_err(|e| e.error),
            None => Ok(()),
        }
    }
}

/// The start of a temporary file's name for a target named `name`: it says
/// what the file is (`.golf.rrd.partial-Ab3dE1`).
fn temporary_prefix(name: &str) -> String {
    format!(".{name}.partial-")
}

/// Temporary files next to `target` left by earlier runs that never
/// finished (a run killed while writing): `.{name}.partial-*`. Another run
/// writing the same target at this moment also has one, so they are
/// reported, not removed.
pub fn unfinished_temporaries(target: &Path) -> Vec<PathBuf> {
    let Some(name) = target.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return Vec::new();
    };
    let prefix = temporary_prefix(&name);
    let Ok(entries) = std::fs::read_dir(dir_of(target)) else {
        return Vec::new();
    };
    let mut found: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
        .map(|e| e.path())
        .collect();
    found.sort();
    found
}

/// Which step of finishing an output file failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FinishStep {
    /// Writing what was still buffered.
    Flushing,
    /// Syncing the file to the disk.
    Syncing,
    /// Renaming the finished file to its target.
    Renaming,
}

impl FinishStep {
    /// The step in words: "flushing", "syncing", "renaming the finished
    /// file into place".
    pub fn doing(self) -> &'static str {
        match self {
            FinishStep::Flushing => "flushing",
            FinishStep::Syncing => "syncing",
            FinishStep::Renaming => "renaming the finished file into place",
        }
    }

    fn with(self) -> impl FnOnce(io::Error) -> FinishError {
        move |cause| FinishError { step: self, cause }
    }
}

/// Finishing an output file failed: the step, and the operating system's
/// error. The callers name the file in their own error types.
#[derive(Debug, thiserror::Error)]
#[error("{}: {}", step.doing(), crate::error_text::full_text(.cause))]
pub struct FinishError {
    /// What failed.
    pub step: FinishStep,
    /// The operating system's error.
    pub cause: io::Error,
}

/// Flushes `file`'s buffer, syncs the file ([`sync`]) and closes it.
pub fn seal(mut file: BufWriter<File>) -> Result<(), FinishError> {
    file.flush().map_err(FinishStep::Flushing.with())?;
    let file = file
        .into_inner()
        .map_err(|e| FinishStep::Flushing.with()(e.into_error()))?;
    sync(&file).map_err(FinishStep::Syncing.with())
}

/// Bytes of output between two calls of [`start_writeback`] by a writer
/// that writes a long file in one go.
pub const WRITEBACK_BYTES: u64 = 8 << 20;

/// Asks the kernel to start writing `file`'s data written so far to the
/// disk, without waiting for it, so that the [`sync`] that finishes the
/// file has only the rest to wait for (Linux: `sync_file_range` with
/// `SYNC_FILE_RANGE_WRITE`; nothing elsewhere). Advisory: an error here is
/// ignored, and the final [`sync`] reports any failure to write.
pub fn start_writeback(file: &File) {
    #[cfg(target_os = "linux")]
    {
        use std::os::fd::AsRawFd;
        // SAFETY: the descriptor is open for as long as `file` is borrowed;
        // offset 0 and length 0 mean "the whole file", and the call only
        // starts the writeback of its dirty pages.
        let _ =
            unsafe { libc::sync_file_range(file.as_raw_fd(), 0, 0, libc::SYNC_FILE_RANGE_WRITE) };
    }
    #[cfg(not(target_os = "linux"))]
    let _ = file;
}

/// Makes a finished output durable: syncs a regular file to the disk; a
/// device or a pipe (written directly, see the module documentation)
/// cannot be synced and needs not be.
pub fn sync(file: &File) -> io::Result<()> {
    if file.metadata()?.is_file() {
        file.sync_all()?;
    }
    Ok(())
}

/// The `tempfile` crate's errors say the path in their text and also give
/// the operating system's error as their source, so a chain printer would
/// say the reason twice: keep one message with no source
/// ([`crate::error_text`]).
fn one_message(err: io::Error) -> io::Error {
    if err.get_ref().is_none() {
        return err;
    }
    io::Error::new(err.kind(), crate::error_text::full_text(&err))
}

fn dir_of(target: &Path) -> &Path {
    match target.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}
