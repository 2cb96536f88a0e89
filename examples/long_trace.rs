//! Writes a long generated trace, for measuring replay throughput and
//! memory on traces of any length (nothing this big is kept in the
//! repository).
//!
//! ```text
//! cargo run --release --example long_trace -- OUT.mcap SWEEPS [SEED]
//! ```
//!
//! The scene is the built-in terrain (`scenes::terrain(32)`, 2,048
//! triangles); 8 balls of radius 0.25 wander over it, one sweep each per
//! frame, starting up to 0.6 above the ground and moving up to 0.3 sideways
//! and 0.5 down, so that some sweeps hit and most do not. Seeded: the same
//! arguments give the same file.
//!
//! Each sweep starts at a new random place, so the balls jump between
//! sweeps and often start within ρ of the ground: replaying it reports many
//! tunnels, on purpose (it measures the work, not a plausible engine).

use std::io::{Seek, Write};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sweeptrace::core::Facing;
use sweeptrace::sim::scenes;
use sweeptrace::{SceneMsg, SweepMsg, TraceError, TraceWriter};

/// Balls per frame.
pub const BALLS: u32 = 8;

/// Writes a trace of `sweeps` sweeps to `w` (see the module documentation).
pub fn write_long_trace<W: Write + Seek>(w: W, sweeps: u64, seed: u64) -> Result<W, TraceError> {
    let terrain = scenes::terrain(32);
    let mut out = TraceWriter::new(w)?;
    out.scene(
        0,
        &SceneMsg {
            name: Some(terrain.name),
            vertices: terrain.vertices,
            triangles: terrain.triangles,
            margin: 0.0,
            facing: Facing::NonStrict,
        },
    )?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (lo, hi) = bounds(&scenes::terrain(32).vertices);
    for i in 0..sweeps {
        let frame = i / BALLS as u64;
        let ball = (i % BALLS as u64) as u32;
        let x = rng.random_range(lo[0]..hi[0]);
        let y = rng.random_range(lo[1]..hi[1]);
        let z = scenes::terrain_height(x, y) + rng.random_range(0.0..0.6);
        let p0 = [x, y, z];
        let p1 = [
            x + rng.random_range(-0.3..0.3),
            y + rng.random_range(-0.3..0.3),
            z - rng.random_range(0.0..0.5),
        ];
        out.sweep(
            1_000_000 * (frame + 1),
            &SweepMsg {
                frame,
                ball,
                radius: 0.25,
                p0,
                p1,
            },
        )?;
    }
    out.finish()
}

fn bounds(vertices: &[[f64; 3]]) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for v in vertices {
        for k in 0..2 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, sweeps, rest @ ..] = args.as_slice() else {
        return Err("usage: long_trace OUT.mcap SWEEPS [SEED]".into());
    };
    let sweeps: u64 = sweeps.parse()?;
    let seed: u64 = rest.first().map(|s| s.parse()).transpose()?.unwrap_or(1);
    let file = std::io::BufWriter::new(std::fs::File::create(out)?);
    write_long_trace(file, sweeps, seed)?.flush()?;
    eprintln!("wrote {sweeps} sweeps to {out}");
    Ok(())
}
