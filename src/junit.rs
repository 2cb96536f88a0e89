//! JUnit XML, the test report every CI system reads (GitHub, GitLab,
//! Jenkins, Buildkite, Azure): a small document model and its rendering
//! as a pure function, in the de-facto Jenkins/Surefire format
//! (`testsuites` > `testsuite` > `properties`, `testcase` > `failure` /
//! `error` / `skipped`, `system-out`).
//!
//! `check` ([`crate::suite::check_junit`]) and `conform`
//! ([`crate::conform::conform_junit`]) build a [`Report`] from their reports;
//! [`render`] writes it, counting `tests`, `failures`, `errors` and
//! `skipped` on every suite and on the root. Text is escaped for XML 1.0,
//! and characters XML 1.0 cannot hold at all (control characters other
//! than tab, newline and carriage return; unpaired surrogates cannot occur
//! in a Rust string) are replaced by `U+FFFD`.

use std::fmt::Write as _;

/// How many test cases a report has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Detail {
    /// One per trace (`check`) or per rule (`conform`), plus one per
    /// divergence rounding explains (skipped).
    #[default]
    Traces,
    /// Also one per divergent sweep kept in detail (`check`) or failing
    /// case (`conform`), and per tunnel that fails the check.
    Sweeps,
}

/// Options of the JUnit reports of `check` and `conform`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JunitOptions {
    /// How many test cases.
    pub detail: Detail,
    /// When the run started ([`timestamp`]), written on the suites and
    /// the root; `None` leaves it out.
    pub timestamp: Option<String>,
}

/// The whole document: the `<testsuites>` root.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// The root's `name`.
    pub name: String,
    /// The root's `time`, in seconds (the whole run's, when measured).
    pub time_seconds: Option<f64>,
    /// The root's `timestamp`: when the run started (ISO 8601, UTC; see
    /// [`timestamp`]).
    pub timestamp: Option<String>,
    /// The suites.
    pub suites: Vec<Suite>,
}

/// A `<testsuite>`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Suite {
    /// `name`.
    pub name: String,
    /// `time`, in seconds.
    pub time_seconds: Option<f64>,
    /// `timestamp` (ISO 8601, UTC).
    pub timestamp: Option<String>,
    /// `<properties>`: name and value.
    pub properties: Vec<(String, String)>,
    /// The test cases.
    pub cases: Vec<Case>,
}

/// A `<testcase>`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Case {
    /// `name`.
    pub name: String,
    /// `classname`.
    pub classname: String,
    /// `file` (GitLab and several GitHub reporters link the case to it).
    pub file: Option<String>,
    /// `time`, in seconds.
    pub time_seconds: Option<f64>,
    /// Passed, failed, errored or skipped.
    pub result: CaseResult,
    /// `<system-out>`: what the command printed for this case.
    pub system_out: Option<String>,
}

/// How a test case came out.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum CaseResult {
    /// Passed.
    #[default]
    Passed,
    /// `<failure>`: the check found a difference.
    Failure(Problem),
    /// `<error>`: the case could not be checked.
    Error(Problem),
    /// `<skipped>`: not a failure, with the reason.
    Skipped {
        /// `message`.
        message: String,
    },
}

/// A failure's or an error's content.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Problem {
    /// `message`: one line (line breaks are replaced by spaces).
    pub message: String,
    /// `type`: a short word for the kind of problem.
    pub kind: String,
    /// The element's text: the full explanation.
    pub body: String,
}

/// The counts of a suite or of the whole report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Test cases.
    pub tests: u64,
    /// Cases with a `<failure>`.
    pub failures: u64,
    /// Cases with an `<error>`.
    pub errors: u64,
    /// Cases `<skipped>`.
    pub skipped: u64,
}

impl Counts {
    /// The counts of `cases`.
    pub fn of(cases: &[Case]) -> Counts {
        let mut c = Counts::default();
        for case in cases {
            c.tests += 1;
            match case.result {
                CaseResult::Passed => {}
                CaseResult::Failure(_) => c.failures += 1,
                CaseResult::Error(_) => c.errors += 1,
                CaseResult::Skipped { .. } => c.skipped += 1,
            }
        }
        c
    }

    fn add(self, other: Counts) -> Counts {
        Counts {
            tests: self.tests + other.tests,
            failures: self.failures + other.failures,
            errors: self.errors + other.errors,
            skipped: self.skipped + other.skipped,
        }
    }

    fn attributes(self) -> String {
        format!(
            r#" tests="{}" failures="{}" errors="{}" skipped="{}""#,
            self.tests, self.failures, self.errors, self.skipped
        )
    }
}

impl Report {
    /// The counts over every suite.
    pub fn counts(&self) -> Counts {
        self.suites
            .iter()
            .map(|s| Counts::of(&s.cases))
            .fold(Counts::default(), Counts::add)
    }
}

/// The document as XML 1.0 (UTF-8, ending with a newline).
pub fn render(report: &Report) -> String {
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = write!(
        s,
        "<testsuites name=\"{}\"{}",
        attribute(&report.name),
        report.counts().attributes()
    );
    optional_attributes(&mut s, report.time_seconds, report.timestamp.as_deref());
    s.push_str(">\n");
    for suite in &report.suites {
        render_suite(&mut s, suite);
    }
    s.push_str("</testsuites>\n");
    s
}

fn render_suite(s: &mut String, suite: &Suite) {
    let _ = write!(
        s,
        "  <testsuite name=\"{}\"{}",
        attribute(&suite.name),
        Counts::of(&suite.cases).attributes()
    );
    optional_attributes(s, suite.time_seconds, suite.timestamp.as_deref());
    s.push_str(">\n");
    if !suite.properties.is_empty() {
        s.push_str("    <properties>\n");
        for (name, value) in &suite.properties {
            let _ = writeln!(
                s,
                "      <property name=\"{}\" value=\"{}\"/>",
                attribute(name),
                attribute(value)
            );
        }
        s.push_str("    </properties>\n");
    }
    for case in &suite.cases {
        render_case(s, case);
    }
    s.push_str("  </testsuite>\n");
}

fn render_case(s: &mut String, case: &Case) {
    let _ = write!(
        s,
        "    <testcase name=\"{}\" classname=\"{}\"",
        attribute(&case.name),
        attribute(&case.classname)
    );
    if let Some(file) = &case.file {
        let _ = write!(s, " file=\"{}\"", attribute(file));
    }
    optional_attributes(s, case.time_seconds, None);
    if case.result == CaseResult::Passed && case.system_out.is_none() {
        s.push_str("/>\n");
        return;
    }
    s.push_str(">\n");
    let problem = |s: &mut String, element: &str, p: &Problem| {
        let _ = writeln!(
            s,
            "      <{element} message=\"{}\" type=\"{}\">{}</{element}>",
            attribute(&one_line(&p.message)),
            attribute(&p.kind),
            text(&p.body)
        );
    };
    match &case.result {
        CaseResult::Passed => {}
        CaseResult::Failure(p) => problem(s, "failure", p),
        CaseResult::Error(p) => problem(s, "error", p),
        CaseResult::Skipped { message } => {
            let _ = writeln!(
                s,
                "      <skipped message=\"{}\"/>",
                attribute(&one_line(message))
            );
        }
    }
    if let Some(out) = &case.system_out {
        let _ = writeln!(s, "      <system-out>{}</system-out>", text(out));
    }
    s.push_str("    </testcase>\n");
}

fn optional_attributes(s: &mut String, time_seconds: Option<f64>, timestamp: Option<&str>) {
    if let Some(t) = time_seconds {
        let _ = write!(s, " time=\"{}\"", seconds(t));
    }
    if let Some(t) = timestamp {
        let _ = write!(s, " timestamp=\"{}\"", attribute(t));
    }
}

/// A duration as JUnit's `time`: seconds with millisecond digits
/// (`0.042`); a negative or non-finite value (which no clock gives) is 0.
fn seconds(t: f64) -> String {
    if t.is_finite() && t > 0.0 {
        format!("{t:.3}")
    } else {
        "0.000".to_string()
    }
}

/// `text` on one line: every line break (and the spaces around it) becomes
/// one space.
pub fn one_line(text: &str) -> String {
    text.split(['\n', '\r'])
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Whether XML 1.0 can hold `c` at all (its `Char` production).
fn is_xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r' | '\u{20}'..='\u{D7FF}' | '\u{E000}'..='\u{FFFD}' | '\u{10000}'..)
}

/// `value` escaped for an attribute in double quotes. Tab, newline and
/// carriage return are written as character references, which a parser's
/// attribute-value normalization keeps (a literal one would become a
/// space); other characters XML 1.0 cannot hold become `U+FFFD`.
pub fn attribute(value: &str) -> String {
    let mut s = String::with_capacity(value.len());
    for c in value.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            '\t' => s.push_str("&#9;"),
            '\n' => s.push_str("&#10;"),
            '\r' => s.push_str("&#13;"),
            c if is_xml_char(c) => s.push(c),
            _ => s.push('\u{FFFD}'),
        }
    }
    s
}

/// `value` escaped as element text. A carriage return is written as a
/// character reference (a parser would turn a literal one into a newline);
/// other characters XML 1.0 cannot hold become `U+FFFD`.
pub fn text(value: &str) -> String {
    let mut s = String::with_capacity(value.len());
    for c in value.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '\r' => s.push_str("&#13;"),
            c if is_xml_char(c) => s.push(c),
            _ => s.push('\u{FFFD}'),
        }
    }
    s
}

/// A time as JUnit's `timestamp`: ISO 8601 in UTC to the second,
/// `2026-03-01T12:34:56Z`, from seconds since the Unix epoch (a time
/// before the epoch is the epoch).
pub fn timestamp(unix_seconds: u64) -> String {
    let days = unix_seconds / 86_400;
    let rem = unix_seconds % 86_400;
    let (year, month, day) = civil_from_days(days as i64);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// The proleptic Gregorian date `days` after 1970-01-01 (Howard Hinnant's
/// `civil_from_days`).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let year = yoe + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attribute_and_text_escape_markup_and_replace_illegal_characters() {
        assert_eq!(
            attribute("a<b>&\"c'\t\n\r\u{1}\u{FFFE}é"),
            "a&lt;b&gt;&amp;&quot;c&apos;&#9;&#10;&#13;\u{FFFD}\u{FFFD}é"
        );
        assert_eq!(
            text("x < y && z\r\n\u{0}"),
            "x &lt; y &amp;&amp; z&#13;\n\u{FFFD}"
        );
    }

    #[test]
    fn timestamps_are_utc_dates() {
        assert_eq!(timestamp(0), "1970-01-01T00:00:00Z");
        assert_eq!(timestamp(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(timestamp(1_709_251_199), "2024-02-29T23:59:59Z");
        assert_eq!(timestamp(4_102_444_800), "2100-01-01T00:00:00Z");
    }

    #[test]
    fn counts_add_up_on_suites_and_root() {
        let case = |result| Case {
            name: "c".into(),
            classname: "k".into(),
            result,
            ..Case::default()
        };
        let problem = Problem {
            message: "first\nsecond".into(),
            kind: "divergence".into(),
            body: "why".into(),
        };
        let report = Report {
            name: "r".into(),
            suites: vec![
                Suite {
                    name: "a".into(),
                    cases: vec![
                        case(CaseResult::Passed),
                        case(CaseResult::Failure(problem.clone())),
                    ],
                    ..Suite::default()
                },
                Suite {
                    name: "b".into(),
                    cases: vec![
                        case(CaseResult::Error(problem)),
                        case(CaseResult::Skipped {
                            message: "rounding".into(),
                        }),
                    ],
                    ..Suite::default()
                },
            ],
            ..Report::default()
        };
        let xml = render(&report);
        assert!(
            xml.contains(r#"<testsuites name="r" tests="4" failures="1" errors="1" skipped="1">"#)
        );
        assert!(
            xml.contains(r#"<testsuite name="a" tests="2" failures="1" errors="0" skipped="0">"#)
        );
        assert!(
            xml.contains(r#"<testsuite name="b" tests="2" failures="0" errors="1" skipped="1">"#)
        );
        assert!(xml.contains(r#"<failure message="first second" type="divergence">why</failure>"#));
    }
}
