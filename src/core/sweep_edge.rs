//! The edge test, in the edge's standard frame (the algorithm of the CS121
//! edge collision notes that SEMANTICS.md follows).

use super::mesh::Triangle;
use super::options::{Facing, PARALLEL_TOLERANCE};
use super::path::SweptPath;
use super::quadratic;
use super::record::{EdgeRecord, Verdict};

/// Runs the edge test of SEMANTICS.md on edge `edge` (0..3) of `triangle`.
#[inline]
pub fn sweep_edge(triangle: &Triangle, edge: u8, path: &SweptPath, facing: Facing) -> EdgeRecord {
    let frame = triangle.edges[edge as usize];
    let p0_in_edge = frame.to_edge(&path.p0);
    let p1_in_edge = frame.to_edge(&path.p1);
    let (x0, y0, z0) = (p0_in_edge.x, p0_in_edge.y, p0_in_edge.z);
    let (x1, y1, z1) = (p1_in_edge.x, p1_in_edge.y, p1_in_edge.z);
    let dy = y1 - y0;
    let dz = z1 - z0;
    let a = dy * dy + dz * dz;
    let b = 2.0 * (y0 * dy + z0 * dz);
    let c = y0 * y0 + z0 * z0 - path.rho * path.rho;
    // B² - 4AC without cancellation: in the (y, z) plane, m = (y0, z0) and
    // d = (dy, dz), so |d × m|² = (y0 dz - z0 dy)².
    let w = y0 * dz - z0 * dy;
    let discriminant = quadratic::discriminant_from_cross(a, path.rho, w * w);
    let normal_dot_d = triangle.normal.dot(&path.d);
    let mut record = EdgeRecord {
        triangle: triangle.index,
        edge,
        frame,
        length: frame.length,
        p0_in_edge,
        p1_in_edge,
        a,
        b,
        c,
        discriminant,
        roots: None,
        xc: None,
        normal_dot_d,
        back: triangle.back,
        verdict: Verdict::Hit,
    };
    let parallel_limit = PARALLEL_TOLERANCE * path.length;
    record.verdict = if a <= parallel_limit * parallel_limit {
        Verdict::Parallel
    } else {
        // `solve` answers `None` for a negative (or NaN) discriminant.
        record.roots = quadratic::solve(a, b, c, discriminant);
        match quadratic::first_contact(record.roots) {
            Err(verdict) => verdict,
            Ok(s0) => {
                let xc = x0 + s0 * (x1 - x0);
                record.xc = Some(xc);
                // On the edge, ends included, up to the tie distance
                // (see TIE_WINDOW_ULPS).
                let tolerance = path.tie_distance();
                if xc < -tolerance || xc > frame.length + tolerance {
                    Verdict::OffEdge
                } else if !facing.allows(normal_dot_d) {
                    Verdict::BackFacing
                } else {
                    Verdict::Hit
                }
            }
        }
    };
    record
}
