//! The command line that starts an engine, split like a POSIX shell splits
//! words (quotes and backslashes), without running a shell.

use super::EngineError;

/// The engine's program and arguments, as given on the command line
/// (`--engine "python3 engine.py --bug skip-vertex"`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EngineCommand {
    /// The program: a name looked up on `PATH`, or a path (`./build/engine`).
    pub program: String,
    /// Its arguments.
    pub arguments: Vec<String>,
    /// The command as given, for messages.
    pub text: String,
}

impl EngineCommand {
    /// Splits `text` into words: whitespace separates them; `'...'` keeps
    /// everything literally, `"..."` keeps everything but `\"` and `\\`,
    /// and a backslash outside quotes keeps the next character.
    pub fn parse(text: &str) -> Result<EngineCommand, EngineError> {
        let bad = |reason: &str| EngineError::BadCommand {
            command: text.to_string(),
            reason: reason.to_string(),
        };
        let mut words: Vec<String> = Vec::new();
        let mut word: Option<String> = None;
        let mut chars = text.chars();
        while let Some(c) = chars.next() {
            match c {
                c if c.is_whitespace() => {
                    if let Some(w) = word.take() {
                        words.push(w);
                    }
                }
                '\'' => {
                    let w = word.get_or_insert_with(String::new);
                    loop {
                        match chars.next() {
                            Some('\'') => break,
                            Some(c) => w.push(c),
                            None => return Err(bad("a single quote is not closed")),
                        }
                    }
                }
                '"' => {
                    let w = word.get_or_insert_with(String::new);
                    loop {
                        match chars.next() {
                            Some('"') => break,
                            Some('\\') => match chars.next() {
                                Some(c @ ('"' | '\\' | '$' | '`')) => w.push(c),
                                Some(c) => {
                                    w.push('\\');
                                    w.push(c);
                                }
                                None => return Err(bad("a double quote is not closed")),
                            },
                            Some(c) => w.push(c),
                            None => return Err(bad("a double quote is not closed")),
                        }
                    }
                }
                '\\' => match chars.next() {
                    Some(c) => word.get_or_insert_with(String::new).push(c),
                    None => return Err(bad("it ends with a backslash")),
                },
                c => word.get_or_insert_with(String::new).push(c),
            }
        }
        if let Some(w) = word.take() {
            words.push(w);
        }
        let mut words = words.into_iter();
        let program = words.next().ok_or_else(|| bad("it is empty"))?;
        Ok(EngineCommand {
            program,
            arguments: words.collect(),
            text: text.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::EngineCommand;

    #[test]
    fn splits_like_a_shell() {
        let c =
            EngineCommand::parse(r#"python3  "my engine.py" --bug 'skip vertex' a\ b"#).unwrap();
        assert_eq!(c.program, "python3");
        assert_eq!(c.arguments, ["my engine.py", "--bug", "skip vertex", "a b"]);
        assert!(EngineCommand::parse("  ").is_err());
        assert!(EngineCommand::parse("a 'b").is_err());
    }
}
