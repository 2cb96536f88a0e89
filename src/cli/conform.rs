//! `sweeptrace conform`: the built-in conformance suite run through an
//! engine (the library's [`sweeptrace::conform`]).

use anyhow::{Context, bail};

use super::Exit;
use sweeptrace::conform::{self, CaseQuery, ConformOptions, ConformStatus, RULES};
use sweeptrace::engine::EngineCommand;
use sweeptrace::trace::EventBody;

/// Arguments of `conform`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Examples:
  sweeptrace conform --engine 'python3 examples/engines/sweep_engine.py'
  sweeptrace conform --engine 'python3 examples/engines/trivial_engine.py' --json
  sweeptrace conform --engine 'python3 examples/engines/sweep_engine.py' --case vertex.hit/1
  sweeptrace conform --list
  sweeptrace conform --case vertex.hit --write-trace cases.mcap
  sweeptrace conform --engine 'python3 examples/engines/sweep_engine.py' --junit conform.xml
  sweeptrace conform --engine 'python3 examples/engines/sweep_engine.py' --contacts

Every case is a small scene and one sweep (sent to the engine as in `check
--engine`, docs/ENGINE_PROTOCOL.md), grouped by the rule of
docs/SEMANTICS.md it exercises: face, edge and vertex hits and each way
each can miss, shared edges and vertices with ties, cube corners, grazing
and parallel paths, starts touching or inside ρ, zero-length paths,
margins, strict and non-strict facing, degenerate triangles. The core's
outcome is the expected answer. The cases are exact in binary, so the
rules, not rounding, decide them: an answer naming another member of the
tie set fails its rule (the report says which member the tie order face <
edge < vertex, then triangle, then feature chooses, and why), and a
divergence fails even when a perturbation of the inputs reproduces it
(counted as `fragile` too). --lenient lets both pass. One line per rule with passed / failed / fragile counts,
then each failing rule's first failing case explained, with a command that
runs it alone. With --contacts, contact queries too (the `contact.*` rules:
face, edges, vertices, a flat seam, a shallow convex edge, a concave corner,
the contact distance, apart and behind), judged as `check --engine
--engine-contacts` judges them; a ghost contact fails its rule. Exit status: 0 every case passes, 1 a case fails, 2 a fault
of the engine or a bad argument, 125 the engine cannot be started.")]
pub struct Args {
    /// The command that starts the engine, split like a shell's words, e.g.
    /// `--engine "python3 engine.py"` or `--engine ./build/engine`.
    #[arg(long, value_name = "COMMAND", required_unless_present_any = ["list", "write_trace"])]
    pub engine: Option<String>,
    /// Run only this case (`edge.hit/2`), rule (`edge.hit`) or group of
    /// rules (`edge`, `edge.miss`).
    #[arg(long, value_name = "RULE[/INDEX]")]
    pub case: Option<String>,
    /// Run the contact rules too (`contact.*`): contact queries, which the
    /// engine must answer (docs/ENGINE_PROTOCOL.md, `contact`). Naming a
    /// contact rule with --case runs it without this flag.
    #[arg(long)]
    pub contacts: bool,
    /// List the rules and their cases (no engine needed; the contact rules'
    /// too).
    #[arg(long)]
    pub list: bool,
    /// Write the chosen cases as a trace (each case's scene, then its sweep
    /// or contact query as frame N, the case's number), to look at them with the other
    /// commands, e.g. `--case vertex.hit --write-trace cases.mcap`, then
    /// `sweeptrace sweep --trace cases.mcap --frame 21` or `sweeptrace
    /// replay cases.mcap --spawn`. No engine needed.
    #[arg(long, value_name = "FILE")]
    pub write_trace: Option<std::path::PathBuf>,
    /// Judge as `check` does without --strict: an answer naming another
    /// member of the tie set passes, and so does a divergence that a
    /// perturbation of the inputs within the rounding budget reproduces
    /// (counted apart). By default both fail: every case is exact in
    /// binary, so the rules decide it; the `fragile` count says how many
    /// failures sit at a rounding boundary, where an engine that computes
    /// in another order could differ.
    #[arg(long)]
    pub lenient: bool,
    #[command(flatten)]
    pub tolerances: super::ToleranceArgs,
    /// The longest wait, in seconds, for the engine's next answer, e.g.
    /// `--engine-timeout 2.5`.
    #[arg(long, value_name = "SECONDS", default_value_t = sweeptrace::engine::DEFAULT_TIMEOUT.as_secs_f64())]
    pub engine_timeout: f64,
    /// Print one JSON document instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub junit: super::junit::JunitArgs,
    #[command(flatten)]
    pub conventions: sweeptrace::conventions::PartialConventions,
    /// The engine's conventions from this `sweeptrace.toml` (its `[engine]`
    /// table) instead of the nearest one from the current directory up.
    #[arg(long, value_name = "FILE", conflicts_with = "no_config")]
    pub config: Option<std::path::PathBuf>,
    /// Judge by the rules and the flags only: read no `sweeptrace.toml`.
    #[arg(long)]
    pub no_config: bool,
}

/// The engine's conventions for `conform`: the `[engine]` table of
/// `--config FILE`, or of the nearest `sweeptrace.toml` from the current
/// directory up (none with `--no-config`), under the flags.
fn conventions(args: &Args) -> anyhow::Result<sweeptrace::conventions::EngineConventions> {
    use sweeptrace::suite::config::{ConfigFile, Overrides, resolve, settings_for};
    let overrides = Overrides {
        engine: args.conventions.clone(),
        ..Overrides::default()
    };
    let here = std::env::current_dir()
        .context("finding the current directory")?
        .join("conform");
    let settings = if args.no_config {
        resolve(&[], &here, &overrides)
    } else if let Some(path) = &args.config {
        let file = ConfigFile::read(path, &path.display().to_string())?;
        resolve(&[file], &here, &overrides)
    } else {
        settings_for(&here, &overrides)?
    };
    Ok(settings.engine.conventions())
}

/// Runs the suite, prints the report, returns the exit code.
pub fn run(args: Args) -> anyhow::Result<Exit> {
    let cases = conform::select(args.case.as_deref(), args.contacts || args.list)?;
    if args.list {
        print!("{}", list_text(&cases));
        return Ok(Exit::Success);
    }
    if let Some(path) = &args.write_trace {
        super::warn_unfinished(path);
        sweeptrace::trace::write_trace_file(path, |w| {
            for event in conform::case_events(&cases) {
                let log_time_nanos = event.header.log_time_nanos;
                match event.body {
                    EventBody::Scene(scene) => w.scene(log_time_nanos, &scene)?,
                    EventBody::Sweep(sweep) => w.sweep(log_time_nanos, &sweep)?,
                    EventBody::Contact(query) => w.contact(log_time_nanos, &query)?,
                    EventBody::Expected(_) | EventBody::ExpectedContacts(_) => {}
                }
            }
            Ok::<_, sweeptrace::trace::TraceError>(())
        })
        .with_context(|| format!("writing {}", path.display()))?;
        eprintln!(
            "wrote {} ({}; frame N is case N: {})",
            path.display(),
            sweeptrace::numbers::counted(cases.len() as u64, "case", "cases"),
            cases
                .iter()
                .map(|c| format!("{} {}", c.frame(), c.id()))
                .collect::<Vec<_>>()
                .join(", ")
        );
        if args.engine.is_none() {
            return Ok(Exit::Success);
        }
    }
    let Some(text) = &args.engine else {
        bail!("--engine is required (or --list)");
    };
    let command = EngineCommand::parse(text)?;
    let engine = super::check::engine_options(args.engine_timeout)?;
    let options = ConformOptions {
        tolerances: args.tolerances.to_tolerances()?,
        strict: !args.lenient,
        only: args.case.clone(),
        conventions: conventions(&args)?,
    };
    let junit = args.junit.start()?;
    let report = match conform::run(&command, engine, &cases, &options) {
        Ok(report) => report,
        Err(err) => {
            eprintln!("error: {err}");
            return Ok(Exit::EngineUnavailable);
        }
    };
    let outcome = outcome_of(report.status());
    if args.json {
        print!("{}", conform::render_json(&report, outcome.exit_code()));
    } else {
        print!("{}", conform::render_text(&report));
    }
    if let Some(junit) = junit {
        let xml = conform::conform_junit(
            &report,
            &options.tolerances,
            Some(junit.elapsed()),
            junit.options(),
        );
        junit.finish(&xml)?;
    }
    Ok(outcome)
}

/// What a conformance run came to: a fault of the engine is an error, a
/// failed case a difference.
fn outcome_of(status: ConformStatus) -> Exit {
    match status {
        ConformStatus::Ok => Exit::Success,
        ConformStatus::Fail => Exit::Differences,
        ConformStatus::Error => Exit::Error,
    }
}

/// The rules and their cases, one line each.
fn list_text(cases: &[conform::Case]) -> String {
    let mut s = String::new();
    for rule in RULES {
        let of_rule: Vec<&conform::Case> = cases.iter().filter(|c| c.rule == rule.name).collect();
        if of_rule.is_empty() {
            continue;
        }
        s.push_str(&format!("{}: {}\n", rule.name, rule.description));
        for c in of_rule {
            let asked = match &c.query {
                CaseQuery::Sweep(sweep) => format!(
                    "radius {}, p0 {:?}, p1 {:?}, margin {}, facing {}; the core: {}",
                    sweep.radius, sweep.p0, sweep.p1, c.scene.margin, c.scene.facing, c.kind
                ),
                CaseQuery::Contact { query, set } => format!(
                    "radius {}, centre {:?}, contact distance {}; the core: {}",
                    query.radius,
                    query.centre,
                    query.distance,
                    if set.is_empty() {
                        "no contact".to_string()
                    } else {
                        set.iter()
                            .map(|(t, f)| format!("{f} of triangle {t}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ),
            };
            s.push_str(&format!("  {}: {} ({asked})\n", c.id(), c.what));
        }
    }
    s
}
