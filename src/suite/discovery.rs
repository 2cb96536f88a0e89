//! Trace discovery: the trace files `check` (and the other commands over a
//! suite) reads, from the paths given on the command line.

use std::path::PathBuf;

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
/// An error names the directory that could not be listed.
pub fn find_traces(paths: &[PathBuf]) -> Result<Vec<PathBuf>, DiscoveryError> {
    let mut out = Vec::new();
    for p in paths {
        if !p.is_dir() {
            out.push(p.clone());
            continue;
        }
        let walk = walkdir::WalkDir::new(p)
            .follow_links(true)
            .sort_by_file_name()
            .into_iter()
            .filter_entry(|e| e.depth() == 0 || !e.file_name().to_string_lossy().starts_with('.'));
        for entry in walk {
            let entry = entry.map_err(|e| DiscoveryError::CannotList {
                dir: e.path().unwrap_or(p).to_path_buf(),
                cause: e
                    .io_error()
                    .map_or_else(|| e.to_string(), std::io::Error::to_string),
            })?;
            if !entry.file_type().is_dir()
                && entry
                    .path()
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
            {
                out.push(entry.into_path());
            }
        }
    }
    Ok(out)
}
