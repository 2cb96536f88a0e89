//! Built-in scenes: small meshes to try the core on and to record from.

use serde::{Deserialize, Serialize};

use super::SimOptions;

/// A named mesh as plain data (what a trace's `/scene` message holds).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneMesh {
    /// Name of the scene.
    pub name: String,
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Vertex-index triples, counter-clockwise seen from the front.
    pub triangles: Vec<[u64; 3]>,
}

/// The unit cube `[-1, 1]³` as 12 outward-facing triangles.
pub fn cube() -> SceneMesh {
    let mut vertices = Vec::with_capacity(8);
    for i in 0..8 {
        let c = |bit: usize| if i & bit != 0 { 1.0 } else { -1.0 };
        vertices.push([c(1), c(2), c(4)]);
    }
    // Vertex index = x + 2y + 4z with bits set for +1.
    let quads: [[u64; 4]; 6] = [
        [1, 3, 7, 5], // +x
        [0, 4, 6, 2], // -x
        [2, 6, 7, 3], // +y
        [0, 1, 5, 4], // -y
        [4, 5, 7, 6], // +z
        [0, 2, 3, 1], // -z
    ];
    let mut triangles = Vec::with_capacity(12);
    for [a, b, c, d] in quads {
        triangles.push([a, b, c]);
        triangles.push([a, c, d]);
    }
    SceneMesh {
        name: "cube".into(),
        vertices,
        triangles,
    }
}

/// The triangle `(0,0,0), (4,0,0), (0,4,0)` of SEMANTICS.md's worked
/// examples, front normal `+z`.
pub fn triangle() -> SceneMesh {
    SceneMesh {
        name: "triangle".into(),
        vertices: vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    }
}

/// The built-in scenes: one definition of their names, meshes and the
/// simulation parameters `record` uses for them.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    strum::EnumIter,
    strum::IntoStaticStr,
    strum::EnumString,
    strum::Display,
)]
#[strum(serialize_all = "snake_case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[cfg_attr(feature = "cli", clap(rename_all = "snake_case"))]
pub enum BuiltinScene {
    /// The cube `[-1, 1]³`, 12 outward triangles.
    Cube,
    /// `(0,0,0), (4,0,0), (0,4,0)`, front `+z` (SEMANTICS.md's examples).
    Triangle,
    /// A mini-golf hole: tee, ramp with a drop, walls, a cup.
    MiniGolf,
    /// A bowl seen from inside.
    Bowl,
    /// A closed box, faces inward.
    #[strum(serialize = "box")]
    #[cfg_attr(feature = "cli", value(name = "box"))]
    Box,
    /// A height-field terrain (100,352 triangles at its default size).
    Terrain,
}

impl BuiltinScene {
    /// Every built-in scene, in the order `--help` lists them.
    pub fn all() -> impl Iterator<Item = BuiltinScene> {
        <BuiltinScene as strum::IntoEnumIterator>::iter()
    }

    /// The scene's name (`mini_golf`, `box`, ...).
    pub fn name(self) -> &'static str {
        self.into()
    }

    /// The scene named `name`, if it is built in.
    pub fn from_name(name: &str) -> Option<BuiltinScene> {
        name.parse().ok()
    }

    /// The names of every built-in scene, comma-separated (for messages).
    pub fn names() -> String {
        Self::all()
            .map(BuiltinScene::name)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The scene's mesh; the terrain at its default size
    /// ([`TERRAIN_DEFAULT_CELLS`]).
    pub fn mesh(self) -> SceneMesh {
        self.mesh_with_terrain_cells(TERRAIN_DEFAULT_CELLS)
    }

    /// The scene's mesh, the terrain with `terrain_cells` cells a side.
    pub fn mesh_with_terrain_cells(self, terrain_cells: usize) -> SceneMesh {
        match self {
            BuiltinScene::Cube => cube(),
            BuiltinScene::Triangle => triangle(),
            BuiltinScene::MiniGolf => mini_golf(),
            BuiltinScene::Bowl => bowl(),
            BuiltinScene::Box => closed_box(),
            BuiltinScene::Terrain => terrain(terrain_cells),
        }
    }

    /// Simulation parameters chosen so that the scene's recording shows
    /// face, edge and vertex collisions and misses where the scene allows.
    pub fn sim_options(self) -> SimOptions {
        let base = SimOptions::default();
        match self {
            // Ball 0 dropped onto the corner (1, 1, 1) (a vertex hit), the
            // others around it: edge and face hits, then falls off the cube.
            BuiltinScene::Cube => SimOptions {
                radius: 0.25,
                position: [1.05, 1.05, 2.5],
                velocity: [0.0, 0.0, 0.0],
                balls: 6,
                position_jitter: 0.5,
                velocity_jitter: 0.2,
                frames: 150,
                ..base
            },
            BuiltinScene::Triangle => SimOptions {
                radius: 0.5,
                position: [1.0, 1.0, 3.0],
                velocity: [0.5, 0.5, 0.0],
                balls: 3,
                position_jitter: 1.0,
                velocity_jitter: 0.5,
                frames: 150,
                ..base
            },
            // Putted from the tee up the ramp, over its drop, toward the cup.
            BuiltinScene::MiniGolf => SimOptions {
                radius: 0.1,
                position: [1.0, 2.0, 0.2],
                velocity: [3.0, 0.4, 0.0],
                balls: 8,
                position_jitter: 1.2,
                velocity_jitter: 3.0,
                frames: 600,
                restitution: 0.6,
                ..base
            },
            // Released on the rim with a sideways push: it circles the bowl.
            BuiltinScene::Bowl => SimOptions {
                radius: 0.2,
                position: [1.5, 0.0, 1.0],
                velocity: [0.0, 2.5, 1.0],
                balls: 8,
                position_jitter: 0.3,
                velocity_jitter: 1.5,
                frames: 400,
                restitution: 0.7,
                ..base
            },
            // Thrown across the box: bounces off every wall.
            BuiltinScene::Box => SimOptions {
                radius: 0.3,
                position: [0.0, 0.0, 0.5],
                velocity: [3.0, 2.0, 4.0],
                balls: 3,
                position_jitter: 0.8,
                velocity_jitter: 2.0,
                frames: 300,
                restitution: 0.9,
                ..base
            },
            // Boulders thrown onto the hills: they roll and hop over crests.
            BuiltinScene::Terrain => SimOptions {
                radius: 0.8,
                position: [0.0, 0.0, 4.0],
                velocity: [5.0, 2.0, 3.0],
                balls: 8,
                position_jitter: 10.0,
                velocity_jitter: 3.0,
                frames: 400,
                restitution: 0.5,
                ..base
            },
        }
    }
}

/// Builds a scene from quads and triangles, orienting each triangle so that
/// its front normal points to the side the ball plays on.
#[derive(Default)]
struct Builder {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u64; 3]>,
}

impl Builder {
    fn vertex(&mut self, p: [f64; 3]) -> u64 {
        self.vertices.push(p);
        (self.vertices.len() - 1) as u64
    }

    /// Adds the triangle `(a, b, c)`, flipped if needed so that its front
    /// normal has a positive component along `toward`.
    fn triangle(&mut self, [a, b, c]: [u64; 3], toward: [f64; 3]) {
        let [pa, pb, pc] = [a, b, c].map(|i| self.vertices[i as usize]);
        let u = sub(pb, pa);
        let v = sub(pc, pa);
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let dot = n[0] * toward[0] + n[1] * toward[1] + n[2] * toward[2];
        self.triangles
            .push(if dot >= 0.0 { [a, b, c] } else { [a, c, b] });
    }

    /// Adds the planar quad `a b c d` (in order around it) as two triangles
    /// facing `toward`.
    fn quad(&mut self, corners: [[f64; 3]; 4], toward: [f64; 3]) {
        let [a, b, c, d] = corners.map(|p| self.vertex(p));
        self.triangle([a, b, c], toward);
        self.triangle([a, c, d], toward);
    }

    fn finish(self, name: &str) -> SceneMesh {
        SceneMesh {
            name: name.into(),
            vertices: self.vertices,
            triangles: self.triangles,
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

const UP: [f64; 3] = [0.0, 0.0, 1.0];

/// Size of the mini-golf green: `[0, 12] × [0, 4]` at `z = 0`.
pub const GREEN: [f64; 2] = [12.0, 4.0];

/// A mini-golf hole (`+z` up): the green `[0, 12] × [0, 4]` at `z = 0`,
/// walls 0.4 high around it, a ramp rising along `+x` from `x = 3` to a
/// 0.25-high drop at `x = 5.5` (for `1 ≤ y ≤ 3`), and a square cup 0.6 wide
/// and 0.4 deep centred on `(10, 2)`. Every triangle faces the side the ball
/// plays on: the green and the ramp up, the walls toward the green, the
/// ramp's sides and drop outward, the cup's walls toward its axis and its
/// bottom up. The walls are cut where the green's grid lines meet them, so
/// that green and walls share their edges. 56 triangles.
pub fn mini_golf() -> SceneMesh {
    let [length, width] = GREEN;
    let wall = 0.4;
    let (cup_x, cup_y, cup_half, cup_depth) = (10.0, 2.0, 0.3, 0.4);
    let mut b = Builder::default();

    // The green: a 3 × 3 grid of quads around the cup, the centre cell left open.
    let xs = [0.0, cup_x - cup_half, cup_x + cup_half, length];
    let ys = [0.0, cup_y - cup_half, cup_y + cup_half, width];
    let mut grid = [[0u64; 4]; 4];
    for (i, &x) in xs.iter().enumerate() {
        for (j, &y) in ys.iter().enumerate() {
            grid[i][j] = b.vertex([x, y, 0.0]);
        }
    }
    for i in 0..3 {
        for j in 0..3 {
            if i == 1 && j == 1 {
                continue;
            }
            b.triangle([grid[i][j], grid[i + 1][j], grid[i + 1][j + 1]], UP);
            b.triangle([grid[i][j], grid[i + 1][j + 1], grid[i][j + 1]], UP);
        }
    }

    // The cup: four walls facing its axis, and a bottom facing up.
    let (x0, x1, y0, y1, z) = (
        cup_x - cup_half,
        cup_x + cup_half,
        cup_y - cup_half,
        cup_y + cup_half,
        -cup_depth,
    );
    b.quad(
        [[x0, y0, 0.0], [x0, y1, 0.0], [x0, y1, z], [x0, y0, z]],
        [1.0, 0.0, 0.0],
    );
    b.quad(
        [[x1, y0, 0.0], [x1, y1, 0.0], [x1, y1, z], [x1, y0, z]],
        [-1.0, 0.0, 0.0],
    );
    b.quad(
        [[x0, y0, 0.0], [x1, y0, 0.0], [x1, y0, z], [x0, y0, z]],
        [0.0, 1.0, 0.0],
    );
    b.quad(
        [[x0, y1, 0.0], [x1, y1, 0.0], [x1, y1, z], [x0, y1, z]],
        [0.0, -1.0, 0.0],
    );
    b.quad([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], UP);

    // The walls around the green, facing it, each cut where a grid line of
    // the green meets it, so that the green and the walls share their
    // edges (no vertex of the green on the interior of a wall's edge: a
    // T-junction, where a ball meets two boundary edges instead of one
    // concave edge).
    for (x, toward) in [(0.0, [1.0, 0.0, 0.0]), (length, [-1.0, 0.0, 0.0])] {
        for y in ys.windows(2) {
            b.quad(
                [
                    [x, y[0], 0.0],
                    [x, y[1], 0.0],
                    [x, y[1], wall],
                    [x, y[0], wall],
                ],
                toward,
            );
        }
    }
    for (y, toward) in [(0.0, [0.0, 1.0, 0.0]), (width, [0.0, -1.0, 0.0])] {
        for x in xs.windows(2) {
            b.quad(
                [
                    [x[0], y, 0.0],
                    [x[1], y, 0.0],
                    [x[1], y, wall],
                    [x[0], y, wall],
                ],
                toward,
            );
        }
    }

    // The ramp: a wedge standing on the green, its slope facing up and
    // back toward the tee, its sides and its drop facing outward.
    let (rx0, rx1, ry0, ry1, rh) = (3.0, 5.5, 1.0, 3.0, 0.25);
    b.quad(
        [
            [rx0, ry0, 0.0],
            [rx1, ry0, rh],
            [rx1, ry1, rh],
            [rx0, ry1, 0.0],
        ],
        [-rh, 0.0, rx1 - rx0],
    );
    b.quad(
        [
            [rx1, ry0, 0.0],
            [rx1, ry1, 0.0],
            [rx1, ry1, rh],
            [rx1, ry0, rh],
        ],
        [1.0, 0.0, 0.0],
    );
    for (y, toward) in [(ry0, [0.0, -1.0, 0.0]), (ry1, [0.0, 1.0, 0.0])] {
        let a = b.vertex([rx0, y, 0.0]);
        let c = b.vertex([rx1, y, 0.0]);
        let d = b.vertex([rx1, y, rh]);
        b.triangle([a, c, d], toward);
    }
    b.finish("mini_golf")
}

/// Half-width of the bowl: the paraboloid covers `[-2, 2]²`.
pub const BOWL_HALF_WIDTH: f64 = 2.0;

/// A bowl: the paraboloid `z = (x² + y²) / 4` over `[-2, 2]²` as a
/// 16 × 16 grid (512 triangles), every triangle facing up, into the bowl.
pub fn bowl() -> SceneMesh {
    let cells = 16;
    let h = BOWL_HALF_WIDTH;
    height_field("bowl", cells, h, |x, y| (x * x + y * y) / 4.0)
}

/// Half-width of the closed box: it is `[-2, 2]³`.
pub const BOX_HALF_WIDTH: f64 = 2.0;

/// A closed box `[-2, 2]³` seen from inside: each face a 2 × 2 grid of
/// quads (48 triangles), every triangle facing inward, toward the centre.
pub fn closed_box() -> SceneMesh {
    let h = BOX_HALF_WIDTH;
    let mut b = Builder::default();
    let steps = [-h, 0.0, h];
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [-h, h] {
            let mut toward = [0.0; 3];
            toward[axis] = -side;
            for i in 0..2 {
                for j in 0..2 {
                    let corner = |a: f64, c: f64| {
                        let mut p = [0.0; 3];
                        p[axis] = side;
                        p[u] = a;
                        p[v] = c;
                        p
                    };
                    b.quad(
                        [
                            corner(steps[i], steps[j]),
                            corner(steps[i + 1], steps[j]),
                            corner(steps[i + 1], steps[j + 1]),
                            corner(steps[i], steps[j + 1]),
                        ],
                        toward,
                    );
                }
            }
        }
    }
    b.finish("box")
}

/// Cells per side of the default terrain: 224² cells, 100,352 triangles.
pub const TERRAIN_DEFAULT_CELLS: usize = 224;
/// Largest terrain [`terrain`] builds (cells per side): 4096² cells,
/// about 33.5 million triangles.
pub const TERRAIN_MAX_CELLS: usize = 4096;
/// Half-width of the terrain: it covers `[-50, 50]²` whatever its resolution.
pub const TERRAIN_HALF_WIDTH: f64 = 50.0;

/// Height of the terrain at `(x, y)`: a sum of sines, at most 2.5 in
/// absolute value.
pub fn terrain_height(x: f64, y: f64) -> f64 {
    1.2 * det_sin(0.21 * x + 0.4) * det_sin(0.17 * y - 0.3)
        + 0.8 * det_sin(0.53 * x + 0.37 * y)
        + 0.35 * det_sin(1.3 * x - 0.9 * y + 1.0)
        + 0.15 * det_sin(2.9 * y + 0.5 * x)
}

/// A terrain height field over `[-50, 50]²`: `cells × cells` square cells
/// (clamped to `1 ..= TERRAIN_MAX_CELLS`), two triangles each, heights from
/// [`terrain_height`], every triangle facing up. `cells = 224` gives 100,352
/// triangles.
pub fn terrain(cells: usize) -> SceneMesh {
    let cells = cells.clamp(1, TERRAIN_MAX_CELLS);
    height_field("terrain", cells, TERRAIN_HALF_WIDTH, terrain_height)
}

/// A square height field over `[-half, half]²` with `cells × cells` cells,
/// split along alternating diagonals, every triangle facing up.
fn height_field(
    name: &str,
    cells: usize,
    half: f64,
    height: impl Fn(f64, f64) -> f64,
) -> SceneMesh {
    let n = cells + 1;
    let step = 2.0 * half / cells as f64;
    let mut vertices = Vec::with_capacity(n * n);
    for j in 0..n {
        let y = if j == cells {
            half
        } else {
            -half + j as f64 * step
        };
        for i in 0..n {
            let x = if i == cells {
                half
            } else {
                -half + i as f64 * step
            };
            vertices.push([x, y, height(x, y)]);
        }
    }
    let mut triangles = Vec::with_capacity(2 * cells * cells);
    let at = |i: usize, j: usize| (j * n + i) as u64;
    for j in 0..cells {
        for i in 0..cells {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Counter-clockwise seen from above: front normals point up.
            if (i + j) % 2 == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    SceneMesh {
        name: name.into(),
        vertices,
        triangles,
    }
}

/// `sin(x)` from additions and multiplications only (range reduction and a
/// degree-15 Taylor polynomial, error below 1e-9), so that scenes built
/// from it are bit-identical on every platform, whatever its `libm`.
pub fn det_sin(x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    if !x.is_finite() {
        return 0.0;
    }
    let mut r = x - (x / TAU).round() * TAU; // [-π, π]
    if r > FRAC_PI_2 {
        r = PI - r;
    } else if r < -FRAC_PI_2 {
        r = -PI - r;
    }
    let r2 = r * r;
    let mut term = r;
    let mut sum = r;
    for k in 1..8 {
        let k = k as f64;
        term *= -r2 / ((2.0 * k) * (2.0 * k + 1.0));
        sum += term;
    }
    sum
}

impl SceneMesh {
    /// Builds the collision mesh.
    pub fn to_mesh(&self) -> Result<crate::core::Mesh, crate::core::MeshError> {
        crate::core::Mesh::new(self.vertices.clone(), &self.triangles)
    }
}
