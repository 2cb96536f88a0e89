//! `sweeptrace info`: what a trace holds.

use super::NameFileOnce;
use std::io::BufReader;
use std::path::PathBuf;

use super::Exit;
use sweeptrace::trace::TraceReader;
use sweeptrace::trace::info::{collect_info, render_info_json, render_info_text};

/// Arguments of `info`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Example:\n  sweeptrace info traces/record_mini_golf.mcap --json")]
pub struct Args {
    /// The trace (an MCAP file).
    pub trace: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Prints the report. A trace that cannot be read to its end still gets the
/// report of what came before the error, then the error; an input that is
/// not an MCAP file at all (it cannot be read, is empty, has no MCAP
/// header) gets only the error, and nothing on stdout.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let name = args.trace.display().to_string();
    let file = super::open_trace(&args.trace)?;
    let file_bytes = file
        .metadata()
        .ok()
        .filter(|m| m.is_file())
        .map(|m| m.len());
    let (mut info, error) = collect_info(TraceReader::new_indexed(BufReader::new(file), &name));
    info.file_bytes = file_bytes;
    let (error, not_mcap) = match error {
        Some(err) if !info.stats.header_read => (None, Some(err)),
        other => (other, None),
    };
    if let Some(err) = not_mcap {
        return Err(err).name_file_once("reading the trace", &name);
    }
    let report = if args.json {
        render_info_json(&info)
    } else {
        render_info_text(&info)
    };
    print!("{report}");
    if args.json {
        println!();
    }
    match error {
        None => Ok(Exit::Success),
        // The report says why already (`incomplete:`): the error once.
        Some(err) if err.is_truncation() => {
            eprintln!(
                "error: {name} ends early (truncated): the report covers what was read \
                 before the end"
            );
            Ok(Exit::IncompleteInput)
        }
        Some(err) => Err(err).name_file_once("reading the trace", &name),
    }
}
