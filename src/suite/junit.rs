//! `check`'s reports for CI systems: JUnit XML ([`check_junit`]) and
//! GitHub Actions annotations ([`github_annotations`]), pure functions of
//! the reports, as [`super::render_text`] is.
//!
//! One `<testsuite>` per trace, with the tolerances, the compared fields
//! and (`check --engine`) the engine's command as `<properties>`. In it, a
//! `<testcase>` for the trace: a `FAIL` (a divergence, a divergent contact
//! query, or a tunnel or ghost contact that fails the check) is a
//! `<failure>` whose `message` is the first divergence on one line and whose text is what `check` prints for the
//! trace; a trace that could not be checked (`ERROR`, `NO EXPECTATIONS`)
//! is an `<error>`. Each divergence rounding explains (the report's
//! `fragile_divergences`, kept apart without `--strict`) is a `<skipped>`
//! test case of its own; under `--strict` it is a divergence like any
//! other. With [`Detail::Sweeps`], each divergence and each divergent
//! contact query kept in detail, and each listed tunnel or ghost contact
//! that fails the check, is a failing test case too.

use std::time::Duration;

use crate::junit::{Case, CaseResult, Detail, JunitOptions, Problem, Report, Suite};

use super::render::{render_text, sides_of};
use super::report::{Status, TraceReport};
use crate::judge::divergence::{divergence_line, render_divergence_as};

/// The `classname` of a trace's test case.
const TRACE_CLASS: &str = "check";
/// The `classname` of a divergent sweep's test case (with [`Detail::Sweeps`]).
const SWEEP_CLASS: &str = "check.sweep";
/// The `classname` of a divergence rounding explains.
const FRAGILE_CLASS: &str = "check.fragile";
/// The `classname` of a tunnel's test case (with [`Detail::Sweeps`]).
const TUNNEL_CLASS: &str = "check.tunnel";
/// The `classname` of a ghost contact's test case (with [`Detail::Sweeps`]).
const GHOST_CLASS: &str = "check.ghost_contact";
/// The `classname` of a divergent contact query's test case (with
/// [`Detail::Sweeps`]).
const CONTACT_CLASS: &str = "check.contact_query";

/// A divergent contact query in one line: where, and its first problem.
fn contact_line(v: &crate::judge::ContactVerdict) -> String {
    let first = v
        .problems
        .first()
        .map_or_else(String::new, |p| format!(": {p}"));
    let more = match v.problems.len() {
        0 | 1 => String::new(),
        n => format!(" (and {} more)", n - 1),
    };
    format!(
        "contact query, frame {}, ball {}{first}{more}",
        v.frame, v.ball
    )
}

/// The reports of one `check` run as a JUnit XML document. `times[i]` is
/// how long `reports[i]` took (a trace without one has no `time`).
pub fn check_junit(reports: &[TraceReport], times: &[Duration], options: &JunitOptions) -> String {
    let suites = reports
        .iter()
        .enumerate()
        .map(|(i, r)| trace_suite(r, times.get(i).copied(), options))
        .collect();
    crate::junit::render(&Report {
        name: "sweeptrace check".to_string(),
        time_seconds: Some(times.iter().map(Duration::as_secs_f64).sum()),
        timestamp: options.timestamp.clone(),
        suites,
    })
}

/// What went wrong with a trace, on one line: for a `FAIL`, the first
/// divergence (with how many there are) and the first tunnel that fails
/// the check; for an `ERROR`, the first error; for `NO EXPECTATIONS`,
/// why. `None` for a trace that passed.
pub fn first_problem(r: &TraceReport) -> Option<String> {
    let sides = sides_of(r);
    match r.status() {
        Status::Ok => None,
        Status::Fail => {
            let mut parts: Vec<String> = Vec::new();
            if r.divergent > 0 {
                let first = match (r.divergences.details.first(), r.divergences.frames.first()) {
                    (Some(d), _) => divergence_line(d, sides),
                    (None, Some(frame)) => format!("frame {frame}"),
                    (None, None) => "not kept".to_string(),
                };
                parts.push(format!(
                    "{} of {} compared {} {}; first divergence: {first}",
                    r.divergent,
                    r.compared,
                    crate::numbers::plural(r.compared, "sweep"),
                    crate::numbers::verb(r.divergent, "diverges", "diverge")
                ));
            }
            if r.contacts.divergent > 0 {
                let first = r
                    .contacts
                    .details
                    .first()
                    .map_or_else(String::new, |v| format!("; first: {}", contact_line(v)));
                parts.push(format!(
                    "{} of {} contact queries diverge{first}",
                    r.contacts.divergent, r.contacts.compared
                ));
            }
            if r.fails_on_tunnels() {
                let first = r
                    .tunnels
                    .details
                    .first()
                    .map_or_else(String::new, |t| format!("; first tunnel: {}", t.line()));
                parts.push(format!(
                    "{} {} (a ball's centre went through a triangle from its front to its back){first}",
                    r.tunnels.count,
                    if r.tunnels.count == 1 { "tunnel" } else { "tunnels" }
                ));
            }
            if r.fails_on_ghosts() {
                let first = r
                    .ghosts
                    .contacts
                    .first()
                    .map_or_else(String::new, |g| format!("; first ghost contact: {g}"));
                parts.push(format!(
                    "{}{first}",
                    crate::numbers::counted(r.ghosts.count, "ghost contact", "ghost contacts")
                ));
            }
            Some(crate::junit::one_line(&parts.join("; ")))
        }
        Status::Error => {
            let prefix = format!("{}: ", r.trace);
            let first = r.errors.first().map_or("error", String::as_str);
            Some(crate::junit::one_line(
                first.strip_prefix(&prefix).unwrap_or(first),
            ))
        }
        Status::NoExpectations => {
            // The status line's reason, before the counts.
            let text = render_text(r);
            let line = text.lines().next().unwrap_or_default();
            let prefix = format!("{} {}: ", r.status(), r.trace);
            let why = line.strip_prefix(&prefix).unwrap_or(line);
            Some(why.split_once("; ").map_or(why, |(w, _)| w).to_string())
        }
    }
}

fn properties(r: &TraceReport) -> Vec<(String, String)> {
    let t = &r.tolerances;
    let mut p = vec![
        ("tolerance.alpha".to_string(), t.alpha.to_string()),
        (
            "tolerance.normal_degrees".to_string(),
            t.normal_degrees.to_string(),
        ),
        ("tolerance.contact".to_string(), t.contact.to_string()),
        ("fields".to_string(), t.fields.names()),
        ("strict".to_string(), r.fragile.strict.to_string()),
        ("fail_on_tunnel".to_string(), r.tunnels.fail.to_string()),
    ];
    if let Some(engine) = &r.engine {
        p.push(("engine".to_string(), engine.command.clone()));
        p.push((
            "against".to_string(),
            match engine.against {
                super::report::Against::Core => "core",
                super::report::Against::Expected => "expected",
            }
            .to_string(),
        ));
    }
    p
}

fn trace_suite(r: &TraceReport, time: Option<Duration>, options: &JunitOptions) -> Suite {
    let sides = sides_of(r);
    let text = render_text(r);
    let file = Some(r.trace.clone());
    let problem = |kind: &str, message: String| Problem {
        message,
        kind: kind.to_string(),
        body: text.clone(),
    };
    let result = match (r.status(), first_problem(r)) {
        (Status::Ok, _) | (_, None) => CaseResult::Passed,
        (Status::Fail, Some(m)) => CaseResult::Failure(problem(
            if r.divergent > 0 {
                "divergence"
            } else if r.contacts.divergent > 0 {
                "contact_divergence"
            } else if r.fails_on_tunnels() {
                "tunnel"
            } else {
                "ghost_contact"
            },
            m,
        )),
        (Status::NoExpectations, Some(m)) => CaseResult::Error(problem("no_expectations", m)),
        (Status::Error, Some(m)) => CaseResult::Error(problem(
            if r.incomplete && r.errors.len() == 1 {
                "incomplete"
            } else {
                "error"
            },
            m,
        )),
    };
    let passed = result == CaseResult::Passed;
    let mut cases = vec![Case {
        name: r.trace.clone(),
        classname: TRACE_CLASS.to_string(),
        file: file.clone(),
        time_seconds: time.map(|t| t.as_secs_f64()),
        result,
        system_out: passed.then(|| text.clone()),
    }];
    if options.detail == Detail::Sweeps {
        for d in &r.divergences.details {
            cases.push(Case {
                name: format!("{}: frame {}, ball {}", r.trace, d.frame, d.ball),
                classname: SWEEP_CLASS.to_string(),
                file: file.clone(),
                time_seconds: None,
                result: CaseResult::Failure(Problem {
                    message: divergence_line(d, sides),
                    kind: "divergence".to_string(),
                    body: render_divergence_as(d, "", sides),
                }),
                system_out: None,
            });
        }
        for v in &r.contacts.details {
            let body: String = v.problems.iter().map(|p| format!("{p}\n")).collect();
            cases.push(Case {
                name: format!(
                    "{}: contact query, frame {}, ball {}",
                    r.trace, v.frame, v.ball
                ),
                classname: CONTACT_CLASS.to_string(),
                file: file.clone(),
                time_seconds: None,
                result: CaseResult::Failure(Problem {
                    message: contact_line(v),
                    kind: "contact_divergence".to_string(),
                    body,
                }),
                system_out: None,
            });
        }
        if r.fails_on_tunnels() {
            for t in &r.tunnels.details {
                cases.push(Case {
                    name: format!("{}: tunnel, frame {}, ball {}", r.trace, t.frame, t.ball),
                    classname: TUNNEL_CLASS.to_string(),
                    file: file.clone(),
                    time_seconds: None,
                    result: CaseResult::Failure(Problem {
                        message: format!("tunnel: {}", t.line()),
                        kind: "tunnel".to_string(),
                        body: format!(
                            "a ball's centre went through a triangle from its front to its back: {}\n",
                            t.line()
                        ),
                    }),
                    system_out: None,
                });
            }
        }
        if r.fails_on_ghosts() {
            for g in &r.ghosts.contacts {
                cases.push(Case {
                    name: format!(
                        "{}: ghost contact, frame {}, ball {}",
                        r.trace, g.frame, g.ball
                    ),
                    classname: GHOST_CLASS.to_string(),
                    file: file.clone(),
                    time_seconds: None,
                    result: CaseResult::Failure(Problem {
                        message: format!("ghost contact: {g}"),
                        kind: "ghost_contact".to_string(),
                        body: format!("{g}\n"),
                    }),
                    system_out: None,
                });
            }
        }
    }
    for d in &r.fragile.details {
        cases.push(Case {
            name: format!("{}: frame {}, ball {} (fragile)", r.trace, d.frame, d.ball),
            classname: FRAGILE_CLASS.to_string(),
            file: file.clone(),
            time_seconds: None,
            result: CaseResult::Skipped {
                message: format!(
                    "a divergence rounding explains (not a failure without --strict): {}",
                    divergence_line(d, sides)
                ),
            },
            system_out: Some(render_divergence_as(d, "", sides)),
        });
    }
    Suite {
        name: r.trace.clone(),
        time_seconds: time.map(|t| t.as_secs_f64()),
        timestamp: options.timestamp.clone(),
        properties: properties(r),
        cases,
    }
}

/// GitHub Actions workflow commands for one trace's report, one line each
/// (`::error file=TRACE,title=...::message`): the first divergences of a
/// failing trace (those kept in detail) and its tunnels that fail the
/// check, or why a trace could not be checked. Empty for a trace that
/// passed.
pub fn github_annotations(r: &TraceReport) -> String {
    let sides = sides_of(r);
    let mut lines: Vec<(String, String)> = Vec::new();
    match r.status() {
        Status::Ok => {}
        Status::Fail => {
            for d in &r.divergences.details {
                lines.push((
                    format!(
                        "sweeptrace check: frame {}, ball {} diverges",
                        d.frame, d.ball
                    ),
                    divergence_line(d, sides),
                ));
            }
            if r.divergences.details.is_empty()
                && r.divergent > 0
                && let Some(message) = first_problem(r)
            {
                lines.push(("sweeptrace check: FAIL".to_string(), message));
            }
            for v in &r.contacts.details {
                lines.push((
                    format!(
                        "sweeptrace check: contact query, frame {}, ball {} diverges",
                        v.frame, v.ball
                    ),
                    contact_line(v),
                ));
            }
            if r.fails_on_tunnels() {
                for t in &r.tunnels.details {
                    lines.push((
                        format!("sweeptrace check: tunnel, frame {}, ball {}", t.frame, t.ball),
                        format!(
                            "a ball's centre went through a triangle from its front to its back: {}",
                            t.line()
                        ),
                    ));
                }
            }
            if r.fails_on_ghosts() {
                for g in &r.ghosts.contacts {
                    lines.push((
                        format!(
                            "sweeptrace check: ghost contact, frame {}, ball {}",
                            g.frame, g.ball
                        ),
                        g.to_string(),
                    ));
                }
            }
        }
        Status::Error | Status::NoExpectations => {
            if let Some(message) = first_problem(r) {
                lines.push((format!("sweeptrace check: {}", r.status()), message));
            }
        }
    }
    lines
        .iter()
        .map(|(title, message)| {
            format!(
                "::error file={},title={}::{}\n",
                github_property(&r.trace),
                github_property(title),
                github_data(message)
            )
        })
        .collect()
}

/// A workflow command's message escaped as GitHub requires: `%`, carriage
/// return and newline as `%25`, `%0D`, `%0A`.
pub fn github_data(s: &str) -> String {
    s.replace('%', "%25")
        .replace('\r', "%0D")
        .replace('\n', "%0A")
}

/// A workflow command's property value (`file=`, `title=`): as
/// [`github_data`], and `:` and `,` as `%3A`, `%2C`.
pub fn github_property(s: &str) -> String {
    github_data(s).replace(':', "%3A").replace(',', "%2C")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn github_escapes_what_workflow_commands_reserve() {
        assert_eq!(github_data("50% a\r\nb: c, d"), "50%25 a%0D%0Ab: c, d");
        assert_eq!(github_property("a%:b,c\n"), "a%25%3Ab%2Cc%0A");
    }
}
