//! The globs of a settings file (`match`, `exclude`), matched against many
//! traces without a regular expression per glob: a glob without a wildcard
//! is its text, a glob whose only wildcard is `*` is matched directly, and
//! only the others get globset's matcher, compiled at their first use.
//! [`Patterns`] indexes a file's `[[traces]]` globs by the literal text
//! before their first wildcard, so that a trace is tried against the few
//! globs that can match it, not every block of the file.

use std::collections::HashMap;
use std::path::Path;
use std::sync::OnceLock;

/// The characters that make a glob more than its text.
const WILDCARDS: &[char] = &['*', '?', '[', ']', '{', '}', '\\'];

/// One glob, as globset reads it with `literal_separator` (`*` and `?`
/// never match `/`).
#[derive(Clone, Debug)]
pub(super) struct Pattern {
    glob: globset::Glob,
    fast: Fast,
    /// globset's matcher, for the globs [`Fast`] does not match (and paths
    /// that are not UTF-8): compiled at its first use.
    matcher: OnceLock<globset::GlobMatcher>,
}

/// How a glob is matched without globset's matcher.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fast {
    /// No wildcard: the path is the glob's text.
    Literal,
    /// Literal characters and single `*`s (any characters but `/`).
    Stars,
    /// Another glob: globset's matcher.
    No,
}

impl Pattern {
    /// `text` parsed as a glob (globset's errors for one that is not).
    pub(super) fn new(text: &str) -> Result<Pattern, globset::Error> {
        let glob = globset::GlobBuilder::new(text)
            .literal_separator(true)
            .build()?;
        let fast = if !text.contains(WILDCARDS) {
            Fast::Literal
        } else if !text.contains(&WILDCARDS[1..]) && !text.contains("**") {
            Fast::Stars
        } else {
            Fast::No
        };
        Ok(Pattern {
            glob,
            fast,
            matcher: OnceLock::new(),
        })
    }

    /// The literal text before the glob's first wildcard: every path it
    /// matches starts with it.
    fn prefix(&self) -> &str {
        let text = self.glob.glob();
        text.find(WILDCARDS).map_or(text, |end| &text[..end])
    }

    /// Whether the glob matches `path` (relative, `/`-separated), as
    /// globset's matcher does.
    pub(super) fn is_match(&self, path: &Path) -> bool {
        match (self.fast, path.to_str()) {
            (Fast::Literal, Some(text)) => text == self.glob.glob(),
            (Fast::Stars, Some(text)) => stars_match(self.glob.glob().as_bytes(), text.as_bytes()),
            _ => self
                .matcher
                .get_or_init(|| self.glob.compile_matcher())
                .is_match(path),
        }
    }
}

/// Whether `pattern`, literal bytes and `*`s (each any bytes but `/`),
/// matches all of `text`. Backtracking to the last `*` only: a `*` never
/// crosses a `/`, so each `/` of the text meets the same `/` of the
/// pattern whatever the stars took, and within one component the last `*`
/// can take whatever an earlier one could.
fn stars_match(pattern: &[u8], text: &[u8]) -> bool {
    let (mut p, mut t) = (0, 0);
    // The last `*`: the pattern after it, and where its match ends now.
    let mut star: Option<(usize, usize)> = None;
    while t < text.len() {
        if pattern.get(p) == Some(&b'*') {
            star = Some((p + 1, t));
            p += 1;
        } else if pattern.get(p) == Some(&text[t]) {
            p += 1;
            t += 1;
        } else if let Some((after, end)) = star
            && text[end] != b'/'
        {
            star = Some((after, end + 1));
            p = after;
            t = end + 1;
        } else {
            return false;
        }
    }
    pattern[p..].iter().all(|&c| c == b'*')
}

/// A file's `[[traces]]` globs, in the file's order, indexed by the
/// literal text before their first wildcard.
#[derive(Clone, Debug, Default)]
pub(super) struct Patterns {
    patterns: Vec<Pattern>,
    /// The globs of each prefix, by index.
    by_prefix: HashMap<String, Vec<usize>>,
    /// The longest prefix, in bytes.
    longest: usize,
}

impl Patterns {
    /// Adds the next glob.
    pub(super) fn push(&mut self, pattern: Pattern) {
        let prefix = pattern.prefix().to_string();
        self.longest = self.longest.max(prefix.len());
        self.by_prefix
            .entry(prefix)
            .or_default()
            .push(self.patterns.len());
        self.patterns.push(pattern);
    }

    /// Whether there is none.
    pub(super) fn is_empty(&self) -> bool {
        self.patterns.is_empty()
    }

    /// The indices of the globs that match `path`, ascending: those whose
    /// prefix starts the path, tried (every glob for a path that is not
    /// UTF-8).
    pub(super) fn matching(&self, path: &Path) -> Vec<usize> {
        let Some(text) = path.to_str() else {
            return (0..self.patterns.len())
                .filter(|&i| self.patterns[i].is_match(path))
                .collect();
        };
        let mut found: Vec<usize> = (0..=text.len().min(self.longest))
            .filter(|&end| text.is_char_boundary(end))
            .filter_map(|end| self.by_prefix.get(&text[..end]))
            .flatten()
            .copied()
            .filter(|&i| self.patterns[i].is_match(path))
            .collect();
        found.sort_unstable();
        found
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use rand::seq::IndexedRandom;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::{Pattern, Patterns};

    /// Random globs and paths over a small alphabet: the fast matching
    /// and the index give what globset's own matcher gives.
    #[test]
    fn fast_matching_agrees_with_globset() {
        let mut rng = ChaCha8Rng::seed_from_u64(43);
        let glob_parts = [
            "a", "b", "/", "*", ".", "ab", "*", "?", "**", "[ab]", "{a,b}", "é",
        ];
        let path_parts = ["a", "b", "/", ".", "ab", "é", "c"];
        let mut patterns = Patterns::default();
        let mut compiled = Vec::new();
        let mut fast = 0;
        while compiled.len() < 400 {
            let n = rng.random_range(0..6);
            let text: String = (0..n)
                .map(|_| *glob_parts.choose(&mut rng).expect("parts"))
                .collect();
            let Ok(pattern) = Pattern::new(&text) else {
                continue;
            };
            fast += usize::from(pattern.fast != super::Fast::No);
            let matcher = globset::GlobBuilder::new(&text)
                .literal_separator(true)
                .build()
                .expect("globset parses it")
                .compile_matcher();
            patterns.push(pattern);
            compiled.push((text, matcher));
        }
        assert!(fast > 100, "{fast} fast globs");
        let mut matched = 0;
        for _ in 0..3000 {
            let n = rng.random_range(0..7);
            let text: String = (0..n)
                .map(|_| *path_parts.choose(&mut rng).expect("parts"))
                .collect();
            let path = Path::new(&text);
            let want: Vec<usize> = (0..compiled.len())
                .filter(|&i| compiled[i].1.is_match(path))
                .collect();
            for (i, (glob, matcher)) in compiled.iter().enumerate() {
                assert_eq!(
                    patterns.patterns[i].is_match(path),
                    matcher.is_match(path),
                    "glob {glob:?}, path {text:?}"
                );
            }
            assert_eq!(patterns.matching(path), want, "path {text:?}");
            matched += want.len();
        }
        assert!(matched > 1000, "{matched} matches");
    }
}
