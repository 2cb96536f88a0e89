//! ARCHITECTURE.md is the map of `src/`: it names every file there, and
//! names no file that is not there.

use std::collections::BTreeSet;
use std::path::Path;

use libtest_mimic::Trial;

use crate::ensure;
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![trial!(architecture_names_every_src_file)]
}

fn architecture_names_every_src_file() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md"))?;
    let named = named_src_files(&text);
    let mut present = BTreeSet::new();
    rust_files(&root.join("src"), root, &mut present)?;
    let unnamed: Vec<_> = present.difference(&named).collect();
    let stale: Vec<_> = named.difference(&present).collect();
    ensure!(
        unnamed.is_empty() && stale.is_empty(),
        "ARCHITECTURE.md does not match src/:\n\
         files it does not name (add a row to its folder's table): {unnamed:?}\n\
         files it names that do not exist: {stale:?}"
    );
    Ok(())
}

/// The `.rs` files under `dir`, as paths from `root` with `/` between parts.
fn rust_files(dir: &Path, root: &Path, out: &mut BTreeSet<String>) -> anyhow::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            rust_files(&path, root, out)?;
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(root)?;
            let parts: Vec<_> = relative
                .components()
                .map(|c| c.as_os_str().to_string_lossy())
                .collect();
            out.insert(parts.join("/"));
        }
    }
    Ok(())
}

/// Every `src/….rs` path in `text`, leaving out those inside a longer path
/// (`capi/src/lib.rs` is not `src/lib.rs`).
fn named_src_files(text: &str) -> BTreeSet<String> {
    let in_path = |c: char| c.is_ascii_alphanumeric() || "/_-.".contains(c);
    text.match_indices("src/")
        .filter(|(at, _)| !text[..*at].chars().next_back().is_some_and(in_path))
        .filter_map(|(at, _)| {
            let rest = &text[at..];
            let end = rest.find(|c: char| !in_path(c)).unwrap_or(rest.len());
            let path = rest[..end].trim_end_matches('.');
            path.ends_with(".rs").then(|| path.to_string())
        })
        .collect()
}
