//! A trace's contact queries as Foxglove messages, judged as `check`
//! judges them: what each query shows is the judge's
//! ([`crate::judge::contact_marks`]), as in the Rerun recording.

use std::fmt::Write as _;

use super::FRAME_ID;
use super::convert::{arrow, key_value, sphere};
use super::messages::{Log, LogLevel, SceneEntity, SceneUpdate, Time};
use crate::judge::PairedContacts;
use crate::judge::contact_marks::{Mark, contact_marks};
use crate::palette::{EXPECTED_COLOR, FACE_NORMAL_COLOR, GHOST_COLOR, NORMAL_COLOR};

/// One contact query, on [`super::CONTACT_QUERIES_TOPIC`]: entity
/// `contact_query/{ball}` (replacing the ball's previous query) with a
/// marker at each answered contact (green when it agrees with the core's
/// contact set, magenta where a problem names it, cyan for a ghost
/// contact) and its normal, the normal expected beside a differing or
/// ghost one, the places the answer leaves out (magenta, larger), and in
/// the metadata the counts and each problem or ghost in words.
pub(crate) fn contact_query_update(p: &PairedContacts) -> SceneUpdate {
    let q = &p.query;
    let time = Time::from_nanos(p.log_time_nanos);
    let size = q.radius.max(1e-3);
    let marks = contact_marks(p);
    let mut entity = SceneEntity::new(time, FRAME_ID, format!("contact_query/{}", q.ball));
    entity.metadata = vec![
        key_value("frame", q.frame),
        key_value("ball", q.ball),
        key_value("contacts", p.answer.contacts.len()),
        key_value("core's contacts", p.verdict.reference),
        key_value("ghost contacts", p.verdict.ghosts.len()),
    ];
    entity
        .metadata
        .extend(marks.log.iter().map(|line| key_value("divergence", line)));
    let unit = |n: [f64; 3]| {
        let n = nalgebra::Vector3::from(n);
        (n.norm() > 0.0).then(|| n.normalize())
    };
    for c in &marks.contacts {
        let rgba = match c.mark {
            Mark::Agrees => NORMAL_COLOR,
            Mark::Problem(_) => EXPECTED_COLOR,
            Mark::Ghost(_) => GHOST_COLOR,
        };
        let at = nalgebra::Point3::from(c.point);
        entity.spheres.push(sphere(&at, 0.1 * size, rgba));
        if let Some(n) = c.normal.and_then(unit) {
            entity.arrows.push(arrow(&at, &n, 1.5 * size, rgba));
        }
    }
    for (at, n) in &marks.expected_normals {
        if let Some(n) = unit(*n) {
            let at = nalgebra::Point3::from(*at);
            entity
                .arrows
                .push(arrow(&at, &n, 1.5 * size, FACE_NORMAL_COLOR));
        }
    }
    for (at, _) in &marks.missing {
        let at = nalgebra::Point3::from(*at);
        entity
            .spheres
            .push(sphere(&at, 0.15 * size, EXPECTED_COLOR));
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// One contact query as a Log line, on [`super::CONTACT_DECISIONS_TOPIC`]: how
/// many contacts each side has, then each problem and ghost contact;
/// WARNING when `check` fails the query (a problem or a ghost contact),
/// INFO otherwise.
pub(crate) fn contact_query_log(p: &PairedContacts, trace_name: &str) -> Log {
    let (q, v) = (&p.query, &p.verdict);
    let mut message = format!(
        "contact query, frame {}, ball {}: the core finds {}, the answer has {}",
        q.frame,
        q.ball,
        crate::numbers::counted(v.reference as u64, "contact", "contacts"),
        v.answered
    );
    for line in contact_marks(p).log {
        let _ = write!(message, "\n{line}");
    }
    let fails = !v.agrees() || !v.ghosts.is_empty();
    Log {
        timestamp: Time::from_nanos(p.log_time_nanos),
        level: if fails {
            LogLevel::Warning
        } else {
            LogLevel::Info
        },
        message,
        name: format!("ball {}", q.ball),
        file: trace_name.to_string(),
        line: 0,
    }
}
