//! Test records in words: one line per test, saying what was computed and
//! why the test decided as it did. Pure functions returning strings.

use std::fmt::{self, Write};

use super::record::{EdgeRecord, FaceRecord, TestRecord, Verdict, VertexRecord};

/// A short number: 4 significant decimals, no trailing noise.
pub fn num(x: f64) -> String {
    Num(x).to_string()
}

/// [`num`] as a `Display` value that writes without allocating.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x == 0.0 {
            return f.write_str("0");
        }
        let a = x.abs();
        if !(1e-4..1e6).contains(&a) {
            return write!(f, "{x:.4e}");
        }
        // Below 10^6 with 5 decimals: at most 14 bytes.
        let mut buf = StackText::default();
        write!(buf, "{x:.5}")?;
        f.write_str(buf.as_str().trim_end_matches('0').trim_end_matches('.'))
    }
}

/// A few bytes of text on the stack.
#[derive(Default)]
struct StackText {
    bytes: [u8; 32],
    len: usize,
}

impl StackText {
    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..self.len]).unwrap_or("")
    }
}

impl Write for StackText {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let end = self.len + s.len();
        if end > self.bytes.len() {
            return Err(fmt::Error);
        }
        self.bytes[self.len..end].copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// `face 7`, `edge 12.1`, `vertex 3.2`.
pub fn label(record: &TestRecord) -> String {
    Label(record).to_string()
}

/// [`label`] as a `Display` value that writes without allocating.
#[derive(Clone, Copy, Debug)]
pub struct Label<'a>(pub &'a TestRecord);

impl fmt::Display for Label<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            TestRecord::Face(r) => write!(f, "face {}", r.triangle)?,
            TestRecord::Edge(r) => write!(f, "edge {}.{}", r.triangle, r.edge)?,
            TestRecord::Vertex(r) => write!(f, "vertex {}.{}", r.triangle, r.vertex)?,
        }
        // Under `sides = two`, a triangle tested from its back.
        if self.0.back() {
            f.write_str(" (back side)")?;
        }
        Ok(())
    }
}

/// One line: label, the numbers that decided, the verdict.
pub fn describe(record: &TestRecord) -> String {
    let mut s = String::with_capacity(128);
    let _ = write_describe(&mut s, record);
    s
}

/// Writes [`describe`]'s line into `w` (no allocation of its own).
pub fn write_describe(w: &mut impl Write, record: &TestRecord) -> fmt::Result {
    write!(w, "{}: ", Label(record))?;
    match record {
        TestRecord::Face(r) => describe_face(w, r),
        TestRecord::Edge(r) => describe_edge(w, r),
        TestRecord::Vertex(r) => describe_vertex(w, r),
    }
}

/// `facing ok`, or why the facing rule failed.
struct FacingText(f64, Verdict);

impl fmt::Display for FacingText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.1 == Verdict::BackFacing {
            write!(f, "n·d = {} fails the facing rule", Num(self.0))
        } else {
            f.write_str("facing ok")
        }
    }
}

fn describe_face(w: &mut impl Write, r: &FaceRecord) -> fmt::Result {
    write!(w, "h0 = {}, h1 = {}", Num(r.h0), Num(r.h1))?;
    match r.verdict {
        Verdict::StartsTooClose => {
            w.write_str(" (h0 < ρ: starts within ρ of the plane or behind it): none")
        }
        Verdict::Parallel => write!(
            w,
            ", n·d = {} (|n·d| ≤ PARALLEL_TOLERANCE·|d|: moving parallel to the plane): none",
            Num(r.normal_dot_d)
        ),
        Verdict::BackFacing => write!(
            w,
            ", {}: back-facing",
            FacingText(r.normal_dot_d, r.verdict)
        ),
        Verdict::BeyondEnd => write!(
            w,
            ", n·d = {}, β = (h0 - ρ)/-(n·d) = {} > 1: does not reach the plane",
            Num(r.normal_dot_d),
            Num(r.beta.unwrap_or(f64::NAN))
        ),
        Verdict::OutsideTriangle | Verdict::Hit => {
            let b = r.barycentric.unwrap_or([f64::NAN; 3]);
            write!(
                w,
                ", n·d = {}, β = (h0 - ρ)/-(n·d) = {} in [0, 1], touch point barycentric ({}, {}, {})",
                Num(r.normal_dot_d),
                Num(r.beta.unwrap_or(f64::NAN)),
                Num(b[0]),
                Num(b[1]),
                Num(b[2])
            )?;
            if r.verdict == Verdict::Hit && b.iter().any(|&x| x < 0.0) {
                w.write_str(
                    " outside by less than the tie distance (on the boundary up to rounding), \
                     facing ok: hit",
                )
            } else if r.verdict == Verdict::Hit {
                w.write_str(" inside, facing ok: hit")
            } else {
                w.write_str(" outside the triangle: none")
            }
        }
        other => write!(w, ": {other}"),
    }
}

/// The quadratic's numbers of an edge or vertex test.
trait Quadratic {
    fn numbers(&self) -> (f64, f64, f64, f64, Option<(f64, f64)>);
}

impl Quadratic for EdgeRecord {
    fn numbers(&self) -> (f64, f64, f64, f64, Option<(f64, f64)>) {
        (self.a, self.b, self.c, self.discriminant, self.roots)
    }
}

impl Quadratic for VertexRecord {
    fn numbers(&self) -> (f64, f64, f64, f64, Option<(f64, f64)>) {
        (self.a, self.b, self.c, self.discriminant, self.roots)
    }
}

/// The words of the ladder both quadratic tests share
/// (`quadratic::first_contact`): no real roots (never within ρ of `what`),
/// before the start, beyond the end.
fn write_no_contact(
    w: &mut impl Write,
    verdict: Verdict,
    r: &impl Quadratic,
    what: &str,
) -> fmt::Result {
    let (a, b, c, discriminant, roots) = r.numbers();
    let (s0, s1) = roots.unwrap_or((f64::NAN, f64::NAN));
    match verdict {
        Verdict::NoRealRoots => write!(
            w,
            "A = {}, B = {}, C = {}, disc = {} < 0 (never within ρ of {what}): none",
            Num(a),
            Num(b),
            Num(c),
            Num(discriminant)
        ),
        Verdict::BeforeStart => write!(
            w,
            "s0 = {}, s1 = {}: s0 < 0 (before the start of the path): none",
            Num(s0),
            Num(s1)
        ),
        _ => write!(
            w,
            "s0 = {}, s1 = {}: s0 > 1 (beyond the end of the path): none",
            Num(s0),
            Num(s1)
        ),
    }
}

fn describe_edge(w: &mut impl Write, r: &EdgeRecord) -> fmt::Result {
    match r.verdict {
        Verdict::Parallel => write!(
            w,
            "A = {} ≤ (PARALLEL_TOLERANCE·|d|)² (path parallel to the edge, or not moving): none",
            Num(r.a)
        ),
        verdict @ (Verdict::NoRealRoots | Verdict::BeforeStart | Verdict::BeyondEnd) => {
            write_no_contact(w, verdict, r, "the edge's line")
        }
        _ => {
            let (s0, _) = r.roots.unwrap_or((f64::NAN, f64::NAN));
            let xc = r.xc.unwrap_or(f64::NAN);
            write!(w, "s0 = {} in [0, 1], xc = {}", Num(s0), Num(xc))?;
            match r.verdict {
                Verdict::OffEdge => write!(
                    w,
                    " outside [0, {}] (touches the line off the edge: a vertex case): none",
                    Num(r.length)
                ),
                Verdict::BackFacing => write!(
                    w,
                    " in [0, {}], {}: back-facing",
                    Num(r.length),
                    FacingText(r.normal_dot_d, r.verdict)
                ),
                _ if xc < 0.0 || xc > r.length => write!(
                    w,
                    " outside [0, {}] by less than the tie distance (at an end up to \
                     rounding), facing ok: hit",
                    Num(r.length)
                ),
                _ => write!(w, " in [0, {}], facing ok: hit", Num(r.length)),
            }
        }
    }
}

fn describe_vertex(w: &mut impl Write, r: &VertexRecord) -> fmt::Result {
    match r.verdict {
        Verdict::NotMoving => w.write_str("A = 0 (zero-length path): none"),
        verdict @ (Verdict::NoRealRoots | Verdict::BeforeStart | Verdict::BeyondEnd) => {
            write_no_contact(w, verdict, r, "the vertex")
        }
        _ => {
            let (s0, _) = r.roots.unwrap_or((f64::NAN, f64::NAN));
            match r.verdict {
                Verdict::BackFacing => write!(
                    w,
                    "s0 = {} in [0, 1], {}: back-facing",
                    Num(s0),
                    FacingText(r.normal_dot_d, r.verdict)
                ),
                _ => write!(w, "s0 = {} in [0, 1], facing ok: hit", Num(s0)),
            }
        }
    }
}

/// The rejected test that came nearest to a hit ([`miss_distance`]); the
/// first of equals.
pub fn nearest_miss(records: &[TestRecord]) -> Option<&TestRecord> {
    records
        .iter()
        .filter_map(|r| miss_distance(r).map(|d| (d, r)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, r)| r)
}

/// How close a rejected test came to a hit, for choosing the "nearest miss"
/// to explain when nothing is hit: smaller is closer. `None` for hits.
pub fn miss_distance(record: &TestRecord) -> Option<f64> {
    match record {
        TestRecord::Face(f) => face_miss_distance(f),
        TestRecord::Edge(e) => edge_miss_distance(e),
        TestRecord::Vertex(v) => vertex_miss_distance(v),
    }
}

/// [`miss_distance`] of a face test.
#[inline]
pub fn face_miss_distance(f: &FaceRecord) -> Option<f64> {
    Some(match f.verdict {
        Verdict::Hit => return None,
        Verdict::OutsideTriangle => {
            let b = f.barycentric.unwrap_or([0.0; 3]);
            -b.iter().copied().fold(0.0, f64::min)
        }
        Verdict::BeyondEnd => f.beta.unwrap_or(f64::INFINITY) - 1.0,
        Verdict::BackFacing => 2.0,
        _ => 10.0,
    })
}

/// [`miss_distance`] of an edge test.
#[inline]
pub fn edge_miss_distance(e: &EdgeRecord) -> Option<f64> {
    Some(match e.verdict {
        Verdict::Hit => return None,
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
    })
}

/// [`miss_distance`] of a vertex test.
#[inline]
pub fn vertex_miss_distance(v: &VertexRecord) -> Option<f64> {
    Some(match v.verdict {
        Verdict::Hit => return None,
        Verdict::BeyondEnd => v.roots.map_or(f64::INFINITY, |r| r.0 - 1.0),
        Verdict::BackFacing => 2.0,
        Verdict::NoRealRoots => {
            3.0 + (-v.discriminant).max(0.0).sqrt() / v.a.max(f64::MIN_POSITIVE)
        }
        _ => 10.0,
    })
}

#[cfg(test)]
mod tests {
    use super::Num;

    /// The allocating formulation `Num` replaces.
    fn reference(x: f64) -> String {
        if x == 0.0 {
            return "0".into();
        }
        if !(1e-4..1e6).contains(&x.abs()) {
            return format!("{x:.4e}");
        }
        let s = format!("{x:.5}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }

    #[test]
    fn num_writes_what_the_string_formulation_writes() {
        let mut x = 1.234_567_89e-7_f64;
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            1e-4,
            1e6,
            999_999.999_999,
            f64::NAN,
        ];
        values.extend([f64::INFINITY, f64::NEG_INFINITY, f64::MIN, f64::MAX, 1e-300]);
        while x < 1e9 {
            values.extend([x, -x, x * 1.000_001, (x * 1e5).round() / 1e5]);
            x *= 1.37;
        }
        for v in values {
            assert_eq!(Num(v).to_string(), reference(v), "{v:e}");
        }
    }
}
