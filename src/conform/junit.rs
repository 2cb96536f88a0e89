//! `conform`'s report as JUnit XML ([`conform_junit`]), a pure function of
//! the report.
//!
//! One `<testsuite>` per group of rules (the rule's first dotted component:
//! `face`, `edge`, `tie`, ...) with the engine's command, the tolerances
//! and the compared fields as `<properties>`; one `<testcase>` per rule. A
//! rule with a failing case is a `<failure>` whose `message` is its first
//! failing case on one line and whose text is what `conform` prints for
//! it; a rule whose only divergences are ones rounding explains (under
//! `--lenient`) is `<skipped>`. A fault of the engine is an `<error>` in a
//! suite `engine`. With [`Detail::Sweeps`], each divergent case is a test
//! case of its own too.

use std::time::Duration;

use crate::judge::Tolerances;
use crate::judge::divergence::{Parties, divergence_line};
use crate::junit::{Case, CaseResult, Detail, JunitOptions, Problem, Report, Suite, one_line};

use super::render::contact_verdict_line;
use super::{CaseFailure, ConformReport, RuleReport, render_case_failure, render_rule_failure};

/// The group of a rule: its first dotted component (`edge` of
/// `edge.miss.parallel`).
pub fn rule_group(rule: &str) -> &str {
    rule.split_once('.').map_or(rule, |(group, _)| group)
}

/// A divergent case on one line: its id, what it does, the tie order or
/// the divergence.
fn case_line(f: &CaseFailure) -> String {
    let what = match (&f.tie_order, &f.divergence, &f.contacts) {
        (Some(t), _, _) => format!("tie order: {t}"),
        (None, Some(d), _) => divergence_line(d, Parties::EngineAndCore),
        (None, None, Some(v)) => contact_verdict_line(v),
        (None, None, None) => String::new(),
    };
    one_line(&format!("{} ({}): {what}", f.case, f.what))
}

/// The report of one `conform` run as a JUnit XML document; `tolerances`
/// are the comparison's, `elapsed` how long the run took.
pub fn conform_junit(
    r: &ConformReport,
    tolerances: &Tolerances,
    elapsed: Option<Duration>,
    options: &JunitOptions,
) -> String {
    let properties = vec![
        ("engine".to_string(), r.engine.clone()),
        ("tolerance.alpha".to_string(), tolerances.alpha.to_string()),
        (
            "tolerance.normal_degrees".to_string(),
            tolerances.normal_degrees.to_string(),
        ),
        (
            "tolerance.contact".to_string(),
            tolerances.contact.to_string(),
        ),
        ("fields".to_string(), tolerances.fields.names()),
        ("strict".to_string(), r.strict.to_string()),
    ];
    let mut suites: Vec<Suite> = Vec::new();
    for rule in &r.rules {
        let group = rule_group(rule.rule);
        let index = match suites.iter().position(|s| s.name == group) {
            Some(i) => i,
            None => {
                suites.push(Suite {
                    name: group.to_string(),
                    timestamp: options.timestamp.clone(),
                    properties: properties.clone(),
                    ..Suite::default()
                });
                suites.len() - 1
            }
        };
        let classname = format!("conform.{group}");
        suites[index].cases.push(rule_case(rule, &classname));
        if options.detail == Detail::Sweeps {
            for f in &rule.divergent_cases {
                suites[index].cases.push(divergent_case(f, &classname));
            }
        }
    }
    if let Some(error) = &r.error {
        suites.push(Suite {
            name: "engine".to_string(),
            timestamp: options.timestamp.clone(),
            properties,
            cases: vec![Case {
                name: "engine".to_string(),
                classname: "conform.engine".to_string(),
                result: CaseResult::Error(Problem {
                    message: one_line(error),
                    kind: "engine_fault".to_string(),
                    body: format!("{error}\n"),
                }),
                ..Case::default()
            }],
            ..Suite::default()
        });
    }
    crate::junit::render(&Report {
        name: "sweeptrace conform".to_string(),
        time_seconds: elapsed.map(|t| t.as_secs_f64()),
        timestamp: options.timestamp.clone(),
        suites,
    })
}

fn rule_case(rule: &RuleReport, classname: &str) -> Case {
    let explained = render_rule_failure(rule);
    let first = rule.first_failure.as_ref().map(case_line);
    let result = match first {
        Some(first) if rule.failed > 0 => CaseResult::Failure(Problem {
            message: format!(
                "{} of {} {} {}; first failing case: {first}",
                rule.failed,
                rule.cases,
                crate::numbers::plural(rule.cases, "case"),
                crate::numbers::verb(rule.failed, "fails", "fail")
            ),
            kind: rule
                .first_failure
                .as_ref()
                .map_or("divergence", failure_type)
                .to_string(),
            body: explained.clone().unwrap_or_default(),
        }),
        Some(first) if rule.fragile == 0 && rule.within_precision > 0 => CaseResult::Skipped {
            message: format!(
                "{} of {} cases differ within single precision (the engine's declared f32 \
                 arithmetic, not failures); first: {first}",
                rule.within_precision, rule.cases
            ),
        },
        Some(first) => CaseResult::Skipped {
            message: format!(
                "{} of {} cases diverge where rounding explains it (not failures under \
                 --lenient); first: {first}",
                rule.fragile, rule.cases
            ),
        },
        None => CaseResult::Passed,
    };
    let system_out = match &result {
        CaseResult::Skipped { .. } => explained,
        _ => None,
    };
    Case {
        name: rule.rule.to_string(),
        classname: classname.to_string(),
        result,
        system_out,
        ..Case::default()
    }
}

/// The JUnit failure type of a divergent case: `tie_order`,
/// `contact_divergence` (as `check` calls a contact query's) or
/// `divergence`.
fn failure_type(f: &CaseFailure) -> &'static str {
    if f.tie_order.is_some() {
        "tie_order"
    } else if f.contacts.is_some() {
        "contact_divergence"
    } else {
        "divergence"
    }
}

fn divergent_case(f: &CaseFailure, classname: &str) -> Case {
    let body = render_case_failure(f, "");
    let (result, system_out) = if f.fails {
        (
            CaseResult::Failure(Problem {
                message: case_line(f),
                kind: failure_type(f).to_string(),
                body,
            }),
            None,
        )
    } else {
        (
            CaseResult::Skipped {
                message: format!(
                    "a divergence rounding explains (not a failure under --lenient): {}",
                    case_line(f)
                ),
            },
            Some(body),
        )
    };
    Case {
        name: f.case.clone(),
        classname: classname.to_string(),
        result,
        system_out,
        ..Case::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fault_of_the_engine_is_an_error_in_a_suite_of_its_own() {
        let report = ConformReport {
            engine: "./engine --flag".to_string(),
            rules: Vec::new(),
            cases: 0,
            passed: 0,
            failed: 0,
            fragile: 0,
            within_precision: 0,
            strict: true,
            conventions: Default::default(),
            error: Some("the engine exited\nits last stderr line".to_string()),
        };
        let xml = conform_junit(
            &report,
            &Tolerances::default(),
            None,
            &JunitOptions::default(),
        );
        assert!(
            xml.contains(r#"<testsuites name="sweeptrace conform" tests="1" failures="0" errors="1" skipped="0">"#),
            "{xml}"
        );
        assert!(
            xml.contains(r#"<error message="the engine exited its last stderr line" type="engine_fault">the engine exited
its last stderr line
</error>"#),
            "{xml}"
        );
        assert!(
            xml.contains(r#"<property name="engine" value="./engine --flag"/>"#),
            "{xml}"
        );
    }

    #[test]
    fn a_rule_s_group_is_its_first_component() {
        assert_eq!(rule_group("edge.miss.parallel"), "edge");
        assert_eq!(rule_group("tie"), "tie");
    }
}
