//! The mesh sweep: every test of every candidate triangle, combined into one
//! outcome by the rules of SEMANTICS.md.

use nalgebra::{Point3, Vector3};
use serde::Serialize;

use super::error::SweepError;
use super::mesh::{Mesh, Triangle};
use super::options::{Options, SIMULTANEOUS_TOLERANCE};
use super::path::{Path, Sweep};
use super::record::{Kind, NoObserver, Observer, TestRecord, Verdict};
use super::sweep_edge::sweep_edge;
use super::sweep_face::sweep_face;
use super::sweep_vertex::sweep_vertex;

/// The result of one sweep.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Outcome {
    /// Fraction of the path travelled at first contact; 1 when nothing is hit.
    pub alpha: f64,
    /// Kind of the primary collision.
    pub kind: Kind,
    /// Input index of the primary triangle.
    pub triangle: Option<u32>,
    /// Feature of the primary collision: the edge or vertex index (0..3)
    /// within its triangle; `None` for a face (a face has no feature) and
    /// when nothing is hit.
    pub feature: Option<u8>,
    /// The reported normal: the primary triangle's front normal, or the
    /// normalised average of the front normals of every triangle colliding
    /// within [`SIMULTANEOUS_TOLERANCE`] of `alpha`.
    pub normal: Option<Vector3<f64>>,
    /// The point of the mesh the ball touches at `alpha`.
    pub contact: Option<Point3<f64>>,
}

impl Outcome {
    /// The outcome of a sweep that touches nothing.
    pub const NONE: Outcome = Outcome {
        alpha: 1.0,
        kind: Kind::None,
        triangle: None,
        feature: None,
        normal: None,
        contact: None,
    };

    /// Whether something was hit.
    pub fn is_hit(&self) -> bool {
        self.kind != Kind::None
    }

    /// Whether `record` is the test that reported this outcome's primary
    /// collision (a hit on the same triangle, kind and feature).
    pub fn is_reported_by(&self, record: &TestRecord) -> bool {
        record.alpha().is_some()
            && Some(record.triangle()) == self.triangle
            && record.kind() == self.kind
            && record.reported_feature() == self.feature
    }
}

/// How the candidate triangles are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Broadphase {
    /// Only triangles whose grown bounding boxes the path enters, nearest
    /// first, stopping past the best hit (the default).
    Bvh,
    /// Every triangle of the mesh.
    Exhaustive,
}

/// The best collision of one triangle.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    alpha: f64,
    kind: Kind,
    feature: u8,
    contact: Point3<f64>,
}

impl Candidate {
    #[inline]
    fn better_than(&self, other: &Candidate) -> bool {
        (self.alpha, self.kind, self.feature) < (other.alpha, other.kind, other.feature)
    }
}

/// Runs the seven tests of one triangle; returns its best collision.
#[inline]
fn test_triangle<O: Observer>(
    triangle: &Triangle,
    path: &Path,
    options: &Options,
    observer: &mut O,
) -> Option<Candidate> {
    let facing = options.facing;
    let mut best: Option<Candidate> = None;
    let mut offer = |c: Candidate| {
        if best.as_ref().is_none_or(|b| c.better_than(b)) {
            best = Some(c);
        }
    };
    let face = sweep_face(triangle, path, facing);
    observer.face(&face);
    if face.verdict == Verdict::Hit {
        offer(Candidate {
            alpha: face.beta.unwrap_or(1.0),
            kind: Kind::Face,
            feature: 0,
            contact: face.touch.unwrap_or(triangle.vertices[0]),
        });
    }
    for e in 0..3u8 {
        let r = sweep_edge(triangle, e, path, facing);
        observer.edge(&r);
        if r.verdict == Verdict::Hit {
            let s0 = r.roots.map_or(1.0, |x| x.0);
            let xc = r.xc.unwrap_or(0.0);
            offer(Candidate {
                alpha: s0,
                kind: Kind::Edge,
                feature: e,
                contact: r.frame.to_world(&Point3::new(xc, 0.0, 0.0)),
            });
        }
    }
    for v in 0..3u8 {
        let r = sweep_vertex(triangle, v, path, facing);
        observer.vertex(&r);
        if r.verdict == Verdict::Hit {
            offer(Candidate {
                alpha: r.roots.map_or(1.0, |x| x.0),
                kind: Kind::Vertex,
                feature: v,
                contact: r.position,
            });
        }
    }
    best
}

const WINDOW: usize = 32;

/// Combines triangle results: the primary collision and the triangles that
/// collide simultaneously with it. Allocates nothing.
struct Combiner {
    best: Option<(Candidate, u32, usize)>,
    /// `(alpha, position)` of triangles that may be within the tolerance.
    window: [(f64, u32); WINDOW],
    len: usize,
    overflow: bool,
}

impl Combiner {
    fn new() -> Self {
        Combiner {
            best: None,
            window: [(0.0, 0); WINDOW],
            len: 0,
            overflow: false,
        }
    }

    fn best_alpha(&self) -> f64 {
        self.best.as_ref().map_or(1.0, |b| b.0.alpha)
    }

    #[inline]
    fn add(&mut self, c: Candidate, triangle_index: u32, position: usize) {
        let replace = match &self.best {
            None => true,
            Some((b, bi, _)) => {
                (c.alpha, c.kind, triangle_index, c.feature) < (b.alpha, b.kind, *bi, b.feature)
            }
        };
        if replace {
            self.best = Some((c, triangle_index, position));
        }
        let limit = self.best_alpha() + SIMULTANEOUS_TOLERANCE;
        if c.alpha <= limit {
            if replace {
                // Drop entries the new minimum pushed out of the window.
                let mut k = 0;
                for i in 0..self.len {
                    if self.window[i].0 <= limit {
                        self.window[k] = self.window[i];
                        k += 1;
                    }
                }
                self.len = k;
            }
            if self.len < WINDOW {
                self.window[self.len] = (c.alpha, position as u32);
                self.len += 1;
            } else {
                self.overflow = true;
            }
        }
    }
}

/// The fast query: the outcome of `sweep` against `mesh`, using the BVH.
/// Allocates nothing.
pub fn sweep_mesh(mesh: &Mesh, sweep: &Sweep, options: &Options) -> Result<Outcome, SweepError> {
    sweep_mesh_with(mesh, sweep, options, Broadphase::Bvh, &mut NoObserver)
}

/// The explained query: like [`sweep_mesh`], and hands the record of every
/// test it runs to `observer` (the tests of every candidate triangle with
/// [`Broadphase::Bvh`], of every triangle with [`Broadphase::Exhaustive`]).
pub fn sweep_mesh_with<O: Observer>(
    mesh: &Mesh,
    sweep: &Sweep,
    options: &Options,
    broadphase: Broadphase,
    observer: &mut O,
) -> Result<Outcome, SweepError> {
    let path = Path::new(sweep, options)?;
    Ok(sweep_path(mesh, &path, options, broadphase, observer))
}

fn visit_triangles<O: Observer>(
    mesh: &Mesh,
    path: &Path,
    options: &Options,
    broadphase: Broadphase,
    observer: &mut O,
    combiner: &mut Combiner,
) {
    let triangles = mesh.triangles();
    let run = |position: usize, combiner: &mut Combiner, observer: &mut O| {
        let t = &triangles[position];
        if !O::WANTS_RECORDS && !options.facing.allows(t.normal.dot(&path.d)) {
            // Every test of a back-facing triangle ends back-facing.
            return;
        }
        if let Some(c) = test_triangle(t, path, options, observer) {
            combiner.add(c, t.index, position);
        }
    };
    match broadphase {
        Broadphase::Exhaustive => {
            for position in 0..triangles.len() {
                run(position, combiner, observer);
            }
        }
        Broadphase::Bvh => {
            let (lo, hi) = mesh.bounds();
            let scale = [
                lo.coords.amax(),
                hi.coords.amax(),
                path.p0.coords.amax(),
                path.p1.coords.amax(),
            ]
            .into_iter()
            .fold(path.rho, f64::max);
            let grow = path.rho + 1e-9 * scale;
            mesh.bvh().traverse(
                &path.p0,
                &path.d,
                grow,
                1.0 + SIMULTANEOUS_TOLERANCE,
                |range| {
                    for position in range {
                        run(position, combiner, observer);
                    }
                    combiner.best_alpha() + SIMULTANEOUS_TOLERANCE
                },
            );
        }
    }
}

fn sweep_path<O: Observer>(
    mesh: &Mesh,
    path: &Path,
    options: &Options,
    broadphase: Broadphase,
    observer: &mut O,
) -> Outcome {
    let mut combiner = Combiner::new();
    visit_triangles(mesh, path, options, broadphase, observer, &mut combiner);
    let Some((best, triangle_index, position)) = combiner.best else {
        return Outcome::NONE;
    };
    let limit = best.alpha + SIMULTANEOUS_TOLERANCE;
    let triangles = mesh.triangles();
    let mut sum = Vector3::zeros();
    if combiner.overflow {
        // More simultaneous triangles than the window holds: a second pass.
        for t in triangles {
            if let Some(c) = test_triangle(t, path, options, &mut NoObserver)
                && c.alpha <= limit
            {
                sum += t.normal;
            }
        }
    } else {
        // Sum in mesh order so the bits do not depend on the traversal order.
        let window = &mut combiner.window[..combiner.len];
        window.sort_unstable_by_key(|w| w.1);
        for &(alpha, position) in window.iter() {
            if alpha <= limit {
                sum += triangles[position as usize].normal;
            }
        }
    }
    let primary_normal = triangles[position].normal;
    let norm = sum.norm();
    let normal = if norm > 1e-9 {
        sum / norm
    } else {
        primary_normal
    };
    Outcome {
        alpha: best.alpha,
        kind: best.kind,
        triangle: Some(triangle_index),
        feature: (best.kind != Kind::Face).then_some(best.feature),
        normal: Some(normal),
        contact: Some(best.contact),
    }
}
