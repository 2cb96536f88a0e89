//! `sweeptrace bless`: rewrite a trace's `/expected` channel with the
//! current core's outcomes (or a running engine's answers), keeping every
//! other channel, schema, metadata record and attachment (the library's
//! [`sweeptrace::regress`]). A selection (`--frames`, `--ball`,
//! `--accept`, `--review`) blesses some sweeps only.

use super::NameFileOnce;
use std::collections::BTreeSet;
use std::io::{BufRead, Read, Write};
use std::path::PathBuf;

use anyhow::{Context, bail};

use super::Exit;
use sweeptrace::engine::EngineCommand;
use sweeptrace::error_text::escaped;
use sweeptrace::judge::divergence::{Divergence, Parties, render_divergence_as};
use sweeptrace::numbers::counted;
use sweeptrace::suite::bless::{
    BlessEngine, BlessError, BlessOptions, BlessSelection, bless_file_with,
};
use sweeptrace::suite::engine_check::check_file_with_engine;
use sweeptrace::suite::report::Against;
use sweeptrace::suite::{CheckOptions, check_file};

/// Arguments of `bless`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  sweeptrace bless traces/record_mini_golf.mcap -o golf.mcap
  sweeptrace bless golf.mcap --in-place         # the file the first example wrote
  sweeptrace bless golf.mcap --frames 100..200 --ball 1 -o golf2.mcap
  sweeptrace bless golf.mcap --accept 12:0,40:3 -o golf2.mcap
  sweeptrace bless golf.mcap --review -o golf2.mcap   # accept or reject each change
  sweeptrace bless traces/record_cube_corner_margin.mcap --engine 'python3 examples/engines/sweep_engine.py' --engine-name sweep_engine --engine-version 1 -o snapshot.mcap

Each sweep gets the outcome the core computes with the scene's own margin
and facing rule, under the engine conventions of the sweeptrace.toml
beside or above the trace (or --config, or the convention flags), or,
with --engine, the engine's answer: an engine snapshot, which `check
--engine CMD --against expected` compares a later version with.

--frames/--ball, --accept and --review bless some sweeps only: the others
keep the expectation they had (or none). --review walks the sweeps whose
new expectation differs from the trace's, one at a time, with the
explanation `check` prints, and reads a for accept, r for reject, s for
skip (the skipped are listed as an --accept for later), A to accept the
rest, q to quit (the rest keep theirs) from standard input, a line each
(at most 1,024 bytes). A selection that selects no sweep is an error
(exit 2): nothing is written.

The output is written under a temporary name next to it and renamed when
complete; the input is untouched unless --in-place. A trace that ends
early (truncated) is an error, exit 3, and nothing is written.")]
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
    /// Bless only frames A..B (A included, B excluded; also `A..`, `..B`,
    /// `A..=B`, `A`), e.g. `--frames 100..200`.
    #[arg(long, value_name = "A..B", conflicts_with_all = ["accept", "review"])]
    pub frames: Option<sweeptrace::replay::FrameRange>,
    /// Bless only ball N, e.g. `--ball 0`.
    #[arg(long, value_name = "N", conflicts_with_all = ["accept", "review"])]
    pub ball: Option<u32>,
    /// Bless only these sweeps, as FRAME:BALL pairs, e.g. `--accept
    /// 12:0,40:3` (what --review lists as skipped).
    #[arg(long, value_name = "FRAME:BALL,...", value_parser = parse_sweeps, conflicts_with = "review")]
    pub accept: Option<BTreeSet<(u64, u32)>>,
    /// Walk the sweeps whose new expectation differs from the trace's and
    /// accept, reject or skip each (answers read from standard input).
    #[arg(long)]
    pub review: bool,
    /// The expectations are this engine's answers (an engine snapshot):
    /// the command, as `check --engine` runs it.
    #[arg(long, value_name = "CMD")]
    pub engine: Option<String>,
    /// With --engine: the engine's name in the expectations' source
    /// [default: the command, cut to 128 bytes].
    #[arg(long, value_name = "NAME", requires = "engine")]
    pub engine_name: Option<String>,
    /// With --engine: the engine's version in the expectations' source.
    #[arg(long, value_name = "VERSION", requires = "engine")]
    pub engine_version: Option<String>,
    /// With --engine: the longest wait, in seconds, for the engine's next
    /// answer.
    #[arg(long, value_name = "SECONDS", default_value_t = sweeptrace::engine::DEFAULT_TIMEOUT.as_secs_f64(), requires = "engine")]
    pub engine_timeout: f64,
    /// Where the `[engine]` table comes from (`check`'s files by default).
    #[command(flatten)]
    pub config: super::check_config::ConfigArgs,
    /// The engine's conventions: the core's answers are computed under
    /// them (docs/ENGINES.md).
    #[command(flatten)]
    pub conventions: sweeptrace::conventions::PartialConventions,
}

/// `12:0,40:3` as a set of `(frame, ball)`.
fn parse_sweeps(text: &str) -> Result<BTreeSet<(u64, u32)>, String> {
    let mut out = BTreeSet::new();
    for pair in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (frame, ball) = pair
            .split_once(':')
            .ok_or_else(|| format!("`{}` is not FRAME:BALL (e.g. `12:0`)", escaped(pair)))?;
        let frame = frame
            .trim()
            .parse::<u64>()
            .map_err(|e| number_problem(pair, "frame", frame, &e, u64::MAX))?;
        let ball = ball
            .trim()
            .parse::<u32>()
            .map_err(|e| number_problem(pair, "ball", ball, &e, u32::MAX.into()))?;
        out.insert((frame, ball));
    }
    if out.is_empty() {
        return Err("no FRAME:BALL pair given (e.g. `12:0,40:3`)".to_string());
    }
    Ok(out)
}

/// Why `text`, the `what` of `pair`, is not a frame or ball number: too
/// large (above `max`), or not a whole number at all.
fn number_problem(
    pair: &str,
    what: &str,
    text: &str,
    err: &std::num::ParseIntError,
    max: u64,
) -> String {
    let (pair, text) = (escaped(pair), escaped(text.trim()));
    match err.kind() {
        std::num::IntErrorKind::PosOverflow => {
            format!("`{pair}`: the {what} `{text}` is too large (at most {max})")
        }
        _ => format!("`{pair}`: the {what} `{text}` is not a whole number"),
    }
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
    let settings = super::check_config::for_trace(&args.trace, &args.conventions, &args.config)?;
    let conventions = settings.engine.conventions();
    if args.engine.is_none()
        && let Some(line) = super::check_config::conventions_line(&settings)
    {
        eprintln!("{line}");
    }
    let engine = match &args.engine {
        None => None,
        Some(text) => {
            let command = EngineCommand::parse(text)?;
            let name = args
                .engine_name
                .clone()
                .unwrap_or_else(|| command.text.clone());
            Some(BlessEngine {
                options: super::check::engine_options(args.engine_timeout)?,
                name,
                version: args.engine_version.clone().unwrap_or_default(),
                command,
            })
        }
    };
    let replay = sweeptrace::replay::ReplayOptions {
        conventions,
        ..Default::default()
    };
    let select = if args.review {
        let check_options = CheckOptions {
            tolerances: settings.tolerances(),
            max_details: usize::MAX,
            replay,
            ..CheckOptions::default()
        };
        match review(&args, engine.as_ref(), &check_options) {
            Ok(Some(chosen)) => BlessSelection::Sweeps(chosen),
            Ok(None) => return Ok(Exit::Success),
            // An engine that cannot be started: 125, as without --review.
            Err(e)
                if e.downcast_ref::<sweeptrace::engine::EngineError>()
                    .is_some_and(|c| c.cannot_start()) =>
            {
                eprintln!("error: {e}\nnothing written");
                return Ok(Exit::EngineUnavailable);
            }
            Err(e) => return Err(e),
        }
    } else if let Some(set) = &args.accept {
        BlessSelection::Sweeps(set.clone())
    } else if args.frames.is_some() || args.ball.is_some() {
        BlessSelection::Range {
            frames: args.frames.unwrap_or_default(),
            ball: args.ball,
        }
    } else {
        BlessSelection::All
    };
    let options = BlessOptions {
        replay,
        select,
        engine,
        conventions: (!conventions.is_rules()).then(|| conventions.summary()),
    };
    super::warn_unfinished(&output);
    let summary = match bless_file_with(&args.trace, &output, &options) {
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
        Err(BlessError::Engine { cause }) => {
            let exit = if cause.cannot_start() {
                Exit::EngineUnavailable
            } else {
                Exit::Error
            };
            eprintln!("error: {cause}\nnothing written");
            return Ok(exit);
        }
        // An answer the trace cannot hold: a fault of the engine, exit 2.
        Err(err @ BlessError::Answer { .. }) => {
            eprintln!(
                "error: {err}\nnothing written{}",
                if args.in_place {
                    " (the trace is left as it was)"
                } else {
                    ""
                }
            );
            return Ok(Exit::Error);
        }
        // A declared margin that does not fit the balls: the setting's
        // fault, named where it was set.
        Err(BlessError::Replay { cause, file }) => {
            match sweeptrace::suite::report::MarginFault::of(&cause) {
                Some(fault) => bail!(
                    "{}; nothing written",
                    super::check_config::margin_fault(
                        &settings,
                        &args.trace.display().to_string(),
                        &fault
                    )
                ),
                None => {
                    return Err(BlessError::Replay { cause, file })
                        .name_file_once("blessing", args.trace.display());
                }
            }
        }
        Err(err) => return Err(err).name_file_once("blessing", args.trace.display()),
    };
    // One line for what was written, then one for each thing to know.
    let selection = if matches!(options.select, BlessSelection::All) {
        String::new()
    } else {
        format!(
            " ({} blessed, {} kept)",
            counted(summary.blessed, "sweep", "sweeps"),
            summary.kept
        )
    };
    eprintln!(
        "wrote {}: {}, replacing {}{selection}",
        output.display(),
        counted(summary.expected_written, "expectation", "expectations"),
        summary.expected_dropped,
    );
    eprintln!("  expectations from {}", summary.expected_source);
    if let Some(old) = &summary.replaced_expected_source {
        eprintln!("  they were from {old}");
    }
    eprintln!(
        "  kept as they were: {}, {}, {}, {} and {}",
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

/// The longest answer line `--review` reads: an answer is a word; a longer
/// line (`--review < /dev/zero`) is an error, not a line kept growing.
const MAX_ANSWER_LINE_BYTES: usize = 1024;

/// What the reviewer said of one change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Answer {
    Accept,
    Reject,
    Skip,
    AcceptRest,
    Quit,
}

/// Reads one answer (a line) from `input`; `None` at the end of input.
/// Asks again, on `prompt`, after a line that is not an answer. With
/// `echo` (the answers come from a script, not a terminal), writes each
/// answer after its prompt, so that the transcript reads as a dialogue.
fn read_answer(
    input: &mut impl BufRead,
    prompt: &mut impl Write,
    echo: bool,
) -> anyhow::Result<Option<Answer>> {
    loop {
        let mut bytes = Vec::new();
        let limit = MAX_ANSWER_LINE_BYTES as u64 + 1;
        let n = input
            .by_ref()
            .take(limit)
            .read_until(b'\n', &mut bytes)
            .context("reading the answer")?;
        if n == 0 {
            if echo {
                let _ = writeln!(prompt, "(end of input)");
            }
            return Ok(None);
        }
        if n as u64 == limit && bytes.last() != Some(&b'\n') {
            bail!(
                "an answer line longer than {MAX_ANSWER_LINE_BYTES} bytes on standard input: \
                 each answer is a line of its own (a, r, s, A or q); nothing written"
            );
        }
        let line = String::from_utf8_lossy(&bytes);
        if echo {
            let _ = writeln!(prompt, "{}", escaped(line.trim_end()));
        }
        let answer = match line.trim() {
            "a" | "accept" | "y" | "yes" => Answer::Accept,
            "r" | "reject" | "n" | "no" => Answer::Reject,
            "s" | "skip" | "" => Answer::Skip,
            "A" | "all" => Answer::AcceptRest,
            "q" | "quit" => Answer::Quit,
            other => {
                let _ = write!(
                    prompt,
                    "`{}` is not an answer: a (accept), r (reject), s (skip), A (accept the rest), q (quit)? ",
                    escaped(other)
                );
                let _ = prompt.flush();
                continue;
            }
        };
        return Ok(Some(answer));
    }
}

/// `--review`: checks the trace as `check` does (against the core, or the
/// engine's answers against the trace's expectations), shows each
/// divergent sweep with its explanation and asks. Returns the accepted
/// sweeps, or `None` when there is nothing to write.
fn review(
    args: &Args,
    engine: Option<&BlessEngine>,
    options: &CheckOptions,
) -> anyhow::Result<Option<BTreeSet<(u64, u32)>>> {
    let (report, sides) = match engine {
        None => (check_file(&args.trace, options), Parties::ExpectedAndCore),
        Some(e) => (
            check_file_with_engine(
                &args.trace,
                &e.command,
                e.options,
                Against::Expected,
                options,
            )
            .map_err(anyhow::Error::new)?,
            Parties::ExpectedAndEngine,
        ),
    };
    if let Some(error) = report.errors.first() {
        bail!("{error}");
    }
    let changes: Vec<&Divergence> = report
        .divergences
        .details
        .iter()
        .chain(report.fragile.details.iter())
        .collect();
    let new_side = if engine.is_some() {
        "the engine's answer"
    } else {
        "the core's outcome"
    };
    if changes.is_empty() {
        eprintln!(
            "nothing to review: every expectation of {} agrees with {new_side} ({} compared); nothing written",
            args.trace.display(),
            counted(report.compared, "sweep", "sweeps")
        );
        return Ok(None);
    }
    let stdin = std::io::stdin();
    let echo = !std::io::IsTerminal::is_terminal(&stdin);
    let mut input = stdin.lock();
    let mut prompt = std::io::stderr();
    let (mut accepted, mut skipped, mut rejected) = (BTreeSet::new(), Vec::new(), 0u64);
    let mut accept_rest = false;
    let total = changes.len();
    for (i, d) in changes.iter().enumerate() {
        let key = (d.frame, d.ball);
        if accept_rest {
            accepted.insert(key);
            continue;
        }
        let _ = write!(
            prompt,
            "\n[{}/{total}] {}",
            i + 1,
            render_divergence_as(d, "  ", sides)
        );
        let _ = write!(
            prompt,
            "make {new_side} this sweep's expectation? a (accept), r (reject), s (skip), A (accept the rest), q (quit)? "
        );
        let _ = prompt.flush();
        match read_answer(&mut input, &mut prompt, echo)? {
            Some(Answer::Accept) => {
                accepted.insert(key);
            }
            Some(Answer::Reject) => rejected += 1,
            Some(Answer::Skip) => skipped.push(key),
            Some(Answer::AcceptRest) => {
                accepted.insert(key);
                accept_rest = true;
            }
            Some(Answer::Quit) | None => {
                skipped.extend(changes[i..].iter().map(|d| (d.frame, d.ball)));
                break;
            }
        }
    }
    eprintln!(
        "\nreviewed {}: {} accepted, {rejected} rejected, {} skipped",
        counted(total as u64, "change", "changes"),
        accepted.len(),
        skipped.len()
    );
    if !skipped.is_empty() {
        let list = skipped
            .iter()
            .map(|(f, b)| format!("{f}:{b}"))
            .collect::<Vec<_>>()
            .join(",");
        eprintln!("the skipped, to accept later: --accept {list}");
    }
    if accepted.is_empty() {
        eprintln!("nothing accepted: nothing written");
        return Ok(None);
    }
    Ok(Some(accepted))
}
