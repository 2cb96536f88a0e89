//! A trace's contact queries drawn in the recording: each query's answered
//! contacts at their points with their normals (green when they agree with
//! the core's contact set, magenta where a problem names them, cyan for a
//! ghost contact with its angle as the label), the normal expected there
//! beside a differing one, the places the answer leaves out, and per ball
//! a plot of how many contacts and ghost contacts each query has. What each
//! query shows is the judge's ([`crate::judge::contact_marks`]), shared with
//! the Foxglove file.
//!
//! The rows go into the logger's typed columns, as the sweeps' do (one
//! chunk per entity, through the temporary file for a recording file), not
//! row by row through the SDK: a query costs a handful of plain appends.

use std::collections::BTreeSet;
use std::io::{Seek, Write};

use thiserror::Error;

use rerun::components::{Position3D, Radius, Scalar, TextLogLevel, Vector3D};
use rerun::{Arrows3D, Color, Points3D, Scalars, SeriesLines, TextLog};

use crate::foxglove::{FoxgloveError, FoxgloveWriter};
use crate::judge::PairedContacts;
use crate::judge::contact_marks::{
    ContactDrawing, ContactEvent, ContactsDrawn, Mark, contact_marks, for_each_judged_query,
};
use crate::palette::{EXPECTED_COLOR, FACE_NORMAL_COLOR, GHOST_COLOR, NORMAL_COLOR};
use crate::trace::{TraceError, TraceEvent};

use super::columns::{Columns, Time};
use super::convert::{SERIES_COLORS, rgba, ui_points};
use super::logger::time_of;
use super::out::set;
use super::paths::{CONTACT_SERIES, Entity};
use super::{Logger, RecordError};

/// Queries drawn between two looks at whether the logger's buffer is full
/// (a look visits every entity's columns).
const QUERIES_PER_LOOK: u32 = 64;

/// Draws the contact queries of `events` (a trace read again: sweeps and
/// expectations pass by) into `logger`'s recording, each at its frame and
/// `log_time`; with `foxglove`, writes them into that file too
/// ([`FoxgloveWriter::contact_queries`]), judged once for both.
pub fn draw_contacts<W: Write + Seek>(
    logger: &mut Logger,
    mut foxglove: Option<&mut FoxgloveWriter<W>>,
    events: impl Iterator<Item = Result<TraceEvent, TraceError>>,
    how: &ContactDrawing<'_>,
) -> Result<ContactsDrawn, DrawContactsError> {
    // A scene without sweeps (a trace of contact queries only) is shown now.
    logger
        .show_pending_scene(None)
        .map_err(|e| DrawContactsError::Recording(e.into()))?;
    let mut rows = QueryRows {
        logger,
        styled: BTreeSet::new(),
        since_look: 0,
    };
    let drawn = for_each_judged_query(events, how, |event| {
        rows.draw(event).map_err(DrawContactsError::Recording)?;
        if let Some(file) = foxglove.as_deref_mut() {
            file.contact_event(event)
                .map_err(DrawContactsError::Foxglove)?;
        }
        Ok(())
    })?;
    rows.logger.flush().map_err(DrawContactsError::Recording)?;
    Ok(drawn)
}

/// Drawing the contact queries failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DrawContactsError {
    /// Into the recording.
    #[error("drawing the contact queries")]
    Recording(#[source] RecordError),
    /// Into the Foxglove file.
    #[error("writing the contact queries to the Foxglove file")]
    Foxglove(#[source] FoxgloveError),
}

/// The recording's side of [`draw_contacts`].
struct QueryRows<'l> {
    logger: &'l mut Logger,
    /// The balls whose plot's style is sent.
    styled: BTreeSet<u32>,
    /// Queries drawn since the last look at the logger's buffer.
    since_look: u32,
}

impl QueryRows<'_> {
    fn draw(&mut self, event: ContactEvent<'_>) -> Result<(), RecordError> {
        // (A ball's entities keep what its last query showed until its
        // next one, across scenes as for its sweeps.)
        let ContactEvent::Query(paired) = event else {
            return Ok(());
        };
        let ball = paired.query.ball;
        if self.styled.insert(ball) {
            let style = SeriesLines::new().with_names(CONTACT_SERIES).with_colors(
                SERIES_COLORS[..CONTACT_SERIES.len()]
                    .iter()
                    .map(|&c| rgba(c)),
            );
            self.logger
                .log_static(Entity::ContactPlot(ball).path(), &style)?;
        }
        contact_rows(self.logger.columns(), paired);
        self.logger.count_contact_query(
            ball,
            !paired.verdict.agrees() || !paired.verdict.ghosts.is_empty(),
        );
        self.since_look += 1;
        if self.since_look == QUERIES_PER_LOOK {
            self.since_look = 0;
            self.logger.flush_if_full()?;
        }
        Ok(())
    }
}

/// The rows of one judged query: its contacts, their normals, the expected
/// normals, the places left out (each logged, empty or not, at every query
/// of the ball), a line per ghost and problem in the divergences' log, and
/// the ball's plot of the counts.
fn contact_rows(columns: &mut Columns, p: &PairedContacts) {
    let q = &p.query;
    let (b, frame, time) = (
        q.ball,
        i64::try_from(q.frame).unwrap_or(i64::MAX),
        time_of(p.log_time_nanos),
    );
    let length = (q.radius * 3.0) as f32;
    let arrow = |n: [f64; 3]| {
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
            .sqrt()
            .max(f64::MIN_POSITIVE);
        Vector3D::from(n.map(|x| (x / norm) as f32 * length))
    };
    let at = |p: [f64; 3]| Position3D::from(p.map(|x| x as f32));
    let marks = contact_marks(p);
    fn color_and_label(mark: &Mark) -> ([u8; 4], &str) {
        match mark {
            Mark::Ghost(label) => (GHOST_COLOR, label),
            Mark::Problem(problem) => (EXPECTED_COLOR, problem),
            Mark::Agrees => (NORMAL_COLOR, ""),
        }
    }
    let colors = || {
        marks
            .contacts
            .iter()
            .map(|c| rgba(color_and_label(&c.mark).0))
    };
    let points = || marks.contacts.iter().map(|c| at(c.point));
    let when = (frame, time);
    labelled_points(
        columns,
        Entity::Contacts(b),
        when,
        points(),
        colors(),
        5.0,
        marks.contacts.iter().map(|c| color_and_label(&c.mark).1),
    );
    let normals = marks
        .contacts
        .iter()
        .map(|c| c.normal.map_or(Vector3D::from([0.0; 3]), arrow));
    arrows(
        columns,
        Entity::ContactNormals(b),
        when,
        normals,
        points(),
        colors(),
    );
    // What the core expected where the answer differs: the normal beside a
    // differing or ghost normal, and the places left out.
    let expected = &marks.expected_normals;
    arrows(
        columns,
        Entity::ContactExpected(b),
        when,
        expected.iter().map(|(_, n)| arrow(*n)),
        expected.iter().map(|(p, _)| at(*p)),
        [rgba(FACE_NORMAL_COLOR)],
    );
    labelled_points(
        columns,
        Entity::ContactMissing(b),
        when,
        marks.missing.iter().map(|(p, _)| at(*p)),
        [rgba(EXPECTED_COLOR)],
        6.0,
        marks.missing.iter().map(|(_, words)| words.as_str()),
    );
    // The text log of divergences gets a line per ghost and problem.
    for line in &marks.log {
        columns
            .row(Entity::Divergences, set::TEXT_LOG, frame, time)
            .put_strs(TextLog::descriptor_text, [line.as_str()])
            .put_strs(TextLog::descriptor_level, [TextLogLevel::WARN]);
    }
    columns
        .row(Entity::ContactPlot(b), set::SCALAR, frame, time)
        .put::<Scalar>(
            Scalars::descriptor_scalars,
            [
                (p.answer.contacts.len() as f64).into(),
                (p.verdict.ghosts.len() as f64).into(),
            ],
        );
}

/// A row of labelled points (`radius` in UI points) of `entity` at `when`
/// (frame, time).
fn labelled_points<'s>(
    columns: &mut Columns,
    entity: Entity,
    when: (i64, Time),
    positions: impl IntoIterator<Item = Position3D>,
    colors: impl IntoIterator<Item = Color>,
    radius: f32,
    labels: impl IntoIterator<Item = &'s str>,
) {
    columns
        .row(entity, set::CONTACT_POINTS, when.0, when.1)
        .put::<Position3D>(Points3D::descriptor_positions, positions)
        .put::<Color>(Points3D::descriptor_colors, colors)
        .put::<Radius>(Points3D::descriptor_radii, [ui_points(radius)])
        .put_strs(Points3D::descriptor_labels, labels);
}

/// A row of arrows (2 UI points wide) of `entity` at `when` (frame, time).
fn arrows(
    columns: &mut Columns,
    entity: Entity,
    when: (i64, Time),
    vectors: impl IntoIterator<Item = Vector3D>,
    origins: impl IntoIterator<Item = Position3D>,
    colors: impl IntoIterator<Item = Color>,
) {
    columns
        .row(entity, set::ARROWS, when.0, when.1)
        .put::<Vector3D>(Arrows3D::descriptor_vectors, vectors)
        .put::<Position3D>(Arrows3D::descriptor_origins, origins)
        .put::<Color>(Arrows3D::descriptor_colors, colors)
        .put::<Radius>(Arrows3D::descriptor_radii, [ui_points(2.0)]);
}
