//! `diff`'s contact queries: each side's `/contact` queries answered by the
//! core (the contact set under that side's scene and `sides` convention,
//! docs/SEMANTICS.md "Contacts"), matched by `(frame, ball)` and compared
//! triangle by triangle with the diff's tolerances.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use crate::core::explain::num;
use crate::core::{Contact, ContactQuery, Sides, contact_set};
use crate::judge::{Tolerances, angle_degrees};
use crate::replay::SceneState;
use crate::trace::ContactMsg;

/// One side's contact queries, by `(frame, ball)`: the scene each belongs
/// to (its position among the side's scenes) and the query.
#[derive(Clone, Debug, Default)]
pub(crate) struct SideQueries {
    queries: BTreeMap<(u64, u32), (usize, ContactMsg)>,
    /// Queries that share a `(frame, ball)` with an earlier one (only the
    /// first is compared).
    pub(crate) duplicates: u64,
}

impl SideQueries {
    /// A query of the scene at `scene` (the number of scenes before it,
    /// less one).
    pub(crate) fn add(&mut self, scene: usize, query: ContactMsg) {
        match self.queries.entry((query.frame, query.ball)) {
            std::collections::btree_map::Entry::Vacant(e) => {
                e.insert((scene, query));
            }
            std::collections::btree_map::Entry::Occupied(_) => self.duplicates += 1,
        }
    }

    /// Whether there is no query.
    pub(crate) fn is_empty(&self) -> bool {
        self.queries.is_empty()
    }

    /// The core's contact set of each query, against its scene.
    fn sets(
        &self,
        scenes: &[std::sync::Arc<SceneState>],
        sides: Sides,
    ) -> BTreeMap<(u64, u32), Vec<Contact>> {
        self.queries
            .iter()
            .filter_map(|(key, (scene, q))| {
                let scene = scenes.get(*scene)?;
                let query = ContactQuery {
                    centre: q.centre.into(),
                    radius: q.radius,
                    distance: q.distance,
                };
                Some((*key, contact_set(&scene.mesh, &query, sides)))
            })
            .collect()
    }
}

/// One contact of a set, as the report shows it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactLine {
    /// The triangle.
    pub triangle: u32,
    /// `face`, `edge N` or `vertex N`.
    pub feature: String,
    /// The closest point.
    pub point: [f64; 3],
    /// The separation.
    pub separation: f64,
    /// The geometric normal.
    pub normal: [f64; 3],
}

impl From<&Contact> for ContactLine {
    fn from(c: &Contact) -> Self {
        ContactLine {
            triangle: c.triangle,
            feature: c.feature.to_string(),
            point: c.point.into(),
            separation: c.separation,
            normal: c.normal.into(),
        }
    }
}

/// The first contact query whose sets differ.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactDifference {
    /// Frame.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// The first difference, in words.
    pub what: String,
    /// Side A's contact set.
    pub a: Vec<ContactLine>,
    /// Side B's contact set.
    pub b: Vec<ContactLine>,
}

/// The comparison of two sides' contact queries (`contacts` in `diff`'s
/// JSON, absent when neither side has a query).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ContactDiff {
    /// Queries on both sides.
    pub compared: u64,
    /// Queries whose contact sets agree.
    pub same: u64,
    /// Queries whose contact sets differ.
    pub different: u64,
    /// Queries only in A.
    pub only_in_a: u64,
    /// Queries only in B.
    pub only_in_b: u64,
    /// The first differing query (in frame, then ball order).
    pub first: Option<ContactDifference>,
    /// The first query on one side only: `(frame, ball, side)`.
    pub first_unmatched: Option<(u64, u32, char)>,
}

impl ContactDiff {
    /// Whether the two sides agree on every query.
    pub fn is_same(&self) -> bool {
        self.different == 0 && self.only_in_a == 0 && self.only_in_b == 0
    }
}

/// Where two contact sets of one query first differ, in words; `None`
/// when they agree within `tolerances` (positions and separations within
/// the contact tolerance, normals within the normal tolerance).
fn set_difference(a: &[Contact], b: &[Contact], tolerances: &Tolerances) -> Option<String> {
    let mut triangles: Vec<u32> = a.iter().chain(b).map(|c| c.triangle).collect();
    triangles.sort_unstable();
    triangles.dedup();
    for t in triangles {
        let (ca, cb) = (
            a.iter().find(|c| c.triangle == t),
            b.iter().find(|c| c.triangle == t),
        );
        let (ca, cb) = match (ca, cb) {
            (Some(ca), Some(cb)) => (ca, cb),
            (Some(c), None) | (None, Some(c)) => {
                let (has, lacks) = if b.iter().any(|x| x.triangle == t) {
                    ('B', 'A')
                } else {
                    ('A', 'B')
                };
                return Some(format!(
                    "triangle {t} ({}, separation {}) is a contact in {has}, not in {lacks}",
                    c.feature,
                    num(c.separation)
                ));
            }
            (None, None) => continue,
        };
        if ca.feature != cb.feature {
            return Some(format!(
                "triangle {t}: {} in A, {} in B",
                ca.feature, cb.feature
            ));
        }
        if !within((ca.separation - cb.separation).abs(), tolerances.contact) {
            return Some(format!(
                "triangle {t}: separation {} in A, {} in B",
                num(ca.separation),
                num(cb.separation)
            ));
        }
        let apart = (ca.point - cb.point).norm();
        if !within(apart, tolerances.contact) {
            return Some(format!(
                "triangle {t}: the closest points are {} apart",
                num(apart)
            ));
        }
        let degrees = angle_degrees(ca.normal.into(), cb.normal.into()).unwrap_or(f64::NAN);
        if !within(degrees, tolerances.normal_degrees) {
            return Some(format!("triangle {t}: the normals are {degrees:.3}° apart"));
        }
    }
    None
}

/// Keeps in `first` the earliest `(frame, ball, side)` of what is on one
/// side only (`diff`'s sweeps and contact queries alike).
pub(crate) fn note_unmatched(first: &mut Option<(u64, u32, char)>, key: (u64, u32), side: char) {
    if first.is_none_or(|(f, b, _)| key < (f, b)) {
        *first = Some((key.0, key.1, side));
    }
}

/// `x ≤ tolerance`, false for NaN.
fn within(x: f64, tolerance: f64) -> bool {
    x <= tolerance
}

/// Compares the contact queries of two sides (each with its scenes and
/// `sides` convention); `None` when neither has a query.
pub(crate) fn diff_contacts(
    a: (&SideQueries, &[std::sync::Arc<SceneState>], Sides),
    b: (&SideQueries, &[std::sync::Arc<SceneState>], Sides),
    tolerances: &Tolerances,
) -> Option<ContactDiff> {
    if a.0.is_empty() && b.0.is_empty() {
        return None;
    }
    let (sets_a, sets_b) = (a.0.sets(a.1, a.2), b.0.sets(b.1, b.2));
    let mut report = ContactDiff::default();
    for (key, set_a) in &sets_a {
        let Some(set_b) = sets_b.get(key) else {
            report.only_in_a += 1;
            note_unmatched(&mut report.first_unmatched, *key, 'A');
            continue;
        };
        report.compared += 1;
        match set_difference(set_a, set_b, tolerances) {
            None => report.same += 1,
            Some(what) => {
                report.different += 1;
                if report.first.is_none() {
                    report.first = Some(ContactDifference {
                        frame: key.0,
                        ball: key.1,
                        what,
                        a: set_a.iter().map(ContactLine::from).collect(),
                        b: set_b.iter().map(ContactLine::from).collect(),
                    });
                }
            }
        }
    }
    for key in sets_b.keys() {
        if !sets_a.contains_key(key) {
            report.only_in_b += 1;
            note_unmatched(&mut report.first_unmatched, *key, 'B');
        }
    }
    Some(report)
}

/// The contact queries' part of `diff`'s text.
pub(crate) fn write_contact_diff(s: &mut String, c: &ContactDiff) {
    let queries = crate::numbers::counted(c.compared, "contact query", "contact queries");
    if c.is_same() {
        let _ = writeln!(s, "contacts: {queries}, the same contact sets");
        return;
    }
    let _ = writeln!(
        s,
        "contacts: {} of {queries} {}; {} only in A, {} only in B",
        c.different,
        crate::numbers::verb(c.different, "differs", "differ"),
        c.only_in_a,
        c.only_in_b
    );
    if let Some(f) = &c.first {
        let _ = writeln!(
            s,
            "first contact difference: frame {}, ball {}: {}",
            f.frame, f.ball, f.what
        );
        for (side, set) in [("A", &f.a), ("B", &f.b)] {
            if set.is_empty() {
                let _ = writeln!(s, "  {side}: no contact");
            }
            for l in set {
                let _ = writeln!(
                    s,
                    "  {side}: triangle {} ({}) at ({}, {}, {}), separation {}",
                    l.triangle,
                    l.feature,
                    num(l.point[0]),
                    num(l.point[1]),
                    num(l.point[2]),
                    num(l.separation)
                );
            }
        }
    }
    if let Some((frame, ball, side)) = c.first_unmatched {
        let _ = writeln!(
            s,
            "first contact query on one side only: frame {frame}, ball {ball}, in {side}"
        );
    }
}
