//! `check` reports in words and as JSON: pure functions of a report.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde_json::json;

use super::report::{Status, TraceReport, counts_by_name};
use crate::judge::divergence::{Parties, render_divergence_as};
use crate::judge::write_contact_verdict;

/// Who the two sides of a report's divergences are.
pub fn sides_of(r: &TraceReport) -> Parties {
    match &r.engine {
        None => Parties::ExpectedAndCore,
        Some(e) if e.against == super::report::Against::Expected => Parties::ExpectedAndEngine,
        Some(_) => Parties::EngineAndCore,
    }
}

/// One line of a trace's status, then (when it failed) the first
/// divergences in detail.
pub fn render_text(r: &TraceReport) -> String {
    let mut s = String::new();
    let sides = sides_of(r);
    let counts = counts_text(r);
    match r.status() {
        Status::Ok => {
            let _ = writeln!(s, "ok {}: {counts}", r.trace);
            write_conventions(&mut s, r);
            write_tunnels_and_ghosts(&mut s, r);
            write_fragile_divergences(&mut s, r, sides);
        }
        Status::Fail => {
            let _ = writeln!(s, "FAIL {}: {}; {counts}", r.trace, failures(r).join("; "));
            write_conventions(&mut s, r);
            if !r.convention_hints.is_empty() {
                let _ = writeln!(s, "  {}", r.convention_hints.line());
            }
            write_tunnels_and_ghosts(&mut s, r);
            write_divergences(&mut s, r, sides);
        }
        Status::NoExpectations => {
            let why = no_expectations_reason(r);
            let _ = writeln!(s, "NO EXPECTATIONS {}: {why}; {counts}", r.trace);
            write_tunnels_and_ghosts(&mut s, r);
        }
        Status::Error => {
            write_errors(&mut s, r, &counts);
            write_tunnels_and_ghosts(&mut s, r);
            for d in &r.divergences.details {
                s.push_str(&render_divergence_as(d, "  ", sides));
            }
        }
    }
    if let Some(inferred) = &r.inferred {
        for line in inferred.lines() {
            let _ = writeln!(s, "  {line}");
        }
    }
    if let Some(line) = source_line(r) {
        // Right below the status line: part of the trace's header.
        let at = s.find('\n').map_or(s.len(), |i| i + 1);
        s.insert_str(at, &line);
    }
    s
}

/// The counts of the status line: sweeps, comparisons, the fields
/// compared, ties, and what was found but does not fail the check.
fn counts_text(r: &TraceReport) -> String {
    let mut counts = format!(
        "{}, {} compared, {} without expectation, {} without a sweep",
        crate::numbers::counted(r.sweeps, "sweep", "sweeps"),
        r.compared,
        r.expectations.missing,
        crate::numbers::counted(r.expectations.unmatched, "expectation", "expectations"),
    );
    if !r.tolerances.fields.is_all() {
        let _ = write!(counts, ", fields compared: {}", r.tolerances.fields.names());
    }
    if r.tie_members > 0 {
        let _ = write!(
            counts,
            ", {} (the expectation names another member of the tie set: a match)",
            crate::numbers::counted(r.tie_members, "tie", "ties")
        );
    }
    if r.fragile.count > 0 {
        let _ = write!(
            counts,
            ", {} ({}){}",
            crate::numbers::counted(r.fragile.count, "fragile divergence", "fragile divergences"),
            names_and_counts(&r.fragile.by_reason),
            if r.fragile.strict {
                ", failures under --strict"
            } else {
                ", not failures without --strict"
            }
        );
    }
    if let Some(within) = &r.within_precision
        && within.count > 0
    {
        let _ = write!(
            counts,
            ", {} within {} (largest backward error {}, p99 {} u32 units of the \
             sweep's scale){}",
            crate::numbers::counted(within.count, "difference", "differences"),
            r.conventions.within_words(),
            crate::core::explain::num(within.max_backward_error),
            crate::core::explain::num(within.p99_backward_error),
            if r.fragile.strict {
                ", failures under --strict"
            } else {
                ", not failures without --strict"
            }
        );
    }
    if let Some(within) = &r.within_precision
        && within.alpha_later + within.alpha_earlier > 0
    {
        let _ = write!(
            counts,
            "; of the hits whose α differs, {} later than the core's, {} earlier{}",
            within.alpha_later,
            within.alpha_earlier,
            if within.lopsided() {
                format!(
                    " (lopsided beyond chance, z = {:.1}: a bias of the engine or of its \
                     arithmetic)",
                    within.balance_z()
                )
            } else {
                String::new()
            }
        );
    }
    if r.tunnels.count > 0 && r.tunnels.of_the_recording {
        let _ = write!(
            counts,
            ", {} {} in the recorded paths (a note about the trace, not the engine's verdict: \
             the same whatever engine answers)",
            r.tunnels.count,
            tunnel_words(r.tunnels.count)
        );
    } else if r.tunnels.count > 0 && !r.tunnels.fail {
        let _ = write!(
            counts,
            ", {} {} (not failures: tunnels allowed)",
            r.tunnels.count,
            tunnel_words(r.tunnels.count)
        );
    }
    if r.ghosts.count > 0 && !r.ghosts.fail {
        let _ = write!(
            counts,
            ", {} (not failures: ghost contacts allowed)",
            ghost_words(r.ghosts.count)
        );
    }
    if r.ghosts.unjudged > 0 {
        let _ = write!(
            counts,
            ", {} not judged for ghost contacts (without a triangle, feature or normal)",
            crate::numbers::counted(
                r.ghosts.unjudged,
                "edge or vertex contact",
                "edge or vertex contacts"
            )
        );
    }
    counts
}

/// `key: n, key: n` in the keys' alphabetical order.
fn names_and_counts<K: std::fmt::Display>(counts: &BTreeMap<K, u64>) -> String {
    counts_by_name(counts)
        .iter()
        .map(|(k, n)| format!("{k}: {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Why a trace failed, one phrase a cause: divergences, tunnels, ghost
/// contacts.
fn failures(r: &TraceReport) -> Vec<String> {
    let mut failures: Vec<String> = Vec::new();
    let contacts_fail = r.contacts.divergent > 0;
    if r.divergent > 0 || !(r.fails_on_tunnels() || r.fails_on_ghosts() || contacts_fail) {
        failures.push(format!(
            "{} of {} compared {} {} ({})",
            r.divergent,
            r.compared,
            crate::numbers::plural(r.compared, "sweep"),
            crate::numbers::verb(r.divergent, "diverges", "diverge"),
            names_and_counts(&r.divergences.by_kind)
        ));
    }
    if contacts_fail {
        failures.push(format!(
            "{} of {} contact {} {} (the reported contacts are not the core's contact set)",
            r.contacts.divergent,
            r.contacts.compared,
            if r.contacts.compared == 1 {
                "query"
            } else {
                "queries"
            },
            crate::numbers::verb(r.contacts.divergent, "diverges", "diverge"),
        ));
    }
    if r.fails_on_tunnels() {
        failures.push(format!(
            "{} {} (a ball's centre went through a triangle from its front to its back: {})",
            r.tunnels.count,
            tunnel_words(r.tunnels.count),
            names_and_counts(&r.tunnels.by_kind)
        ));
    }
    if r.fails_on_ghosts() {
        failures.push(format!(
            "{} (an edge or vertex contact on an internal flat or concave place \
             with a normal more than {}° off the faces')",
            ghost_words(r.ghosts.count),
            crate::core::explain::num(r.ghosts.degrees)
        ));
    }
    failures
}

/// The engine conventions the trace was judged by, when some are declared.
fn write_conventions(s: &mut String, r: &TraceReport) {
    if !r.conventions.is_rules() {
        let _ = writeln!(
            s,
            "  judged under the engine's declared conventions: {}",
            r.conventions.summary()
        );
    }
}

/// The contact queries: their counts, and the first divergent ones with
/// each problem on a line.
fn write_contacts(s: &mut String, r: &TraceReport) {
    let c = &r.contacts;
    if c.is_empty() {
        return;
    }
    let mut line = format!(
        "  contacts: {}, {} compared, {} {}",
        crate::numbers::counted(c.queries, "query", "queries"),
        c.compared,
        c.divergent,
        crate::numbers::verb(c.divergent, "diverges", "diverge")
    );
    if c.without_answer > 0 {
        let _ = write!(line, ", {} without an answer", c.without_answer);
    }
    if c.answers_without_query > 0 {
        let _ = write!(
            line,
            ", {} answers without a query",
            c.answers_without_query
        );
    }
    if c.not_asked > 0 {
        let _ = write!(
            line,
            ", {} not judged (an engine is asked for contacts only with --engine-contacts, its answers compared with the core)",
            c.not_asked
        );
    }
    let _ = writeln!(s, "{line}");
    for v in &c.details {
        let _ = write!(
            s,
            "  contact divergence at frame {}, ball {}: ",
            v.frame, v.ball
        );
        write_contact_verdict(s, v, "    ");
    }
}

/// The listed tunnels and ghost contacts, one line each, and how many
/// more there are.
fn write_tunnels_and_ghosts(s: &mut String, r: &TraceReport) {
    write_contacts(s, r);
    for t in &r.tunnels.details {
        let _ = writeln!(s, "  tunnel: {}", t.line());
    }
    if r.tunnels.count as usize > r.tunnels.details.len() {
        let _ = writeln!(
            s,
            "  ... {} more {}",
            r.tunnels.count as usize - r.tunnels.details.len(),
            tunnel_words(r.tunnels.count - r.tunnels.details.len() as u64)
        );
    }
    for g in &r.ghosts.contacts {
        let _ = writeln!(s, "  ghost contact: {g}");
    }
    if r.ghosts.count as usize > r.ghosts.contacts.len() {
        let _ = writeln!(
            s,
            "  ... {} more",
            ghost_words(r.ghosts.count - r.ghosts.contacts.len() as u64)
        );
    }
}

/// The fragile divergences kept in detail (a passing trace's).
fn write_fragile_divergences(s: &mut String, r: &TraceReport, sides: Parties) {
    for d in &r.fragile.details {
        let _ = writeln!(
            s,
            "  fragile divergence (not a failure; rounding could change this decision):"
        );
        s.push_str(&render_divergence_as(d, "    ", sides));
    }
}

/// A failed trace's divergences: the first one, those kept in detail,
/// then the frames of the next ones.
fn write_divergences(s: &mut String, r: &TraceReport, sides: Parties) {
    let divergences = &r.divergences;
    if divergences.details.is_empty()
        && let Some(frame) = divergences.frames.first()
    {
        let _ = writeln!(s, "  first divergence: frame {frame}");
    }
    if let Some(first) = divergences.details.first() {
        let _ = writeln!(
            s,
            "  first divergence: frame {}, ball {} ({})",
            first.frame,
            first.ball,
            first
                .fields
                .iter()
                .map(|f| f.field.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    for d in &divergences.details {
        s.push_str(&render_divergence_as(d, "  ", sides));
    }
    let kept = divergences.details.len();
    if r.divergent as usize > kept {
        let rest = (r.divergent as usize - kept) as u64;
        let _ = writeln!(
            s,
            "  ... {} (frames {}{})",
            if kept == 0 {
                format!(
                    "{}, none shown in detail (--max-details)",
                    crate::numbers::counted(rest, "divergent sweep", "divergent sweeps")
                )
            } else {
                crate::numbers::counted(rest, "more divergent sweep", "more divergent sweeps")
            },
            divergences
                .frames
                .iter()
                .skip(kept)
                .take(20)
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            if r.divergent as usize > kept + 20 {
                ", ..."
            } else {
                ""
            }
        );
    }
}

/// Why nothing was compared.
fn no_expectations_reason(r: &TraceReport) -> String {
    if !r.expectations.has_channel {
        "no /expected channel".to_string()
    } else if r.expectations.read == 0 {
        "the /expected channel holds no message".to_string()
    } else {
        format!(
            "none of the {} /expected messages matches a sweep",
            r.expectations.read
        )
    }
}

/// The status line of a trace that could not be checked, and its errors.
fn write_errors(s: &mut String, r: &TraceReport, counts: &str) {
    // The errors name the trace; the line names it once. A message of
    // several lines (an engine's last stderr lines) keeps its first line
    // with the counts, the rest below.
    let prefix = format!("{}: ", r.trace);
    let unnamed = |e: &str| e.strip_prefix(&prefix).unwrap_or(e).to_string();
    let first = r.errors.first().map_or("error".to_string(), |e| unnamed(e));
    let (head, below) = first.split_once('\n').unwrap_or((first.as_str(), ""));
    let _ = writeln!(
        s,
        "ERROR {}: {head}; {counts}, {} diverge",
        r.trace, r.divergent
    );
    for line in below.lines() {
        let _ = writeln!(s, "{line}");
    }
    for e in r.errors.iter().skip(1) {
        let _ = writeln!(s, "  also: {}", unnamed(e));
    }
}

/// Who computed the expectations the report compared with, one line: the
/// engine command (`check --engine`, against the core), or the trace's
/// `sweeptrace.expected_source` record; `None` when the trace does not say.
fn source_line(r: &TraceReport) -> Option<String> {
    match (&r.engine, &r.expected_source) {
        (Some(e), _) if e.against == super::report::Against::Core => Some(format!(
            "  expectations from the engine command `{}` (answers to every sweep; the \
             trace's /expected is not used)\n",
            e.command
        )),
        (_, Some(source)) => Some(format!("  expectations from {source}\n")),
        (_, None) => None,
    }
}

fn ghost_words(n: u64) -> String {
    crate::numbers::counted(n, "ghost contact", "ghost contacts")
}

fn tunnel_words(n: u64) -> &'static str {
    if n == 1 { "tunnel" } else { "tunnels" }
}

/// The reports as one JSON document: `{"status": ..., "exit_code": ...,
/// "traces": [...]}` (pretty-printed, ending with a newline); `exit_code`
/// is the command's exit code for these reports, as its caller maps them.
pub fn render_json(reports: &[TraceReport], exit_code: u8) -> String {
    let overall = reports
        .iter()
        .map(|r| r.status())
        .max()
        .unwrap_or(Status::Ok);
    let doc = json!({
        "status": overall,
        "exit_code": exit_code,
        "traces": reports,
    });
    let mut s = serde_json::to_string_pretty(&doc).unwrap_or_else(|e| {
        json!({"status": "error", "error": format!("serializing the report: {e}")}).to_string()
    });
    s.push('\n');
    s
}
