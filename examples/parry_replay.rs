//! The peer of `sweeptrace replay --outcomes` in BENCHMARKS.md: the same
//! whole process (read and decode a trace, build each scene's mesh, answer
//! every sweep, write one JSON line per sweep) with parry3d-f64's
//! `cast_shapes` of a `Ball` against its `TriMesh` as the query.
//!
//! It reads the trace with sweeptrace's own reader on a thread of its own
//! (the same decoding, so the comparison is of what follows it) and answers
//! each batch of 4,096 sweeps on every core with rayon, as `replay` does.
//! parry has no margin and no facing rule: a sweep's answer is its first
//! contact with either side, so its hits are not `replay`'s outcomes; the
//! line gives `frame`, `ball`, `hit` and `alpha` only.
//!
//! ```sh
//! cargo run --release --no-default-features --example parry_replay -- T.mcap o.parry.jsonl
//! ```

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};

#[path = "../benches/parry_cast.rs"]
mod parry_cast;

use parry3d_f64::shape::TriMesh;
use rayon::prelude::*;
use sweeptrace::trace::prefetch::{DEFAULT_PREFETCH_CHUNK, DEFAULT_PREFETCH_DEPTH, prefetch};
use sweeptrace::trace::{EventBody, SweepMsg, TraceReader};

const BATCH: usize = 4096;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [trace, out] = args.as_slice() else {
        anyhow::bail!("usage: parry_replay TRACE.mcap OUT.jsonl");
    };
    let file = File::open(trace)?;
    let reader = TraceReader::new_indexed(BufReader::with_capacity(1 << 16, file), trace);
    let mut events = prefetch(reader, DEFAULT_PREFETCH_CHUNK, DEFAULT_PREFETCH_DEPTH)?;
    let mut output = BufWriter::new(File::create(out)?);
    let mut mesh: Option<TriMesh> = None;
    let mut batch: Vec<SweepMsg> = Vec::with_capacity(BATCH);
    let (mut sweeps, mut hits) = (0u64, 0u64);
    loop {
        let event = events.next().transpose()?;
        let scene = match event.as_ref().map(|e| &e.body) {
            Some(EventBody::Sweep(sweep)) => {
                batch.push(*sweep);
                None
            }
            Some(EventBody::Scene(scene)) => Some(scene),
            Some(
                EventBody::Expected(_) | EventBody::Contact(_) | EventBody::ExpectedContacts(_),
            ) => {
                continue;
            }
            None => None,
        };
        // A batch is answered when full, before a new scene and at the end.
        if batch.len() == BATCH || scene.is_some() || event.is_none() {
            if let Some(mesh) = &mesh {
                let answers: Vec<Option<f64>> = batch
                    .par_iter()
                    .with_min_len(16)
                    .map(|s| cast(mesh, s))
                    .collect();
                for (s, alpha) in batch.iter().zip(answers) {
                    sweeps += 1;
                    hits += u64::from(alpha.is_some());
                    let line = serde_json::json!({
                        "frame": s.frame,
                        "ball": s.ball,
                        "hit": alpha.is_some(),
                        "alpha": alpha,
                    });
                    writeln!(output, "{line}")?;
                }
            } else if !batch.is_empty() {
                anyhow::bail!("{trace}: a sweep before the first scene");
            }
            batch.clear();
        }
        match (event.is_none(), scene) {
            (true, _) => break,
            (false, Some(scene)) => {
                mesh = Some(parry_cast::parry_mesh(&scene.vertices, &scene.triangles)?)
            }
            (false, None) => {}
        }
    }
    output
        .into_inner()
        .map_err(|e| e.into_error())?
        .sync_all()?;
    eprintln!("parry_replay: {sweeps} sweeps, {hits} hits, written to {out}");
    Ok(())
}

/// parry's first time of impact in `[0, 1]` of the sweep, if any.
fn cast(mesh: &TriMesh, s: &SweepMsg) -> Option<f64> {
    parry_cast::parry_cast(mesh, s.p0, s.p1, s.radius)
}
