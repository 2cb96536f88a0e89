//! ARCHITECTURE.md is the map of `src/`: it names every file there, and
//! names no file that is not there; and its layers hold: no two of `src/`'s
//! top-level modules import each other, directly or around a circle, nor
//! two files of the judge; and the `pub use` lists stay short.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use libtest_mimic::Trial;

use crate::ensure;
use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(architecture_names_every_src_file),
        trial!(top_level_modules_import_in_one_direction),
        trial!(the_judges_files_import_in_one_direction),
        trial!(the_public_lists_stay_short),
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
    if let Some(circle) = find_circle(&imports) {
        anyhow::bail!("an import circle: {circle}");
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

/// The first circle in an import graph, as the path that closes it.
fn find_circle(imports: &BTreeMap<String, BTreeSet<String>>) -> Option<String> {
    for start in imports.keys() {
        let mut stack: Vec<(String, Vec<String>)> = vec![(start.clone(), vec![start.clone()])];
        let mut seen = BTreeSet::new();
        while let Some((at, path)) = stack.pop() {
            for next in imports.get(&at).into_iter().flatten() {
                if next == start {
                    return Some(format!("{} -> {start}", path.join(" -> ")));
                }
                if seen.insert(next.clone()) {
                    let mut longer = path.clone();
                    longer.push(next.clone());
                    stack.push((next.clone(), longer));
                }
            }
        }
    }
    None
}

/// The names of a `use` list's braces or its single last segment
/// (`a::{B, c as D}` gives `B`, `c`).
fn use_list_names(list: &str) -> Vec<String> {
    let inner = match (list.find('{'), list.rfind('}')) {
        (Some(open), Some(close)) => &list[open + 1..close],
        _ => list.rsplit("::").next().unwrap_or(list),
    };
    inner
        .split(',')
        .filter_map(|item| item.split_whitespace().next())
        .map(|name| name.rsplit("::").next().unwrap_or(name).to_string())
        .filter(|name| !name.is_empty())
        .collect()
}

/// The `use` statements of a file's code (comments left out) that start
/// with `prefix` (`pub use `), each up to its `;`.
fn use_statements<'t>(code: &'t str, prefix: &str) -> Vec<&'t str> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find(prefix) {
        let before = rest[..at].trim_end_matches(' ');
        let starts_line = before.is_empty() || before.ends_with('\n');
        rest = &rest[at + prefix.len()..];
        let end = rest.find(';').unwrap_or(rest.len());
        if starts_line {
            out.push(&rest[..end]);
        }
        rest = &rest[end..];
    }
    out
}

/// A file's text without its `//` comments and its inline test module.
fn code_of(text: &str) -> String {
    let code = text
        .split("#[cfg(test)]\nmod tests {")
        .next()
        .unwrap_or(text);
    code.lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Inside the judge (one answer judged against the core), the files import
/// each other in one direction: no circle between `src/judge/`'s files,
/// following `super::` and `crate::judge::` paths through `mod.rs`'s lists
/// to the file that defines the name.
fn the_judges_files_import_in_one_direction() -> anyhow::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/judge");
    let mod_rs = code_of(&std::fs::read_to_string(dir.join("mod.rs"))?);
    let mut files = BTreeSet::new();
    for entry in std::fs::read_dir(&dir)? {
        let path = entry?.path();
        if let Some(stem) = path
            .file_stem()
            .filter(|_| path.extension().is_some_and(|e| e == "rs"))
        {
            files.insert(stem.to_string_lossy().into_owned());
        }
    }
    ensure!(files.len() > 5, "src/judge/ has {} files", files.len());
    // The name each `mod.rs` list re-exports, and the file it comes from.
    let mut home: BTreeMap<String, String> = BTreeMap::new();
    for prefix in ["pub use ", "pub(crate) use "] {
        for list in use_statements(&mod_rs, prefix) {
            let file = list.split("::").next().unwrap_or("").trim().to_string();
            for name in use_list_names(list) {
                home.insert(name, file.clone());
            }
        }
    }
    let mut imports: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in files.iter().filter(|f| *f != "mod") {
        let code = code_of(&std::fs::read_to_string(dir.join(format!("{file}.rs")))?);
        let mut targets = BTreeSet::new();
        for prefix in ["super::", "crate::judge::"] {
            let mut rest = code.as_str();
            while let Some(at) = rest.find(prefix) {
                rest = &rest[at + prefix.len()..];
                let path_end = rest
                    .find(|c: char| !(c.is_ascii_alphanumeric() || "_:{}, \n".contains(c)))
                    .unwrap_or(rest.len());
                let path = &rest[..path_end];
                let first: String = path
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if files.contains(&first) {
                    targets.insert(first);
                } else if path.starts_with('{') {
                    for name in use_list_names(path) {
                        if let Some(home) = home.get(&name) {
                            targets.insert(home.clone());
                        }
                    }
                } else if let Some(home) = home.get(&first) {
                    targets.insert(home.clone());
                }
            }
        }
        targets.remove(file);
        imports.insert(file.clone(), targets);
    }
    ensure!(
        imports.values().map(BTreeSet::len).sum::<usize>() > 5,
        "found too few imports between the judge's files to trust the check: {imports:?}"
    );
    if let Some(circle) = find_circle(&imports) {
        anyhow::bail!("an import circle inside the judge: {circle}");
    }
    Ok(())
}

/// The library's public lists stay short: the `pub use` names of `src/`
/// (the crate root's and each folder's entry points) are at most 260. A
/// subject's details are public under their own module's name instead
/// (ARCHITECTURE.md, "The public surface").
fn the_public_lists_stay_short() -> anyhow::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = BTreeSet::new();
    rust_files(&root.join("src"), root, &mut files)?;
    let mut count = 0;
    let mut largest = Vec::new();
    for file in &files {
        let code = code_of(&std::fs::read_to_string(root.join(file))?);
        let names: usize = use_statements(&code, "pub use ")
            .iter()
            .map(|list| use_list_names(list).len())
            .sum();
        count += names;
        largest.push((names, file.clone()));
    }
    largest.sort();
    largest.reverse();
    largest.truncate(5);
    ensure!(
        count > 100,
        "counted only {count} re-exported names: the count is broken"
    );
    ensure!(
        count <= 260,
        "{count} names re-exported by `pub use` (at most 260): put a subject's details in a \
         public submodule instead (ARCHITECTURE.md). Longest lists: {largest:?}"
    );
    Ok(())
}
