//! `replay --json`: the summary as one JSON object.

use std::time::Instant;
use sweeptrace::judge::contact_marks::ContactsDrawn;

use super::Args;

/// `--json`'s summary: one object, the counts of [`ReplaySummary`]
/// (`sweeptrace::replay`) by name, the engine conventions the answers
/// were computed under (every key; the rules' values when none is
/// declared), the files written (each "wrote" line),
/// the selection of a filter that kept part of the trace, and `incomplete`
/// (the error of a trace that ends early, or `null`).
#[expect(
    clippy::too_many_arguments,
    reason = "each argument is one part of the document, from a different stage of the replay"
)]
pub(super) fn summary_json(
    args: &Args,
    conventions: &sweeptrace::conventions::EngineConventions,
    summary: &sweeptrace::replay::ReplaySummary,
    selection: Option<String>,
    wrote: &[String],
    truncation: Option<&sweeptrace::trace::TraceError>,
    contacts: Option<&ContactsDrawn>,
    started: Instant,
) -> String {
    use serde_json::{Map, Value, json};
    let counts = |pairs: Vec<(String, u64)>| -> Value {
        Value::Object(
            pairs
                .into_iter()
                .map(|(k, n)| (k, json!(n)))
                .collect::<Map<_, _>>(),
        )
    };
    let kinds = [
        sweeptrace::Kind::Face,
        sweeptrace::Kind::Edge,
        sweeptrace::Kind::Vertex,
        sweeptrace::Kind::None,
    ];
    let value = json!({
        "trace": args.trace.display().to_string(),
        "conventions": conventions,
        "sweeps": summary.sweeps,
        "filtered_out": summary.filtered_out,
        "selection": selection,
        "scenes": summary.scenes,
        "collisions": summary.collisions(),
        "outcomes": counts(kinds.iter().map(|k| (k.to_string(), summary.outcomes.get(k).copied().unwrap_or(0))).collect()),
        "verdicts": counts(summary.verdicts.iter().map(|(v, n)| (v.as_str().to_string(), n)).collect()),
        "skipped": counts(summary.skipped.iter().map(|(r, n)| (r.as_str().to_string(), n)).collect()),
        "expected": {
            "attached": summary.expected_matched,
            "unmatched": summary.expected_unmatched,
        },
        "fragile": {
            "count": summary.fragile,
            "by_reason": counts(summary.fragile_by_reason.iter().map(|(r, n)| (r.as_str().to_string(), *n)).collect()),
        },
        "tunnels": {
            "count": summary.tunnel_count(),
            "by_kind": counts(summary.tunnels.iter().map(|(k, n)| (k.to_string(), *n)).collect()),
            "first": summary.first_tunnels.iter().map(|t| json!({
                "frame": t.frame,
                "ball": t.ball,
                "text": t.to_string(),
            })).collect::<Vec<_>>(),
        },
        "degenerate_triangles": summary.degenerate_triangles,
        "contacts": (summary.contact_queries > 0).then(|| json!({
            "queries": summary.contact_queries,
            "drawn": contacts.map(|d| json!({
                "queries": d.queries,
                "contacts": d.contacts,
                "divergent": d.divergent,
                "ghosts": d.ghosts,
            })),
        })),
        "wrote": wrote,
        "incomplete": truncation.map(|e| format!("{e:#}")),
        "seconds": {
            "total": started.elapsed().as_secs_f64(),
            "core": summary.elapsed.as_secs_f64(),
        },
    });
    serde_json::to_string_pretty(&value)
        .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()))
}

/// `--json`'s document for a replay that failed: the trace, the status,
/// the exit code and the error's text.
pub(super) fn error_json(trace: &str, err: &anyhow::Error) -> String {
    let value = serde_json::json!({
        "trace": trace,
        "status": "error",
        "exit_code": crate::cli::Exit::Error.exit_code(),
        "error": format!("{err:#}"),
    });
    serde_json::to_string_pretty(&value)
        .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()))
}
