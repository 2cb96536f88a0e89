//! Test records in words: one line per test, saying what was computed and
//! why the test decided as it did. Pure functions returning strings.

use std::fmt::Write;

use super::record::{EdgeRecord, FaceRecord, TestRecord, Verdict, VertexRecord};

/// A short number: 4 significant decimals, no trailing noise.
pub fn num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if !(1e-4..1e6).contains(&a) {
        return format!("{x:.4e}");
    }
    let s = format!("{x:.5}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// `face 7`, `edge 12.1`, `vertex 3.2`.
pub fn label(record: &TestRecord) -> String {
    match record {
        TestRecord::Face(r) => format!("face {}", r.triangle),
        TestRecord::Edge(r) => format!("edge {}.{}", r.triangle, r.edge),
        TestRecord::Vertex(r) => format!("vertex {}.{}", r.triangle, r.vertex),
    }
}

/// One line: label, the numbers that decided, the verdict.
pub fn describe(record: &TestRecord) -> String {
    let body = match record {
        TestRecord::Face(r) => describe_face(r),
        TestRecord::Edge(r) => describe_edge(r),
        TestRecord::Vertex(r) => describe_vertex(r),
    };
    format!("{}: {}", label(record), body)
}

fn facing(n_dot_d: f64, verdict: Verdict) -> String {
    if verdict == Verdict::BackFacing {
        format!("n·d = {} fails the facing rule", num(n_dot_d))
    } else {
        "facing ok".to_string()
    }
}

fn describe_face(r: &FaceRecord) -> String {
    let mut s = format!("h0 = {}, h1 = {}", num(r.h0), num(r.h1));
    match r.verdict {
        Verdict::StartsTooClose => {
            s.push_str(" (h0 < ρ: starts within ρ of the plane or behind it): none")
        }
        Verdict::Parallel => {
            s.push_str(" (|h0 - h1| ≤ PARALLEL_TOLERANCE·|d|: moving parallel to the plane): none")
        }
        Verdict::BackFacing if r.h1 > r.h0 && r.normal_dot_d <= 0.0 => write!(
            s,
            ", n·d = {} but h1 > h0 (moving away from the plane, by rounding): back-facing",
            num(r.normal_dot_d)
        )
        .unwrap(),
        Verdict::BackFacing => {
            write!(s, ", {}: back-facing", facing(r.normal_dot_d, r.verdict)).unwrap()
        }
        Verdict::BeyondEnd => write!(
            s,
            ", β = {} > 1: does not reach the plane",
            num(r.beta.unwrap_or(f64::NAN))
        )
        .unwrap(),
        Verdict::OutsideTriangle | Verdict::Hit => {
            let b = r.barycentric.unwrap_or([f64::NAN; 3]);
            write!(
                s,
                ", β = {} in [0, 1], touch point barycentric ({}, {}, {})",
                num(r.beta.unwrap_or(f64::NAN)),
                num(b[0]),
                num(b[1]),
                num(b[2])
            )
            .unwrap();
            if r.verdict == Verdict::Hit {
                s.push_str(" inside, facing ok: hit");
            } else {
                s.push_str(" outside the triangle: none");
            }
        }
        other => write!(s, ": {other}").unwrap(),
    }
    s
}

fn describe_edge(r: &EdgeRecord) -> String {
    let quad = format!(
        "A = {}, B = {}, C = {}, disc = {}",
        num(r.a),
        num(r.b),
        num(r.c),
        num(r.discriminant)
    );
    match r.verdict {
        Verdict::Parallel => format!(
            "A = {} ≤ (PARALLEL_TOLERANCE·|d|)² (path parallel to the edge, or not moving): none",
            num(r.a)
        ),
        Verdict::NoRealRoots => format!("{quad} < 0 (never within ρ of the edge's line): none"),
        _ => {
            let (s0, s1) = r.roots.unwrap_or((f64::NAN, f64::NAN));
            let roots = format!("s0 = {}, s1 = {}", num(s0), num(s1));
            match r.verdict {
                Verdict::BeforeStart => {
                    format!("{roots}: s0 < 0 (before the start of the path): none")
                }
                Verdict::BeyondEnd => format!("{roots}: s0 > 1 (beyond the end of the path): none"),
                _ => {
                    let xc = r.xc.unwrap_or(f64::NAN);
                    let head = format!("s0 = {} in [0, 1], xc = {}", num(s0), num(xc));
                    match r.verdict {
                        Verdict::OffEdge => format!(
                            "{head} outside [0, {}] (touches the line off the edge: a vertex case): none",
                            num(r.length)
                        ),
                        Verdict::BackFacing => format!(
                            "{head} in [0, {}], {}: back-facing",
                            num(r.length),
                            facing(r.normal_dot_d, r.verdict)
                        ),
                        _ => format!("{head} in [0, {}], facing ok: hit", num(r.length)),
                    }
                }
            }
        }
    }
}

fn describe_vertex(r: &VertexRecord) -> String {
    match r.verdict {
        Verdict::NotMoving => "A = 0 (zero-length path): none".to_string(),
        Verdict::NoRealRoots => format!(
            "A = {}, B = {}, C = {}, disc = {} < 0 (never within ρ of the vertex): none",
            num(r.a),
            num(r.b),
            num(r.c),
            num(r.discriminant)
        ),
        _ => {
            let (s0, s1) = r.roots.unwrap_or((f64::NAN, f64::NAN));
            match r.verdict {
                Verdict::BeforeStart => format!(
                    "s0 = {}, s1 = {}: s0 < 0 (before the start): none",
                    num(s0),
                    num(s1)
                ),
                Verdict::BeyondEnd => format!(
                    "s0 = {}: s0 > 1 (beyond the end of the path): none",
                    num(s0)
                ),
                Verdict::BackFacing => format!(
                    "s0 = {} in [0, 1], {}: back-facing",
                    num(s0),
                    facing(r.normal_dot_d, r.verdict)
                ),
                _ => format!("s0 = {} in [0, 1], facing ok: hit", num(s0)),
            }
        }
    }
}

/// How close a rejected test came to a hit, for choosing the "nearest miss"
/// to explain when nothing is hit: smaller is closer. `None` for hits.
pub fn miss_distance(record: &TestRecord) -> Option<f64> {
    let r = record;
    if r.verdict() == Verdict::Hit {
        return None;
    }
    Some(match r {
        TestRecord::Face(f) => match f.verdict {
            Verdict::OutsideTriangle => {
                let b = f.barycentric.unwrap_or([0.0; 3]);
                -b.iter().copied().fold(0.0, f64::min)
            }
            Verdict::BeyondEnd => f.beta.unwrap_or(f64::INFINITY) - 1.0,
            Verdict::BackFacing => 2.0,
            _ => 10.0,
        },
        TestRecord::Edge(e) => match e.verdict {
            Verdict::OffEdge => {
                let xc = e.xc.unwrap_or(0.0);
                (if xc < 0.0 { -xc } else { xc - e.length }) / e.length.max(f64::MIN_POSITIVE)
            }
            Verdict::BeyondEnd => e.roots.map_or(f64::INFINITY, |r| r.0 - 1.0),
            Verdict::BackFacing => 2.0,
            Verdict::NoRealRoots => {
                3.0 + (-e.discriminant).max(0.0).sqrt() / e.a.max(f64::MIN_POSITIVE)
            }
            _ => 10.0,
        },
        TestRecord::Vertex(v) => match v.verdict {
            Verdict::BeyondEnd => v.roots.map_or(f64::INFINITY, |r| r.0 - 1.0),
            Verdict::BackFacing => 2.0,
            Verdict::NoRealRoots => {
                3.0 + (-v.discriminant).max(0.0).sqrt() / v.a.max(f64::MIN_POSITIVE)
            }
            _ => 10.0,
        },
    })
}
