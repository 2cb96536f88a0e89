//! Tunnels: a ball whose centre went through a triangle from its front to
//! its back, during a sweep or between two sweeps of the same ball (see
//! SEMANTICS.md, "Tunnelling", and [`crate::core::first_crossing`]).

use std::collections::HashMap;

use nalgebra::Point3;
use serde::Serialize;

use crate::core::{Crossing, Mesh, Outcome, Sweep, first_crossing};

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

/// A ball's centre through a triangle, front to back.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
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
}

impl Tunnel {
    fn new(
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
/// outcome stops it crosses a triangle of `mesh` front to back.
pub fn tunnel_during_sweep(mesh: &Mesh, sweep: &Sweep, outcome: &Outcome) -> Option<Tunnel> {
    let end = sweep_end(sweep, outcome);
    first_crossing(mesh, &sweep.p0, &end)
        .map(|c| Tunnel::new(TunnelKind::DuringSweep, c, sweep.p0, end, None))
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
    /// the same scene) left it to `p0`, if it crosses a triangle of `mesh`
    /// front to back.
    pub(crate) fn jump(
        &self,
        ball: u32,
        scene: usize,
        mesh: &Mesh,
        p0: &Point3<f64>,
    ) -> Option<Tunnel> {
        let prev = self.ends.get(&ball).filter(|e| e.scene == scene)?;
        first_crossing(mesh, &prev.position, p0).map(|c| {
            Tunnel::new(
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
