//! A trace's contact queries drawn in the recording: each query's answered
//! contacts at their points with their normals (green when they agree with
//! the core's contact set, magenta where a problem names them, cyan for a
//! ghost contact with its angle as the label), the normal expected there
//! beside a differing one, the places the answer leaves out, and per ball
//! a plot of how many contacts and ghost contacts each query has.

use rerun::{Arrows3D, Points3D, RecordingStream, Scalars, TextLog, TextLogLevel, TimeCell};

use crate::conventions::EngineConventions;
use crate::judge::{ContactPairing, ContactProblem, PairedContacts, Tolerances};
use crate::palette::{EXPECTED_COLOR, FACE_NORMAL_COLOR, GHOST_COLOR, NORMAL_COLOR};
use crate::replay::FrameRange;
use crate::trace::{EventBody, TraceError, TraceEvent};

use super::convert::{rgba, ui_points};
use super::{FRAME_TIMELINE, TIME_TIMELINE, TIMESTAMP_THRESHOLD_NANOS};

/// How a trace's contact queries are judged for drawing: as `check` judges
/// them.
#[derive(Clone, Copy, Debug)]
pub struct ContactDrawing<'a> {
    /// The comparison's tolerances.
    pub tolerances: &'a Tolerances,
    /// The engine's conventions (its normal rule, sides, precision).
    pub conventions: &'a EngineConventions,
    /// The ghost-contact threshold, in degrees.
    pub ghost_degrees: f64,
    /// Only these frames,
    pub frames: FrameRange,
    /// and this ball.
    pub ball: Option<u32>,
}

/// What [`draw_contacts`] drew.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContactsDrawn {
    /// Queries drawn (judged against their answers).
    pub queries: u64,
    /// Contacts drawn, over the queries.
    pub contacts: u64,
    /// Of the queries, those whose contacts differ from the core's.
    pub divergent: u64,
    /// Ghost contacts drawn.
    pub ghosts: u64,
}

/// Draws the contact queries of `events` (a trace read again: sweeps and
/// expectations pass by) into `rec`, each at its frame and `log_time`.
pub fn draw_contacts(
    rec: &RecordingStream,
    events: impl Iterator<Item = Result<TraceEvent, TraceError>>,
    how: &ContactDrawing<'_>,
) -> Result<ContactsDrawn, rerun::RecordingStreamError> {
    let mut pairing = ContactPairing::new(how.tolerances, how.conventions, how.ghost_degrees);
    let mut drawn = ContactsDrawn::default();
    let wants =
        |frame: u64, ball: u32| how.frames.contains(frame) && how.ball.is_none_or(|b| b == ball);
    for event in events {
        // A read error ends the drawing; the replay reported it already.
        let Ok(event) = event else { break };
        let paired = match &event.body {
            EventBody::Scene(scene) => {
                pairing.scene(scene);
                None
            }
            EventBody::Contact(q) if wants(q.frame, q.ball) => {
                pairing.query(q, event.header.log_time_nanos)
            }
            EventBody::ExpectedContacts(a) if wants(a.frame, a.ball) => pairing.answer(a),
            _ => None,
        };
        if let Some(paired) = paired {
            draw_one(rec, &paired, &mut drawn)?;
        }
    }
    Ok(drawn)
}

fn draw_one(
    rec: &RecordingStream,
    p: &PairedContacts,
    drawn: &mut ContactsDrawn,
) -> Result<(), rerun::RecordingStreamError> {
    let (q, v) = (&p.query, &p.verdict);
    rec.set_time_sequence(FRAME_TIMELINE, i64::try_from(q.frame).unwrap_or(i64::MAX));
    let nanos = i64::try_from(p.log_time_nanos).unwrap_or(i64::MAX);
    if p.log_time_nanos >= TIMESTAMP_THRESHOLD_NANOS {
        rec.set_time(
            TIME_TIMELINE,
            TimeCell::from_timestamp_nanos_since_epoch(nanos),
        );
    } else {
        rec.set_time(TIME_TIMELINE, TimeCell::from_duration_nanos(nanos));
    }
    let length = (q.radius * 3.0) as f32;
    let arrow = |n: [f64; 3]| {
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
            .sqrt()
            .max(f64::MIN_POSITIVE);
        n.map(|x| (x / norm) as f32 * length)
    };
    let f32x3 = |p: [f64; 3]| p.map(|x| x as f32);
    let names = |p: &ContactProblem| match p {
        ContactProblem::Extra { triangle, .. }
        | ContactProblem::Feature { triangle, .. }
        | ContactProblem::Point { triangle, .. }
        | ContactProblem::Separation { triangle, .. }
        | ContactProblem::Normal { triangle, .. }
        | ContactProblem::NormalLength { triangle, .. } => Some(*triangle),
        ContactProblem::Missing { .. } => None,
    };
    let (mut points, mut colors, mut labels, mut vectors) = (vec![], vec![], vec![], vec![]);
    for c in &p.answer.contacts {
        let ghost = v.ghosts.iter().find(|g| g.triangle == c.triangle);
        let problem = v.problems.iter().find(|p| names(p) == Some(c.triangle));
        let Some(at) = c.point else { continue };
        let (color, label) = match (ghost, problem) {
            (Some(g), _) => (GHOST_COLOR, g.label()),
            (None, Some(problem)) => (EXPECTED_COLOR, problem.to_string()),
            (None, None) => (NORMAL_COLOR, String::new()),
        };
        points.push(f32x3(at));
        colors.push(rgba(color));
        labels.push(label);
        vectors.push(c.normal.map_or([0.0; 3], arrow));
    }
    let path = format!("world/ball/{}/contacts", q.ball);
    rec.log(
        path.as_str(),
        &Points3D::new(points.clone())
            .with_colors(colors.clone())
            .with_radii([ui_points(5.0)])
            .with_labels(labels),
    )?;
    rec.log(
        format!("{path}/normals"),
        &Arrows3D::from_vectors(vectors)
            .with_origins(points)
            .with_colors(colors)
            .with_radii([ui_points(2.0)]),
    )?;
    // What the core expected where the answer differs: the normal beside a
    // differing or ghost normal, and the places left out.
    let (mut origins, mut expected) = (vec![], vec![]);
    let (mut missing, mut missing_labels) = (vec![], vec![]);
    for problem in &v.problems {
        match problem {
            ContactProblem::Normal {
                triangle,
                expected: n,
                ..
            } => {
                if let Some(at) = p
                    .answer
                    .contacts
                    .iter()
                    .find(|c| c.triangle == *triangle)
                    .and_then(|c| c.point)
                {
                    origins.push(f32x3(at));
                    expected.push(arrow(*n));
                }
            }
            ContactProblem::Missing { point, .. } => {
                missing.push(f32x3(*point));
                missing_labels.push(problem.to_string());
            }
            _ => {}
        }
    }
    for g in &v.ghosts {
        if let Some(at) = p
            .answer
            .contacts
            .iter()
            .find(|c| c.triangle == g.triangle)
            .and_then(|c| c.point)
        {
            origins.push(f32x3(at));
            expected.push(arrow(g.face_normal));
        }
    }
    rec.log(
        format!("{path}/expected"),
        &Arrows3D::from_vectors(expected)
            .with_origins(origins)
            .with_colors([rgba(FACE_NORMAL_COLOR)])
            .with_radii([ui_points(2.0)]),
    )?;
    rec.log(
        format!("{path}/missing"),
        &Points3D::new(missing)
            .with_colors([rgba(EXPECTED_COLOR)])
            .with_radii([ui_points(6.0)])
            .with_labels(missing_labels),
    )?;
    // The text log of divergences gets a line per ghost and problem.
    for line in v
        .ghosts
        .iter()
        .map(|g| format!("ghost contact: {g}"))
        .chain(
            v.problems
                .iter()
                .map(|p| format!("contact query, frame {}, ball {}: {p}", q.frame, q.ball)),
        )
    {
        rec.log(
            super::paths::DIVERGENCES,
            &TextLog::new(line).with_level(TextLogLevel::WARN),
        )?;
    }
    rec.log(
        format!("plots/contacts/ball/{}", q.ball),
        &Scalars::new([p.answer.contacts.len() as f64, v.ghosts.len() as f64]),
    )?;
    drawn.queries += 1;
    drawn.contacts += p.answer.contacts.len() as u64;
    drawn.divergent += u64::from(!v.agrees());
    drawn.ghosts += v.ghosts.len() as u64;
    Ok(())
}
