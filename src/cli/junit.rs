//! `--junit` and `--junit-detail` of `check` and `conform`, and `check`'s
//! GitHub Actions annotations: the file is created (under a temporary
//! name) before the run, so an unwritable place fails at once, and renamed
//! into place when the report is complete; rendering is the library's
//! ([`sweeptrace::suite::check_junit`], [`sweeptrace::conform::conform_junit`]).

use std::io::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime};

use anyhow::Context;

use sweeptrace::atomic::{FinishStep, PendingFile};
use sweeptrace::junit::{Detail, JunitOptions};
use sweeptrace::suite::TraceReport;

/// The environment variable GitHub Actions sets to `true` in its jobs.
const GITHUB_ACTIONS: &str = "GITHUB_ACTIONS";

/// The JUnit report's arguments.
#[derive(Debug, clap::Args)]
pub struct JunitArgs {
    /// Also write the results as JUnit XML, the test report CI systems
    /// show (GitHub, GitLab, Jenkins, Buildkite, Azure), e.g. `--junit
    /// report.xml`: check writes one test suite per trace with a test case
    /// for the trace; conform one test suite per group of rules (face,
    /// edge, tie, ...) with a test case per rule. A failure's message is
    /// the first divergence; its text is what is printed for that trace or
    /// rule. A trace that could not be checked is an error; a divergence
    /// that rounding explains is a skipped test case (check without
    /// --strict, conform with --lenient), otherwise a failure. The file is
    /// written under a temporary name and renamed when complete.
    #[arg(long, value_name = "FILE")]
    pub junit: Option<PathBuf>,
    /// With --junit: `traces` (the default), one test case per trace
    /// (check) or rule (conform); `sweeps`, also one per divergent sweep
    /// shown in detail and per tunnel (check) or per divergent case
    /// (conform).
    #[arg(long, value_enum, value_name = "LEVEL", default_value_t = DetailArg::Traces, requires = "junit")]
    pub junit_detail: DetailArg,
}

/// `--junit-detail`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DetailArg {
    /// One test case per trace (check) or rule (conform).
    Traces,
    /// Also one per divergent sweep (check) or case (conform).
    Sweeps,
}

/// A JUnit report being written: its temporary file, from the start of
/// the run.
#[derive(Debug)]
pub struct JunitOutput {
    pending: PendingFile,
    file: std::io::BufWriter<std::fs::File>,
    options: JunitOptions,
    started: Instant,
}

impl JunitArgs {
    /// Creates the report's temporary file next to `--junit FILE` (none
    /// without `--junit`).
    pub fn start(&self) -> anyhow::Result<Option<JunitOutput>> {
        let Some(target) = &self.junit else {
            return Ok(None);
        };
        if target.is_dir() {
            anyhow::bail!(
                "--junit {}: is a directory, not a file to write the JUnit report to",
                target.display()
            );
        }
        super::warn_unfinished(target);
        let (pending, file) = PendingFile::create(target).with_context(|| {
            format!(
                "creating the JUnit report {}: cannot create a temporary file next to it",
                target.display()
            )
        })?;
        let unix_seconds = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        Ok(Some(JunitOutput {
            pending,
            file: std::io::BufWriter::new(file),
            options: JunitOptions {
                detail: match self.junit_detail {
                    DetailArg::Traces => Detail::Traces,
                    DetailArg::Sweeps => Detail::Sweeps,
                },
                timestamp: Some(sweeptrace::junit::timestamp(unix_seconds)),
            },
            started: Instant::now(),
        }))
    }
}

impl JunitOutput {
    /// The report's options.
    pub fn options(&self) -> &JunitOptions {
        &self.options
    }

    /// How long since the report was started.
    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// Writes `xml`, makes it durable and renames it into place.
    pub fn finish(mut self, xml: &str) -> anyhow::Result<()> {
        let target = self.pending.target().to_path_buf();
        let writing = || format!("writing the JUnit report {}", target.display());
        self.file.write_all(xml.as_bytes()).with_context(writing)?;
        self.pending.finish(self.file).map_err(|e| match e.step {
            FinishStep::Renaming => anyhow::Error::new(e.cause).context(format!(
                "renaming the finished JUnit report to {}",
                target.display()
            )),
            FinishStep::Flushing | FinishStep::Syncing => {
                anyhow::Error::new(e.cause).context(writing())
            }
        })?;
        eprintln!("wrote the JUnit report {}", target.display());
        Ok(())
    }
}

/// `check`'s JUnit report, when `--junit` asked for one: `times[i]` is how
/// long `reports[i]` took.
pub fn finish_check(
    junit: Option<JunitOutput>,
    reports: &[TraceReport],
    times: &[Duration],
) -> anyhow::Result<()> {
    let Some(junit) = junit else {
        return Ok(());
    };
    let xml = sweeptrace::suite::check_junit(reports, times, junit.options());
    junit.finish(&xml)
}

/// In a GitHub Actions job (`GITHUB_ACTIONS=true`), prints the trace's
/// annotations on stdout, where the runner reads workflow commands.
pub fn print_github_annotations(report: &TraceReport) {
    if std::env::var_os(GITHUB_ACTIONS).is_some_and(|v| v == "true") {
        print!("{}", sweeptrace::suite::github_annotations(report));
    }
}
