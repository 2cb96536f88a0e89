//! ARCHITECTURE.md is the map of `src/`: it names every file there, and
//! names no file that is not there; and its layers hold: no two of `src/`'s
//! top-level modules import each other, directly or around a circle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use libtest_mimic::Trial;

use crate::ensure;
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(architecture_names_every_src_file),
        trial!(top_level_modules_import_in_one_direction),
    ]
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

/// The top-level module a file of `src/` belongs to (`judge` for
/// `src/judge/compare.rs`, `numbers` for `src/numbers.rs`).
fn top_level(relative: &str) -> Option<&str> {
    let rest = relative.strip_prefix("src/")?;
    let first = rest.split('/').next()?;
    Some(first.strip_suffix(".rs").unwrap_or(first))
}

/// The `crate::X` paths of a file's code, outside comments and its
/// `#[cfg(test)] mod tests` (tests may borrow from anywhere).
fn imported_modules(text: &str) -> BTreeSet<String> {
    let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    let mut out = BTreeSet::new();
    for line in code.lines() {
        let line = line.split("//").next().unwrap_or("");
        let mut rest = line;
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            out.insert(name);
        }
    }
    out
}

/// The layers of ARCHITECTURE.md, checked against the code: the import
/// graph between `src/`'s top-level modules (from `crate::` paths, the
/// binary and test files left out) has no circle.
fn top_level_modules_import_in_one_direction() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = BTreeSet::new();
    rust_files(&root.join("src"), root, &mut files)?;
    let modules: BTreeSet<String> = files
        .iter()
        .filter_map(|f| top_level(f))
        .map(str::to_string)
        .collect();
    let mut imports: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let Some(module) = top_level(file) else {
            continue;
        };
        if ["lib", "main", "cli"].contains(&module) || file.ends_with("/tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(root.join(file))?;
        for target in imported_modules(&text) {
            if target != module && modules.contains(&target) {
                imports
                    .entry(module.to_string())
                    .or_default()
                    .insert(target);
            }
        }
    }
    // A circle: some module reaches itself.
    for start in imports.keys() {
        let mut stack: Vec<(String, Vec<String>)> = vec![(start.clone(), vec![start.clone()])];
        let mut seen = BTreeSet::new();
        while let Some((at, path)) = stack.pop() {
            for next in imports.get(&at).into_iter().flatten() {
                if next == start {
                    anyhow::bail!("an import circle: {} -> {start}", path.join(" -> "));
                }
                if seen.insert(next.clone()) {
                    let mut longer = path.clone();
                    longer.push(next.clone());
                    stack.push((next.clone(), longer));
                }
            }
        }
    }
    // The judge stays below the suite, and the trace layer below both.
    for (below, above) in [
        ("judge", "suite"),
        ("trace", "judge"),
        ("trace", "suite"),
        ("core", "trace"),
    ] {
        ensure!(
            !imports.get(below).is_some_and(|i| i.contains(above)),
            "{below} imports {above}, a layer above it"
        );
    }
    Ok(())
}
