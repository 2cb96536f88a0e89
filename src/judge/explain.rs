//! Why a sweep diverged: the tests that decided the core's outcome, and the
//! tests that would have produced the expected one, with why they did not.

use serde::Serialize;

use crate::core::explain::{describe, label, nearest_miss, num};
use crate::core::record::{CollectRecords, TestRecord, Verdict};
use crate::core::{Broadphase, Kind, Outcome, sweep_mesh_with};
use crate::replay::{SceneState, SweepResult, primary_records};
use crate::trace::OutcomeMsg;

/// The test that would have produced the expected result, and why it did not.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExpectedTest {
    /// `edge 12.1`, `face 3`, ...
    pub test: String,
    /// Its record in words (`explain::describe`), or why there is none.
    pub description: String,
    /// Its verdict, when the test ran.
    pub verdict: Option<Verdict>,
    /// Why it did not decide the sweep, in words.
    pub why_not: String,
    /// The known mistake whose α is the expected one on this test
    /// ([`super::mistakes::KNOWN_MISTAKES`]'s name), if any; `why_not`
    /// says it in words.
    pub mistake: Option<&'static str>,
}

/// Re-runs a sweep with every test recorded (the same core, every triangle
/// of the scene it was swept against).
pub fn explained_records(result: &SweepResult) -> Vec<TestRecord> {
    let mut collect = CollectRecords::default();
    match sweep_mesh_with(
        &result.scene.mesh,
        &result.sweep,
        result.options(),
        Broadphase::Exhaustive,
        &mut collect,
    ) {
        Ok(_) => collect.records,
        Err(_) => Vec::new(),
    }
}

/// The records that decided `outcome`, described: the primary test then the
/// other hits tied with it ([`Outcome::ties_with`]); when nothing is
/// hit, the nearest miss.
pub fn explain_outcome(outcome: &Outcome, records: &[TestRecord]) -> Vec<String> {
    if !outcome.is_hit() {
        return match nearest_miss(records) {
            Some(r) => vec![format!("no test hit; nearest miss: {}", describe(r))],
            None => vec!["no test hit (no triangle was tested)".to_string()],
        };
    }
    let decided = primary_records(outcome, records.to_vec());
    let primary = decided.iter().find(|r| outcome.is_reported_by(r));
    primary
        .map(|r| format!("primary: {}", describe(r)))
        .into_iter()
        .chain(
            decided
                .iter()
                .filter(|r| !outcome.is_reported_by(r))
                .take(8)
                .map(|r| format!("also at this α: {}", describe(r))),
        )
        .collect()
}

/// The path of `result`'s sweep against its scene's mesh, as the core
/// tested it; `None` for an invalid sweep.
fn path_of(result: &SweepResult) -> Option<crate::core::SweptPath> {
    crate::core::SweptPath::against(&result.scene.mesh, &result.sweep, result.options()).ok()
}

/// The initial contacts that decided a hit at `α = 0` under a declared
/// `initial_overlap` (no test of the sweep reports it): the primary then
/// the others tied with it, each with its distance from the start; empty
/// when `result` is no such hit.
pub fn explain_initial(result: &SweepResult) -> Vec<String> {
    let options = result.options();
    let Some(hit) = result.outcome.hit.filter(|h| h.alpha == 0.0) else {
        return Vec::new();
    };
    if options.initial_overlap.is_rules() {
        return Vec::new();
    }
    let Some(path) = path_of(result) else {
        return Vec::new();
    };
    let contacts = crate::core::initial_contacts(&result.scene.mesh, &path, options);
    let name = |h: &crate::core::SweepHit| match h.feature.index() {
        None => format!("face {}", h.triangle),
        Some(f) => format!("{} {}.{f}", h.feature.kind(), h.triangle),
    };
    let mut lines = Vec::new();
    for (i, (c, distance)) in contacts.iter().enumerate() {
        let primary = c.triangle == hit.triangle && c.feature == hit.feature;
        let line = format!(
            "{}initial contact: {} at distance {} < ρ = {} from the start \
             (initial_overlap = {}): a hit at α = 0",
            if primary {
                "primary: "
            } else {
                "also at α = 0: "
            },
            name(c),
            num(*distance),
            num(path.rho),
            options.initial_overlap
        );
        if primary {
            lines.insert(0, line);
        } else if i < 9 {
            lines.push(line);
        }
    }
    lines
}

/// For a test that refused a start within `ρ` (`starts_too_close`,
/// `before_start`) under a declared `initial_overlap`: what that convention
/// makes of the triangle, in words (an initial contact tied at `α = 0`, or
/// why it is none); `None` when no such convention is declared.
pub fn initial_why(result: &SweepResult, test: &ExpectedTest, triangle: u32) -> Option<String> {
    let options = result.options();
    if options.initial_overlap.is_rules()
        || !matches!(
            test.verdict,
            Some(Verdict::StartsTooClose | Verdict::BeforeStart)
        )
    {
        return None;
    }
    let path = path_of(result)?;
    let convention = format!("initial_overlap = {}", options.initial_overlap);
    let contacts = crate::core::initial_contacts(&result.scene.mesh, &path, options);
    Some(
        match contacts.iter().find(|(h, _)| h.triangle == triangle) {
            Some((h, distance)) => format!(
                "the ball starts within ρ of triangle {triangle} (its nearest point, on its {}, \
             at distance {} < ρ = {}): under {convention} an initial contact at α = 0, tied \
             with the core's (the answer is compared with that contact)",
                match h.feature.index() {
                    None => "face".to_string(),
                    Some(f) => format!("{} {f}", h.feature.kind()),
                },
                num(*distance),
                num(path.rho)
            ),
            None => {
                let t = result.scene.mesh.triangle_by_index(triangle)?;
                let (point, _) = crate::core::closest_point(t, &path.p0);
                let distance = (path.p0 - point).norm();
                if distance >= path.rho {
                    format!(
                        "the ball starts {} from triangle {triangle}, not within ρ = {}: under \
                     {convention} no initial contact",
                        num(distance),
                        num(path.rho)
                    )
                } else {
                    format!(
                        "the ball starts within ρ of triangle {triangle} (distance {}) but moves \
                     away from its front, which {convention} does not count as a contact",
                        num(distance)
                    )
                }
            }
        },
    )
}

/// How far from touching, as a fraction of `ρ`, a hit the core does not
/// find may be to be named a limitation ([`limitation`]).
const NEAR_MISS: f64 = 0.01;

/// The largest angle off the surface at which leaving is grazing.
const GRAZING_DEGREES: f64 = 10.0;

/// A hit the core does not find, named when it is one of an engine's known
/// limitations, within 1 % of `ρ` of touching: `a hit past the path's end`
/// (the exact test meets the triangle only beyond `α = 1`), or `a false hit
/// while leaving at a grazing angle` (at the answer's `α` the ball is not
/// within `ρ` of the triangle and moves away from it, less than 10° off
/// its surface); when the core hits later, `an early hit` or `a seam bump`
/// ([`early_hit`]), or a normal off at a touching start
/// ([`normal_at_a_touching_start`]); no hit where the core starts in
/// contact on a path too short to cast ([`too_short_to_cast`]). `None`
/// otherwise.
pub fn limitation(
    result: &SweepResult,
    expected: &OutcomeMsg,
    tests: &[ExpectedTest],
) -> Option<String> {
    if expected.kind == Kind::None {
        return too_short_to_cast(result);
    }
    if let Some(hit) = result.outcome.hit {
        return early_hit(result, expected, hit.alpha)
            .or_else(|| normal_at_a_touching_start(result, expected));
    }
    let triangle = expected.triangle.flatten()?;
    if !(0.0..=1.0).contains(&expected.alpha) {
        return None;
    }
    let path = path_of(result)?;
    let t = result.scene.mesh.triangle_by_index(triangle)?;
    // Only a near miss is named (a gap of at most 1 % of ρ): further off,
    // the answer is some other mistake (a margin ignored, a wrong radius).
    let near = NEAR_MISS * path.rho;
    if tests.iter().any(|t| t.verdict == Some(Verdict::BeyondEnd)) {
        let (point, _) = crate::core::closest_point(t, &path.p1);
        let gap = (path.p1 - point).norm() - path.rho;
        return (0.0..=near).contains(&gap).then(|| {
            format!(
                "a hit past the path's end: the exact test meets triangle {triangle} only \
                 beyond α = 1 (the path ends {} short of touching it), the answer says α = {}",
                num(gap),
                num(expected.alpha)
            )
        });
    }
    grazing(expected, &path, t, triangle).or_else(|| normal_at_a_touching_start(result, expected))
}

/// `a false hit while leaving at a grazing angle` (see [`limitation`]);
/// `None` otherwise (then [`normal_at_a_touching_start`] may name it: a
/// start within 1 % of `ρ` answered with a normal off).
fn grazing(
    expected: &OutcomeMsg,
    path: &crate::core::SweptPath,
    t: &crate::core::mesh::Triangle,
    triangle: u32,
) -> Option<String> {
    let near = NEAR_MISS * path.rho;
    let centre = path.p0 + path.d * expected.alpha;
    let (point, _) = crate::core::closest_point(t, &centre);
    let outward = centre - point;
    let distance = outward.norm();
    let length = path.d.norm();
    if distance == 0.0 || length == 0.0 {
        return None;
    }
    let leaving = path.d.dot(&outward) / (distance * length);
    let angle = leaving.clamp(-1.0, 1.0).asin().to_degrees();
    if leaving <= 0.0
        || distance < path.rho
        || distance - path.rho > near
        || angle > GRAZING_DEGREES
    {
        return None;
    }
    Some(format!(
        "a false hit while leaving at a grazing angle: at the answer's α = {} the ball is {} \
         beyond ρ from triangle {triangle} and moves away from it, {}° off its surface",
        num(expected.alpha),
        num(distance - path.rho),
        num(angle)
    ))
}

/// A hit whose normal is off where the ball starts touching: the start
/// within 1 % of `ρ` of touching the answer's triangle (overlapping or
/// not), the answer's `α` within 1 % of `ρ` of travel, and its normal at
/// least 0.1° from the direction from its own contact to the centre there.
/// A shape cast that starts (nearly) in contact takes its normal from a
/// penetration query (parry's, Rapier's: GJK and EPA), coarser than the
/// geometry. `None` otherwise. Named, it still fails.
fn normal_at_a_touching_start(result: &SweepResult, expected: &OutcomeMsg) -> Option<String> {
    let triangle = expected.triangle.flatten()?;
    let (normal, contact) = (expected.normal.flatten()?, expected.contact.flatten()?);
    let path = path_of(result)?;
    let t = result.scene.mesh.triangle_by_index(triangle)?;
    let near = NEAR_MISS * path.rho;
    let (start_point, _) = crate::core::closest_point(t, &path.p0);
    let start_gap = (path.p0 - start_point).norm() - path.rho;
    if !(start_gap.abs() <= near && (0.0..=1.0).contains(&expected.alpha)) {
        return None;
    }
    if expected.alpha * path.d.norm() > near {
        return None;
    }
    let centre = path.p0 + path.d * expected.alpha;
    let towards = centre - nalgebra::Point3::from(contact);
    let normal = nalgebra::Vector3::from(normal);
    if towards.norm() == 0.0 || normal.norm() == 0.0 {
        return None;
    }
    let angle = towards
        .normalize()
        .dot(&normal.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    (angle >= 0.1).then(|| {
        format!(
            "a normal at a touching start: the ball starts {} {} ρ of triangle {triangle} \
             (within 1 % of ρ) and the answer's normal is {}° from the direction from its \
             contact to the centre; a cast that starts in contact takes its normal from a \
             penetration query, coarser than the geometry",
            num(start_gap.abs()),
            if start_gap < 0.0 { "inside" } else { "beyond" },
            num(angle)
        )
    })
}

/// No hit where the core has a start in contact (`α = 0`) and the path
/// is no longer than single precision's `ε` (2⁻²³ ≈ 1.2e-7, an absolute
/// length): parry's shape casts (Rapier's) return nothing for a cast that
/// short before looking for an overlap (`minkowski_ray_cast`: a ray of
/// length 0 hits nothing), so a ball that starts overlapping and does not
/// move, or moves less than that, is no hit. `None` otherwise.
fn too_short_to_cast(result: &SweepResult) -> Option<String> {
    let hit = result.outcome.hit?;
    let length = path_of(result)?.d.norm();
    (hit.alpha == 0.0 && length <= f64::from(f32::EPSILON)).then(|| {
        format!(
            "no cast for a path too short: the path is {} long, not more than single \
             precision's ε (1.2e-7, a length), and the engine's shape cast returns nothing \
             for such a path, even for a ball that starts in contact (the core: a hit at \
             α = 0 on triangle {})",
            num(length),
            hit.triangle
        )
    })
}

/// An answer that hits before the core does (`core_alpha`), where at the
/// answer's `α` the ball is still beyond `ρ` of the answer's triangle, by at
/// most 1 % of `ρ`: `an early hit`, and `a seam bump` when the answer is at
/// an internal flat or concave edge or vertex (a ball rolling over a seam
/// kicked up).
fn early_hit(result: &SweepResult, expected: &OutcomeMsg, core_alpha: f64) -> Option<String> {
    if !(expected.alpha >= 0.0 && expected.alpha < core_alpha) {
        return None;
    }
    let triangle = expected.triangle.flatten()?;
    let path = path_of(result)?;
    let t = result.scene.mesh.triangle_by_index(triangle)?;
    let centre = path.p0 + path.d * expected.alpha;
    let (point, _) = crate::core::closest_point(t, &centre);
    let gap = (centre - point).norm() - path.rho;
    if !(gap > 0.0 && gap <= NEAR_MISS * path.rho) {
        return None;
    }
    let feature = match (expected.kind, expected.feature.flatten()) {
        (Kind::Edge, Some(i)) => Some(crate::core::Feature::Edge(i)),
        (Kind::Vertex, Some(i)) => Some(crate::core::Feature::Vertex(i)),
        _ => None,
    };
    let seam = feature
        .and_then(|f| crate::replay::feature_class(&result.scene.topology, triangle, f))
        .is_some_and(|c| {
            matches!(
                c,
                crate::core::topology::EdgeClass::Flat | crate::core::topology::EdgeClass::Concave
            )
        });
    Some(format!(
        "{}: at the answer's α = {} the ball is still {} beyond ρ from triangle {triangle}; \
         the core meets the surface at α = {}",
        if seam {
            "a seam bump (an early hit at an internal flat or concave place)"
        } else {
            "an early hit"
        },
        num(expected.alpha),
        num(gap),
        num(core_alpha)
    ))
}

/// The tests that would have produced `expected`, each with why it did not
/// decide the sweep (and, when the expected α is what a known mistake
/// gives on it with the sweep's `rho`, the mistake).
pub fn expected_tests(
    expected: &OutcomeMsg,
    got: &Outcome,
    records: &[TestRecord],
    scene: Option<&SceneState>,
    rho: f64,
) -> Vec<ExpectedTest> {
    if expected.kind == Kind::None {
        return Vec::new();
    }
    let Some(Some(triangle)) = expected.triangle else {
        // Without a triangle every test of that kind could be the one; name
        // the hits of that kind, if any.
        return records
            .iter()
            .filter(|r| r.kind() == expected.kind && r.verdict() == Verdict::Hit)
            .take(3)
            .map(|r| expected_test(r, expected, got, rho))
            .collect();
    };
    let feature = expected.feature.flatten();
    let found: Vec<&TestRecord> = records
        .iter()
        .filter(|r| {
            r.kind() == expected.kind
                && r.triangle() == triangle
                && (expected.kind == Kind::Face
                    || feature.is_none_or(|f| Some(f) == r.feature().index()))
        })
        .collect();
    if found.is_empty() {
        let test = match (expected.kind, feature) {
            (Kind::Face, _) => format!("face {triangle}"),
            (k, Some(f)) => format!("{k} {triangle}.{f}"),
            (k, None) => format!("{k} {triangle}.*"),
        };
        let why = match scene {
            Some(s) if triangle as usize >= s.mesh.input_triangle_count() => format!(
                "triangle {triangle} does not exist: the scene has {}",
                crate::numbers::counted(
                    s.mesh.input_triangle_count() as u64,
                    "triangle",
                    "triangles"
                )
            ),
            Some(s)
                if s.mesh
                    .degenerate()
                    .iter()
                    .any(|d| d.index == triangle as usize) =>
            {
                format!("triangle {triangle} is degenerate and left out of every test")
            }
            _ => "this test did not run".to_string(),
        };
        return vec![ExpectedTest {
            test,
            description: why.clone(),
            verdict: None,
            why_not: why,
            mistake: None,
        }];
    }
    found
        .into_iter()
        .map(|r| expected_test(r, expected, got, rho))
        .collect()
}

fn expected_test(r: &TestRecord, expected: &OutcomeMsg, got: &Outcome, rho: f64) -> ExpectedTest {
    let verdict = r.verdict();
    let decides = got.is_reported_by(r);
    let mistake = super::mistakes::known_mistake(r, rho, expected.alpha);
    let why_not = match r.alpha() {
        None => format!("it reports no collision ({verdict})"),
        Some(a) if decides && a == expected.alpha => format!(
            "it is the test that decides the sweep, at the compared answer's α = {}: \
             only the fields above differ",
            num(a)
        ),
        Some(a) if decides => {
            // In full when the short forms would read the same.
            let (here, there) = match (num(a), num(expected.alpha)) {
                (x, y) if x == y => (a.to_string(), expected.alpha.to_string()),
                short => short,
            };
            match mistake {
                Some(m) => format!(
                    "it is the test that decides the sweep, at α = {here} where the \
                     compared answer has α = {there}: the same test, computed with a \
                     known mistake: {}",
                    m.words
                ),
                None => format!(
                    "it is the test that decides the sweep, at α = {here} where the \
                     compared answer has α = {there}: the same test with other numbers (a \
                     computation less precise than the tolerances, or another margin or \
                     facing rule)"
                ),
            }
        }
        Some(a) if got.is_hit() && !got.ties_with(a) => format!(
            "it hits at α = {}, later than the primary collision at α = {}",
            num(a),
            num(got.travelled())
        ),
        Some(a) if (a - expected.alpha).abs() > 1e-12 && got.is_hit() => format!(
            "it hits at α = {} (the compared answer: α = {}); the primary collision is at α = {}",
            num(a),
            num(expected.alpha),
            num(got.travelled())
        ),
        Some(a) if got.is_hit() => format!(
            "it hits at α = {}, the compared answer's α, tied with the primary test, which the tie \
             order puts first (face < edge < vertex, then lower triangle, then lower feature)",
            num(a)
        ),
        Some(a) => format!("it hits at α = {} but the sweep reports none", num(a)),
    };
    // Where the mistake is not said yet, after the reason.
    let why_not = match mistake {
        Some(m) if !why_not.contains(m.words) => format!(
            "{why_not}; the compared answer's α = {} is what this test gives with a known \
             mistake: {}",
            num(expected.alpha),
            m.words
        ),
        _ => why_not,
    };
    ExpectedTest {
        test: label(r),
        description: describe(r),
        verdict: Some(verdict),
        why_not,
        mistake: mistake.map(|m| m.name),
    }
}
