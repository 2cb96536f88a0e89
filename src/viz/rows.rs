//! The rows one sweep logs: the ball, its sweep, contact and normal, the
//! primary feature, the expected outcome when it differs, the plots, the
//! status series and the text lines. (The edge frames are in
//! `edge_frame`.)

use std::iter::once;

use rerun::components::{
    AlbedoFactor, FillMode, HalfSize3D, Length, Position3D, Radius, RotationQuat, Scalar, Scale3D,
    Text, TextLogLevel, Translation3D, TriangleIndices, Vector3D,
};
use rerun::{
    Arrows3D, Capsules3D, Color, Ellipsoids3D, LineStrips3D, Mesh3D, Points3D, Scalars, TextLog,
    Transform3D,
};

use super::columns::row::Row;
use super::convert::{
    BOLD_EDGE_POINTS, CONTACT_BALL_COLOR, EXPECTED_COLOR, FACE_NORMAL_COLOR, GHOST_COLOR,
    HIT_COLOR, MISS_COLOR, NORMAL_COLOR, OUTLINE_POINTS, P0_COLOR, P1_COLOR, SWEEP_COLOR,
    TUNNEL_COLOR, VERTEX_POINTS, albedo, any_value, capsule_pose, f32x3, rgba, ui_points,
};
use super::edge_frame::{Slot0, count_edges};
use super::out::{Out, PrepareOptions, Shown, set};
use super::paths::{Entity, FACE_NAMES, QUADRATIC_NAMES};
use crate::core::Kind;
use crate::core::explain::Label;
use crate::core::record::{EdgeRecord, TestRecord};
use crate::judge::{FieldDiff, divergence, write_decision_line, write_divergence_line};
use crate::replay::SweepResult;
use crate::replay::ghost::GhostContact;
use crate::trace::OutcomeMsg;

/// What the rows of `r` show, as the logger with `options` draws them
/// (worked out without drawing them or running any test).
pub(crate) fn shown_of(r: &SweepResult, options: &PrepareOptions) -> Shown {
    let mut bits = 0;
    let decisive = r.decisive_record();
    if let Some(t) = decisive
        && r.scene.mesh.triangle_by_index(t.triangle()).is_some()
    {
        bits |= Shown::PRIMARY;
    }
    if r.expected.is_some() && !divergence(r, &options.tolerances).is_empty() {
        bits |= Shown::EXPECTED;
    }
    if !r.tunnels.is_empty() {
        bits |= Shown::TUNNEL;
    }
    if r.ghost().is_some() {
        bits |= Shown::GHOST;
    }
    let edges = count_edges(r, decisive, options.max_edge_frames);
    Shown::drawn(
        edges,
        plot_bits(decisive),
        bits & Shown::PRIMARY != 0,
        bits & Shown::EXPECTED != 0,
        bits & Shown::TUNNEL != 0,
        bits & Shown::GHOST != 0,
    )
}

/// Clears, at ball `b`'s sweep that shows `now`, what its previous sweep
/// showed (`out.before`) and this one does not log: the primary triangle,
/// edge frames, plot series, expected outcome, tunnel marker and ghost
/// contact's mark.
pub(crate) fn transition_rows(out: &mut Out<'_>, b: u32, now: Shown) {
    let before = out.before;
    if before.has(Shown::PRIMARY) && !now.has(Shown::PRIMARY) {
        out.clear(Entity::Primary(b), false);
    }
    for slot in now.edge_slots..before.edge_slots {
        out.clear(Entity::EdgeFrame(b, usize::from(slot)), false);
    }
    let gone = before.plotted & !now.plotted;
    for bit in (0..PLOT_BITS).filter(|bit| gone & (1 << bit) != 0) {
        out.clear(plot_entity(b, bit), false);
    }
    if before.has(Shown::EXPECTED) && !now.has(Shown::EXPECTED) {
        out.clear(Entity::Expected(b), false);
    }
    if before.has(Shown::TUNNEL) && !now.has(Shown::TUNNEL) {
        out.clear(Entity::Tunnel(b), false);
    }
    if before.has(Shown::GHOST) && !now.has(Shown::GHOST) {
        out.clear(Entity::Ghost(b), false);
    }
}

/// The plot entities of the decisive test's numbers, by their bit in
/// [`plot_bits`]'s answer.
pub(crate) fn plot_entity(ball: u32, bit: u16) -> Entity {
    match bit {
        0 => Entity::Quadratic(ball),
        _ => Entity::Face(ball),
    }
}

/// How many plot bits there are.
pub(crate) const PLOT_BITS: u16 = 2;

/// The ball at p0, at the contact and at p1, the swept volume, the contact
/// and the normal, in one row (the contact and the normal empty when
/// nothing is hit). No labels: the numbers are in the decision line.
pub(crate) fn ball_row(out: &mut Out<'_>, r: &SweepResult) {
    let b = r.ball;
    let o = &r.outcome;
    let p0 = r.sweep.p0;
    let d = r.sweep.p1 - p0;
    let rho = r.rho();
    let radius = r.sweep.radius as f32;
    let at_contact = p0 + d * o.travelled();

    let hit = o.is_hit();
    let contact_center = hit.then(|| f32x3(at_contact.coords));
    let contact_color = hit.then(|| rgba(CONTACT_BALL_COLOR));
    let (length, rotation) = capsule_pose(&d);
    let contact = o.hit.map(|h| (h.contact, h.normal));
    let mut row = out.row(Entity::Ball(b), set::BALL);
    // One half size for the two or three balls (the viewer repeats it).
    row.put::<HalfSize3D>(
        Ellipsoids3D::descriptor_half_sizes,
        [HalfSize3D::splat(radius)],
    )
    .put::<Translation3D>(
        Ellipsoids3D::descriptor_centers,
        once(f32x3(p0.coords))
            .chain(contact_center)
            .chain(once(f32x3(r.sweep.p1.coords)))
            .map(Translation3D::from),
    )
    .put::<Color>(
        Ellipsoids3D::descriptor_colors,
        once(rgba(P0_COLOR))
            .chain(contact_color)
            .chain(once(rgba(P1_COLOR))),
    )
    .put::<FillMode>(Ellipsoids3D::descriptor_fill_mode, [FillMode::Solid])
    // The swept volume at the detection radius.
    .put::<Length>(Capsules3D::descriptor_lengths, [length.into()])
    .put::<Radius>(Capsules3D::descriptor_radii, [(rho as f32).into()])
    .put::<Translation3D>(
        Capsules3D::descriptor_translations,
        [f32x3(p0.coords).into()],
    )
    .put::<RotationQuat>(Capsules3D::descriptor_quaternions, [rotation.into()])
    .put::<Color>(Capsules3D::descriptor_colors, [rgba(SWEEP_COLOR)])
    .put::<FillMode>(Capsules3D::descriptor_fill_mode, [FillMode::MajorWireframe]);
    contact_parts(
        &mut row,
        contact.map(|(c, _)| f32x3(c.coords)),
        contact.map(|(_, nrm)| f32x3(nrm * (r.sweep.radius.max(1e-3) * 1.5))),
        [HIT_COLOR, NORMAL_COLOR],
    );
}

/// The `Points3D` and `Arrows3D` parts of a row: a contact point (or none)
/// and its normal drawn from it (when both are given; else none), in
/// `colors` (point, arrow).
fn contact_parts(
    row: &mut Row<'_>,
    at: Option<[f32; 3]>,
    normal: Option<[f32; 3]>,
    colors: [[u8; 4]; 2],
) {
    let arrow = at.zip(normal);
    row.put::<Position3D>(Points3D::descriptor_positions, at.map(Position3D::from))
        .put::<Radius>(Points3D::descriptor_radii, [ui_points(5.0)])
        .put::<Color>(Points3D::descriptor_colors, [rgba(colors[0])])
        .put::<Vector3D>(
            Arrows3D::descriptor_vectors,
            arrow.map(|(_, v)| Vector3D::from(v)),
        )
        .put::<Position3D>(
            Arrows3D::descriptor_origins,
            arrow.map(|(p, _)| Position3D::from(p)),
        )
        .put::<Color>(Arrows3D::descriptor_colors, [rgba(colors[1])]);
}

/// The transform the view that follows ball `r.ball` looks from: at the
/// ball where the decision happens, scaled so that one unit is five ball
/// radii. Where: at α when something is hit; else at the expected α when
/// the expectation is a hit; else where the path comes nearest to the
/// decisive (nearest-miss) triangle; else at p1.
pub(crate) fn focus_rows(
    out: &mut Out<'_>,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    divergent: bool,
) {
    let p0 = r.sweep.p0;
    let d = r.sweep.p1 - p0;
    let alpha = if r.outcome.is_hit() {
        r.outcome.travelled()
    } else if let Some(e) = r.expected.filter(|e| divergent && e.kind != Kind::None) {
        e.alpha
    } else if let Some(t) = decisive.and_then(|t| r.scene.mesh.triangle_by_index(t.triangle())) {
        let centroid = (t.vertices[0].coords + t.vertices[1].coords + t.vertices[2].coords) / 3.0;
        let dd = d.norm_squared();
        if dd > 0.0 {
            (centroid - p0.coords).dot(&d) / dd
        } else {
            0.0
        }
    } else {
        1.0
    };
    let alpha = if alpha.is_finite() {
        alpha.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let center = p0 + d * alpha;
    let size = 5.0 * r.sweep.radius.max(1e-6);
    out.row(Entity::Focus(r.ball), set::FOCUS)
        .put::<Translation3D>(
            Transform3D::descriptor_translation,
            [f32x3(center.coords).into()],
        )
        .put::<Scale3D>(
            Transform3D::descriptor_scale,
            [Scale3D::uniform(size as f32)],
        );
}

/// Which of a sweep's archetypes carry a label, so that no two labels say
/// the same thing in the same place: the primary feature's label, the
/// expected ball's, slot 0's edge test's and the ghost contact's (see
/// [`SweepLabels::of`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct SweepLabels {
    /// The primary triangle's label is drawn on its decisive feature.
    pub(crate) primary: bool,
    /// The expected ball carries its label.
    pub(crate) expected: bool,
    /// Slot 0's edge test's label, on its edge (none for a decisive edge
    /// test, whose label is the primary edge's).
    pub(crate) slot0: Option<String>,
    /// The ghost contact's mark carries its own label (when the expected
    /// ball is drawn, its label, on the ball or folded into slot 0's, says
    /// it instead).
    pub(crate) ghost: bool,
}

impl SweepLabels {
    /// The labels of a sweep: the primary feature's when it is hit, or for
    /// the followed ball (`followed`) when it is the nearest miss (so that
    /// balls that hit nothing do not cover the picture with labels); the
    /// expected ball's at a divergent sweep (`expected`); slot 0's edge test
    /// (`edges[0]`, `slot0` as `choose_edges` returned), for the followed
    /// ball only, when it is not the decisive test.
    ///
    /// Two of them say one thing about one place when slot 0 is the nearest
    /// edge test of a face decision (the face's label sits on the outline of
    /// the triangle whose edge is labelled) or the expected edge test of a
    /// divergent sweep (the expected ball sits on that edge): each pair is
    /// one label then, on slot 0's edge, which every 3D view shows (the
    /// edge-frame view included): `face 0; nearest edge test: edge 0.1
    /// (parallel)`, `expected: edge; expected edge test: edge 0.0
    /// (no_real_roots)`.
    ///
    /// The ghost contact `ghost` is marked at the expected contact, which
    /// the expected ball touches: when that ball is drawn its label says
    /// both (`expected: edge; ghost contact 10.0°: edge 0.2 is internal
    /// and flat`), else the mark has its own label.
    pub(crate) fn of(
        r: &SweepResult,
        decisive: Option<&TestRecord>,
        edges: &[EdgeRecord],
        slot0: Slot0,
        followed: bool,
        expected: bool,
        ghost: Option<&GhostContact>,
    ) -> SweepLabels {
        let shown = decisive.filter(|t| r.scene.mesh.triangle_by_index(t.triangle()).is_some());
        let mut labels = SweepLabels {
            primary: shown.is_some_and(|t| t.alpha().is_some() || followed),
            expected,
            slot0: None,
            ghost: ghost.is_some() && !expected,
        };
        let Some(e) = edges.first().filter(|_| followed) else {
            return labels;
        };
        let edge_test =
            |what: &str| format!("{what}: {} ({})", Label(&TestRecord::Edge(*e)), e.verdict);
        labels.slot0 = match slot0 {
            Slot0::Decisive => None,
            Slot0::Nearest => match shown {
                Some(face @ TestRecord::Face(_))
                    if labels.primary && face.triangle() == e.triangle =>
                {
                    labels.primary = false;
                    Some(format!(
                        "{}; {}",
                        primary_text(face),
                        edge_test("nearest edge test")
                    ))
                }
                _ => Some(edge_test("nearest edge test")),
            },
            Slot0::Expected => match r.expected.filter(|_| expected) {
                Some(x) => {
                    labels.expected = false;
                    Some(format!(
                        "{}; {}",
                        expected_text(&x, ghost),
                        edge_test("expected edge test")
                    ))
                }
                None => Some(edge_test("expected edge test")),
            },
        };
        labels
    }
}

/// The primary feature's label: the test (`edge 12.1`), after `nearest
/// miss: ` when it does not hit.
fn primary_text(test: &TestRecord) -> String {
    let prefix = if test.alpha().is_some() {
        ""
    } else {
        "nearest miss: "
    };
    format!("{prefix}{}", Label(test))
}

/// The expected ball's label, with the ghost contact's when the
/// expectation is one.
fn expected_text(e: &OutcomeMsg, ghost: Option<&GhostContact>) -> String {
    match ghost {
        Some(g) => format!("expected: {}; {}", e.kind, g.label()),
        None => format!("expected: {}", e.kind),
    }
}

/// The primary (or nearest-miss) triangle, in one row: filled, its three
/// edges outlined, its decisive edge bold (a second strip) or its vertex as
/// a point; with `labelled` one label, on the decisive feature. Returns
/// whether it was drawn (when not, [`transition_rows`] clears it).
pub(crate) fn primary_rows(
    out: &mut Out<'_>,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    labelled: bool,
) -> bool {
    let b = r.ball;
    let triangle = decisive.and_then(|t| r.scene.mesh.triangle_by_index(t.triangle()));
    let (Some(t), Some(test)) = (triangle, decisive) else {
        return false;
    };
    let hit = test.alpha().is_some();
    let color = if hit { HIT_COLOR } else { MISS_COLOR };
    // Lift the highlight a little off the mesh so it is not hidden by it.
    let lift = t.normal * (r.rho() * 0.02);
    let verts: [[f32; 3]; 3] = std::array::from_fn(|i| f32x3(t.vertices[i].coords + lift));
    let label = primary_text(test);
    let f = usize::from(test.feature().index().unwrap_or(0)) % 3;
    let outline = [verts[0], verts[1], verts[2], verts[0]];
    let bold = [verts[f], verts[(f + 1) % 3]];
    let (strips, radii): (&[&[[f32; 3]]], &[f32]) = match test {
        TestRecord::Edge(_) => (&[&outline, &bold], &[OUTLINE_POINTS, BOLD_EDGE_POINTS]),
        _ => (&[&outline], &[OUTLINE_POINTS]),
    };
    let vertex = matches!(test, TestRecord::Vertex(_)).then(|| Position3D::from(verts[f]));
    let mut row = out.row(Entity::Primary(b), set::PRIMARY);
    row.put::<Position3D>(
        Mesh3D::descriptor_vertex_positions,
        verts.map(Position3D::from),
    )
    .put::<TriangleIndices>(Mesh3D::descriptor_triangle_indices, [[0u32, 1, 2].into()])
    .put::<AlbedoFactor>(
        Mesh3D::descriptor_albedo_factor,
        [albedo([color[0], color[1], color[2], 90]).into()],
    )
    .put_strips(LineStrips3D::descriptor_strips, strips)
    .put::<Radius>(
        LineStrips3D::descriptor_radii,
        radii.iter().map(|&p| ui_points(p)),
    )
    .put::<Color>(LineStrips3D::descriptor_colors, [rgba(color)])
    .put_texts(LineStrips3D::descriptor_labels, |s| {
        // On the outline for a face test, on the bold edge for an edge
        // test (the outline's label then empty, which is not drawn).
        match test {
            TestRecord::Face(_) if labelled => {
                s.push_fmt(format_args!("{label}"));
            }
            TestRecord::Edge(_) if labelled => {
                s.push_fmt(format_args!(""));
                s.push_fmt(format_args!("{label}"));
            }
            _ => {}
        }
    })
    .put::<Position3D>(Points3D::descriptor_positions, vertex)
    .put::<Radius>(Points3D::descriptor_radii, [ui_points(VERTEX_POINTS)])
    .put::<Color>(Points3D::descriptor_colors, [rgba(color)])
    .put_texts(Points3D::descriptor_labels, |s| {
        if labelled && vertex.is_some() {
            s.push_fmt(format_args!("{label}"));
        }
    });
    true
}

/// The expected outcome beside the replayed one, for a divergent sweep, in
/// one row: the ball at the expected α, the expected contact (when the
/// expectation names one) and normal (when it names a contact and a normal
/// of finite, non-zero length; else none); the ball labelled with the
/// expected kind (and the ghost contact, `ghost`) when `labelled`.
pub(crate) fn expected_rows(
    out: &mut Out<'_>,
    r: &SweepResult,
    e: &OutcomeMsg,
    labelled: bool,
    ghost: Option<&GhostContact>,
) {
    let b = r.ball;
    let p0 = r.sweep.p0;
    let d = r.sweep.p1 - p0;
    let alpha = if e.alpha.is_finite() {
        e.alpha.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let center = p0 + d * alpha;
    let contact = e.contact.flatten().map(|c| c.map(|x| x as f32));
    let normal = match (e.normal.flatten(), contact) {
        (Some(n), Some(_)) => {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            (len > 0.0 && len.is_finite()).then(|| {
                let k = r.sweep.radius.max(1e-3) * 1.5 / len;
                n.map(|x| (x * k) as f32)
            })
        }
        _ => None,
    };
    let mut row = out.row(Entity::Expected(b), set::EXPECTED);
    row.put::<HalfSize3D>(
        Ellipsoids3D::descriptor_half_sizes,
        [HalfSize3D::splat(r.sweep.radius as f32)],
    )
    .put::<Translation3D>(
        Ellipsoids3D::descriptor_centers,
        [f32x3(center.coords).into()],
    )
    .put::<Color>(Ellipsoids3D::descriptor_colors, [rgba(EXPECTED_COLOR)])
    .put::<FillMode>(
        Ellipsoids3D::descriptor_fill_mode,
        [FillMode::MajorWireframe],
    )
    .put_texts(Ellipsoids3D::descriptor_labels, |t| {
        if labelled {
            t.push_fmt(format_args!("{}", expected_text(e, ghost)));
        }
    });
    // The contact point alone when the normal is missing or unusable.
    contact_parts(&mut row, contact, normal, [EXPECTED_COLOR; 2]);
}

/// A `Scalars` row.
fn scalar(out: &mut Out<'_>, entity: Entity, v: f64) {
    out.row(entity, set::SCALAR)
        .put::<Scalar>(Scalars::descriptor_scalars, [v.into()]);
}

/// The series of the plot entity of bit `bit` (see [`plot_entity`]), in
/// the order of its values.
pub(crate) fn plot_series(bit: u16) -> &'static [&'static str] {
    match bit {
        0 => &QUADRATIC_NAMES,
        _ => &FACE_NAMES,
    }
}

/// The decisive test's numbers for the plots, when one of them is finite:
/// its plot bit (see [`plot_entity`]) and its values, a series each
/// (`None` where the test has no such value; the first
/// `plot_series(bit).len()` are used).
fn plot_values(decisive: Option<&TestRecord>) -> Option<(u16, [Option<f64>; 6])> {
    let quadratic = |a, b, c, d, roots: Option<(f64, f64)>| {
        let (s0, s1) = roots.unzip();
        (0, [Some(a), Some(b), Some(c), Some(d), s0, s1])
    };
    let (bit, values) = match decisive? {
        TestRecord::Edge(e) => quadratic(e.a, e.b, e.c, e.discriminant, e.roots),
        TestRecord::Vertex(v) => quadratic(v.a, v.b, v.c, v.discriminant, v.roots),
        TestRecord::Face(f) => (1, [Some(f.h0), Some(f.h1), f.beta, None, None, None]),
    };
    values
        .iter()
        .flatten()
        .any(|v| v.is_finite())
        .then_some((bit, values))
}

/// Which plot entities the decisive test's numbers go to (bit `i` for
/// `plot_entity(ball, i)`): the test's entity when one of its values is
/// finite.
pub(crate) fn plot_bits(decisive: Option<&TestRecord>) -> u16 {
    plot_values(decisive).map_or(0, |(bit, _)| 1 << bit)
}

/// The α plot and the decisive test's numbers (one row of a series each,
/// NaN, which breaks a series' line, where a value is missing or not
/// finite); returns which plot entities got a row (as [`plot_bits`]).
pub(crate) fn plot_rows(out: &mut Out<'_>, r: &SweepResult, decisive: Option<&TestRecord>) -> u16 {
    let b = r.ball;
    // One row: α and the kind beside it.
    out.row(Entity::Alpha(b), set::KIND)
        .put::<Scalar>(Scalars::descriptor_scalars, [r.outcome.travelled().into()])
        .put_strs(|| any_value::<Text>("kind"), [r.outcome.kind().as_str()]);
    let Some((bit, values)) = plot_values(decisive) else {
        return 0;
    };
    out.row(plot_entity(b, bit), set::SCALAR).put::<Scalar>(
        Scalars::descriptor_scalars,
        values[..plot_series(bit).len()]
            .iter()
            .map(|v| v.filter(|v| v.is_finite()).unwrap_or(f64::NAN).into()),
    );
    1 << bit
}

/// The decision in words; for a divergent sweep (`diffs` not empty) also
/// the status series at 1 and a line in the divergences log (the status is
/// 0 for a sweep that matches its expectation, absent without one).
pub(crate) fn text_rows(
    out: &mut Out<'_>,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    diffs: &[FieldDiff],
) {
    let divergent = !diffs.is_empty();
    {
        let mut row = out.row(Entity::Log, set::TEXT_LOG);
        row.put_texts(TextLog::descriptor_text, |t| {
            t.push_with(|s| write_decision_line(s, r, decisive, diffs));
        });
        let level = if divergent || !r.tunnels.is_empty() {
            TextLogLevel::WARN
        } else if r.outcome.is_hit() {
            TextLogLevel::INFO
        } else {
            TextLogLevel::DEBUG
        };
        row.put_strs(TextLog::descriptor_level, [level]);
    }
    if r.expected.is_some() {
        scalar(
            out,
            Entity::Status(r.ball),
            if divergent { 1.0 } else { 0.0 },
        );
    }
    if !r.outcome.fragile.is_robust() {
        scalar(out, Entity::Fragile(r.ball), 1.0);
    }
    if divergent {
        out.row(Entity::Divergences, set::TEXT_LOG)
            .put_texts(TextLog::descriptor_text, |t| {
                t.push_with(|s| write_divergence_line(s, r, diffs));
            })
            .put_strs(TextLog::descriptor_level, [TextLogLevel::WARN]);
    }
}

/// The tunnels of a sweep (a ball's centre through a triangle, front to
/// back, or a flipped one back to front), each labelled with the defect it
/// went through if any: a marker where each crossed the triangle's plane and a WARN line
/// each in the divergences log. Returns whether there was one (the marker
/// is cleared at the ball's next sweep without one).
pub(crate) fn tunnel_rows(out: &mut Out<'_>, r: &SweepResult) -> bool {
    if r.tunnels.is_empty() {
        return false;
    }
    out.row(Entity::Tunnel(r.ball), set::TUNNEL)
        .put::<Position3D>(
            Points3D::descriptor_positions,
            r.tunnels.iter().map(|t| {
                let [x, y, z] = t.point;
                Position3D::new(x as f32, y as f32, z as f32)
            }),
        )
        .put::<Radius>(Points3D::descriptor_radii, [ui_points(9.0)])
        .put::<Color>(Points3D::descriptor_colors, [rgba(TUNNEL_COLOR)])
        .put_texts(Points3D::descriptor_labels, |t| {
            for tunnel in &r.tunnels {
                match &tunnel.through {
                    Some(through) => t.push_fmt(format_args!(
                        "tunnel: triangle {}, through {}",
                        tunnel.triangle, through.text
                    )),
                    None => t.push_fmt(format_args!("tunnel: triangle {}", tunnel.triangle)),
                };
            }
        });
    for tunnel in &r.tunnels {
        let at = crate::replay::TunnelAt {
            frame: r.frame,
            ball: r.ball,
            tunnel: tunnel.clone(),
        };
        out.row(Entity::Divergences, set::TEXT_LOG)
            .put_texts(TextLog::descriptor_text, |t| {
                t.push_fmt(format_args!("tunnel: {at}"));
            })
            .put_strs(TextLog::descriptor_level, [TextLogLevel::WARN]);
    }
    true
}

/// A ghost contact (`ghost`, the sweep's expected outcome as
/// [`SweepResult::ghost`] judges it), in one row: a point where it is
/// ([`SweepResult::ghost_point`]), labelled when `labelled`, and two arrows from it, the
/// expected (ghost) normal and the faces' normal; and a WARN line in the
/// divergences log. Returns whether it was drawn (the mark is cleared at
/// the ball's next sweep without one).
pub(crate) fn ghost_rows(
    out: &mut Out<'_>,
    r: &SweepResult,
    ghost: Option<&GhostContact>,
    labelled: bool,
) -> bool {
    let Some(g) = ghost else {
        return false;
    };
    let at = r.ghost_point(g).map(|x| x as f32);
    let length = r.sweep.radius.max(1e-3) * 3.0;
    let arrow = |n: [f64; 3]| {
        let v = nalgebra::Vector3::from(n);
        let k = length / v.norm().max(f64::MIN_POSITIVE);
        Vector3D::from(f32x3(v * k))
    };
    out.row(Entity::Ghost(r.ball), set::GHOST)
        .put::<Position3D>(Points3D::descriptor_positions, [Position3D::from(at)])
        .put::<Radius>(Points3D::descriptor_radii, [ui_points(7.0)])
        .put::<Color>(Points3D::descriptor_colors, [rgba(GHOST_COLOR)])
        .put_texts(Points3D::descriptor_labels, |t| {
            if labelled {
                t.push_fmt(format_args!("{}", g.label()));
            }
        })
        .put::<Vector3D>(
            Arrows3D::descriptor_vectors,
            [arrow(g.normal), arrow(g.face_normal)],
        )
        .put::<Position3D>(Arrows3D::descriptor_origins, [Position3D::from(at)])
        .put::<Radius>(Arrows3D::descriptor_radii, [ui_points(2.5)])
        .put::<Color>(
            Arrows3D::descriptor_colors,
            [rgba(GHOST_COLOR), rgba(FACE_NORMAL_COLOR)],
        );
    out.row(Entity::Divergences, set::TEXT_LOG)
        .put_texts(TextLog::descriptor_text, |t| {
            t.push_fmt(format_args!("ghost contact: {g}"));
        })
        .put_strs(TextLog::descriptor_level, [TextLogLevel::WARN]);
    true
}
