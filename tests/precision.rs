//! Single precision in the judgement, against an independent single-
//! precision computation: the core's answers for inputs rounded to `f32`
//! (what an exact engine fed `f32` coordinates answers) are accepted at
//! `precision = "f32"` and mostly refused at `f64`; the same answers with
//! `α` moved by ten times the sweep's reported bound are refused. Seeded
//! random sweeps over a bumpy height field (faces, edges and vertices hit),
//! and sweeps that graze an edge, where the first-order bound is infinite
//! and the bound grows as the square root of the budget.

use anyhow::ensure;
use libtest_mimic::Trial;
use rand::{Rng, SeedableRng};
use sweeptrace::conventions::{EngineConventions, Precision};
use sweeptrace::judge::Tolerances;
use sweeptrace::judge::precision::{F32_OPERATIONS, Sensitivity};
use sweeptrace::replay::ReplayEvent;
use sweeptrace::trace::{OutcomeMsg, SceneMsg, SweepMsg, TraceReader, TraceWriter};
use sweeptrace::{Agreement, Facing, Mesh, Options, ReplayOptions, Sweep};

use crate::trial;

pub fn tests() -> Vec<Trial> {
    vec![
        trial!(answers_for_inputs_rounded_to_f32_are_accepted_at_f32),
        trial!(alpha_moved_by_ten_bounds_is_refused_at_f32),
        trial!(grazing_edge_contacts_have_finite_square_root_bounds),
        trial!(face_answers_bent_off_the_triangle_are_refused_at_f32),
        trial!(a_perturbation_does_not_spend_the_f32_budget_twice),
        trial!(a_small_bias_shows_in_the_balance_of_later_and_earlier),
        trial!(a_touching_start_answered_as_a_hit_is_judged_by_the_hit_rounding_gives),
        trial!(a_tie_member_is_held_to_its_own_bound),
    ]
}

/// A 6 × 6 height field with bumps, fronts up, in coordinates around 1000
/// (so that `f32` rounding is visible).
fn terrain() -> SceneMsg {
    let n = 7;
    let mut vertices = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (1000.0 + f64::from(i), 1000.0 + f64::from(j));
            vertices.push([x, y, 0.3 * (x * 1.3).sin() * (y * 0.7).cos()]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..(n - 1) as u64 {
        for i in 0..(n - 1) as u64 {
            let a = j * n as u64 + i;
            triangles.push([a, a + 1, a + n as u64 + 1]);
            triangles.push([a, a + n as u64 + 1, a + n as u64]);
        }
    }
    SceneMsg {
        name: Some("bumps".into()),
        vertices,
        triangles,
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

/// `x` rounded to the nearest `f32`.
fn f32_of(x: f64) -> f64 {
    f64::from(x as f32)
}

/// Seeded sweeps falling onto the terrain at assorted angles.
fn sweeps(count: u64) -> Vec<SweepMsg> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(32);
    (0..count)
        .map(|frame| {
            let x = 1000.0 + rng.random_range(1.0..5.0);
            let y = 1000.0 + rng.random_range(1.0..5.0);
            let p0 = [x, y, rng.random_range(0.8..2.0)];
            let p1 = [
                x + rng.random_range(-1.0..1.0),
                y + rng.random_range(-1.0..1.0),
                rng.random_range(-1.5..0.0),
            ];
            SweepMsg {
                frame,
                ball: 0,
                radius: 0.25,
                p0,
                p1,
            }
        })
        .collect()
}

/// The answer of an exact engine fed `f32` inputs: the core's outcome for
/// the scene and the sweep with every coordinate rounded to `f32`.
fn f32_answer(scene: &SceneMsg, s: &SweepMsg) -> anyhow::Result<OutcomeMsg> {
    let round = |p: [f64; 3]| p.map(f32_of);
    let vertices: Vec<[f64; 3]> = scene.vertices.iter().copied().map(round).collect();
    let mesh = Mesh::new(vertices, &scene.triangles)?;
    let sweep = Sweep::new(round(s.p0), round(s.p1), f32_of(s.radius));
    let o = sweeptrace::sweep_mesh(&mesh, &sweep, &Options::default())?;
    Ok(OutcomeMsg::from_outcome(s.frame, s.ball, &o))
}

/// The replayed results of `sweeps` over `scene`, each with `answer` of it
/// as its expectation.
fn results(
    scene: &SceneMsg,
    sweeps: &[SweepMsg],
    answer: impl Fn(&SweepMsg) -> anyhow::Result<OutcomeMsg>,
) -> anyhow::Result<Vec<sweeptrace::replay::SweepResult>> {
    results_at(Precision::F32, scene, sweeps, answer)
}

/// [`results`] replayed (and so judged) at `precision`.
fn results_at(
    precision: Precision,
    scene: &SceneMsg,
    sweeps: &[SweepMsg],
    answer: impl Fn(&SweepMsg) -> anyhow::Result<OutcomeMsg>,
) -> anyhow::Result<Vec<sweeptrace::replay::SweepResult>> {
    let mut w = TraceWriter::new(std::io::Cursor::new(Vec::new()))?;
    w.scene(0, scene)?;
    for s in sweeps {
        let t = 1_000 * (s.frame + 1);
        w.sweep(t, s)?;
        w.expected(t, &answer(s)?)?;
    }
    let bytes = w.finish()?.into_inner();
    let mut out = Vec::new();
    for event in sweeptrace::replay_events(
        TraceReader::new(bytes.as_slice(), "precision.mcap"),
        at(precision),
    ) {
        if let ReplayEvent::Sweep(r) = event? {
            out.push(*r);
        }
    }
    Ok(out)
}

/// A replay under the rules but for the arithmetic: its results are
/// judged at `precision`.
fn at(precision: Precision) -> ReplayOptions {
    ReplayOptions {
        conventions: EngineConventions {
            precision,
            ..EngineConventions::default()
        },
        ..ReplayOptions::default()
    }
}

fn answers_for_inputs_rounded_to_f32_are_accepted_at_f32() -> anyhow::Result<()> {
    let scene = terrain();
    let sweeps = sweeps(400);
    let results = results(&scene, &sweeps, |s| f32_answer(&scene, s))?;
    let results_at_f64 = results_at(Precision::F64, &scene, &sweeps, |s| f32_answer(&scene, s))?;
    let (mut hits, mut refused_at_f64, mut refused_at_f32) = (0, 0, Vec::new());
    for (r, r64) in results.iter().zip(&results_at_f64) {
        let expected = r.expected.expect("every sweep has its answer");
        hits += u32::from(r.outcome.is_hit());
        if sweeptrace::agreement(&expected, r64, &Tolerances::default()).fails(false) {
            refused_at_f64 += 1;
        }
        if sweeptrace::agreement(&expected, r, &Tolerances::default()).fails(false) {
            refused_at_f32.push(r.frame);
        }
    }
    ensure!(hits > 300, "{hits} hits: the sweeps must reach the terrain");
    // The rounding is visible at the fixed tolerances...
    ensure!(refused_at_f64 > 50, "only {refused_at_f64} refused at f64");
    // ...and every one of those answers is within single precision.
    ensure!(
        refused_at_f32.is_empty(),
        "refused at f32: frames {refused_at_f32:?}"
    );
    Ok(())
}

fn alpha_moved_by_ten_bounds_is_refused_at_f32() -> anyhow::Result<()> {
    let scene = terrain();
    let sweeps = sweeps(400);
    let exact = results(&scene, &sweeps, |s| f32_answer(&scene, s))?;
    let (mut tried, mut refused) = (0, 0);
    for r in &exact {
        let Some(s) = Sensitivity::of(r) else {
            continue;
        };
        let Some(hit) = r.outcome.hit else { continue };
        let bound = s.bounds(F32_OPERATIONS).alpha;
        // Only where ten bounds keep α inside [0, 1] (and the sweep away
        // from a grazing contact, where the bound is the whole path).
        let moved = hit.alpha + 10.0 * bound;
        if !(moved <= 1.0 && bound < 0.01) {
            continue;
        }
        let mut expected = r.expected.expect("every sweep has its answer");
        expected.alpha = moved;
        tried += 1;
        let agreement = sweeptrace::agreement(&expected, r, &Tolerances::default());
        if agreement.fails(false) {
            refused += 1;
        } else {
            ensure!(
                !matches!(agreement, Agreement::Precision { .. }),
                "frame {}: α moved by 10 bounds ({bound}) is called rounding",
                r.frame
            );
        }
    }
    ensure!(tried > 200, "only {tried} sweeps tried");
    ensure!(refused == tried, "{refused} of {tried} refused");
    Ok(())
}

/// One triangle in the plane `z = 0` (front up) whose edge from
/// `(1000, 995)` to `(1000, 1005)` faces `+x`.
fn edge_scene() -> SceneMsg {
    SceneMsg {
        name: Some("edge".into()),
        vertices: vec![
            [1000.0, 995.0, 0.0],
            [1000.0, 1005.0, 0.0],
            [990.0, 1000.0, 0.0],
        ],
        triangles: vec![[0, 1, 2]],
        margin: 0.0,
        facing: Facing::NonStrict,
    }
}

/// Sweeps moving in `-x` over the edge at heights `ρ (1 − t)`, `t` from
/// 10⁻⁹ to 10⁻², so that the edge is met ever more tangentially (the
/// double root of the edge's quadratic at `t = 0`).
fn grazing_sweeps() -> Vec<SweepMsg> {
    let rho = 0.25;
    (0..64u64)
        .map(|frame| {
            let t = 10f64.powf(-9.0 + 7.0 * frame as f64 / 63.0);
            let h = rho * (1.0 - t);
            let y = 999.0 + 0.03 * frame as f64;
            SweepMsg {
                frame,
                ball: 0,
                radius: rho,
                p0: [1002.0, y, h],
                p1: [998.0, y, h],
            }
        })
        .collect()
}

fn grazing_edge_contacts_have_finite_square_root_bounds() -> anyhow::Result<()> {
    let scene = edge_scene();
    let sweeps = grazing_sweeps();
    let results = results(&scene, &sweeps, |s| f32_answer(&scene, s))?;
    let f32_tol = Tolerances::default();
    let (mut edge_hits, mut refused, mut moved_refused) = (0, Vec::new(), 0);
    for r in &results {
        let Some(hit) = r.outcome.hit else { continue };
        ensure!(
            hit.feature.kind() == sweeptrace::Kind::Edge,
            "frame {}: {:?} instead of the edge",
            r.frame,
            hit.feature
        );
        edge_hits += 1;
        let s = Sensitivity::of(r).expect("a hit has a sensitivity");
        let bound = s.bounds(F32_OPERATIONS).alpha;
        // Finite, and never more than the square-root growth allows: at
        // most √(2ρε + ε²) + 2ε/3 over |d⊥| with ε = 3 · 16 · δ.
        let eps = 3.0 * F32_OPERATIONS * s.unit;
        let ceiling = ((2.0 * 0.25 * eps + eps * eps).sqrt() + 2.0 * eps / 3.0) / 4.0;
        ensure!(
            bound.is_finite() && bound <= ceiling * (1.0 + 1e-9) + 1e-12,
            "frame {}: bound {bound} above the tangent ceiling {ceiling}",
            r.frame
        );
        let expected = r.expected.expect("every sweep has its answer");
        if sweeptrace::agreement(&expected, r, &f32_tol).fails(false) {
            refused.push(r.frame);
        }
        let mut moved = expected;
        moved.alpha = hit.alpha + 10.0 * bound;
        if moved.alpha <= 1.0 && sweeptrace::agreement(&moved, r, &f32_tol).fails(false) {
            moved_refused += 1;
        }
    }
    ensure!(edge_hits > 50, "only {edge_hits} edge hits");
    ensure!(
        refused.is_empty(),
        "f32-rounded answers refused at frames {refused:?}"
    );
    ensure!(
        moved_refused == edge_hits,
        "α moved by ten bounds refused on {moved_refused} of {edge_hits} grazing hits"
    );
    Ok(())
}

/// Issue 42's first three defects, seeded into an exact engine fed `f32`
/// inputs (whose plain answers all pass, above): on every face hit, the
/// normal tilted by 1°, the normal of length 0.5, or the contact put off
/// the triangle's plane by twice its f32 bound along the normal (`6 · c ·
/// δ`; around 1000 the inputs' own rounding is `δ ≈ 6e-5`), which is
/// inside the old bound (a sphere) where α's bound is wide. A face normal is the
/// triangle's whatever `α` is, a normal is a unit vector, and uncertainty
/// in `α` slides a contact within the plane, never off it: each of them
/// is refused on every face hit, the sweep's f32 bound however wide, and
/// the divergence names what is wrong.
fn face_answers_bent_off_the_triangle_are_refused_at_f32() -> anyhow::Result<()> {
    let scene = terrain();
    let sweeps = sweeps(400);
    let exact = results(&scene, &sweeps, |s| f32_answer(&scene, s))?;
    type Bend = fn(&mut OutcomeMsg, f64);
    let bends: [(&str, Bend, &str); 3] = [
        (
            "normal tilted by 1°",
            |o, _| {
                let n = o.normal.flatten().expect("a hit has a normal");
                let (c, s) = (1f64.to_radians().cos(), 1f64.to_radians().sin());
                // About the x axis (the terrain's normals are near +z).
                o.normal = Some(Some([n[0], c * n[1] - s * n[2], s * n[1] + c * n[2]]));
            },
            "angle",
        ),
        (
            "normal of length 0.5",
            |o, _| {
                let n = o.normal.flatten().expect("a hit has a normal");
                o.normal = Some(Some(n.map(|x| 0.5 * x)));
            },
            "not a unit vector",
        ),
        (
            "contact off the plane by twice its bound",
            |o, along| {
                let n = o.normal.flatten().expect("a hit has a normal");
                let c = o.contact.flatten().expect("a hit has a contact");
                o.contact = Some(Some([0, 1, 2].map(|i| c[i] + 2.0 * along * n[i])));
            },
            "off the triangle's plane",
        ),
    ];
    for (what, bend, named) in bends {
        let (mut tried, mut inside_the_sphere, mut passed) = (0, 0, Vec::new());
        for r in &exact {
            let Some(hit) = r.outcome.hit else { continue };
            let mut answer = r.expected.expect("every sweep has its answer");
            if hit.feature != sweeptrace::Feature::Face || answer.kind != sweeptrace::Kind::Face {
                continue;
            }
            let bounds = Sensitivity::of(r).expect("a hit").bounds(F32_OPERATIONS);
            // The bound a sphere around the contact gave before.
            inside_the_sphere += u32::from(2.0 * bounds.contact_along_normal < bounds.contact);
            bend(&mut answer, bounds.contact_along_normal);
            tried += 1;
            match sweeptrace::agreement(&answer, r, &Tolerances::default()) {
                Agreement::Diverges {
                    fields,
                    reproduced: None,
                    ..
                } => {
                    let words: String = fields.iter().filter_map(|f| f.detail.clone()).collect();
                    ensure!(words.contains(named), "{what}, frame {}: {words}", r.frame);
                }
                other => passed.push((r.frame, other)),
            }
        }
        ensure!(tried > 100, "{what}: only {tried} face hits");
        // Where the sweep's bound on α is wide, the old bound (a sphere
        // around the contact) held the bent contact: those sweeps failed
        // nothing before.
        ensure!(inside_the_sphere > 0, "{inside_the_sphere} of {tried}");
        ensure!(
            passed.is_empty(),
            "{what}: {} of {tried} pass: {:?}",
            passed.len(),
            passed.first()
        );
    }
    Ok(())
}

/// Issue 42's fourth defect, its own repro: mini golf frame 55, ball 1, an
/// answer backed off by a skin of 1e-3 along the path. `|Δα|` is beyond
/// the sweep's bound at the whole budget of 16 units; before, a
/// perturbation of 8 units plus the bound widened by 16 more excused it
/// ("rounding explains it"). A perturbation leaves only the rest of the
/// budget for the widening.
fn a_perturbation_does_not_spend_the_f32_budget_twice() -> anyhow::Result<()> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("traces/record_mini_golf.mcap");
    let file = std::fs::File::open(&path)?;
    let mut found = None;
    for event in sweeptrace::replay_events(
        TraceReader::new(std::io::BufReader::new(file), "record_mini_golf.mcap"),
        at(Precision::F32),
    ) {
        if let ReplayEvent::Sweep(r) = event?
            && r.frame == 55
            && r.ball == 1
        {
            found = Some(*r);
            break;
        }
    }
    let r = found.ok_or_else(|| anyhow::anyhow!("no frame 55, ball 1"))?;
    let hit = r
        .outcome
        .hit
        .ok_or_else(|| anyhow::anyhow!("frame 55, ball 1 misses"))?;
    let d = r.sweep.p1 - r.sweep.p0;
    let mut answer = OutcomeMsg::from_outcome(55, 1, &r.outcome);
    answer.alpha = hit.alpha - 1e-3 / d.norm();
    let bound = Sensitivity::of(&r)
        .expect("a hit")
        .bounds(F32_OPERATIONS)
        .alpha;
    ensure!(
        (hit.alpha - answer.alpha) > bound,
        "the skin ({}) must be beyond the bound ({bound})",
        hit.alpha - answer.alpha
    );
    let agreement = sweeptrace::agreement(&answer, &r, &Tolerances::default());
    ensure!(
        matches!(
            agreement,
            Agreement::Diverges {
                reproduced: None,
                ..
            }
        ),
        "the skin passes: {agreement:?}"
    );
    // The answer's α as an exact engine fed f32 inputs gives it passes.
    let mut rounded = answer;
    rounded.alpha = hit.alpha + 0.5 * bound / F32_OPERATIONS;
    ensure!(
        !sweeptrace::agreement(&rounded, &r, &Tolerances::default()).fails(false),
        "half a unit's move fails"
    );
    Ok(())
}

/// Issue 42: a bias too small for any one sweep's bound (every α a tenth
/// of its own f32 bound late) passes sweep by sweep, and shows in the
/// report's balance of later and earlier α: lopsided beyond chance, where
/// the exact engine fed f32 inputs is not. The p99 of the backward errors
/// is reported beside the largest.
fn a_small_bias_shows_in_the_balance_of_later_and_earlier() -> anyhow::Result<()> {
    let scene = terrain();
    let sweeps = sweeps(400);
    let check = |late: bool| -> anyhow::Result<sweeptrace::TraceReport> {
        let mut w = TraceWriter::new(std::io::Cursor::new(Vec::new()))?;
        w.scene(0, &scene)?;
        let exact = results(&scene, &sweeps, |s| f32_answer(&scene, s))?;
        for (s, r) in sweeps.iter().zip(&exact) {
            let t = 1_000 * (s.frame + 1);
            w.sweep(t, s)?;
            let mut answer = r.expected.expect("every sweep has its answer");
            if late && let (Some(hit), Some(sens)) = (r.outcome.hit, Sensitivity::of(r)) {
                answer.alpha = (hit.alpha + 0.1 * sens.bounds(F32_OPERATIONS).alpha).min(1.0);
            }
            w.expected(t, &answer)?;
        }
        let bytes = w.finish()?.into_inner();
        let options = sweeptrace::CheckOptions {
            replay: at(Precision::F32),
            ..sweeptrace::CheckOptions::default()
        };
        Ok(sweeptrace::check_reader(
            bytes.as_slice(),
            "bias.mcap",
            &options,
        ))
    };
    let fair = check(false)?;
    let biased = check(true)?;
    for (what, r) in [("fair", &fair), ("biased", &biased)] {
        ensure!(
            r.status() == sweeptrace::Status::Ok,
            "{what}: every sweep is within its bound: {}",
            sweeptrace::suite::render_text(r)
        );
    }
    let (f, b) = (
        fair.within_precision.clone().expect("an f32 report"),
        biased.within_precision.clone().expect("an f32 report"),
    );
    ensure!(
        !f.lopsided(),
        "fair: {} later, {} earlier",
        f.alpha_later,
        f.alpha_earlier
    );
    ensure!(
        b.lopsided() && b.alpha_later > 10 * b.alpha_earlier.max(1),
        "biased: {} later, {} earlier",
        b.alpha_later,
        b.alpha_earlier
    );
    ensure!(
        sweeptrace::suite::render_text(&biased).contains("lopsided beyond chance"),
        "the report says so"
    );
    ensure!(
        b.p99_backward_error > 0.0 && b.p99_backward_error <= b.max_backward_error,
        "p99 {} max {}",
        b.p99_backward_error,
        b.max_backward_error
    );
    Ok(())
}

/// Issues 42 and 47: a ball that starts touching a face (its centre at ρ
/// from the plane, to a few f32 units) and moves away, answered as a hit at
/// α = 0 under `initial_overlap = "alpha0_always"` (Rapier's
/// stopAtPenetration). The core misses (the start is not within ρ); a
/// move of the radius by a unit gives the hit. The engine's contact is
/// judged within that hit's bound, not the fixed 1e-6 (which failed every
/// such answer on its contact's last digits); the seeded bugs still fail:
/// a contact 1 % of ρ off, and a hit for a ball 1 % of ρ away.
fn a_touching_start_answered_as_a_hit_is_judged_by_the_hit_rounding_gives() -> anyhow::Result<()> {
    use sweeptrace::core::InitialOverlap;
    let scene = SceneMsg {
        name: Some("triangle".into()),
        vertices: vec![
            [100.0, 100.0, 0.0],
            [104.0, 100.0, 0.0],
            [100.0, 104.0, 0.0],
        ],
        triangles: vec![[0, 1, 2]],
        margin: 0.0,
        facing: Facing::NonStrict,
    };
    let judged = |gap: f64, contact: [f64; 3]| -> anyhow::Result<Agreement> {
        let sweep = SweepMsg {
            frame: 0,
            ball: 0,
            radius: 0.5,
            p0: [101.0, 101.0, 0.5 + gap],
            p1: [101.2, 101.0, 0.8],
        };
        let answer = OutcomeMsg {
            frame: 0,
            ball: 0,
            kind: sweeptrace::Kind::Face,
            alpha: 0.0,
            triangle: Some(Some(0)),
            feature: Some(None),
            normal: Some(Some([0.0, 0.0, 1.0])),
            contact: Some(Some(contact)),
        };
        let mut w = TraceWriter::new(std::io::Cursor::new(Vec::new()))?;
        w.scene(0, &scene)?;
        w.sweep(1_000, &sweep)?;
        w.expected(1_000, &answer)?;
        let bytes = w.finish()?.into_inner();
        let options = ReplayOptions {
            conventions: EngineConventions {
                precision: Precision::F32,
                initial_overlap: InitialOverlap::Alpha0Always,
                ..EngineConventions::default()
            },
            ..ReplayOptions::default()
        };
        for event in
            sweeptrace::replay_events(TraceReader::new(bytes.as_slice(), "t.mcap"), options)
        {
            if let ReplayEvent::Sweep(r) = event? {
                ensure!(r.outcome.hit.is_none(), "the core hits: {:?}", r.outcome);
                return Ok(sweeptrace::agreement(&answer, &r, &Tolerances::default()));
            }
        }
        anyhow::bail!("no sweep")
    };
    // u32 · S here is about 6e-6: a contact 2e-5 off across the normal
    // (three units) is rounding.
    let touching = judged(1e-9, [101.0 + 2e-5, 101.0, 0.0])?;
    ensure!(
        matches!(
            touching,
            Agreement::Precision {
                reproduced: Some(_),
                ..
            }
        ),
        "a touching start's hit with an f32 contact: {touching:?}"
    );
    let off = judged(1e-9, [101.0 + 5e-3, 101.0, 0.0])?;
    ensure!(off.fails(false), "a contact 1 % of rho off passes: {off:?}");
    let away = judged(5e-3, [101.0, 101.0, 0.0])?;
    ensure!(away.fails(false), "a hit 1 % of rho away passes: {away:?}");
    Ok(())
}

/// Issue 47: under a declared accuracy, an answer naming another member of
/// the core's tie set is held to that member's own bound, not to the
/// primary's. Rapier's answer to the cube corner's frame 32, ball 7 (a ball
/// starting 1.2e-4 inside ρ of the top face's diagonal, an `α = 0` tie of
/// face 9, the primary, and edge 8.2) names the edge with a normal 1.9°
/// from its contact normal: within the edge's bound at 2^17 units (the
/// contact normal turns with the centre: about 8.7°), beyond the face's
/// (0.67°), which is what it was judged by before. A normal tilted 20°
/// still fails.
fn a_tie_member_is_held_to_its_own_bound() -> anyhow::Result<()> {
    let trace = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("traces/record_cube_corner_margin.mcap");
    let bytes = std::fs::read(&trace)?;
    let (mut scene, mut sweep) = (None, None);
    for event in TraceReader::new(bytes.as_slice(), "cube") {
        match event?.body {
            sweeptrace::EventBody::Scene(s) if scene.is_none() => scene = Some(s),
            sweeptrace::EventBody::Sweep(s) if s.frame == 32 && s.ball == 7 => sweep = Some(s),
            _ => {}
        }
    }
    let (scene, sweep) = (
        scene.ok_or_else(|| anyhow::anyhow!("no scene"))?,
        sweep.ok_or_else(|| anyhow::anyhow!("no sweep 32/7"))?,
    );
    let dir = tempfile::tempdir()?;
    let config = dir.path().join("rapier.toml");
    std::fs::write(
        &config,
        "[engine]\nprecision = \"f32\"\nmargin = 0.0\ninitial_overlap = \"alpha0_always\"\n\
         ties = \"any\"\naccuracy = 131072\nnormal = \"contact\"\nsides = \"two\"\n",
    )?;
    // (sweeps judged: divergent, tie members; the ghost contact this
    // answer also is, Rapier's normal at a flat seam, is reported apart)
    let check = |normal: [f64; 3], name: &str| -> anyhow::Result<(u64, u64, String)> {
        let answer = OutcomeMsg::hit(32, 7, 0.0, sweeptrace::Kind::Edge)
            .triangle(8)
            .feature(2)
            .normal(normal)
            .contact([0.84108, 0.84108, 1.0]);
        let path = dir.path().join(name);
        let mut writer = TraceWriter::new(std::fs::File::create(&path)?)?;
        writer.scene(0, &scene)?;
        writer.sweep(1, &sweep)?;
        writer.expected(2, &answer)?;
        writer.finish()?;
        let out = crate::support::bin()
            .arg("check")
            .arg(&path)
            .arg("--config")
            .arg(&config)
            .arg("--json")
            .output()?;
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let report: serde_json::Value = serde_json::from_str(&text)?;
        let t = &report["traces"][0];
        let count = |key: &str| t[key].as_u64().unwrap_or(u64::MAX);
        Ok((count("divergent"), count("ties"), text))
    };
    let rapier = [-0.14856, 0.1485, 0.97769];
    let (divergent, ties, out) = check(rapier, "rapier.mcap")?;
    ensure!(
        divergent == 0 && ties == 1,
        "Rapier's answer is within the edge member's bound: {divergent} divergent, {ties} ties\n{out}"
    );
    // The same answer with its normal turned 20° about the edge's direction.
    let (c, s) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
    let axis = nalgebra::Vector3::new(1.0, 1.0, 0.0).normalize();
    let n = nalgebra::Vector3::from(rapier);
    let tilted = n * c + axis.cross(&n) * s + axis * axis.dot(&n) * (1.0 - c);
    let (divergent, _, out) = check([tilted.x, tilted.y, tilted.z], "tilted.mcap")?;
    ensure!(
        divergent == 1,
        "a normal 20° off the edge member's fails: {divergent} divergent\n{out}"
    );
    Ok(())
}
