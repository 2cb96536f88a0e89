//! The exact reference both exact-tie tests use (integer coordinates,
//! exact in binary): vector arithmetic, the closed-triangle and segment
//! predicates, integer-length directions, and the tie set the rules give
//! at a known first contact.

use sweeptrace::core::Kind;

/// An integer point or vector.
pub(crate) type I3 = [i64; 3];

pub(crate) fn sub3(a: I3, b: I3) -> I3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot3(a: I3, b: I3) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross3(a: I3, b: I3) -> I3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Whether `x` lies on the closed segment `a b` (exact).
pub(crate) fn on_segment(x: I3, a: I3, b: I3) -> bool {
    let (ab, ax) = (sub3(b, a), sub3(x, a));
    cross3(ab, ax) == [0, 0, 0] && dot3(ax, ab) >= 0 && dot3(ax, ab) <= dot3(ab, ab)
}

/// Whether `x` lies in the closed triangle `v` of normal `n ≠ 0` (exact).
pub(crate) fn in_closed_triangle(x: I3, v: [I3; 3], n: I3) -> bool {
    let n = n.map(i128::from);
    let dot = |a: I3, b: [i128; 3]| -> i128 { (0..3).map(|k| i128::from(a[k]) * b[k]).sum() };
    dot(sub3(x, v[0]), n) == 0
        && (0..3).all(|k| {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let c = cross3(sub3(b, a), sub3(x, a));
            dot(c, n) >= 0
        })
}

/// The integer square root of `s`, when `s` is a perfect square.
pub(crate) fn exact_sqrt(s: i64) -> Option<i64> {
    let r = (s as f64).sqrt().round() as i64;
    (r - 1..=r + 1).find(|&q| q >= 0 && q * q == s)
}

/// Every integer vector of integer length `1..=max`, with its length
/// (Pythagorean quadruples).
pub(crate) fn rational_length_vectors(max: i64) -> Vec<(I3, i64)> {
    let mut out = Vec::new();
    for x in -max..=max {
        for y in -max..=max {
            for z in -max..=max {
                let s = x * x + y * y + z * z;
                if let Some(r) = exact_sqrt(s)
                    && r > 0
                    && r <= max
                {
                    out.push(([x, y, z], r));
                }
            }
        }
    }
    out
}

/// The exact tie set at the contact point `x` for the ball centred at
/// `x + w` (radius `ρ = |w|`) travelling along `d`, when `w` is normal to a
/// supporting plane at `x` (so the ball touches the mesh at `x` only, at
/// that moment): `(kind, triangle, feature)` of every test that touches,
/// in the rules' order (kind, then triangle, then feature), under the
/// non-strict facing rule. `triangles` are the mesh's triangles of
/// nonzero area with their input indices.
///
/// The rules (docs/SEMANTICS.md): a face touches when `x` is in the
/// closed triangle and `w` is along its front normal; an edge when `x` is
/// on the closed segment and `w` is perpendicular to it; a vertex when it
/// is `x`; a back-facing triangle (`n · d > 0`) tests nothing.
pub(crate) fn exact_tie_set(
    vertices: &[I3],
    triangles: impl IntoIterator<Item = (u32, [usize; 3])>,
    x: I3,
    w: I3,
    d: I3,
) -> Vec<(Kind, u32, u8)> {
    let mut out = Vec::new();
    for (t, tri) in triangles {
        let v = tri.map(|i| vertices[i]);
        let normal = cross3(sub3(v[1], v[0]), sub3(v[2], v[0]));
        if dot3(normal, d) > 0 {
            continue; // back-facing (non-strict rule)
        }
        if cross3(normal, w) == [0, 0, 0] && dot3(normal, w) > 0 && in_closed_triangle(x, v, normal)
        {
            out.push((Kind::Face, t, 0));
        }
        for e in 0..3 {
            let (a, b) = (v[e], v[(e + 1) % 3]);
            if on_segment(x, a, b) && dot3(sub3(b, a), w) == 0 {
                out.push((Kind::Edge, t, e as u8));
            }
        }
        for (k, &p) in v.iter().enumerate() {
            if p == x {
                out.push((Kind::Vertex, t, k as u8));
            }
        }
    }
    out.sort();
    out
}
