//! The edge tests of a sweep, each in its standard frame (v0 at the origin,
//! the edge on +x, +y the triangle's front normal).
//!
//! Slot 0 always explains the decision when an edge test can: the decisive
//! edge test, or, when the decision was a face or vertex test (or a miss
//! decided by one), the nearest edge test of the same triangle (from the
//! records when they hold one, else run here: three edge tests). When no
//! test ran at all and the expectation names a triangle, slot 0 is the edge
//! test the expectation names (or the nearest edge test of its triangle),
//! run here: it says why the expected collision was not found. The other
//! slots hold the remaining recorded edge tests, hits first, then the
//! nearest misses.

use rerun::components::{
    Color, FillMode, Length, Position3D, Radius, RotationQuat, Scalar, Text, Translation3D,
    Vector3D,
};
use rerun::{Arrows3D, Capsules3D, LineStrips3D, Points3D, Transform3D};

use super::columns::row::Row;
use super::convert::{
    AXIS_COLORS, CYLINDER_COLOR, EDGE_COLOR, HIT_COLOR, MISS_COLOR, PATH_COLOR, any_value, f32x3,
    quaternion, rgba, ui_points,
};
use super::out::{Out, set};
use super::paths::Entity;
use crate::core::explain::miss_distance;
use crate::core::record::{EdgeRecord, TestRecord};
use crate::core::{Kind, SweptPath, sweep_edge};
use crate::replay::SweepResult;

/// How an edge test ranks for a slot: hits by α, then misses by how near
/// they came.
fn rank(e: &EdgeRecord) -> (u8, f64) {
    let t = TestRecord::Edge(*e);
    match t.alpha() {
        Some(a) => (0, a),
        None => (1, miss_distance(&t).unwrap_or(f64::INFINITY)),
    }
}

fn better(x: &EdgeRecord, y: &EdgeRecord) -> bool {
    let (a, b) = (rank(x), rank(y));
    a.0 < b.0 || (a.0 == b.0 && a.1 < b.1)
}

/// What slot 0 is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Slot0 {
    /// The decisive test (labelled on the primary edge already).
    Decisive,
    /// The nearest edge test (of the decisive triangle).
    Nearest,
    /// The edge test of the expected outcome.
    Expected,
}

/// Where slot 0's edge test comes from.
#[derive(Clone, Copy, Debug)]
enum First<'r> {
    /// A test the core recorded.
    Recorded(&'r EdgeRecord),
    /// The nearest of the three edge tests of this triangle, to run here.
    Nearest(u32),
    /// This edge test (triangle, edge), to run here.
    Edge(u32, u8),
}

/// Slot 0's edge test and what it is, without running any test (see
/// [`choose_edges`]). A test to run here is named only when it can run
/// (its triangle exists and the sweep is valid); it is then of a triangle
/// none of whose edge tests was recorded.
fn choose_first<'r>(
    r: &'r SweepResult,
    decisive: Option<&'r TestRecord>,
) -> Option<(First<'r>, Slot0)> {
    let recorded = r.records.iter().filter_map(|t| match t {
        TestRecord::Edge(e) => Some(e),
        _ => None,
    });
    let best = |of: &mut dyn Iterator<Item = &'r EdgeRecord>| {
        of.fold(None::<&EdgeRecord>, |first, e| match first {
            Some(f) if !better(e, f) => Some(f),
            _ => Some(e),
        })
    };
    let can_run = |triangle: u32| {
        r.scene.mesh.triangle_by_index(triangle).is_some()
            && SweptPath::new(&r.sweep, r.options()).is_ok()
    };
    match decisive {
        Some(TestRecord::Edge(e)) => Some((First::Recorded(e), Slot0::Decisive)),
        Some(t) => {
            let triangle = t.triangle();
            match best(&mut recorded.filter(|e| e.triangle == triangle)) {
                Some(e) => Some((First::Recorded(e), Slot0::Nearest)),
                None => can_run(triangle).then_some((First::Nearest(triangle), Slot0::Nearest)),
            }
        }
        None => {
            if let Some(e) = best(&mut recorded.clone()) {
                return Some((First::Recorded(e), Slot0::Nearest));
            }
            let e = r.expected?;
            let triangle = e.triangle.flatten()?;
            let first = match (e.kind, e.feature) {
                (Kind::Edge, Some(Some(edge))) if edge < 3 => First::Edge(triangle, edge),
                _ => First::Nearest(triangle),
            };
            can_run(triangle).then_some((first, Slot0::Expected))
        }
    }
}

/// The edge tests recorded for `r` other than `first` (by triangle and
/// edge).
fn others<'r>(r: &'r SweepResult, first: &First<'_>) -> impl Iterator<Item = &'r EdgeRecord> {
    let key = match first {
        First::Recorded(e) => Some((e.triangle, e.edge)),
        // No edge test of that triangle was recorded.
        First::Nearest(_) | First::Edge(..) => None,
    };
    r.records.iter().filter_map(move |t| match t {
        TestRecord::Edge(e) if key != Some((e.triangle, e.edge)) => Some(e),
        _ => None,
    })
}

/// How many edge tests [`choose_edges`] chooses, without running any.
pub(crate) fn count_edges(r: &SweepResult, decisive: Option<&TestRecord>, max: usize) -> usize {
    if max == 0 {
        return 0;
    }
    match choose_first(r, decisive) {
        Some((first, _)) => (1 + others(r, &first).count()).min(max),
        None => 0,
    }
}

/// Chooses the edge tests to show into `edges` (slot order, at most `max`).
/// Returns what slot 0 is.
pub(crate) fn choose_edges(
    edges: &mut Vec<EdgeRecord>,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    max: usize,
) -> Slot0 {
    edges.clear();
    if max == 0 {
        return Slot0::Nearest;
    }
    let Some((first, what)) = choose_first(r, decisive) else {
        return Slot0::Nearest;
    };
    let test = match first {
        First::Recorded(e) => Some(*e),
        First::Nearest(triangle) => nearest_edge_of(r, triangle),
        First::Edge(triangle, edge) => edge_of(r, triangle, edge),
    };
    let Some(test) = test else {
        return Slot0::Nearest;
    };
    edges.push(test);
    // The others by rank, hits first (at `candidates` a sweep can record
    // hundreds: each rank is worked out once, and only the first `max - 1`
    // put in order).
    let others: Vec<&EdgeRecord> = others(r, &first).collect();
    let order = first_by_key(&others, max - 1, |e| rank(e));
    edges.extend(order.into_iter().map(|i| *others[i]));
    what
}

/// The indices of the first `keep` of `items` in the order of `key`
/// (class, then value by `f64::total_cmp`), equal keys in their order in
/// `items`: what a stable sort by `key` then keeping `keep` gives.
fn first_by_key<T>(items: &[T], keep: usize, key: impl Fn(&T) -> (u8, f64)) -> Vec<usize> {
    let mut keys: Vec<(u8, i64, usize)> = items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let (class, value) = key(item);
            (class, total_order_key(value), i)
        })
        .collect();
    if keys.len() > keep {
        if keep > 0 {
            keys.select_nth_unstable(keep - 1);
        }
        keys.truncate(keep);
    }
    keys.sort_unstable();
    keys.into_iter().map(|(.., i)| i).collect()
}

/// An integer whose order is `f64::total_cmp`'s.
fn total_order_key(x: f64) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ (((bits >> 63) as u64) >> 1) as i64
}

/// Edge test `edge` of `triangle`, run here.
fn edge_of(r: &SweepResult, triangle: u32, edge: u8) -> Option<EdgeRecord> {
    let t = r.scene.mesh.triangle_by_index(triangle)?;
    let path = SweptPath::new(&r.sweep, r.options()).ok()?;
    Some(sweep_edge(t, edge, &path, r.options().facing))
}

/// The nearest of the three edge tests of `triangle`, run here.
fn nearest_edge_of(r: &SweepResult, triangle: u32) -> Option<EdgeRecord> {
    let t = r.scene.mesh.triangle_by_index(triangle)?;
    let path = SweptPath::new(&r.sweep, r.options()).ok()?;
    (0..3u8)
        .map(|i| sweep_edge(t, i, &path, r.options().facing))
        .reduce(|a, b| if better(&b, &a) { b } else { a })
}

/// The rows of the chosen edge tests, one per test; slot 0's edge labelled
/// `slot0_label` (see `rows::SweepLabels`).
pub(crate) fn edge_frame_rows(
    out: &mut Out<'_>,
    r: &SweepResult,
    edges: &[EdgeRecord],
    slot0_label: Option<&str>,
) {
    let b = r.ball;
    let rho = r.rho();
    for (slot, e) in edges.iter().enumerate() {
        let set = if slot == 0 {
            set::EDGE_FRAME_AXES
        } else {
            set::EDGE_FRAME
        };
        let mut row = out.row(Entity::EdgeFrame(b, slot), set);
        edge_frame_values(&mut row, e);
        let hit = e.alpha().is_some();
        let length = e.length as f32;
        // The edge on +x, then the path; slot 0's edge labelled.
        let label = slot0_label.filter(|_| slot == 0);
        let p0e = f32x3(e.p0_in_edge.coords);
        let p1e = f32x3(e.p1_in_edge.coords);
        row.put_strips(
            LineStrips3D::descriptor_strips,
            &[&[[0.0, 0.0, 0.0], [length, 0.0, 0.0]], &[p0e, p1e]],
        )
        .put::<Radius>(
            LineStrips3D::descriptor_radii,
            [ui_points(3.0), ui_points(1.5)],
        )
        .put::<Color>(
            LineStrips3D::descriptor_colors,
            [rgba(EDGE_COLOR), rgba(PATH_COLOR)],
        )
        .put_texts(LineStrips3D::descriptor_labels, |t| {
            // Two labels, the path's empty (not drawn): a single label
            // would be drawn between the two strips.
            if let Some(label) = label {
                t.push_fmt(format_args!("{label}"));
                t.push_fmt(format_args!(""));
            }
        });
        // The cylinder of radius ρ around the edge: a capsule lies along +z;
        // turn it onto +x (90° about +y).
        let half = std::f32::consts::FRAC_1_SQRT_2;
        row.put::<Length>(Capsules3D::descriptor_lengths, [length.into()])
            .put::<Radius>(Capsules3D::descriptor_radii, [(rho as f32).into()])
            .put::<RotationQuat>(
                Capsules3D::descriptor_quaternions,
                [rerun::Quaternion::from_xyzw([0.0, half, 0.0, half]).into()],
            )
            .put::<Color>(Capsules3D::descriptor_colors, [rgba(CYLINDER_COLOR)])
            .put::<FillMode>(Capsules3D::descriptor_fill_mode, [FillMode::MajorWireframe]);
        // p0, p1, the centers at s0 and s1, xc on the edge.
        let at = |s: f64| f32x3((e.p0_in_edge + (e.p1_in_edge - e.p0_in_edge) * s).coords);
        let roots = e
            .roots
            .filter(|(s0, s1)| s0.is_finite() && s1.is_finite() && *s0 > -2.0 && *s1 < 3.0);
        let root_color = rgba(if hit { HIT_COLOR } else { MISS_COLOR });
        let xc = e.xc.filter(|x| x.is_finite());
        row.put::<Position3D>(
            Points3D::descriptor_positions,
            [p0e, p1e]
                .into_iter()
                .chain(roots.map(|(s0, _)| at(s0)))
                .chain(roots.map(|(_, s1)| at(s1)))
                .chain(xc.map(|x| [x as f32, 0.0, 0.0]))
                .map(Position3D::from),
        )
        .put::<Radius>(
            Points3D::descriptor_radii,
            [ui_points(4.0), ui_points(4.0)]
                .into_iter()
                .chain(roots.map(|_| ui_points(5.0)))
                .chain(roots.map(|_| ui_points(3.0)))
                .chain(xc.map(|_| ui_points(6.0))),
        )
        .put::<Color>(
            Points3D::descriptor_colors,
            [rgba(PATH_COLOR), rgba(PATH_COLOR)]
                .into_iter()
                .chain(roots.map(|_| root_color))
                .chain(roots.map(|_| rgba([150, 150, 150, 255])))
                .chain(xc.map(|_| root_color)),
        );
        if slot == 0 {
            let a = (rho.max(e.length * 0.25)) as f32;
            row.put::<Vector3D>(
                Arrows3D::descriptor_vectors,
                [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, a]].map(Vector3D::from),
            )
            .put::<Color>(Arrows3D::descriptor_colors, AXIS_COLORS.map(rgba));
        }
    }
}

/// The edge frame's transform (world from edge) and the numbers of its edge
/// test (as `AnyValues`: test, verdict, length, a, b, c, discriminant, s0,
/// s1 and xc; s0, s1 and xc empty when the test did not get that far, so
/// that no earlier sweep's value shows).
fn edge_frame_values(row: &mut Row<'_>, e: &EdgeRecord) {
    let world_from_edge = e.frame.world_from_edge();
    let (s0, s1) = e.roots.unzip();
    row.put::<Translation3D>(
        Transform3D::descriptor_translation,
        [f32x3(world_from_edge.translation.vector).into()],
    )
    .put::<RotationQuat>(
        Transform3D::descriptor_quaternion,
        [quaternion(&world_from_edge.rotation).into()],
    )
    .put_fmt(
        || any_value::<Text>("test"),
        format_args!("edge {}.{}", e.triangle, e.edge),
    )
    .put_strs(|| any_value::<Text>("verdict"), [e.verdict.as_str()])
    .put::<Scalar>(|| any_value::<Scalar>("length"), [e.length.into()])
    .put::<Scalar>(|| any_value::<Scalar>("a"), [e.a.into()])
    .put::<Scalar>(|| any_value::<Scalar>("b"), [e.b.into()])
    .put::<Scalar>(|| any_value::<Scalar>("c"), [e.c.into()])
    .put::<Scalar>(
        || any_value::<Scalar>("discriminant"),
        [e.discriminant.into()],
    )
    .put::<Scalar>(|| any_value::<Scalar>("s0"), s0.map(Scalar::from))
    .put::<Scalar>(|| any_value::<Scalar>("s1"), s1.map(Scalar::from))
    .put::<Scalar>(|| any_value::<Scalar>("xc"), e.xc.map(Scalar::from));
}

#[cfg(test)]
mod tests {
    use super::first_by_key;

    /// `first_by_key` gives what a stable sort by the key and a truncation
    /// give, with ties, both zeros, infinities and NaNs among the values.
    #[test]
    fn first_by_key_equals_a_stable_sort() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
            1e-300,
            -1e300,
        ];
        let mut state = 12345u64;
        let mut next = |n: usize| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize % n
        };
        for round in 0..500 {
            let len = next(40);
            let items: Vec<(u8, f64)> = (0..len)
                .map(|_| (next(2) as u8, values[next(values.len())]))
                .collect();
            let keep = next(20);
            let mut want: Vec<usize> = (0..len).collect();
            want.sort_by(|&x, &y| {
                let (a, b) = (items[x], items[y]);
                a.0.cmp(&b.0).then(a.1.total_cmp(&b.1))
            });
            want.truncate(keep);
            let got = first_by_key(&items, keep, |&k| k);
            assert_eq!(got, want, "round {round}: {items:?}, keep {keep}");
        }
    }
}
