//! What a judged contact query shows, whatever draws it (the Rerun
//! recording, the Foxglove file): each answered contact at its point with
//! its normal and its mark (agrees, a problem names it, a ghost contact),
//! the normal expected beside a differing or ghost one, the places the
//! answer leaves out, and the lines of the divergences' log.
//! [`for_each_judged_query`] reads a trace's queries and answers and
//! judges them as `check` does, for either drawing.

use crate::conventions::EngineConventions;
use crate::replay::FrameRange;
use crate::trace::{EventBody, TraceError, TraceEvent};

use rayon::prelude::*;

use super::contact_pairing::{ContactPairing, Pair, PairedContacts};
use super::contacts::ContactProblem;
use super::{ContactVerdict, Tolerances};

/// How a trace's contact queries are judged for drawing: as `check` judges
/// them, within a selection of frames and balls.
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
    /// The threads that judge the queries (each scene's, a batch at a
    /// time); none: rayon's global pool.
    pub pool: Option<&'a rayon::ThreadPool>,
}

/// Queries judged together, in parallel, before they are drawn in order.
const JUDGED_TOGETHER: usize = 256;

/// What [`for_each_judged_query`] hands its drawing, in the trace's order.
#[derive(Clone, Copy)]
pub(crate) enum ContactEvent<'a> {
    /// A judged query.
    Query(&'a PairedContacts),
    /// A scene after the first, at its `log_time` (the previous scene's
    /// queries are all drawn; what they show may be cleared).
    NewScene {
        /// The scene's `log_time`.
        log_time_nanos: u64,
    },
}

/// What was drawn of a trace's contact queries.
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

impl ContactsDrawn {
    /// Counts one judged query.
    pub(crate) fn add(&mut self, p: &PairedContacts) {
        self.queries += 1;
        self.contacts += p.answer.contacts.len() as u64;
        self.divergent += u64::from(!p.verdict.agrees());
        self.ghosts += p.verdict.ghosts.len() as u64;
    }
}

/// Reads `events` (a trace: sweeps and expectations pass by), pairs each
/// contact query the selection keeps with its answer, judges it and hands
/// it to `draw`, with each scene change, in the trace's order (the queries of a scene are judged
/// [`JUDGED_TOGETHER`] at a time, in parallel, on `how.pool`). A read
/// error ends the reading (the replay reported it already); an error of
/// `draw` is returned.
pub(crate) fn for_each_judged_query<E>(
    events: impl Iterator<Item = Result<TraceEvent, TraceError>>,
    how: &ContactDrawing<'_>,
    mut draw: impl FnMut(ContactEvent<'_>) -> Result<(), E>,
) -> Result<ContactsDrawn, E> {
    let mut pairing = ContactPairing::new(how.tolerances, how.conventions, how.ghost_degrees);
    let mut drawn = ContactsDrawn::default();
    let mut pairs = Vec::with_capacity(JUDGED_TOGETHER);
    let mut scenes = 0u64;
    let wants =
        |frame: u64, ball: u32| how.frames.contains(frame) && how.ball.is_none_or(|b| b == ball);
    for event in events {
        let Ok(event) = event else { break };
        let pair = match &event.body {
            EventBody::Scene(scene) => {
                judge_and_draw(&pairing, &mut pairs, how.pool, &mut draw, &mut drawn)?;
                if scenes > 0 {
                    draw(ContactEvent::NewScene {
                        log_time_nanos: event.header.log_time_nanos,
                    })?;
                }
                scenes += 1;
                pairing.scene(scene);
                None
            }
            EventBody::Contact(q) if wants(q.frame, q.ball) => {
                pairing.pair_query(q, event.header.log_time_nanos)
            }
            EventBody::ExpectedContacts(a) if wants(a.frame, a.ball) => pairing.pair_answer(a),
            _ => None,
        };
        if let Some(pair) = pair {
            pairs.push(pair);
            if pairs.len() == JUDGED_TOGETHER {
                judge_and_draw(&pairing, &mut pairs, how.pool, &mut draw, &mut drawn)?;
            }
        }
    }
    judge_and_draw(&pairing, &mut pairs, how.pool, &mut draw, &mut drawn)?;
    Ok(drawn)
}

/// Judges `pairs` (emptied) in parallel on `pool`, then draws them in
/// their order and counts them.
fn judge_and_draw<E>(
    pairing: &ContactPairing<'_>,
    pairs: &mut Vec<Pair>,
    pool: Option<&rayon::ThreadPool>,
    draw: &mut impl FnMut(ContactEvent<'_>) -> Result<(), E>,
    drawn: &mut ContactsDrawn,
) -> Result<(), E> {
    let mut judge = || -> Vec<Option<PairedContacts>> {
        pairs
            .par_drain(..)
            .map(|pair| pairing.judge(pair))
            .collect()
    };
    let judged = match pool {
        Some(pool) => pool.install(judge),
        None => judge(),
    };
    for paired in judged.iter().flatten() {
        draw(ContactEvent::Query(paired))?;
        drawn.add(paired);
    }
    Ok(())
}

/// How an answered contact is marked.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Mark {
    /// It agrees with the core's contact set.
    Agrees,
    /// A problem names its triangle (the problem in words).
    Problem(String),
    /// A ghost contact (its label: the angle).
    Ghost(String),
}

/// One answered contact, as drawn.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MarkedContact {
    /// Its point.
    pub(crate) point: [f64; 3],
    /// Its normal, when the answer gives one.
    pub(crate) normal: Option<[f64; 3]>,
    /// Its mark.
    pub(crate) mark: Mark,
}

/// What a judged query shows ([`contact_marks`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct ContactMarks {
    /// The answered contacts that give a point.
    pub(crate) contacts: Vec<MarkedContact>,
    /// Where the expected normal differs from the answer's, or the faces'
    /// normal under a ghost contact: `(point, normal)`.
    pub(crate) expected_normals: Vec<([f64; 3], [f64; 3])>,
    /// The places the answer leaves out: `(point, the problem in words)`.
    pub(crate) missing: Vec<([f64; 3], String)>,
    /// The divergences' log lines: a ghost contact or a problem each.
    pub(crate) log: Vec<String>,
}

/// The triangle a problem names, unless it is a missing place.
fn named_triangle(p: &ContactProblem) -> Option<u32> {
    match p {
        ContactProblem::Extra { triangle, .. }
        | ContactProblem::Feature { triangle, .. }
        | ContactProblem::Point { triangle, .. }
        | ContactProblem::Separation { triangle, .. }
        | ContactProblem::Normal { triangle, .. }
        | ContactProblem::NormalLength { triangle, .. } => Some(*triangle),
        ContactProblem::Missing { .. } => None,
    }
}

/// What the judged query `p` shows.
pub(crate) fn contact_marks(p: &PairedContacts) -> ContactMarks {
    let (q, v): (_, &ContactVerdict) = (&p.query, &p.verdict);
    let point_of = |triangle: u32| {
        p.answer
            .contacts
            .iter()
            .find(|c| c.triangle == triangle)
            .and_then(|c| c.point)
    };
    let mut marks = ContactMarks::default();
    for c in &p.answer.contacts {
        let Some(point) = c.point else { continue };
        let ghost = v.ghosts.iter().find(|g| g.triangle == c.triangle);
        let problem = v
            .problems
            .iter()
            .find(|p| named_triangle(p) == Some(c.triangle));
        let mark = match (ghost, problem) {
            (Some(g), _) => Mark::Ghost(g.label()),
            (None, Some(problem)) => Mark::Problem(problem.to_string()),
            (None, None) => Mark::Agrees,
        };
        marks.contacts.push(MarkedContact {
            point,
            normal: c.normal,
            mark,
        });
    }
    for problem in &v.problems {
        match problem {
            ContactProblem::Normal {
                triangle, expected, ..
            } => {
                if let Some(at) = point_of(*triangle) {
                    marks.expected_normals.push((at, *expected));
                }
            }
            ContactProblem::Missing { point, .. } => {
                marks.missing.push((*point, problem.to_string()));
            }
            _ => {}
        }
    }
    for g in &v.ghosts {
        if let Some(at) = point_of(g.triangle) {
            marks.expected_normals.push((at, g.face_normal));
        }
    }
    marks.log = v
        .ghosts
        .iter()
        .map(|g| format!("ghost contact: {g}"))
        .chain(
            v.problems
                .iter()
                .map(|p| format!("contact query, frame {}, ball {}: {p}", q.frame, q.ball)),
        )
        .collect();
    marks
}
