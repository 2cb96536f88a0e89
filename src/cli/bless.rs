//! `sweeptrace bless`: rewrite a trace's `/expected` channel with the
//! current core's outcomes, keeping every other channel, schema, metadata
//! record and attachment (the library's [`sweeptrace::regress`]).

use super::NameFileOnce;
use std::path::PathBuf;

use anyhow::bail;

use super::Exit;
use sweeptrace::numbers::counted;
use sweeptrace::regress::bless_file;
use sweeptrace::replay::ReplayOptions;

/// Arguments of `bless`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  sweeptrace bless traces/record_mini_golf.mcap -o golf.mcap
  sweeptrace bless golf.mcap --in-place         # the file the first example wrote

Each sweep gets the outcome the core computes with the scene's own margin
and facing rule. The output is written under a temporary name next to it
and renamed when complete; the input is untouched unless --in-place. A
trace that ends early (truncated) is an error, exit 3, and nothing is
written.")]
pub struct Args {
    /// The trace (an MCAP file).
    #[arg(value_name = "TRACE")]
    pub trace: PathBuf,
    /// Write the blessed trace here.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "OUT",
        conflicts_with = "in_place"
    )]
    pub output: Option<PathBuf>,
    /// Replace the trace itself.
    #[arg(long)]
    pub in_place: bool,
}

/// Blesses the trace.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let output = match (&args.output, args.in_place) {
        (Some(out), false) => out.clone(),
        (None, true) => args.trace.clone(),
        _ => bail!("say where the blessed trace goes: -o OUT, or --in-place"),
    };
    // The one wording for an input that cannot be opened.
    drop(super::open_trace(&args.trace)?);
    super::warn_unfinished(&output);
    let summary = match bless_file(&args.trace, &output, ReplayOptions::default()) {
        Ok(summary) => summary,
        // A trace that ends early: exit 3, as every command gives, but
        // nothing written (in place, the trace is left as it was).
        Err(err) if err.is_truncation() => {
            eprintln!(
                "error: {err}\nnothing written: a blessed trace would lose every sweep after the end{}",
                if args.in_place {
                    " (the trace is left as it was)"
                } else {
                    ""
                }
            );
            return Ok(Exit::IncompleteInput);
        }
        Err(err) => return Err(err).name_file_once("blessing", args.trace.display()),
    };
    let replaced = match &summary.replaced_expected_source {
        Some(old) => format!(" (expectations were from {old})"),
        None => String::new(),
    };
    eprintln!(
        "wrote {}: {} from {}{replaced} (replacing {}), {}, {}, {}, {} and {} kept",
        output.display(),
        counted(summary.expected_written, "expectation", "expectations"),
        summary.expected_source,
        summary.expected_dropped,
        counted(summary.messages_copied, "other message", "other messages"),
        counted(summary.channels_copied, "channel", "channels"),
        counted(summary.schemas_copied, "schema", "schemas"),
        counted(
            summary.metadata_copied,
            "metadata record",
            "metadata records"
        ),
        counted(summary.attachments_copied, "attachment", "attachments"),
    );
    Ok(Exit::Success)
}
