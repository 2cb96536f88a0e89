//! Tunnels: a ball whose centre went through a triangle from its front to
//! its back (or through a flipped triangle either way), during a sweep or
//! between two sweeps of the same ball, and the mesh defect it went through
//! when one lies within `ρ` of where it crossed (see SEMANTICS.md,
//! "Tunnelling", and [`crate::core::crossing::first_crossing_with_flipped`]).

use std::collections::HashMap;

use nalgebra::Point3;
use serde::Serialize;

use crate::core::crossing::{Crossing, first_crossing_with_flipped};
use crate::core::explain::num;
use crate::core::topology::{Defect, DefectKind, Topology};
use crate::core::{Mesh, Outcome, Sweep};

/// Where a tunnel happened.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Serialize,
    strum::IntoStaticStr,
    strum::Display,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum TunnelKind {
    /// The centre's path during the sweep, from `p0` to where the replayed
    /// outcome stops the ball (`p0 + α d`; `p1` for a miss), crosses a
    /// triangle front to back: the collision tests let it through (for
    /// example a start within `ρ` of the plane, which the face test ignores).
    DuringSweep,
    /// The jump from where the ball's previous sweep stopped it to this
    /// sweep's `p0` crosses a triangle front to back: the engine's response
    /// moved the ball through the surface.
    BetweenSweeps,
}

impl TunnelKind {
    /// `during_sweep` or `between_sweeps`.
    pub fn as_str(self) -> &'static str {
        self.into()
    }
}

/// The mesh defect a tunnel went through: the one nearest where the centre
/// crossed, within the ball's `ρ` (one that changes collisions first; see
/// [`Topology::defect_near`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Through {
    /// The defect's kind (`flipped`, `crack`, ...), as `mesh --json` names it.
    pub kind: DefectKind,
    /// Its triangles (input indices), as `mesh --json` lists them.
    pub triangles: Vec<u32>,
    /// Its vertices (input indices).
    pub vertices: Vec<u32>,
    /// Where it is (as `mesh` gives it).
    pub position: [f64; 3],
    /// From the crossing point to the defect's triangles, edges or vertices.
    pub distance: f64,
    /// In words: `the flipped triangle 812`, `the crack between triangles
    /// 40 and 41`.
    pub text: String,
}

impl Through {
    fn new(defect: &Defect, distance: f64) -> Through {
        Through {
            kind: defect.kind,
            triangles: defect.triangles.clone(),
            vertices: defect.vertices.clone(),
            position: defect.position,
            distance,
            text: through_words(defect),
        }
    }
}

/// A defect as the object of "through": `the flipped triangle 812`.
fn through_words(d: &Defect) -> String {
    let t = |i: usize| d.triangles.get(i).map_or("?".into(), u32::to_string);
    let v = |i: usize| d.vertices.get(i).map_or("?".into(), u32::to_string);
    match d.kind {
        DefectKind::Flipped => format!("the flipped triangle {}", t(0)),
        DefectKind::Crack => format!("the crack between triangles {} and {}", t(0), t(1)),
        DefectKind::TJunction => format!(
            "the T-junction at vertex {} on an edge of triangle {}",
            v(0),
            t(0)
        ),
        DefectKind::Degenerate => format!("the degenerate triangle {}", t(0)),
        DefectKind::Sliver => format!("the sliver triangle {}", t(0)),
        DefectKind::DuplicateTriangle => {
            format!("the duplicate triangles {} and {}", t(0), t(1))
        }
        DefectKind::DuplicateVertex => {
            format!("the nearly coincident vertices {} and {}", v(0), v(1))
        }
        DefectKind::NonManifoldEdge => format!(
            "the non-manifold edge {}-{} ({} triangles)",
            v(0),
            v(1),
            d.triangles.len()
        ),
    }
}

/// A ball's centre through a triangle, front to back (or a flipped triangle
/// back to front).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Tunnel {
    /// During the sweep or between sweeps.
    pub kind: TunnelKind,
    /// Input index of the triangle crossed (the lowest of those crossed at
    /// the same point, e.g. at a shared edge).
    pub triangle: u32,
    /// Where the centre crossed the triangle's plane.
    pub point: [f64; 3],
    /// Fraction of the segment `from → to` at `point`.
    pub fraction: f64,
    /// Start of the segment that crossed: `p0` during a sweep, where the
    /// previous sweep stopped the ball between sweeps.
    pub from: [f64; 3],
    /// End of the segment: where the outcome stops the ball (`p0 + α d`)
    /// during a sweep, this sweep's `p0` between sweeps.
    pub to: [f64; 3],
    /// Between sweeps: the frame of the ball's previous sweep.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub previous_frame: Option<u64>,
    /// The crossing went from the triangle's back to its front: the
    /// triangle is flipped and the ball came from the side its neighbours
    /// face. Only in the JSON when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub back_to_front: bool,
    /// The mesh defect within `ρ` of [`Tunnel::point`], if any. Only in the
    /// JSON when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub through: Option<Through>,
}

impl Tunnel {
    /// The tunnel in words, after `frame F, ball B: ` (see
    /// [`crate::replay::TunnelAt`]): `through triangle T during its sweep
    /// at (x, y, z)` (or `between its sweeps of frames P and F`, `frame`
    /// being this sweep's), with `(back to front)` after the triangle for
    /// a flipped one crossed that way and `, through the flipped triangle
    /// 812` (the defect within ρ) at the end.
    pub fn sentence(&self, frame: Option<u64>) -> String {
        let mut s = format!("through triangle {} ", self.triangle);
        if self.back_to_front {
            s.push_str("(back to front) ");
        }
        match (self.kind, self.previous_frame, frame) {
            (TunnelKind::DuringSweep, _, _) => s.push_str("during its sweep"),
            (TunnelKind::BetweenSweeps, Some(p), Some(f)) => {
                s.push_str(&format!("between its sweeps of frames {p} and {f}"));
            }
            (TunnelKind::BetweenSweeps, Some(p), None) => {
                s.push_str(&format!("since its sweep of frame {p}"));
            }
            (TunnelKind::BetweenSweeps, None, _) => s.push_str("between sweeps"),
        }
        let [x, y, z] = self.point;
        s.push_str(&format!(" at ({}, {}, {})", num(x), num(y), num(z)));
        if let Some(through) = &self.through {
            s.push_str(&format!(", through {}", through.text));
        }
        s
    }
}

/// What a tunnel is judged against: the scene's mesh, its topology (the
/// flipped triangles, crossed either way, and the defects a tunnel names)
/// and the ball's detection radius `ρ`.
#[derive(Clone, Copy, Debug)]
pub struct TunnelScene<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Its topology.
    pub topology: &'a Topology,
    /// The detection radius `ρ = r − ε` of the ball: a defect that close to
    /// the crossing point is named.
    pub rho: f64,
}

impl TunnelScene<'_> {
    /// The first crossing of `p → q` (flipped triangles either way).
    fn crossing(&self, p: &Point3<f64>, q: &Point3<f64>) -> Option<Crossing> {
        first_crossing_with_flipped(self.mesh, self.topology.flipped(), p, q)
    }

    /// Every defect within `ρ` of the centre's path `from → to`: what the
    /// ball reached on its way, nearest first (see
    /// [`Topology::defects_along`]).
    pub fn within_reach(&self, from: &Point3<f64>, to: &Point3<f64>) -> Vec<Through> {
        if self.topology.defects().is_empty() {
            return Vec::new();
        }
        self.topology
            .defects_along(self.mesh.vertices(), from, to, self.radius())
            .into_iter()
            .map(|(defect, distance)| Through::new(defect, distance))
            .collect()
    }

    /// `ρ`, or 0 when it is not a finite number ≥ 0.
    fn radius(&self) -> f64 {
        if self.rho.is_finite() {
            self.rho.max(0.0)
        } else {
            0.0
        }
    }

    /// The defect within `ρ` of `point`, if any.
    fn through(&self, point: &Point3<f64>) -> Option<Through> {
        if self.topology.defects().is_empty() {
            return None;
        }
        let (_, defect) = self
            .topology
            .defect_near(self.mesh.vertices(), point, self.radius())?;
        Some(Through::new(
            defect,
            defect.distance(self.mesh.vertices(), point),
        ))
    }

    fn tunnel(
        &self,
        kind: TunnelKind,
        c: Crossing,
        from: Point3<f64>,
        to: Point3<f64>,
        previous_frame: Option<u64>,
    ) -> Tunnel {
        Tunnel {
            kind,
            triangle: c.triangle,
            point: c.point.into(),
            fraction: c.fraction,
            from: from.into(),
            to: to.into(),
            previous_frame,
            back_to_front: c.back_to_front,
            through: self.through(&c.point),
        }
    }
}

/// Where the outcome leaves the ball at the end of its sweep: `p0 + α d`,
/// or exactly `p1` when `α = 1`.
pub fn sweep_end(sweep: &Sweep, outcome: &Outcome) -> Point3<f64> {
    if outcome.travelled() >= 1.0 {
        sweep.p1
    } else {
        sweep.p0 + (sweep.p1 - sweep.p0) * outcome.travelled()
    }
}

/// The tunnel during one sweep, if its centre's path up to where the
/// outcome stops it crosses a triangle of the scene's mesh front to back
/// (or a flipped one back to front).
pub fn tunnel_during_sweep(
    scene: &TunnelScene<'_>,
    sweep: &Sweep,
    outcome: &Outcome,
) -> Option<Tunnel> {
    let end = sweep_end(sweep, outcome);
    scene
        .crossing(&sweep.p0, &end)
        .map(|c| scene.tunnel(TunnelKind::DuringSweep, c, sweep.p0, end, None))
}

/// The defects within `ρ` of the centre's path during one sweep, from `p0`
/// to where the outcome stops it ([`sweep_end`]): what the ball reached,
/// nearest first. A tunnel's [`Tunnel::through`] is the one of these
/// nearest its crossing point.
pub fn defects_within_reach(
    scene: &TunnelScene<'_>,
    sweep: &Sweep,
    outcome: &Outcome,
) -> Vec<Through> {
    scene.within_reach(&sweep.p0, &sweep_end(sweep, outcome))
}

/// Where a ball's previous sweep left it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BallEnd {
    frame: u64,
    scene: usize,
    position: Point3<f64>,
}

/// The per-ball memory the between-sweeps check needs: where each ball's
/// last replayed sweep left it (one entry per ball).
#[derive(Clone, Debug, Default)]
pub(crate) struct BallEnds {
    ends: HashMap<u32, BallEnd>,
}

impl BallEnds {
    /// The tunnel of the jump from where `ball`'s previous sweep (against
    /// the same scene, number `scene`) left it to `p0`, if it crosses a
    /// triangle of `tunnel_scene`'s mesh front to back (or a flipped one
    /// back to front).
    pub(crate) fn jump(
        &self,
        ball: u32,
        scene: usize,
        tunnel_scene: &TunnelScene<'_>,
        p0: &Point3<f64>,
    ) -> Option<Tunnel> {
        let prev = self.ends.get(&ball).filter(|e| e.scene == scene)?;
        tunnel_scene.crossing(&prev.position, p0).map(|c| {
            tunnel_scene.tunnel(
                TunnelKind::BetweenSweeps,
                c,
                prev.position,
                *p0,
                Some(prev.frame),
            )
        })
    }

    /// Remembers where `ball`'s sweep of `frame` left it.
    pub(crate) fn set(&mut self, ball: u32, frame: u64, scene: usize, position: Point3<f64>) {
        self.ends.insert(
            ball,
            BallEnd {
                frame,
                scene,
                position,
            },
        );
    }

    /// Forgets `ball` (a sweep of it was not replayed, so the next jump is
    /// unknown).
    pub(crate) fn forget(&mut self, ball: u32) {
        self.ends.remove(&ball);
    }

    /// Forgets every ball (a new scene).
    pub(crate) fn clear(&mut self) {
        self.ends.clear();
    }
}
