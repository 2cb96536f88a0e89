//! Trace discovery: the trace files `check` (and the other commands over a
//! suite) reads, from the paths given on the command line.

use std::path::{Path, PathBuf};

/// Why the traces of a suite could not be listed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DiscoveryError {
    /// A directory given, or one below it, could not be listed.
    #[error("{}: cannot list the directory: {cause}", dir.display())]
    CannotList {
        /// The directory.
        dir: PathBuf,
        /// Why, in words.
        cause: String,
    },
}

/// The traces named by `paths`: files as given, directories searched
/// recursively for `*.mcap` files (sorted by path, hidden entries skipped).
/// An error names the directory that could not be listed. A dangling
/// symbolic link below a directory is skipped ([`discover`] lists them).
pub fn find_traces(paths: &[PathBuf]) -> Result<Vec<PathBuf>, DiscoveryError> {
    discover(paths).map(|found| found.traces)
}

/// What a search of a suite's paths found.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Discovered {
    /// The traces, as [`find_traces`] gives them.
    pub traces: Vec<PathBuf>,
    /// The symbolic links below a directory whose target does not exist:
    /// skipped, as any file that is not a trace.
    pub dangling: Vec<PathBuf>,
}

/// [`find_traces`], with the dangling symbolic links it skipped.
pub fn discover(paths: &[PathBuf]) -> Result<Discovered, DiscoveryError> {
    let mut out = Discovered::default();
    for p in paths {
        if !p.is_dir() {
            out.traces.push(p.clone());
            continue;
        }
        let walk = walkdir::WalkDir::new(p)
            .follow_links(true)
            .sort_by_file_name()
            .into_iter()
            .filter_entry(|e| e.depth() == 0 || !e.file_name().to_string_lossy().starts_with('.'));
        for entry in walk {
            let entry = match entry {
                Ok(entry) => entry,
                Err(e) if e.path().is_some_and(is_dangling) => {
                    out.dangling.extend(e.path().map(Path::to_path_buf));
                    continue;
                }
                Err(e) => {
                    return Err(DiscoveryError::CannotList {
                        dir: e.path().unwrap_or(p).to_path_buf(),
                        cause: e
                            .io_error()
                            .map_or_else(|| e.to_string(), std::io::Error::to_string),
                    });
                }
            };
            if !entry.file_type().is_dir()
                && entry
                    .path()
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
            {
                out.traces.push(entry.into_path());
            }
        }
    }
    Ok(out)
}

/// Whether `path` is a symbolic link whose target does not exist.
fn is_dangling(path: &Path) -> bool {
    path.symlink_metadata()
        .is_ok_and(|m| m.file_type().is_symlink())
        && std::fs::metadata(path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound)
}
