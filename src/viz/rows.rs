//! The rows one sweep logs: the ball, its sweep, contact and normal, the
//! primary feature, the expected outcome when it differs, the plots, the
//! status series and the text lines. (The edge frames are in
//! `edge_frame`.)

use std::iter::once;

use rerun::components::{
    AlbedoFactor, ClearIsRecursive, FillMode, HalfSize3D, Length, Position3D, Radius, RotationQuat,
    Scalar, Scale3D, Text, TextLogLevel, Translation3D, TriangleIndices, Vector3D,
};
use rerun::{
    Arrows3D, Capsules3D, Clear, Color, Ellipsoids3D, LineStrips3D, Mesh3D, Points3D, Scalars,
    TextLog, Transform3D,
};

use super::columns::{self, Row};
use super::convert::{
    BOLD_EDGE_POINTS, CONTACT_BALL_COLOR, EXPECTED_COLOR, HIT_COLOR, MISS_COLOR, NORMAL_COLOR,
    OUTLINE_POINTS, P0_COLOR, P1_COLOR, SWEEP_COLOR, TUNNEL_COLOR, VERTEX_POINTS, albedo,
    any_value, capsule_pose, f32x3, rgba, ui_points,
};
use super::edge_frame::choose_edges;
use super::logger::PrepareOptions;
use super::paths::{Entity, FACE_NAMES, QUADRATIC_NAMES};
use crate::core::explain::Label;
use crate::core::{EdgeRecord, Kind, TestRecord};
use crate::regress::FieldDiff;
use crate::regress::decision::{divergence, write_decision_line, write_divergence_line};
use crate::replay::SweepResult;
use crate::trace::messages::OutcomeMsg;

/// Component sets: the rows of one entity with the same set number have the
/// same components (see `columns::Columns::row`).
pub(crate) mod set {
    pub const SPHERES: u8 = 0;
    pub const SWEEP: u8 = 1;
    pub const CONTACT: u8 = 2;
    pub const NORMAL: u8 = 3;
    pub const CLEAR: u8 = 4;
    pub const TRIANGLE: u8 = 5;
    pub const LABELED_STRIP: u8 = 6;
    pub const LABELED_POINT: u8 = 7;
    pub const STRIP: u8 = 9;
    pub const CYLINDER: u8 = 10;
    pub const EDGE_POINTS: u8 = 11;
    pub const SCALAR: u8 = 12;
    pub const KIND: u8 = 13;
    pub const TEXT_LOG: u8 = 14;
    pub const FOCUS: u8 = 15;
    /// An edge frame's transform and its test's numbers.
    pub const EDGE_FRAME: u8 = 16;
    pub const AXES: u8 = 20;
    pub const EXPECTED_BALL: u8 = 21;
    pub const TUNNEL: u8 = 22;
}

/// What a sweep's rows leave shown for its ball, of the entities that are
/// cleared when a sweep no longer shows them: the contact and its normal,
/// the primary triangle and outline, the primary edge, the primary vertex,
/// the edge frames, the plot series, the expected outcome, the tunnel
/// marker. A ball's rows clear one of them only when the ball's previous
/// sweep showed it, right after the sweep's own rows (so that a clear
/// keeps its place among the sweeps of one frame).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Shown {
    bits: u8,
    /// Edge slots logged.
    edge_slots: u8,
    /// Plot entities that got a value (bits of [`plot_entity`]).
    plotted: u16,
}

impl Shown {
    const CONTACT: u8 = 1;
    const PRIMARY: u8 = 2;
    const EDGE: u8 = 4;
    const VERTEX: u8 = 8;
    const EXPECTED: u8 = 16;
    const TUNNEL: u8 = 32;

    /// What the rows of `r` show, as the logger with `options` draws them
    /// (`edges`: scratch for the edge tests chosen).
    pub(crate) fn of(
        r: &SweepResult,
        options: &PrepareOptions,
        edges: &mut Vec<EdgeRecord>,
    ) -> Shown {
        let mut bits = 0;
        if r.outcome.contact.is_some() && r.outcome.normal.is_some() {
            bits |= Shown::CONTACT;
        }
        let decisive = r.decisive_record();
        if let Some(t) = decisive
            && r.scene.mesh.triangle_by_index(t.triangle()).is_some()
        {
            bits |= Shown::PRIMARY
                | match t {
                    TestRecord::Edge(_) => Shown::EDGE,
                    TestRecord::Vertex(_) => Shown::VERTEX,
                    TestRecord::Face(_) => 0,
                };
        }
        if r.expected.is_some() && !divergence(r, &options.tolerances).is_empty() {
            bits |= Shown::EXPECTED;
        }
        if !r.tunnels.is_empty() {
            bits |= Shown::TUNNEL;
        }
        choose_edges(edges, r, decisive, options.max_edge_frames);
        Shown {
            bits,
            edge_slots: u8::try_from(edges.len()).unwrap_or(u8::MAX),
            plotted: plot_bits(decisive),
        }
    }

    fn has(self, bit: u8) -> bool {
        self.bits & bit != 0
    }

    /// What the rows drawn for a sweep show of what [`transition_rows`]
    /// clears: `edge_slots` edge frames, the `plotted` plot entities,
    /// whether the expected outcome and a tunnel marker were drawn (the rest
    /// is cleared where it is drawn, from the previous sweep's `Shown::of`).
    pub(crate) fn drawn(edge_slots: usize, plotted: u16, expected: bool, tunnel: bool) -> Shown {
        let bit = |on: bool, b: u8| if on { b } else { 0 };
        Shown {
            bits: bit(expected, Shown::EXPECTED) | bit(tunnel, Shown::TUNNEL),
            edge_slots: u8::try_from(edge_slots).unwrap_or(u8::MAX),
            plotted,
        }
    }

    /// Whether `self` and `drawn` agree on what [`transition_rows`] clears.
    pub(crate) fn same_drawn(self, drawn: Shown) -> bool {
        let mask = Shown::EXPECTED | Shown::TUNNEL;
        (self.bits & mask, self.edge_slots, self.plotted)
            == (drawn.bits & mask, drawn.edge_slots, drawn.plotted)
    }
}

/// Clears, at ball `b`'s sweep that shows `now`, what its previous sweep
/// showed (`out.before`) and this one does not, of the edge frames, plot
/// series, expected outcome and tunnel marker (the rest is cleared where it
/// is drawn).
pub(crate) fn transition_rows(out: &mut Out<'_>, b: u32, now: Shown) {
    let before = out.before;
    for slot in now.edge_slots..before.edge_slots {
        out.clear(Entity::EdgeFrame(b, usize::from(slot)), true);
    }
    let gone = before.plotted & !now.plotted;
    for bit in (0..PLOT_BITS).filter(|bit| gone & (1 << bit) != 0) {
        out.clear(plot_entity(b, bit), false);
    }
    if before.has(Shown::EXPECTED) && !now.has(Shown::EXPECTED) {
        out.clear(Entity::Expected(b), true);
    }
    if before.has(Shown::TUNNEL) && !now.has(Shown::TUNNEL) {
        out.clear(Entity::Tunnel(b), false);
    }
}

/// Where the rows of one sweep go.
pub(crate) struct Out<'a> {
    pub(crate) columns: &'a mut columns::Columns,
    pub(crate) frame: i64,
    pub(crate) time: columns::Time,
    /// What the ball's previous sweep left shown ([`Shown`]).
    pub(crate) before: Shown,
}

impl Out<'_> {
    pub(crate) fn row(&mut self, entity: Entity, set: u8) -> Row<'_> {
        self.columns.row(entity, set, self.frame, self.time)
    }

    fn clear(&mut self, entity: Entity, recursive: bool) {
        self.row(entity, set::CLEAR)
            .put::<ClearIsRecursive>(Clear::descriptor_is_recursive, [recursive.into()]);
    }

    /// Clears `entity` (not recursively) if the ball's previous sweep
    /// showed it (`bit` of [`Shown`]).
    fn clear_shown(&mut self, entity: Entity, bit: u8) {
        if self.before.has(bit) {
            self.clear(entity, false);
        }
    }
}

/// Bits of [`plot_rows`]'s answer: which plot entities got a value.
pub(crate) const QUADRATIC_BITS: u16 = 0;
pub(crate) const FACE_BITS: u16 = QUADRATIC_NAMES.len() as u16;

/// The plot entity of bit `bit` (see [`plot_rows`]).
pub(crate) fn plot_entity(ball: u32, bit: u16) -> Entity {
    if bit < FACE_BITS {
        Entity::Quadratic(ball, (bit - QUADRATIC_BITS) as usize)
    } else {
        Entity::Face(ball, (bit - FACE_BITS) as usize)
    }
}

/// How many plot bits there are.
pub(crate) const PLOT_BITS: u16 = FACE_BITS + FACE_NAMES.len() as u16;

/// The ball at p0, at the contact and at p1, the swept volume, the contact
/// and the normal. No labels: the numbers are in the decision line.
pub(crate) fn sweep_rows(out: &mut Out<'_>, r: &SweepResult) {
    let b = r.ball;
    let o = &r.outcome;
    let p0 = r.sweep.p0;
    let d = r.sweep.p1 - p0;
    let rho = r.rho();
    let radius = r.sweep.radius as f32;
    let at_contact = p0 + d * o.alpha;

    let hit = o.is_hit();
    let n = if hit { 3 } else { 2 };
    let contact_center = hit.then(|| f32x3(at_contact.coords));
    let contact_color = hit.then(|| rgba(CONTACT_BALL_COLOR));
    out.row(Entity::Spheres(b), set::SPHERES)
        .put::<HalfSize3D>(
            Ellipsoids3D::descriptor_half_sizes,
            std::iter::repeat_n(HalfSize3D::splat(radius), n),
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
        .put::<FillMode>(Ellipsoids3D::descriptor_fill_mode, [FillMode::Solid]);

    // The swept volume at the detection radius.
    let (length, rotation) = capsule_pose(&d);
    out.row(Entity::Sweep(b), set::SWEEP)
        .put::<Length>(Capsules3D::descriptor_lengths, [length.into()])
        .put::<Radius>(Capsules3D::descriptor_radii, [(rho as f32).into()])
        .put::<Translation3D>(
            Capsules3D::descriptor_translations,
            [f32x3(p0.coords).into()],
        )
        .put::<RotationQuat>(Capsules3D::descriptor_quaternions, [rotation.into()])
        .put::<Color>(Capsules3D::descriptor_colors, [rgba(SWEEP_COLOR)])
        .put::<FillMode>(Capsules3D::descriptor_fill_mode, [FillMode::MajorWireframe]);

    match (o.contact, o.normal) {
        (Some(c), Some(nrm)) => {
            contact_row(out, Entity::Contact(b), f32x3(c.coords), HIT_COLOR);
            normal_row(
                out,
                Entity::Normal(b),
                f32x3(c.coords),
                f32x3(nrm * (r.sweep.radius.max(1e-3) * 1.5)),
                NORMAL_COLOR,
            );
        }
        _ => {
            out.clear_shown(Entity::Contact(b), Shown::CONTACT);
            out.clear_shown(Entity::Normal(b), Shown::CONTACT);
        }
    }
}

fn contact_row(out: &mut Out<'_>, entity: Entity, at: [f32; 3], color: [u8; 4]) {
    out.row(entity, set::CONTACT)
        .put::<Position3D>(Points3D::descriptor_positions, [at.into()])
        .put::<Radius>(Points3D::descriptor_radii, [ui_points(5.0)])
        .put::<Color>(Points3D::descriptor_colors, [rgba(color)]);
}

fn normal_row(out: &mut Out<'_>, entity: Entity, from: [f32; 3], v: [f32; 3], color: [u8; 4]) {
    out.row(entity, set::NORMAL)
        .put::<Vector3D>(Arrows3D::descriptor_vectors, [v.into()])
        .put::<Position3D>(Arrows3D::descriptor_origins, [from.into()])
        .put::<Color>(Arrows3D::descriptor_colors, [rgba(color)]);
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
        r.outcome.alpha
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

/// The primary (or nearest-miss) triangle: filled, its three edges
/// outlined, its decisive edge bold or its vertex as a point; one label, on
/// the decisive feature.
///
/// A nearest miss is labelled only for the followed ball (`followed`), so
/// that the balls that hit nothing do not cover the picture with labels.
pub(crate) fn primary_rows(
    out: &mut Out<'_>,
    r: &SweepResult,
    decisive: Option<&TestRecord>,
    followed: bool,
) {
    let b = r.ball;
    let triangle = decisive.and_then(|t| r.scene.mesh.triangle_by_index(t.triangle()));
    let (Some(t), Some(test)) = (triangle, decisive) else {
        out.clear_shown(Entity::PrimaryTriangle(b), Shown::PRIMARY);
        out.clear_shown(Entity::PrimaryOutline(b), Shown::PRIMARY);
        out.clear_shown(Entity::PrimaryEdge(b), Shown::EDGE);
        out.clear_shown(Entity::PrimaryVertex(b), Shown::VERTEX);
        return;
    };
    let hit = test.alpha().is_some();
    let color = if hit { HIT_COLOR } else { MISS_COLOR };
    // Lift the highlight a little off the mesh so it is not hidden by it.
    let lift = t.normal * (r.rho() * 0.02);
    let verts: [[f32; 3]; 3] = std::array::from_fn(|i| f32x3(t.vertices[i].coords + lift));
    out.row(Entity::PrimaryTriangle(b), set::TRIANGLE)
        .put::<Position3D>(
            Mesh3D::descriptor_vertex_positions,
            verts.map(Position3D::from),
        )
        .put::<TriangleIndices>(Mesh3D::descriptor_triangle_indices, [[0u32, 1, 2].into()])
        .put::<AlbedoFactor>(
            Mesh3D::descriptor_albedo_factor,
            [albedo([color[0], color[1], color[2], 90]).into()],
        );
    let label = Label(test);
    let prefix = if hit { "" } else { "nearest miss: " };
    let labelled = hit || followed;
    let is_face = labelled && matches!(test, TestRecord::Face(_));
    out.row(Entity::PrimaryOutline(b), set::LABELED_STRIP)
        .put_strip(
            LineStrips3D::descriptor_strips,
            &[verts[0], verts[1], verts[2], verts[0]],
        )
        .put::<Radius>(LineStrips3D::descriptor_radii, [ui_points(OUTLINE_POINTS)])
        .put::<Color>(LineStrips3D::descriptor_colors, [rgba(color)])
        .put_texts(LineStrips3D::descriptor_labels, |s| {
            if is_face {
                s.push_fmt(format_args!("{prefix}{label}"));
            }
        });
    let f = test.feature() as usize % 3;
    match test {
        TestRecord::Edge(_) => {
            out.row(Entity::PrimaryEdge(b), set::LABELED_STRIP)
                .put_strip(
                    LineStrips3D::descriptor_strips,
                    &[verts[f], verts[(f + 1) % 3]],
                )
                .put::<Radius>(
                    LineStrips3D::descriptor_radii,
                    [ui_points(BOLD_EDGE_POINTS)],
                )
                .put::<Color>(LineStrips3D::descriptor_colors, [rgba(color)])
                .put_texts(LineStrips3D::descriptor_labels, |s| {
                    if labelled {
                        s.push_fmt(format_args!("{prefix}{label}"));
                    }
                });
            out.clear_shown(Entity::PrimaryVertex(b), Shown::VERTEX);
        }
        TestRecord::Vertex(_) => {
            out.row(Entity::PrimaryVertex(b), set::LABELED_POINT)
                .put::<Position3D>(Points3D::descriptor_positions, [verts[f].into()])
                .put::<Radius>(Points3D::descriptor_radii, [ui_points(VERTEX_POINTS)])
                .put::<Color>(Points3D::descriptor_colors, [rgba(color)])
                .put_texts(Points3D::descriptor_labels, |s| {
                    if labelled {
                        s.push_fmt(format_args!("{prefix}{label}"));
                    }
                });
            out.clear_shown(Entity::PrimaryEdge(b), Shown::EDGE);
        }
        TestRecord::Face(_) => {
            out.clear_shown(Entity::PrimaryEdge(b), Shown::EDGE);
            out.clear_shown(Entity::PrimaryVertex(b), Shown::VERTEX);
        }
    }
}

/// The expected outcome beside the replayed one, for a divergent sweep:
/// the ball at the expected α, the expected contact and normal (when the
/// expectation names them).
pub(crate) fn expected_rows(out: &mut Out<'_>, r: &SweepResult, e: &OutcomeMsg) {
    let b = r.ball;
    let p0 = r.sweep.p0;
    let d = r.sweep.p1 - p0;
    let alpha = if e.alpha.is_finite() {
        e.alpha.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let center = p0 + d * alpha;
    out.row(Entity::ExpectedBall(b), set::EXPECTED_BALL)
        .put::<HalfSize3D>(
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
        .put_fmt(
            Ellipsoids3D::descriptor_labels,
            format_args!("expected: {}", e.kind),
        );
    let contact = e.contact.flatten();
    match contact {
        Some(c) => contact_row(
            out,
            Entity::ExpectedContact(b),
            c.map(|x| x as f32),
            EXPECTED_COLOR,
        ),
        None => out.clear(Entity::ExpectedContact(b), false),
    }
    match (e.normal.flatten(), contact) {
        (Some(n), Some(c)) => {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                let k = r.sweep.radius.max(1e-3) * 1.5 / len;
                normal_row(
                    out,
                    Entity::ExpectedNormal(b),
                    c.map(|x| x as f32),
                    n.map(|x| (x * k) as f32),
                    EXPECTED_COLOR,
                );
            } else {
                out.clear(Entity::ExpectedNormal(b), false);
            }
        }
        _ => out.clear(Entity::ExpectedNormal(b), false),
    }
}

/// A `Scalars` row.
fn scalar(out: &mut Out<'_>, entity: Entity, v: f64) {
    out.row(entity, set::SCALAR)
        .put::<Scalar>(Scalars::descriptor_scalars, [v.into()]);
}

/// Which plot entities the decisive test's numbers go to (bit `i` for
/// `plot_entity(ball, i)`): those of its values that are finite.
pub(crate) fn plot_bits(decisive: Option<&TestRecord>) -> u16 {
    let bits = |values: &[Option<f64>], first: u16| {
        values
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_some_and(f64::is_finite))
            .fold(0u16, |acc, (i, _)| acc | 1 << (first + i as u16))
    };
    let quadratic = |a, b, c, d, roots: Option<(f64, f64)>| {
        let (s0, s1) = roots.unzip();
        bits(
            &[Some(a), Some(b), Some(c), Some(d), s0, s1],
            QUADRATIC_BITS,
        )
    };
    match decisive {
        Some(TestRecord::Edge(e)) => quadratic(e.a, e.b, e.c, e.discriminant, e.roots),
        Some(TestRecord::Vertex(v)) => quadratic(v.a, v.b, v.c, v.discriminant, v.roots),
        Some(TestRecord::Face(f)) => bits(&[Some(f.h0), Some(f.h1), f.beta], FACE_BITS),
        None => 0,
    }
}

/// The α plot and the decisive test's numbers; returns which plot entities
/// got a value (bit `i` for `plot_entity(ball, i)`, as [`plot_bits`]).
pub(crate) fn plot_rows(out: &mut Out<'_>, r: &SweepResult, decisive: Option<&TestRecord>) -> u16 {
    let b = r.ball;
    // One row: α and the kind beside it.
    out.row(Entity::Alpha(b), set::KIND)
        .put::<Scalar>(Scalars::descriptor_scalars, [r.outcome.alpha.into()])
        .put_strs(|| any_value::<Text>("kind"), [r.outcome.kind.as_str()]);
    let mut plotted = 0u16;
    let mut quadratic = |a: f64, bb: f64, c: f64, disc: f64, roots: Option<(f64, f64)>| {
        let (s0, s1) = roots.unzip();
        for (i, v) in [Some(a), Some(bb), Some(c), Some(disc), s0, s1]
            .into_iter()
            .enumerate()
        {
            if let Some(v) = v.filter(|v| v.is_finite()) {
                scalar(out, Entity::Quadratic(b, i), v);
                plotted |= 1 << (QUADRATIC_BITS + i as u16);
            }
        }
    };
    match decisive {
        Some(TestRecord::Edge(e)) => quadratic(e.a, e.b, e.c, e.discriminant, e.roots),
        Some(TestRecord::Vertex(v)) => quadratic(v.a, v.b, v.c, v.discriminant, v.roots),
        Some(TestRecord::Face(f)) => {
            for (i, v) in [Some(f.h0), Some(f.h1), f.beta].into_iter().enumerate() {
                if let Some(v) = v.filter(|v| v.is_finite()) {
                    scalar(out, Entity::Face(b, i), v);
                    plotted |= 1 << (FACE_BITS + i as u16);
                }
            }
        }
        None => {}
    }
    plotted
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
/// back): a marker where each crossed the triangle's plane and a WARN line
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
                t.push_fmt(format_args!("tunnel: triangle {}", tunnel.triangle));
            }
        });
    for tunnel in &r.tunnels {
        let at = crate::replay::TunnelAt {
            frame: r.frame,
            ball: r.ball,
            tunnel: *tunnel,
        };
        out.row(Entity::Divergences, set::TEXT_LOG)
            .put_texts(TextLog::descriptor_text, |t| {
                t.push_fmt(format_args!("tunnel: {at}"));
            })
            .put_strs(TextLog::descriptor_level, [TextLogLevel::WARN]);
    }
    true
}
