//! The minimal case: one sweep found in a trace, the triangles within its
//! reach, its expectation, written as a trace of its own.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::core::explain::num;
use crate::core::{Mesh, Options, Outcome, Sweep, SweptPath, sweep_ties};
use crate::trace::{OutcomeMsg, SceneMsg, SweepMsg, TraceError, TraceWriter};

use crate::conventions::EngineConventions;
use crate::core::topology::Topology;
use crate::judge::precision::Sensitivity;
use crate::judge::{Agreement, agreement};
use crate::judge::{Field, FieldSet, Tolerances};
use crate::replay::{ReplayOptions, SceneNormals};

use super::find::{ReproError, TraceSweep};
use crate::judge::inputs::SweepInputs;

/// A minimal case reproducing one sweep of a trace.
#[derive(Clone, Debug)]
pub struct ReproCase {
    /// The trace's name, as given.
    pub source: String,
    /// The scene's name in the trace, if it has one.
    pub scene_name: Option<String>,
    /// Frame of the sweep.
    pub frame: u64,
    /// Ball of the sweep.
    pub ball: u32,
    /// The sweep's inputs.
    pub inputs: SweepInputs,
    /// Vertices of the reduced scene (those its triangles use, in their
    /// original order).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles of the reduced scene, indexing [`ReproCase::vertices`].
    pub triangles: Vec<[u64; 3]>,
    /// For each triangle of the reduced scene, its index in the trace's
    /// scene (increasing, so the tie order is the same).
    pub original_triangles: Vec<u32>,
    /// Triangles in the trace's scene.
    pub original_triangle_count: usize,
    /// A triangle out of reach kept only because it holds the scene's
    /// largest coordinate, which sets the sweep's rounding unit (and so the
    /// tie window and the fragility bands); its original index.
    pub extent_triangle: Option<u32>,
    /// The expectation, with its triangle renumbered for the reduced scene.
    pub expected: Option<OutcomeMsg>,
    /// The expectation as the trace has it.
    pub original_expected: Option<OutcomeMsg>,
    /// The core's outcome on the trace's whole scene.
    pub outcome: Outcome,
    /// The core's outcome on the reduced scene (triangle renumbered).
    pub reduced_outcome: Outcome,
    /// How the whole scene's outcome stands against the expectation.
    pub agreement: Option<Agreement>,
    /// How the reduced scene's outcome stands against the renumbered
    /// expectation.
    pub reduced_agreement: Option<Agreement>,
    /// The engine's conventions the case is replayed and judged under.
    pub conventions: EngineConventions,
    /// The tolerances the test asserts the numbers within: the run's, or
    /// at single precision the sweep's own bound.
    pub asserted_tolerances: Tolerances,
}

/// A short name of an agreement: `match`, `tie`, `diverges (kind, alpha)`,
/// `fragile divergence (...)`.
pub fn agreement_text(a: &Agreement) -> String {
    match a {
        Agreement::Match => "match".to_string(),
        Agreement::Tie => "tie (the expectation names another member of the tie set)".to_string(),
        Agreement::Precision {
            fields,
            backward_error,
            ..
        } => format!(
            "within single precision ({}; backward error {} u₃₂ · S)",
            fields
                .iter()
                .map(|f| f.field.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            crate::core::explain::num(*backward_error)
        ),
        Agreement::Diverges {
            fields,
            fragile,
            reproduced,
        } => {
            let names = fields
                .iter()
                .map(|f| f.field.as_str())
                .collect::<Vec<_>>()
                .join(", ");
            match (fragile.is_robust(), reproduced) {
                (true, _) => format!("diverges ({names})"),
                (false, Some(_)) => format!("fragile divergence ({names}; {fragile})"),
                (false, None) => format!(
                    "diverges ({names}; the decision is fragile: {fragile}, but no perturbation \
                     gives the expected answer)"
                ),
            }
        }
    }
}

fn same_verdict(a: &Agreement, b: &Agreement) -> bool {
    match (a, b) {
        (Agreement::Match, Agreement::Match) | (Agreement::Tie, Agreement::Tie) => true,
        (
            Agreement::Diverges {
                fields: fa,
                fragile: xa,
                reproduced: ra,
            },
            Agreement::Diverges {
                fields: fb,
                fragile: xb,
                reproduced: rb,
            },
        ) => {
            fa.iter().map(|f| f.field).eq(fb.iter().map(|f| f.field))
                && xa.is_robust() == xb.is_robust()
                && ra.is_some() == rb.is_some()
        }
        _ => false,
    }
}

/// The conventions a case is replayed and judged under, and the normals
/// of its scene under them.
struct Under<'a> {
    conventions: &'a EngineConventions,
    normals: SceneNormals,
}

fn result_of(
    mesh: &Mesh,
    (frame, ball): (u64, u32),
    sweep: Sweep,
    (options, under): (Options, &Under<'_>),
    outcome: Outcome,
    expected: Option<OutcomeMsg>,
) -> crate::replay::SweepResult {
    crate::replay::SweepResult {
        frame,
        ball,
        log_time_nanos: 0,
        index: 0,
        scene: std::sync::Arc::new(crate::replay::SceneState {
            number: 0,
            index: 0,
            log_time_nanos: 0,
            name: None,
            mesh: mesh.clone(),
            // Not built: the judgement of the sweep reads only the mesh.
            topology: crate::core::topology::Topology::default(),
            options,
            normals: under.normals.clone(),
            conventions: *under.conventions,
        }),
        sweep,
        outcome,
        records: Vec::new(),
        skipped: Default::default(),
        expected,
        tunnels: Vec::new(),
    }
}

/// Distance from `c` to the segment `p0 → p1`.
fn segment_distance(p0: &[f64; 3], p1: &[f64; 3], c: &[f64; 3]) -> f64 {
    let d = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
    let m = [c[0] - p0[0], c[1] - p0[1], c[2] - p0[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let t = if dd > 0.0 {
        ((m[0] * d[0] + m[1] * d[1] + m[2] * d[2]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [m[0] - t * d[0], m[1] - t * d[1], m[2] - t * d[2]];
    (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt()
}

impl ReproCase {
    /// Builds the minimal case of `found` (a sweep of the trace `source`).
    ///
    /// A triangle is *within reach* when its bounding sphere (centred on
    /// its centroid) and its bounding box both come within `r` (plus the
    /// core's broadphase margin, far above the rounding of the tests)
    /// of the segment `p0 → p1`: every triangle the ball can touch, or
    /// miss by rounding, is kept. The expected triangle is always kept.
    /// Triangles keep their order, vertices their order within each
    /// triangle, so the tie order and the feature numbers are the same.
    ///
    /// The sweep is replayed and judged under the engine's `conventions`
    /// (the rules by default): the margin, facing, sides, initial overlap
    /// and normal its reference answer is computed under, the precision
    /// and tie rule its expectation is judged under.
    pub fn build(
        trace: &str,
        found: &TraceSweep,
        tol: &Tolerances,
        conventions: &EngineConventions,
    ) -> Result<ReproCase, ReproError> {
        let frame = found.sweep.frame;
        let ball = found.sweep.ball;
        let scene = &found.scene;
        let mesh = Mesh::new(scene.vertices.clone(), &scene.triangles).map_err(|cause| {
            ReproError::Mesh {
                trace: trace.to_string(),
                frame,
                cause,
            }
        })?;
        let sweep = found.core_sweep();
        let replay = ReplayOptions {
            conventions: *conventions,
            ..ReplayOptions::default()
        };
        let options = replay.core_options(scene.margin, scene.facing);
        // The normals of a scene under the declared normal rule (its active
        // edges from the scene's own topology).
        let normals_of = |mesh: &Mesh, vertices: &[[f64; 3]], triangles: &[[u64; 3]]| {
            let topology = Topology::new(vertices, triangles).unwrap_or_default();
            SceneNormals::new(conventions.normal, mesh, &topology)
        };
        let under = Under {
            conventions,
            normals: normals_of(&mesh, &scene.vertices, &scene.triangles),
        };
        let sweep_error = |cause| ReproError::Sweep {
            trace: trace.to_string(),
            frame,
            ball,
            cause,
        };
        let (outcome, _) = sweep_ties(&mesh, &sweep, &options).map_err(sweep_error)?;
        let outcome = under.normals.apply(&sweep, outcome);

        // The core's own scale and broadphase margin; the reach is the
        // radius r, not ρ = r - ε, so a margin only keeps more triangles.
        let (lo, hi) = mesh.bounds();
        let extent = lo.coords.amax().max(hi.coords.amax());
        let path = SweptPath::new(&sweep, &options)
            .map_err(sweep_error)?
            .with_mesh_scale(&lo, &hi);
        let (p0, p1) = (found.sweep.p0, found.sweep.p1);
        let reach = sweep.radius + path.broadphase_margin();
        let box_lo: [f64; 3] = std::array::from_fn(|k| p0[k].min(p1[k]) - reach);
        let box_hi: [f64; 3] = std::array::from_fn(|k| p0[k].max(p1[k]) + reach);
        let expected_triangle = found.expected.and_then(|e| e.triangle.flatten());
        let degenerate: std::collections::HashSet<usize> =
            mesh.degenerate().iter().map(|d| d.index).collect();
        let corners = |t: &[u64; 3]| t.map(|i| scene.vertices[i as usize]);
        let mut keep: Vec<u32> = Vec::new();
        for (i, t) in scene.triangles.iter().enumerate() {
            let wanted = expected_triangle == Some(i as u32)
                || outcome.hit.map(|h| h.triangle) == Some(i as u32);
            if !wanted && degenerate.contains(&i) {
                continue;
            }
            let v = corners(t);
            let in_box = (0..3).all(|k| {
                let lo = v.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
                let hi = v.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
                hi >= box_lo[k] && lo <= box_hi[k]
            });
            let centroid: [f64; 3] = std::array::from_fn(|k| (v[0][k] + v[1][k] + v[2][k]) / 3.0);
            let bound = v
                .iter()
                .map(|p| {
                    ((p[0] - centroid[0]).powi(2)
                        + (p[1] - centroid[1]).powi(2)
                        + (p[2] - centroid[2]).powi(2))
                    .sqrt()
                })
                .fold(0.0, f64::max);
            let near = segment_distance(&p0, &p1, &centroid) <= bound * (1.0 + 1e-12) + reach;
            if wanted || (in_box && near) {
                keep.push(i as u32);
            }
        }
        // The scene's largest coordinate sets the rounding unit of the
        // sweep: keep a triangle that holds it when the kept ones do not.
        let kept_extent = keep
            .iter()
            .flat_map(|&i| corners(&scene.triangles[i as usize]))
            .flat_map(|p| p.map(f64::abs))
            .fold(0.0, f64::max);
        let mut extent_triangle = None;
        if kept_extent < extent {
            let holder = mesh
                .triangles()
                .iter()
                .filter(|t| t.vertices.iter().any(|p| p.coords.amax() == extent))
                .map(|t| t.index)
                .min();
            if let Some(h) = holder {
                let at = keep.partition_point(|&k| k < h);
                keep.insert(at, h);
                extent_triangle = Some(h);
            }
        }
        // Vertices used, in their original order.
        let mut used: Vec<u64> = keep
            .iter()
            .flat_map(|&i| scene.triangles[i as usize])
            .collect();
        used.sort_unstable();
        used.dedup();
        let new_vertex: BTreeMap<u64, u64> = used
            .iter()
            .enumerate()
            .map(|(n, &o)| (o, n as u64))
            .collect();
        let vertices: Vec<[f64; 3]> = used.iter().map(|&o| scene.vertices[o as usize]).collect();
        let triangles: Vec<[u64; 3]> = keep
            .iter()
            .map(|&i| scene.triangles[i as usize].map(|o| new_vertex[&o]))
            .collect();
        let to_new = |t: u32| -> u32 {
            match keep.binary_search(&t) {
                Ok(n) => n as u32,
                // A triangle the scene does not have stays one the reduced
                // scene does not have.
                Err(_) => (keep.len() + (t as usize).saturating_sub(scene.triangles.len())) as u32,
            }
        };
        let expected = found.expected.map(|mut e| {
            if let Some(Some(t)) = e.triangle {
                e.triangle = Some(Some(to_new(t)));
            }
            e
        });

        let reduced =
            Mesh::new(vertices.clone(), &triangles).map_err(|cause| ReproError::Mesh {
                trace: format!("the reduced case of {trace}"),
                frame,
                cause,
            })?;
        let reduced_under = Under {
            conventions,
            normals: normals_of(&reduced, &vertices, &triangles),
        };
        let reduced_outcome_local =
            crate::core::sweep_mesh(&reduced, &sweep, &options).map_err(|cause| {
                ReproError::Sweep {
                    trace: format!("the reduced case of {trace}"),
                    frame,
                    ball,
                    cause,
                }
            })?;
        let reduced_outcome_local = reduced_under.normals.apply(&sweep, reduced_outcome_local);
        let result_on = |mesh: &Mesh, under: &Under<'_>, outcome: Outcome, expected| {
            result_of(
                mesh,
                (frame, ball),
                sweep,
                (options, under),
                outcome,
                expected,
            )
        };
        // The whole scene's result once: its agreement and, at single
        // precision, the sweep's own bound the numbers are asserted within
        // (as the judge widens them).
        let full = result_on(&mesh, &under, outcome, found.expected);
        let full_agreement = found.expected.map(|e| agreement(&e, &full, tol));
        let reduced_agreement = expected.map(|e| {
            let r = result_on(&reduced, &reduced_under, reduced_outcome_local, Some(e));
            agreement(&e, &r, tol)
        });
        let asserted_tolerances = match conventions.budget() {
            None => *tol,
            Some(c) => Sensitivity::of(&full).map_or(*tol, |s| s.widen(tol, c)),
        };
        Ok(ReproCase {
            source: trace.to_string(),
            scene_name: scene.name.clone(),
            frame,
            ball,
            inputs: SweepInputs::of(&sweep, &options),
            vertices,
            triangles,
            original_triangles: keep,
            original_triangle_count: scene.triangles.len(),
            extent_triangle,
            expected,
            original_expected: found.expected,
            outcome,
            reduced_outcome: reduced_outcome_local,
            agreement: full_agreement,
            reduced_agreement,
            conventions: *conventions,
            asserted_tolerances,
        })
    }

    /// The reduced scene's triangle `t` as the trace's scene numbers it.
    pub fn original_triangle(&self, t: u32) -> Option<u32> {
        self.original_triangles.get(t as usize).copied()
    }

    /// Whether the reduced case makes the same decision as the whole
    /// scene: same kind, triangle (renumbered), feature, `α` to the bit,
    /// the normal within 1e-12 (its average is summed in another order),
    /// the same fragility, and the same verdict against the expectation.
    pub fn reproduces(&self) -> bool {
        let (a, b) = (&self.outcome, &self.reduced_outcome);
        let normal_close = match (a.hit.map(|h| h.normal), b.hit.map(|h| h.normal)) {
            (Some(x), Some(y)) => (x - y).norm() <= 1e-12,
            (None, None) => true,
            _ => false,
        };
        let verdicts = match (&self.agreement, &self.reduced_agreement) {
            (Some(x), Some(y)) => same_verdict(x, y),
            (None, None) => true,
            _ => false,
        };
        let same_hit = match (a.hit, b.hit) {
            (Some(x), Some(y)) => {
                x.feature == y.feature
                    && Some(x.triangle) == self.original_triangle(y.triangle)
                    && x.alpha.to_bits() == y.alpha.to_bits()
            }
            (None, None) => true,
            _ => false,
        };
        same_hit && normal_close && a.fragile == b.fragile && verdicts
    }

    /// The trace's file name (without its directory).
    pub fn source_file_name(&self) -> String {
        std::path::Path::new(&self.source)
            .file_name()
            .map_or_else(|| self.source.clone(), |n| n.to_string_lossy().into_owned())
    }

    /// The reduced scene's name: the original's, and where it was cut from.
    pub fn scene_message_name(&self) -> String {
        format!(
            "{} (frame {}, ball {} of {}: triangles {} of its {} as 0..{})",
            self.scene_name.as_deref().unwrap_or("scene"),
            self.frame,
            self.ball,
            self.source_file_name(),
            list(&self.original_triangles),
            self.original_triangle_count,
            self.original_triangles.len()
        )
    }

    /// Writes the case as a trace: the reduced scene (with the sweep's
    /// margin and facing), the sweep, the expectation if any, and a
    /// metadata record `sweeptrace.repro` naming the source, the frame and
    /// ball, and the original index of each triangle.
    pub fn write<W: std::io::Write + std::io::Seek>(
        &self,
        w: &mut TraceWriter<W>,
    ) -> Result<(), TraceError> {
        w.metadata(
            "sweeptrace.repro",
            BTreeMap::from([
                ("source".to_string(), self.source_file_name()),
                ("frame".to_string(), self.frame.to_string()),
                ("ball".to_string(), self.ball.to_string()),
                (
                    "original_triangles".to_string(),
                    list(&self.original_triangles),
                ),
                (
                    "original_triangle_count".to_string(),
                    self.original_triangle_count.to_string(),
                ),
            ]),
        )?;
        w.scene(
            0,
            &SceneMsg {
                name: Some(self.scene_message_name()),
                vertices: self.vertices.clone(),
                triangles: self.triangles.clone(),
                margin: self.inputs.margin,
                facing: self.inputs.facing,
            },
        )?;
        w.sweep(
            1,
            &SweepMsg {
                frame: self.frame,
                ball: self.ball,
                radius: self.inputs.radius,
                p0: self.inputs.p0,
                p1: self.inputs.p1,
            },
        )?;
        if let Some(e) = &self.expected {
            w.expected(1, e)?;
        }
        Ok(())
    }

    /// What the case asserts: the expectation (renumbered), or, when the
    /// trace has none, the core's outcome on the whole scene with every
    /// field.
    pub fn asserted(&self) -> OutcomeMsg {
        self.expected.unwrap_or_else(|| {
            let mut o = OutcomeMsg::from_outcome(self.frame, self.ball, &self.reduced_outcome);
            o.alpha = self.outcome.travelled();
            o
        })
    }

    /// [`ReproCase::asserted`] without the optional fields outside
    /// `fields` (`--fields`): the Rust test does not assert them.
    pub fn asserted_within(&self, fields: FieldSet) -> OutcomeMsg {
        let mut o = self.asserted();
        if !fields.contains(Field::Triangle) {
            o.triangle = None;
        }
        if !fields.contains(Field::Feature) {
            o.feature = None;
        }
        if !fields.contains(Field::Normal) {
            o.normal = None;
        }
        if !fields.contains(Field::Contact) {
            o.contact = None;
        }
        o
    }

    /// A few lines on stderr's side: what was written and whether it
    /// reproduces the decision.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "frame {}, ball {}: {} of {} within reach{}",
            self.frame,
            self.ball,
            self.original_triangles.len(),
            crate::numbers::counted(self.original_triangle_count as u64, "triangle", "triangles"),
            match self.extent_triangle {
                Some(t) => format!(" (with triangle {t}, kept for the scene's extent)"),
                None => String::new(),
            }
        );
        let _ = writeln!(s, "inputs: {}", self.inputs.text());
        let _ = writeln!(s, "inputs (hex): {}", self.inputs.hex().text());
        let o = &self.outcome;
        let _ = writeln!(
            s,
            "the core decides: {} at α = {}{}{}",
            o.kind(),
            num(o.travelled()),
            o.hit
                .map_or(String::new(), |h| format!(", triangle {}", h.triangle)),
            o.hit
                .and_then(|h| h.feature.index())
                .map_or(String::new(), |f| format!(", feature {f}"))
        );
        match &self.agreement {
            Some(a) => {
                let _ = writeln!(s, "against the expectation: {}", agreement_text(a));
            }
            None => {
                let _ = writeln!(s, "the trace has no expectation for this sweep");
            }
        }
        let _ = writeln!(
            s,
            "the reduced case {}",
            if self.reproduces() {
                "makes the same decision"
            } else {
                "does NOT make the same decision (please report it)"
            }
        );
        s
    }
}

fn list(v: &[u32]) -> String {
    v.iter().map(u32::to_string).collect::<Vec<_>>().join(" ")
}

pub(super) fn list_commas(v: &[u32]) -> String {
    v.iter().map(u32::to_string).collect::<Vec<_>>().join(", ")
}
