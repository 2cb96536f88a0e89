//! Trace discovery: the trace files `check` (and the other commands over a
//! suite) reads, from the paths given on the command line.

/// The traces named by `paths`: files as given, directories searched
/// recursively for `*.mcap` files (sorted by path, hidden entries skipped).
/// Errors name the path that could not be read.
pub fn find_traces(paths: &[std::path::PathBuf]) -> Result<Vec<std::path::PathBuf>, String> {
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
            let entry = entry.map_err(|e| {
                let dir = e.path().unwrap_or(p).display().to_string();
                let cause = e
                    .io_error()
                    .map_or_else(|| e.to_string(), std::io::Error::to_string);
                format!("{dir}: cannot list the directory: {cause}")
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
