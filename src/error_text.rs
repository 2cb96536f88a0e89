//! The one rule for error messages: an error's `Display` is its whole
//! message, its cause included, and the library's errors return no
//! `source()`, so a message printed with `{}` or through `anyhow`'s `{:#}`
//! says everything once.
//!
//! A foreign error kept as a cause (an I/O error, the `mcap` crate's) is
//! shown with [`full_text`], which adds the texts of its own sources that
//! its `Display` leaves out, and none twice.

use std::error::Error;

/// `err`'s text followed by the texts of its sources that are not already
/// part of it, joined by `": "`: `I/O error from writing, or reading a
/// compression stream: No space left on device (os error 28)`.
pub fn full_text(err: &(dyn Error + 'static)) -> String {
    let mut text = err.to_string();
    let mut source = err.source();
    while let Some(inner) = source {
        let inner_text = inner.to_string();
        if !text.contains(&inner_text) {
            text.push_str(": ");
            text.push_str(&inner_text);
        }
        source = inner.source();
    }
    text
}

/// A segment of an error message (the text between `": "` separators) of
/// 12 characters or more that an earlier segment already says, if any:
/// the mark of a cause or a file name printed twice (`blessing a.mcap:
/// a.mcap: ...`, `I/O error: I/O error: ...`). The tests and fuzz checks
/// use it.
pub fn repeated_segment(text: &str) -> Option<String> {
    let segments: Vec<&str> = text.split(": ").map(str::trim).collect();
    segments.iter().enumerate().skip(1).find_map(|(j, later)| {
        (later.len() >= 12 && segments[..j].iter().any(|earlier| earlier.contains(later)))
            .then(|| (*later).to_string())
    })
}

/// `text` safe to print on a terminal: each control character (an escape
/// sequence's ESC, a carriage return, a newline, a bell, ...) written as
/// Rust writes it in a string (`\u{1b}`, `\r`, `\n`), and a backslash
/// before one doubled so that the two read apart. For the text of an input
/// (a settings file's value or key, a scene's name, an answer typed at a
/// prompt) placed in a message; text without a control character comes
/// back as it was.
pub fn escaped(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() || c == '\\' {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::escaped;

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(escaped("plain `text` é"), "plain `text` é");
        assert_eq!(escaped("a\u{1b}[31mred\r\nb"), "a\\u{1b}[31mred\\r\\nb");
        assert_eq!(escaped("c:\\dir\u{7}"), "c:\\\\dir\\u{7}");
        assert_eq!(escaped("\u{9b}2J"), "\\u{9b}2J");
    }
}
