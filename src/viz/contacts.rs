//! A trace's contact queries drawn in the recording: each query's answered
//! contacts at their points with their normals (green when they agree with
//! the core's contact set, magenta where a problem names them, cyan for a
//! ghost contact with its angle as the label), the normal expected there
//! beside a differing one, the places the answer leaves out, and per ball
//! a plot of how many contacts and ghost contacts each query has. What each
//! query shows is the judge's ([`crate::judge::contact_marks`]), shared with
//! the Foxglove file.

use rerun::{Arrows3D, Points3D, RecordingStream, Scalars, TextLog, TextLogLevel, TimeCell};

use crate::judge::PairedContacts;
use crate::judge::contact_marks::{
    ContactDrawing, ContactsDrawn, Mark, contact_marks, for_each_judged_query,
};
use crate::palette::{EXPECTED_COLOR, FACE_NORMAL_COLOR, GHOST_COLOR, NORMAL_COLOR};
use crate::trace::{TraceError, TraceEvent};

use super::convert::{rgba, ui_points};
use super::{FRAME_TIMELINE, TIME_TIMELINE, TIMESTAMP_THRESHOLD_NANOS};

/// Draws the contact queries of `events` (a trace read again: sweeps and
/// expectations pass by) into `rec`, each at its frame and `log_time`.
pub fn draw_contacts(
    rec: &RecordingStream,
    events: impl Iterator<Item = Result<TraceEvent, TraceError>>,
    how: &ContactDrawing<'_>,
) -> Result<ContactsDrawn, rerun::RecordingStreamError> {
    for_each_judged_query(events, how, |paired| draw_one(rec, paired))
}

fn draw_one(rec: &RecordingStream, p: &PairedContacts) -> Result<(), rerun::RecordingStreamError> {
    let q = &p.query;
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
    let marks = contact_marks(p);
    let (mut points, mut colors, mut labels, mut vectors) = (vec![], vec![], vec![], vec![]);
    for c in &marks.contacts {
        let (color, label) = match &c.mark {
            Mark::Ghost(label) => (GHOST_COLOR, label.clone()),
            Mark::Problem(problem) => (EXPECTED_COLOR, problem.clone()),
            Mark::Agrees => (NORMAL_COLOR, String::new()),
        };
        points.push(f32x3(c.point));
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
    let (origins, expected): (Vec<_>, Vec<_>) = marks
        .expected_normals
        .iter()
        .map(|(at, n)| (f32x3(*at), arrow(*n)))
        .unzip();
    rec.log(
        format!("{path}/expected"),
        &Arrows3D::from_vectors(expected)
            .with_origins(origins)
            .with_colors([rgba(FACE_NORMAL_COLOR)])
            .with_radii([ui_points(2.0)]),
    )?;
    let (missing, missing_labels): (Vec<_>, Vec<_>) = marks
        .missing
        .iter()
        .map(|(at, words)| (f32x3(*at), words.clone()))
        .unzip();
    rec.log(
        format!("{path}/missing"),
        &Points3D::new(missing)
            .with_colors([rgba(EXPECTED_COLOR)])
            .with_radii([ui_points(6.0)])
            .with_labels(missing_labels),
    )?;
    // The text log of divergences gets a line per ghost and problem.
    for line in marks.log {
        rec.log(
            super::paths::DIVERGENCES,
            &TextLog::new(line).with_level(TextLogLevel::WARN),
        )?;
    }
    rec.log(
        format!("plots/contacts/ball/{}", q.ball),
        &Scalars::new([
            p.answer.contacts.len() as f64,
            p.verdict.ghosts.len() as f64,
        ]),
    )?;
    Ok(())
}
