//! The smallest compiled engine for sweeptrace's engine protocol
//! (docs/ENGINE_PROTOCOL.md), standard library only: it answers "no
//! collision" to every sweep. Used to measure the protocol's overhead
//! without an interpreter in the way (BENCHMARKS.md):
//!
//! ```text
//! cargo build --release --no-default-features --example trivial_engine
//! ```
//!
//! It flushes its output whenever it has answered every line it has read,
//! which the protocol allows (an answer must not wait in a buffer while the
//! engine waits for input).

use std::io::{BufRead, Write};

/// The unsigned integer after `"key":` in a JSON line (the protocol's
/// `frame` and `ball` are plain integers).
fn field(line: &str, key: &str) -> Option<u64> {
    let start = line.find(key)? + key.len();
    let digits: String = line[start..]
        .trim_start_matches([':', ' '])
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().ok()
}

fn main() -> std::io::Result<()> {
    let mut input = std::io::BufReader::with_capacity(1 << 16, std::io::stdin().lock());
    let mut output = std::io::BufWriter::new(std::io::stdout().lock());
    let mut line = String::new();
    loop {
        line.clear();
        if input.read_line(&mut line)? == 0 {
            break;
        }
        if line.contains("\"type\":\"sweep\"") {
            let frame = field(&line, "\"frame\"").unwrap_or(0);
            let ball = field(&line, "\"ball\"").unwrap_or(0);
            writeln!(
                output,
                "{{\"frame\":{frame},\"ball\":{ball},\"alpha\":1.0,\"kind\":\"none\"}}"
            )?;
        }
        // Nothing more to read right now: send what is answered.
        if input.buffer().is_empty() {
            output.flush()?;
        }
    }
    output.flush()
}
