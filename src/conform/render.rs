//! A conformance run's report in words ([`render_text`], with each failing
//! rule's first case explained) and as JSON ([`render_json`]): pure
//! functions of a [`ConformReport`].

use std::fmt::Write as _;

use super::{CaseFailure, ConformReport, RuleReport};
use crate::judge::divergence::{Parties, render_divergence_as};
use crate::judge::{ContactVerdict, write_contact_verdict};

/// The report in words: one line per rule (status, counts, what it
/// checks), then each failing rule's first failing case explained with the
/// command that reproduces it, then the totals.
pub fn render_text(r: &ConformReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "conformance of `{}` to docs/SEMANTICS.md", r.engine);
    let width = r.rules.iter().map(|x| x.rule.len()).max().unwrap_or(0);
    for rule in &r.rules {
        if let Some(why) = &rule.not_applicable {
            let _ = writeln!(
                s,
                "  {:<7} {:<width$}  not applicable: {why}  ({} {})",
                rule.status(),
                rule.rule,
                rule.cases,
                if rule.cases == 1 { "case" } else { "cases" },
            );
            continue;
        }
        let _ = writeln!(
            s,
            "  {:<7} {:<width$}  {} passed, {} failed, {} fragile{}  ({} {})",
            rule.status(),
            rule.rule,
            rule.passed,
            rule.failed,
            rule.fragile,
            if rule.within_precision > 0 {
                format!(", {} within f32", rule.within_precision)
            } else {
                String::new()
            },
            rule.cases,
            if rule.cases == 1 { "case" } else { "cases" },
        );
    }
    for rule in &r.rules {
        if let Some(section) = render_rule_failure(rule) {
            let _ = writeln!(s);
            s.push_str(&section);
        }
    }
    let _ = writeln!(s);
    let failing = r.rules.iter().filter(|x| x.failed > 0).count();
    let _ = writeln!(
        s,
        "{}, {}: {} passed, {} failed, {} fragile{}{}; {} {}",
        crate::numbers::counted(r.rules.len() as u64, "rule", "rules"),
        crate::numbers::counted(r.cases, "case", "cases"),
        r.passed,
        r.failed,
        r.fragile,
        if r.within_precision > 0 {
            format!(
                ", {} within {}",
                r.within_precision,
                if r.conventions.accuracy.is_some() {
                    format!("{}: not failures", r.conventions.within_words())
                } else {
                    "single precision (the engine's declared f32 arithmetic: not failures)"
                        .to_string()
                }
            )
        } else {
            String::new()
        },
        match (r.fragile > 0, r.strict) {
            (false, _) => "",
            (true, true) => {
                " (fragile: divergences a perturbation of the inputs reproduces; they fail, --lenient lets them pass)"
            }
            (true, false) => {
                " (fragile: divergences a perturbation of the inputs reproduces; not failures under --lenient)"
            }
        },
        failing,
        if failing == 1 {
            "rule fails"
        } else {
            "rules fail"
        }
    );
    if let Some(e) = &r.error {
        let _ = writeln!(s, "ERROR: {e}");
    }
    s
}

/// A rule's first failing case (or first fragile divergence) explained,
/// as [`render_text`] shows it; `None` when no case of the rule diverged.
pub fn render_rule_failure(rule: &RuleReport) -> Option<String> {
    let f = rule.first_failure.as_ref()?;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} {}: {}",
        if rule.failed > 0 { "FAIL" } else { "fragile" },
        rule.rule,
        rule.description
    );
    let _ = writeln!(
        s,
        "  first {}: {} ({})",
        if rule.failed > 0 {
            "failing case"
        } else {
            "fragile divergence"
        },
        f.case,
        f.what
    );
    s.push_str(&render_case_failure(f, "  "));
    Some(s)
}

/// One divergent case explained: the tie order when the engine named
/// another member of the tie set, the divergence, the command that
/// reproduces it; each line starts with `indent`.
pub fn render_case_failure(f: &CaseFailure, indent: &str) -> String {
    let mut s = String::new();
    if let Some(t) = &f.tie_order {
        let _ = writeln!(s, "{indent}tie order: {t}");
    }
    if let Some(d) = &f.divergence {
        s.push_str(&render_divergence_as(d, indent, Parties::EngineAndCore));
    }
    if let Some(v) = &f.contacts {
        let _ = write!(s, "{indent}contacts: ");
        write_contact_verdict(&mut s, v, &format!("{indent}  "));
        for g in &v.ghosts {
            let _ = writeln!(s, "{indent}  ghost contact: {g}");
        }
    }
    let _ = writeln!(s, "{indent}reproduce: {}", f.repro);
    s
}

/// A contact query's judgement on one line: the counts, then its first
/// problem or ghost contact.
pub(super) fn contact_verdict_line(v: &ContactVerdict) -> String {
    let first = v
        .problems
        .first()
        .map(ToString::to_string)
        .or_else(|| v.ghosts.first().map(|g| format!("ghost contact: {g}")));
    format!(
        "the core finds {}, the engine reports {}{}",
        crate::numbers::counted(v.reference as u64, "contact", "contacts"),
        v.answered,
        first.map_or_else(String::new, |f| format!("; {f}"))
    )
}

/// The report as one JSON document (pretty-printed, ending with a newline),
/// with the command's exit code `exit_code`, as its caller maps the
/// report's [`ConformReport::status`].
pub fn render_json(r: &ConformReport, exit_code: u8) -> String {
    let mut doc = serde_json::to_value(r)
        .unwrap_or_else(|e| serde_json::json!({"error": format!("serializing the report: {e}")}));
    if let Some(map) = doc.as_object_mut() {
        map.insert("exit_code".into(), exit_code.into());
        map.insert(
            "failing_rules".into(),
            r.rules
                .iter()
                .filter(|x| x.failed > 0)
                .map(|x| x.rule)
                .collect::<Vec<_>>()
                .into(),
        );
    }
    let mut s = serde_json::to_string_pretty(&doc).unwrap_or_default();
    s.push('\n');
    s
}
