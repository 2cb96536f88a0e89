//! The conformance suite: a built-in, generated set of cases that covers
//! every verdict of every test of docs/SEMANTICS.md ([`cases()`]), run
//! through a running engine ([`crate::engine`]) and judged against the
//! core by check's comparison ([`crate::judge::agreement`]: ties are
//! matches; a divergence on a fragile decision is counted as such).
//!
//! [`run`] returns a [`ConformReport`], one [`RuleReport`] per rule with
//! its counts and its first failing case explained;
//! [`render_text`] and [`render_json`] are pure functions of it.

mod cases;
mod contact_cases;
mod junit;
mod render;
mod rules;

pub use cases::{Case, CaseQuery, cases};
pub use junit::conform_junit;
pub use render::{render_case_failure, render_json, render_rule_failure, render_text};
pub use rules::{RULES, Rule};

use serde::Serialize;

use crate::conventions::{EngineConventions, TieRule};
use crate::core::explain::num;
use crate::core::{Kind, Outcome};
use crate::engine::{EngineAnswers, EngineCommand, EngineError, EngineOptions, EngineSession};
use crate::judge::divergence::{Divergence, divergence_details};
use crate::judge::{Agreement, ContactPairing, ContactVerdict, Tolerances, agreement, compare};
use crate::replay::{ReplayEvent, ReplayOptions, replay_events};
use crate::trace::{EventBody, EventHeader, OutcomeMsg, TraceEvent};

/// The first failing case of a rule, explained.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseFailure {
    /// `rule/index`.
    pub case: String,
    /// What the case does.
    pub what: String,
    /// A sweep's case: the engine's answer against the core's outcome,
    /// explained (`expected` is the engine's answer, `got` the core's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub divergence: Option<Divergence>,
    /// A contact query's case: the engine's contacts judged against the
    /// core's contact set (its problems, its ghost contacts).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<ContactVerdict>,
    /// When the engine named another member of the core's tie set (a
    /// failure unless `--lenient`): which member the rule chooses and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tie_order: Option<String>,
    /// A command that runs this case alone and explains it.
    pub repro: String,
    /// Whether the case fails (a divergence rounding explains does not,
    /// under `--lenient`). Not in the JSON, where the rule's counts say it.
    #[serde(skip)]
    pub fails: bool,
}

/// What a hit names, in words: `face of triangle 3`, `edge 2 of triangle 3`.
fn hit_name(kind: Kind, triangle: Option<u32>, feature: Option<u8>) -> String {
    let on = triangle.map_or_else(String::new, |t| format!(" of triangle {t}"));
    match (kind, feature) {
        (Kind::Face, _) => format!("the face{on}"),
        (_, None) => format!("{kind}{on}"),
        (_, Some(f)) => format!("{kind} {f}{on}"),
    }
}

/// Why the rule's tie order chooses the core's primary over the member of
/// the tie set the engine named.
fn tie_order_text(answer: &OutcomeMsg, outcome: &Outcome) -> String {
    let named = (
        answer.kind,
        answer.triangle.flatten(),
        answer.feature.flatten(),
    );
    let hit = outcome.hit.as_ref();
    let chosen = (
        outcome.kind(),
        hit.map(|h| h.triangle),
        hit.and_then(|h| h.feature.index()),
    );
    let why = if named.0 != chosen.0 {
        format!(
            "the kind order face < edge < vertex puts {} before {}",
            chosen.0, named.0
        )
    } else if named.1 != chosen.1 {
        format!(
            "at the same kind, the lower triangle index comes first ({} < {})",
            OrNull(chosen.1),
            OrNull(named.1)
        )
    } else {
        format!(
            "in the same triangle, the lower feature index comes first ({} < {})",
            OrNull(chosen.2),
            OrNull(named.2)
        )
    };
    format!(
        "the engine names {}, a member of the tie set at α = {}; the rule's tie order \
         (kind face < edge < vertex, then triangle index, then feature index) chooses {}: {why}",
        hit_name(named.0, named.1, named.2),
        num(outcome.travelled()),
        hit_name(chosen.0, chosen.1, chosen.2),
    )
}

/// A value, or `null`.
struct OrNull<T>(Option<T>);

impl<T: std::fmt::Display> std::fmt::Display for OrNull<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            Some(v) => v.fmt(f),
            None => f.write_str("null"),
        }
    }
}

/// One rule's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RuleReport {
    /// The rule.
    pub rule: &'static str,
    /// What it checks.
    pub description: &'static str,
    /// Cases run.
    pub cases: u64,
    /// Cases the engine answered as the core did (a tie-set member counts).
    pub passed: u64,
    /// Cases whose answer diverges from the core's outcome, on a robust
    /// decision (with `strict`: on any decision).
    pub failed: u64,
    /// Cases whose answer diverges on a fragile decision (a change at the
    /// level of the inputs' rounding could change it); failures too with
    /// `strict`, where they are also counted in `failed`.
    pub fragile: u64,
    /// At `precision = "f32"`: cases whose answer differs by no more than
    /// single-precision rounding explains (backward error within the
    /// budget). The engine's declared arithmetic: never failures here.
    /// Only in the JSON when some.
    #[serde(skip_serializing_if = "is_zero")]
    pub within_precision: u64,
    /// The first failing case (or, when none fails, the first fragile one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_failure: Option<CaseFailure>,
    /// Why the rule does not apply to this engine: the declared convention
    /// that replaces it (`the engine declares margin = 0.0`). Its cases
    /// are not judged. Only in the JSON when set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_applicable: Option<String>,
    /// Every case whose answer diverges, failing or fragile, in the order
    /// they ran (`conform --junit-detail sweeps`). Not in the JSON, which
    /// keeps the first failure.
    #[serde(skip)]
    pub divergent_cases: Vec<CaseFailure>,
}

impl RuleReport {
    /// `ok`, `FAIL`, or `fragile` (only fragile divergences, not failures).
    pub fn status(&self) -> &'static str {
        if self.not_applicable.is_some() {
            "n/a"
        } else if self.failed > 0 {
            "FAIL"
        } else if self.fragile > 0 {
            "fragile"
        } else {
            "ok"
        }
    }
}

/// The conformance of one engine.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ConformReport {
    /// The engine's command.
    pub engine: String,
    /// The rules, in the order of [`RULES`] (only those with a case run).
    pub rules: Vec<RuleReport>,
    /// Cases run.
    pub cases: u64,
    /// Cases passed.
    pub passed: u64,
    /// Cases failed.
    pub failed: u64,
    /// Fragile divergences.
    pub fragile: u64,
    /// Differences within single precision (`precision = "f32"`), not
    /// failures. Only in the JSON when some.
    #[serde(skip_serializing_if = "is_zero")]
    pub within_precision: u64,
    /// Whether fragile divergences fail.
    pub strict: bool,
    /// The declared conventions (for the words of the summary; not in the
    /// JSON).
    #[serde(skip)]
    pub conventions: EngineConventions,
    /// A fault of the engine, if any (the cases before it are reported).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// What a conformance run came to ([`ConformReport::status`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConformStatus {
    /// Every case run passed (fragile divergences pass unless `strict`).
    Ok,
    /// At least one case failed.
    Fail,
    /// A fault of the engine (the cases before it are reported).
    Error,
}

impl ConformReport {
    /// What the run came to: a fault of the engine is an error, a failed
    /// case a failure.
    pub fn status(&self) -> ConformStatus {
        if self.error.is_some() {
            ConformStatus::Error
        } else if self.failed > 0 {
            ConformStatus::Fail
        } else {
            ConformStatus::Ok
        }
    }
}

/// Options of a conformance run.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ConformOptions {
    /// The comparison's tolerances.
    pub tolerances: Tolerances,
    /// Whether a divergence rounding explains fails, and whether an answer
    /// naming another member of the tie set than the rule's choice fails
    /// (the default of `conform`; `--lenient` turns both off).
    pub strict: bool,
    /// Run only the cases whose id (`rule/index`) or rule is this.
    pub only: Option<String>,
    /// The engine's declared conventions (`sweeptrace.toml`'s `[engine]`
    /// table): every case is judged under them, and the rules a convention
    /// replaces are listed as not applicable.
    pub conventions: EngineConventions,
}

/// `conform --case` named no case, rule or group of rules; the message
/// lists the rules ([`RULES`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "no conformance case or rule `{name}`; the rules are: {}",
    RULES.iter().map(|r| r.name).collect::<Vec<_>>().join(", ")
)]
#[non_exhaustive]
pub struct UnknownCase {
    /// What was asked for.
    pub name: String,
}

/// The cases `only` selects (every case when `None`, the contact
/// queries' only with `contacts`): a case (`edge.hit/2`), a rule
/// (`edge.hit`) or a group of rules (`edge`, `edge.miss`, `contact`); an
/// error names the rules when nothing matches.
pub fn select(only: Option<&str>, contacts: bool) -> Result<Vec<Case>, UnknownCase> {
    let all = cases();
    let Some(only) = only else {
        return Ok(all
            .into_iter()
            .filter(|c| contacts || c.sweep().is_some())
            .collect());
    };
    let chosen: Vec<Case> = all
        .into_iter()
        .filter(|c| {
            c.rule == only
                || c.id() == only
                || c.rule
                    .strip_prefix(only)
                    .is_some_and(|rest| rest.starts_with('.'))
        })
        .collect();
    if chosen.is_empty() {
        return Err(UnknownCase {
            name: only.to_string(),
        });
    }
    Ok(chosen)
}

/// A trace's events for `cases`: each case's scene, then its sweep or
/// contact query.
pub fn case_events(cases: &[Case]) -> Vec<TraceEvent> {
    let mut events = Vec::with_capacity(2 * cases.len());
    for (i, case) in cases.iter().enumerate() {
        let i = i as u64;
        let at = |n: u64| EventHeader {
            log_time_nanos: n,
            index: n,
        };
        events.push(TraceEvent {
            header: at(2 * i),
            body: EventBody::Scene(case.scene.clone()),
        });
        events.push(TraceEvent {
            header: at(2 * i + 1),
            body: match &case.query {
                CaseQuery::Sweep(sweep) => EventBody::Sweep(*sweep),
                CaseQuery::Contact { query, .. } => EventBody::Contact(*query),
            },
        });
    }
    events
}

/// The command that runs one case again as this run judged it: the
/// engine, the case, the declared conventions as flags when there are
/// some (and `--no-config`, so that no other `sweeptrace.toml` adds to
/// them), the tolerances that
/// differ from the defaults, and `--lenient` when the run was.
fn reproduce_command(engine: &str, case: &str, options: &ConformOptions) -> String {
    let mut words = vec![
        "sweeptrace".to_string(),
        "conform".to_string(),
        "--engine".to_string(),
        shell_quote(engine),
        "--case".to_string(),
        case.to_string(),
    ];
    let flags = options.conventions.flags();
    if !flags.is_empty() {
        words.extend(flags.iter().map(|f| shell_quote(f)));
        words.push("--no-config".to_string());
    }
    let (tol, default) = (&options.tolerances, Tolerances::default());
    for (flag, value, was) in [
        ("--tolerance", tol.alpha, default.alpha),
        (
            "--normal-tolerance",
            tol.normal_degrees,
            default.normal_degrees,
        ),
        ("--contact-tolerance", tol.contact, default.contact),
    ] {
        if value != was {
            words.push(flag.to_string());
            words.push(format!("{value:?}"));
        }
    }
    if !tol.fields.is_all() {
        words.push("--fields".to_string());
        words.push(tol.fields.names());
    }
    if !options.strict {
        words.push("--lenient".to_string());
    }
    words.join(" ")
}

/// Shell-quotes `s` for a command line to paste (`'...'` when needed).
pub fn shell_quote(s: &str) -> String {
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// Runs `cases` through the engine and judges every answer. `Err` only
/// when the engine cannot be started; a later fault is the report's
/// `error`.
#[allow(clippy::result_large_err)] // once per run; see crate::engine
pub fn run(
    command: &EngineCommand,
    engine: EngineOptions,
    cases: &[Case],
    options: &ConformOptions,
) -> Result<ConformReport, EngineError> {
    let session = EngineSession::start(command, engine)?;
    let events = case_events(cases).into_iter().map(Ok);
    let asks_contacts = cases.iter().any(|c| c.contact().is_some());
    let mut answers =
        EngineAnswers::new(events, session, engine.window).with_contacts(asks_contacts);
    let mut rules: Vec<RuleReport> = Vec::new();
    let mut report = ConformReport {
        engine: command.text.clone(),
        rules: Vec::new(),
        cases: 0,
        passed: 0,
        failed: 0,
        fragile: 0,
        within_precision: 0,
        strict: options.strict,
        conventions: options.conventions,
        error: None,
    };
    let tolerances = options.tolerances;
    // The contact queries' answers, judged as they pass the replay.
    let mut pairing = ContactPairing::new(
        &tolerances,
        &options.conventions,
        crate::replay::ghost::GHOST_DEGREES,
    );
    let mut contact_verdicts: Vec<ContactVerdict> = Vec::new();
    let events = answers.by_ref().inspect(|e| {
        let judged = match e {
            Ok(TraceEvent {
                body: EventBody::Scene(scene),
                ..
            }) => {
                pairing.scene(scene);
                None
            }
            Ok(TraceEvent {
                header,
                body: EventBody::Contact(query),
            }) => pairing.query(query, header.log_time_nanos),
            Ok(TraceEvent {
                body: EventBody::ExpectedContacts(answer),
                ..
            }) => pairing.answer(answer),
            _ => None,
        };
        contact_verdicts.extend(judged.map(|j| j.verdict));
    });
    let replay = replay_events(
        events,
        ReplayOptions {
            conventions: options.conventions,
            ..ReplayOptions::default()
        },
    );
    for event in replay {
        let result = match event {
            Ok(ReplayEvent::Sweep(result)) => result,
            Ok(ReplayEvent::Scene(_)) => continue,
            Err(e) => {
                // The cases are valid; an error here is a bug of the suite.
                report
                    .error
                    .get_or_insert_with(|| format!("conformance case: {e}"));
                continue;
            }
        };
        let Some(case) = cases.iter().find(|c| c.frame() == result.frame) else {
            continue;
        };
        let Some(answer) = result.expected else {
            continue;
        };
        let rule = rule_of(&mut rules, case.rule, &options.conventions);
        if rule.not_applicable.is_some() {
            rule.cases += 1;
            continue;
        }
        rule.cases += 1;
        report.cases += 1;
        let (fields, reproduced, tie_order, backward_error) =
            match agreement(&answer, &result, &tolerances) {
                Agreement::Match => {
                    rule.passed += 1;
                    report.passed += 1;
                    continue;
                }
                // The cases are exact in binary: the rule's choice among the
                // tie set is the only right answer, unless --lenient.
                Agreement::Tie if options.strict && options.conventions.ties == TieRule::Rule => (
                    compare(&answer, &result.outcome_msg(), &tolerances),
                    None,
                    Some(tie_order_text(&answer, &result.outcome)),
                    None,
                ),
                Agreement::Tie => {
                    rule.passed += 1;
                    report.passed += 1;
                    continue;
                }
                Agreement::Diverges {
                    fields, reproduced, ..
                } => (fields, reproduced, None, None),
                // Within single precision's backward error: the engine's
                // declared arithmetic, never a failure here.
                Agreement::Precision {
                    fields,
                    reproduced,
                    backward_error,
                } => (fields, reproduced, None, Some(backward_error)),
            };
        let excused = reproduced.is_some() || backward_error.is_some();
        if backward_error.is_some() {
            rule.within_precision += 1;
            report.within_precision += 1;
        } else if excused {
            rule.fragile += 1;
            report.fragile += 1;
        }
        // Single precision's differences are what the engine declared:
        // never failures here (the cases are exact, not its rounding).
        let fails = !excused || (options.strict && backward_error.is_none());
        if fails {
            rule.failed += 1;
            report.failed += 1;
        }
        let replace = match &rule.first_failure {
            None => true,
            // A failure is shown before a divergence that does not fail
            // (rounding explains it under --lenient, or it is within the
            // declared single precision, strict or not).
            Some(first) => fails && !first.fails,
        };
        let got = result.outcome_msg();
        let mut divergence = divergence_details(&result, answer, got, fields, false);
        divergence.reproduced = reproduced;
        divergence.backward_error = backward_error;
        divergence.names_tie_member = tie_order.is_some();
        let failure = CaseFailure {
            case: case.id(),
            what: case.what.to_string(),
            divergence: Some(divergence),
            contacts: None,
            tie_order,
            repro: reproduce_command(&command.text, &case.id(), options),
            fails,
        };
        if replace {
            rule.first_failure = Some(failure.clone());
        }
        rule.divergent_cases.push(failure);
    }
    pairing.flush();
    for verdict in contact_verdicts {
        let Some(case) = cases.iter().find(|c| c.frame() == verdict.frame) else {
            continue;
        };
        let rule = rule_of(&mut rules, case.rule, &options.conventions);
        rule.cases += 1;
        if rule.not_applicable.is_some() {
            continue;
        }
        report.cases += 1;
        // A ghost contact fails as a wrong contact does (as in `check`).
        if verdict.agrees() && verdict.ghosts.is_empty() {
            rule.passed += 1;
            report.passed += 1;
            continue;
        }
        rule.failed += 1;
        report.failed += 1;
        let mut verdict = verdict;
        for ghost in &mut verdict.ghosts {
            ghost.answer = true;
        }
        let failure = CaseFailure {
            case: case.id(),
            what: case.what.to_string(),
            divergence: None,
            contacts: Some(verdict),
            tie_order: None,
            repro: reproduce_command(&command.text, &case.id(), options),
            fails: true,
        };
        if rule.first_failure.is_none() {
            rule.first_failure = Some(failure.clone());
        }
        rule.divergent_cases.push(failure);
    }
    if pairing.without_answer > 0 && report.error.is_none() {
        report.error = Some(format!(
            "the engine left {} without an answer",
            crate::numbers::counted(pairing.without_answer, "contact query", "contact queries")
        ));
    }
    let run = answers.finish();
    if let Some(e) = run.error {
        if e.cannot_start() {
            return Err(e);
        }
        report.error = Some(e.to_string());
    }
    // In the order of RULES.
    for r in RULES {
        if let Some(pos) = rules.iter().position(|x| x.rule == r.name) {
            report.rules.push(rules.swap_remove(pos));
        }
    }
    report.rules.append(&mut rules);
    Ok(report)
}

/// The report of `rule`, added (empty, with whether a declared convention
/// replaces it) the first time one of its cases is judged.
fn rule_of<'r>(
    rules: &'r mut Vec<RuleReport>,
    rule: &'static str,
    conventions: &EngineConventions,
) -> &'r mut RuleReport {
    let at = match rules.iter().position(|r| r.rule == rule) {
        Some(at) => at,
        None => {
            let description = RULES
                .iter()
                .find(|r| r.name == rule)
                .map_or("", |r| r.description);
            rules.push(RuleReport {
                rule,
                description,
                cases: 0,
                passed: 0,
                failed: 0,
                fragile: 0,
                within_precision: 0,
                first_failure: None,
                not_applicable: conventions.replaces(rule),
                divergent_cases: Vec::new(),
            });
            rules.len() - 1
        }
    };
    &mut rules[at]
}

/// For `serde(skip_serializing_if)`: a count of none.
fn is_zero(n: &u64) -> bool {
    *n == 0
}
