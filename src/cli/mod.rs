//! Argument structs (kept dumb) and dispatch to one file per subcommand.

use clap::parser::ValueSource;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

pub mod bless;
pub mod check;
pub mod check_config;
pub mod conform;
pub mod diff;
mod exit;
pub mod info;
pub mod junit;
pub mod mesh;
pub mod record;
pub mod replay;
pub mod report;
pub mod repro;
pub mod sweep;
pub mod viewer;

pub(crate) use exit::Exit;

/// `--version`: the version, and whether this build lacks the Rerun viewer
/// (its recordings are refused, see [`viewer`]).
const VERSION: &str = if cfg!(feature = "viewer") {
    env!("CARGO_PKG_VERSION")
} else {
    concat!(env!("CARGO_PKG_VERSION"), " (without the Rerun viewer)")
};

/// Replay recorded ball trajectories through a swept-sphere vs triangle-mesh
/// collision core and see, frame by frame, why each collision was or was not
/// found.
#[derive(Debug, Parser)]
#[command(name = "sweeptrace", version = VERSION, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run one sweep (against a built-in scene, an OBJ mesh, or a trace's scene) and explain it: the tests that came close, a tunnel through the mesh, the defects within reach.
    Sweep(sweep::Args),
    /// Summarise a trace: scenes, sweeps, frames, channels, compression, metadata.
    Info(info::Args),
    /// Check a mesh (an OBJ file or a trace's scenes): edges by class, and the defects that change collisions (flipped, cracks, T-junctions, ...).
    Mesh(mesh::Args),
    /// Replay a trace through the core: outcomes, a Rerun recording or a Foxglove file explaining each sweep.
    Replay(replay::Args),
    /// Compare every sweep's outcome with the trace's /expected channel (regression check).
    Check(check::Args),
    /// Run the built-in conformance suite (a case per rule of SEMANTICS.md) through an engine: which rules it breaks, and why.
    Conform(conform::Args),
    /// Rewrite a trace's /expected channel with the current core's outcomes, keeping everything else.
    Bless(bless::Args),
    /// Compare the outcomes of two traces, or of one trace replayed with different options.
    Diff(diff::Args),
    /// Cut one sweep out of a trace: a minimal trace and a ready-to-paste Rust test, bit-exact.
    Repro(repro::Args),
    /// Simulate balls through a scene and record their sweeps and expected outcomes as a trace.
    Record(record::Args),
}

/// Parses the command line (as [`Parser::parse`] does: a bad argument
/// prints clap's error and exits), noting what only the parsed matches
/// know: whether `replay --detail` was given on the command line.
pub fn parse() -> Cli {
    let matches = Cli::command().get_matches();
    let mut cli = Cli::from_arg_matches(&matches)
        .map_err(|e| e.format(&mut Cli::command()))
        .unwrap_or_else(|e| e.exit());
    if let Command::Replay(args) = &mut cli.command {
        args.detail_given = matches
            .subcommand_matches("replay")
            .and_then(|m| m.value_source("detail"))
            == Some(ValueSource::CommandLine);
    }
    cli
}

/// Runs the chosen subcommand; `main` turns what it came to into the exit
/// code ([`Exit::exit_code`]), an error into
/// [`Exit::Error`]'s.
pub fn run(cli: Cli) -> anyhow::Result<Exit> {
    match cli.command {
        Command::Sweep(args) => sweep::run(args),
        Command::Record(args) => record::run(args),
        Command::Info(args) => info::run(args),
        Command::Mesh(args) => mesh::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Check(args) => check::run(args),
        Command::Conform(args) => conform::run(args),
        Command::Bless(args) => bless::run(args),
        Command::Diff(args) => diff::run(args),
        Command::Repro(args) => repro::run(args),
    }
}

/// The comparison tolerances of `check` and `diff`. A value not given is
/// `None`: the default, or for `check` a `sweeptrace.toml`'s value.
#[derive(Debug, clap::Args)]
pub struct ToleranceArgs {
    /// Absolute tolerance on α [default: 1e-6].
    #[arg(long, value_name = "A")]
    pub tolerance: Option<f64>,
    /// Angular tolerance on the normal, in degrees [default: 0.01].
    #[arg(long, value_name = "DEG")]
    pub normal_tolerance: Option<f64>,
    /// Distance tolerance on the contact point, in scene units [default: 1e-6].
    #[arg(long, value_name = "D")]
    pub contact_tolerance: Option<f64>,
    /// Compare only these fields of each expectation (comma-separated:
    /// kind, triangle, feature, alpha, normal, contact; default: every
    /// field the expectation holds). For engines whose answers differ from
    /// the core's in the others. An engine that reports the contact normal
    /// is better described by `--normal contact` (an engine convention),
    /// which keeps the normal compared.
    #[arg(long, value_name = "FIELD,...", value_delimiter = ',', value_parser = field_parser())]
    pub fields: Vec<sweeptrace::judge::Field>,
}

impl ToleranceArgs {
    /// The library's tolerances (the defaults where not given), validated.
    pub fn to_tolerances(&self) -> anyhow::Result<sweeptrace::judge::Tolerances> {
        use sweeptrace::judge::{
            DEFAULT_ALPHA_TOLERANCE, DEFAULT_CONTACT_TOLERANCE, DEFAULT_NORMAL_TOLERANCE_DEGREES,
        };
        let tolerances = sweeptrace::judge::Tolerances {
            alpha: self.tolerance.unwrap_or(DEFAULT_ALPHA_TOLERANCE),
            normal_degrees: self
                .normal_tolerance
                .unwrap_or(DEFAULT_NORMAL_TOLERANCE_DEGREES),
            contact: self.contact_tolerance.unwrap_or(DEFAULT_CONTACT_TOLERANCE),
            fields: self.field_set().unwrap_or(sweeptrace::judge::FieldSet::ALL),
            ..sweeptrace::judge::Tolerances::default()
        };
        tolerances.validate().map_err(anyhow::Error::msg)?;
        Ok(tolerances)
    }

    /// The values given, as the command line's layer of `check`'s settings
    /// (validated).
    pub fn to_overrides(&self) -> anyhow::Result<sweeptrace::suite::config::Overrides> {
        self.to_tolerances()?;
        Ok(sweeptrace::suite::config::Overrides {
            alpha: self.tolerance,
            normal_degrees: self.normal_tolerance,
            contact: self.contact_tolerance,
            fields: self.field_set(),
            ..Default::default()
        })
    }

    fn field_set(&self) -> Option<sweeptrace::judge::FieldSet> {
        (!self.fields.is_empty()).then(|| sweeptrace::judge::FieldSet::of(&self.fields))
    }
}

/// The parser of `--fields`: a name that is not a field is an error listing
/// the valid ones (and the nearest, on a typo).
fn field_parser() -> impl clap::builder::TypedValueParser<Value = sweeptrace::judge::Field> {
    use clap::builder::TypedValueParser;
    use strum::IntoEnumIterator;
    let names: Vec<&'static str> = sweeptrace::judge::Field::iter()
        .map(<&'static str>::from)
        .collect();
    clap::builder::PossibleValuesParser::new(names).try_map(|name: String| {
        name.parse::<sweeptrace::judge::Field>()
            .map_err(|_| format!("`{name}` is not a field"))
    })
}

/// Context for an error that may already name its file: the library's
/// errors name the file they are about, so `doing FILE` is put in front of
/// an error only when its message does not name `file` yet (a message names
/// each file once).
pub trait NameFileOnce<T> {
    /// `self`, with `doing FILE: ` in front of its error unless the error
    /// names `file`.
    fn name_file_once(self, doing: &str, file: impl std::fmt::Display) -> anyhow::Result<T>;
}

impl<T, E: Into<anyhow::Error>> NameFileOnce<T> for Result<T, E> {
    fn name_file_once(self, doing: &str, file: impl std::fmt::Display) -> anyhow::Result<T> {
        self.map_err(|err| {
            let err = err.into();
            let shown = file.to_string();
            if format!("{err:#}").contains(&shown) {
                err
            } else {
                err.context(format!("{doing} {shown}"))
            }
        })
    }
}

/// Opens the input file `path`. Its error is the one wording every
/// command gives for a file it cannot open, the file first as in the
/// library's errors: `run.mcap: cannot open: No such file or directory
/// (os error 2)` (`check` says the same on its `ERROR` line).
pub fn open_input(path: &std::path::Path) -> anyhow::Result<std::fs::File> {
    use anyhow::Context as _;
    std::fs::File::open(path).with_context(|| format!("{}: cannot open", path.display()))
}

/// Opens the trace `path` ([`open_input`]); an OBJ file given instead is
/// an error saying so and what takes one
/// ([`sweeptrace::sim::obj_instead_of_trace`]).
pub fn open_trace(path: &std::path::Path) -> anyhow::Result<std::fs::File> {
    let file = open_input(path)?;
    if let Some(text) = sweeptrace::sim::obj_instead_of_trace(path) {
        anyhow::bail!(text);
    }
    Ok(file)
}

/// Warns about temporary files an interrupted earlier run left next to
/// `target`, and says how to remove them.
pub fn warn_unfinished(target: &std::path::Path) {
    let found = sweeptrace::atomic::unfinished_temporaries(target);
    if found.is_empty() {
        return;
    }
    let names: Vec<String> = found.iter().map(|p| p.display().to_string()).collect();
    eprintln!(
        "warning: {} of {} from an interrupted earlier run \
         (the target itself was not touched); remove them with: rm {}",
        sweeptrace::numbers::counted(
            found.len() as u64,
            "unfinished temporary file",
            "unfinished temporary files"
        ),
        target.display(),
        names.join(" ")
    );
}

/// Parses `x,y,z` into three finite numbers (decimal, or hexadecimal
/// floating point such as `0x1.8p+1`, read exactly).
pub fn parse_point(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers `x,y,z`, got `{s}`"
        ));
    }
    let mut out = [0.0; 3];
    for (o, p) in out.iter_mut().zip(&parts) {
        let v =
            sweeptrace::numbers::parse_f64(p).ok_or_else(|| format!("`{p}` is not a number"))?;
        sweeptrace::numbers::check(v, sweeptrace::numbers::Rule::Finite)
            .map_err(|e| format!("`{p}`: {e}"))?;
        *o = v;
    }
    Ok(out)
}

/// Parses one finite number `≥ 0` (decimal, or hexadecimal floating
/// point).
pub fn parse_non_negative(s: &str) -> Result<f64, String> {
    let v = sweeptrace::numbers::parse_f64(s).ok_or_else(|| format!("`{s}` is not a number"))?;
    sweeptrace::numbers::check(v, sweeptrace::numbers::Rule::NonNegative)?;
    Ok(v)
}

/// Parses one finite number (decimal, or hexadecimal floating point).
pub fn parse_number(s: &str) -> Result<f64, String> {
    let v = sweeptrace::numbers::parse_f64(s).ok_or_else(|| format!("`{s}` is not a number"))?;
    sweeptrace::numbers::check(v, sweeptrace::numbers::Rule::Finite)?;
    Ok(v)
}
