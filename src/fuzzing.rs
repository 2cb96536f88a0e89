//! The properties the fuzz targets check, in one place shared by the
//! `cargo fuzz` targets (`fuzz/fuzz_targets/`) and the stable tests that run
//! their committed corpus and a seeded loop (`tests/fuzz_corpus.rs`).
//!
//! Each `check_*` function takes arbitrary bytes and returns `Err` with the
//! broken property in words; a panic inside the library is a finding too.
//! Public so that the fuzz targets, a separate crate, call the same code;
//! [`repeated_segment`] is the property of every error message the tests
//! assert too.

use crate::core::record::{CollectRecords, TestRecord};
use crate::core::{
    Broadphase, ContactQuery, Facing, Mesh, MeshError, Options, Outcome, Sides, Sweep, SweptPath,
    contact_set, sweep_edge, sweep_face, sweep_mesh, sweep_mesh_with, sweep_vertex,
};
use crate::trace::validate::{validate_outcome, validate_scene, validate_sweep};
use crate::trace::{
    ContactMsg, ContactsMsg, Encoding, EventBody, MessageAt, OutcomeMsg, ReadLimits, SceneMsg,
    SweepMsg, TraceReader, parse_message_as, validate_contact, validate_contacts,
};

pub use crate::error_text::repeated_segment;

/// The source name the reader is given; every error must name it.
const SOURCE_NAME: &str = "fuzz-input.mcap";

/// Limits small enough that a fuzz input cannot make the reader allocate
/// much (the defaults allow 256 MiB chunks).
const FUZZ_LIMITS: ReadLimits = ReadLimits {
    record_bytes: 1 << 20,
    scene_bytes: 1 << 18,
    small_message_bytes: 1 << 12,
};

/// The trace reader over arbitrary bytes: it never panics; what it yields
/// is validated (finite numbers, indices in range, `log_time` never
/// decreasing, indices increasing); an error names the file, repeats no
/// part of its text, and ends the iteration; every scene it yields builds a
/// mesh or gives a [`MeshError`], and every sweep runs through the core
/// under [`check_outcome`].
///
/// Both readings are checked: in file order over the bytes as a stream, and
/// through the chunk indexes where chunks overlap in log time
/// ([`TraceReader::new_indexed`]).
pub fn check_trace_reader(data: &[u8]) -> Result<(), String> {
    check_reading(
        TraceReader::with_limits(data, SOURCE_NAME, FUZZ_LIMITS),
        data,
    )
    .map_err(|e| format!("in file order: {e}"))?;
    check_reading(
        TraceReader::with_limits_indexed(std::io::Cursor::new(data), SOURCE_NAME, FUZZ_LIMITS),
        data,
    )
    .map_err(|e| format!("through the chunk indexes: {e}"))
}

/// The properties of [`check_trace_reader`] for one reader.
fn check_reading<R: std::io::Read>(mut reader: TraceReader<R>, input: &[u8]) -> Result<(), String> {
    let mut last: Option<(u64, u64)> = None;
    let mut scene: Option<(Option<Mesh>, f64, Facing)> = None;
    let mut events = 0u64;
    while let Some(item) = reader.next() {
        let event = match item {
            Ok(event) => event,
            Err(err) => {
                check_error_text(&err, input)?;
                if reader.next().is_some() {
                    return Err(format!("the reader went on after an error: {err}"));
                }
                break;
            }
        };
        events += 1;
        let order = (event.header.log_time_nanos, event.header.index);
        if let Some(previous) = last
            && (order.0 < previous.0 || order.1 <= previous.1)
        {
            return Err(format!(
                "events out of order: (log_time, index) {order:?} after {previous:?}"
            ));
        }
        last = Some(order);
        match event.body {
            EventBody::Scene(msg) => {
                validate_scene(&msg).map_err(|p| format!("a yielded scene is invalid: {p:?}"))?;
                let mesh = build_mesh(msg.vertices.clone(), &msg.triangles)?;
                scene = Some((mesh, msg.margin, msg.facing));
            }
            EventBody::Sweep(sweep) => {
                let Some((mesh, margin, facing)) = &scene else {
                    return Err("a sweep was yielded before any scene".into());
                };
                validate_sweep(&sweep, Some(*margin))
                    .map_err(|p| format!("a yielded sweep is invalid: {p:?}"))?;
                if let Some(mesh) = mesh {
                    let options = Options {
                        margin: *margin,
                        facing: *facing,
                        ..Options::default()
                    };
                    let outcome = sweep_mesh(
                        mesh,
                        &Sweep::new(sweep.p0, sweep.p1, sweep.radius),
                        &options,
                    )
                    .map_err(|e| format!("a validated sweep is refused by the core: {e}"))?;
                    check_outcome(mesh, &outcome)?;
                }
            }
            EventBody::Expected(outcome) => {
                validate_outcome(&outcome)
                    .map_err(|p| format!("a yielded outcome is invalid: {p:?}"))?;
            }
            EventBody::Contact(contact) => {
                let Some((mesh, _, _)) = &scene else {
                    return Err("a contact query was yielded before any scene".into());
                };
                validate_contact(&contact)
                    .map_err(|p| format!("a yielded contact query is invalid: {p:?}"))?;
                if let Some(mesh) = mesh {
                    let query = ContactQuery {
                        centre: contact.centre.into(),
                        radius: contact.radius,
                        distance: contact.distance,
                    };
                    for c in contact_set(mesh, &query, Sides::One) {
                        if !(c.separation.is_finite() && c.normal.iter().all(|x| x.is_finite())) {
                            return Err(format!("a contact has a non-finite value: {c:?}"));
                        }
                    }
                }
            }
            EventBody::ExpectedContacts(contacts) => {
                validate_contacts(&contacts)
                    .map_err(|p| format!("yielded contacts are invalid: {p:?}"))?;
            }
        }
    }
    if reader.stats().messages < events {
        return Err(format!(
            "the statistics count {} messages, {events} were yielded",
            reader.stats().messages
        ));
    }
    Ok(())
}

/// The message parsing and validation over arbitrary bytes, read as JSON
/// and as CBOR, as each of the three messages: a parse error names the
/// file and the channel; a message that passes validation survives a round
/// trip through both encodings unchanged, and the core accepts it (a scene
/// builds a mesh or gives a [`MeshError`]; a sweep runs; an outcome has `α`
/// in [0, 1]).
pub fn check_message_validation(data: &[u8]) -> Result<(), String> {
    for encoding in Encoding::all() {
        check_message_validation_as(data, encoding).map_err(|e| format!("as {encoding}: {e}"))?;
    }
    Ok(())
}

fn check_message_validation_as(data: &[u8], encoding: Encoding) -> Result<(), String> {
    let at = |channel: &str| {
        let channel = channel.to_string();
        move || MessageAt {
            file: SOURCE_NAME.to_string(),
            channel,
            index: 0,
            frame: None,
        }
    };
    match parse_message_as::<SceneMsg>(data, encoding, at("/scene")) {
        Err(err) => check_error_text(&err, data)?,
        Ok(scene) => {
            if validate_scene(&scene).is_ok() {
                round_trip(&scene)?;
                build_mesh(scene.vertices.clone(), &scene.triangles)?;
            }
        }
    }
    match parse_message_as::<SweepMsg>(data, encoding, at("/sweep")) {
        Err(err) => check_error_text(&err, data)?,
        Ok(sweep) => {
            if validate_sweep(&sweep, Some(0.0)).is_ok() {
                round_trip(&sweep)?;
                let mesh = build_mesh(
                    vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]],
                    &[[0, 1, 2]],
                )?
                .ok_or("the unit triangle is refused")?;
                let outcome = sweep_mesh(
                    &mesh,
                    &Sweep::new(sweep.p0, sweep.p1, sweep.radius),
                    &Options::default(),
                )
                .map_err(|e| format!("a validated sweep is refused by the core: {e}"))?;
                check_outcome(&mesh, &outcome)?;
            }
        }
    }
    match parse_message_as::<OutcomeMsg>(data, encoding, at("/expected")) {
        Err(err) => check_error_text(&err, data)?,
        Ok(outcome) => {
            if validate_outcome(&outcome).is_ok() {
                round_trip(&outcome)?;
                if !(0.0..=1.0).contains(&outcome.alpha) {
                    return Err(format!("a validated outcome has alpha {}", outcome.alpha));
                }
            }
        }
    }
    match parse_message_as::<ContactMsg>(data, encoding, at("/contact")) {
        Err(err) => check_error_text(&err, data)?,
        Ok(contact) => {
            if validate_contact(&contact).is_ok() {
                round_trip(&contact)?;
                let mesh = build_mesh(
                    vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]],
                    &[[0, 1, 2]],
                )?
                .ok_or("the unit triangle is refused")?;
                let query = ContactQuery {
                    centre: contact.centre.into(),
                    radius: contact.radius,
                    distance: contact.distance,
                };
                for sides in [Sides::One, Sides::Two] {
                    for c in contact_set(&mesh, &query, sides) {
                        let finite = c.separation.is_finite()
                            && c.normal.iter().chain(c.point.iter()).all(|x| x.is_finite());
                        if !finite {
                            return Err(format!(
                                "a validated query gives a non-finite contact: {c:?}"
                            ));
                        }
                    }
                }
            }
        }
    }
    match parse_message_as::<ContactsMsg>(data, encoding, at("/expected_contacts")) {
        Err(err) => check_error_text(&err, data)?,
        Ok(contacts) => {
            if validate_contacts(&contacts).is_ok() {
                round_trip(&contacts)?;
            }
        }
    }
    Ok(())
}

/// The core over arbitrary numbers, finite and not (decoded from the bytes
/// by [`Numbers`]): a mesh with a non-finite vertex or an index out of
/// range is refused with an error, never a panic; a sweep is refused
/// exactly when its numbers are invalid (non-finite, radius ≤ 0, margin
/// outside `[0, radius)`, a path too long to measure); otherwise the
/// outcome passes [`check_outcome`], with the BVH and exhaustively, and
/// every per-test record (face, edge, vertex) that hits has a finite `α` in
/// [0, 1].
pub fn check_core(data: &[u8]) -> Result<(), String> {
    let mut numbers = Numbers::new(data);
    let vertex_count = 1 + numbers.byte() as usize % 6;
    let triangle_count = 1 + numbers.byte() as usize % 4;
    let vertices: Vec<[f64; 3]> = (0..vertex_count).map(|_| numbers.point()).collect();
    // One index in seven past the end, to exercise the range check.
    let triangles: Vec<[u64; 3]> = (0..triangle_count)
        .map(|_| [0; 3].map(|_: u64| (numbers.byte() % 7) as u64 % (vertex_count as u64 + 1)))
        .collect();
    let p0 = numbers.point();
    let p1 = numbers.point();
    let radius = numbers.number();
    let margin = numbers.number();
    let facing = if numbers.byte().is_multiple_of(2) {
        Facing::NonStrict
    } else {
        Facing::Strict
    };

    let non_finite_vertex = vertices.iter().flatten().any(|c| !c.is_finite());
    let index_out_of_range = triangles
        .iter()
        .flatten()
        .any(|&i| i >= vertex_count as u64);
    let mesh = match Mesh::new(vertices.clone(), &triangles) {
        Ok(mesh) => mesh,
        Err(MeshError::NonFiniteVertex { .. }) if non_finite_vertex => return Ok(()),
        Err(MeshError::IndexOutOfRange { .. }) if index_out_of_range => return Ok(()),
        Err(MeshError::Empty { .. }) if !non_finite_vertex && !index_out_of_range => {
            return Ok(());
        }
        Err(err) => return Err(format!("the mesh is refused for the wrong reason: {err}")),
    };
    if non_finite_vertex || index_out_of_range {
        return Err("a mesh with a non-finite vertex or a bad index was accepted".into());
    }

    let sweep = Sweep::new(p0, p1, radius);
    let options = Options {
        margin,
        facing,
        ..Options::default()
    };
    let path_is_measurable = (0..3)
        .map(|k| p1[k] - p0[k])
        .map(|d| d * d)
        .sum::<f64>()
        .sqrt()
        .is_finite();
    let valid = p0.iter().chain(&p1).all(|c| c.is_finite())
        && radius.is_finite()
        && radius > 0.0
        && margin.is_finite()
        && margin >= 0.0
        && margin < radius
        && path_is_measurable;
    let fast = sweep_mesh(&mesh, &sweep, &options);
    let mut records = CollectRecords::default();
    let explained = sweep_mesh_with(
        &mesh,
        &sweep,
        &options,
        Broadphase::Exhaustive,
        &mut records,
    );
    match (valid, fast, explained) {
        (false, Err(_), Err(_)) => return Ok(()),
        (true, Ok(fast), Ok(explained)) => {
            check_outcome(&mesh, &fast)?;
            check_outcome(&mesh, &explained)?;
        }
        (valid, fast, explained) => {
            return Err(format!(
                "inputs valid: {valid}, but the core answered {fast:?} (BVH) and {explained:?} (exhaustive)"
            ));
        }
    }
    for record in &records.records {
        check_record_alpha(record)?;
    }

    // The per-test functions on their own, on every triangle.
    let path = SweptPath::against(&mesh, &sweep, &options)
        .map_err(|e| format!("the path is refused after the sweep was accepted: {e}"))?;
    for triangle in mesh.triangles() {
        check_record_alpha(&TestRecord::Face(sweep_face(triangle, &path, facing)))?;
        for feature in 0..3 {
            check_record_alpha(&TestRecord::Edge(sweep_edge(
                triangle, feature, &path, facing,
            )))?;
            check_record_alpha(&TestRecord::Vertex(sweep_vertex(
                triangle, feature, &path, facing,
            )))?;
        }
    }
    Ok(())
}

/// An outcome of the core: `α` in [0, 1] (1 when nothing is hit); a hit
/// names a triangle of the mesh, a feature for an edge or vertex, a finite
/// unit normal and a finite contact; a finite tie window.
pub fn check_outcome(mesh: &Mesh, outcome: &Outcome) -> Result<(), String> {
    let fail = |what: &str| Err(format!("{what}: {outcome:?}"));
    if !(outcome.tie_window.is_finite() && outcome.tie_window >= 0.0) {
        return fail("a tie window that is not a finite number ≥ 0");
    }
    let Some(hit) = outcome.hit else {
        return Ok(());
    };
    if !(0.0..=1.0).contains(&hit.alpha) {
        return fail("alpha outside [0, 1]");
    }
    if mesh.triangle_by_index(hit.triangle).is_none() {
        return fail("a hit on a triangle the mesh does not have");
    }
    if hit.feature.index().is_some_and(|f| f > 2) {
        return fail("a feature index past 2");
    }
    let n = hit.normal;
    if !(n.iter().all(|c| c.is_finite()) && (n.norm() - 1.0).abs() < 1e-9) {
        return fail("a hit without a finite unit normal");
    }
    if !hit.contact.iter().all(|c| c.is_finite()) {
        return fail("a hit without a finite contact");
    }
    Ok(())
}

/// A test's record that says hit has a finite `α` in [0, 1].
fn check_record_alpha(record: &TestRecord) -> Result<(), String> {
    match record.alpha() {
        Some(alpha) if !(0.0..=1.0).contains(&alpha) => {
            Err(format!("a test hits at alpha {alpha}: {record:?}"))
        }
        _ => Ok(()),
    }
}

/// [`Mesh::new`], where a refusal must be one of the documented errors:
/// `Ok(None)` for a mesh with no usable triangle or numbers the core
/// refuses.
fn build_mesh(vertices: Vec<[f64; 3]>, triangles: &[[u64; 3]]) -> Result<Option<Mesh>, String> {
    match Mesh::new(vertices, triangles) {
        Ok(mesh) => Ok(Some(mesh)),
        Err(MeshError::Empty { .. }) => Ok(None),
        Err(err) => Err(format!("a validated scene is refused by the core: {err}")),
    }
}

/// A validated message written as JSON and read back is the same message.
fn round_trip<T>(message: &T) -> Result<(), String>
where
    T: serde::Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug,
{
    for encoding in Encoding::all() {
        let bytes = encoding
            .encode(message)
            .map_err(|e| format!("cannot write {message:?} as {encoding}: {e}"))?;
        let at = || MessageAt {
            file: SOURCE_NAME.to_string(),
            channel: "round trip".to_string(),
            index: 0,
            frame: None,
        };
        let back: T = parse_message_as(&bytes, encoding, at)
            .map_err(|e| format!("cannot read back {message:?} from {encoding}: {e}"))?;
        if &back != message {
            return Err(format!(
                "a round trip through {encoding} changed {message:?} into {back:?}"
            ));
        }
    }
    Ok(())
}

/// An error's text, with the texts of its sources as `anyhow` prints them
/// (`{:#}`), names the file and repeats none of its parts, except a
/// repetition the `input` holds itself (a JSON string quoted in the message).
fn check_error_text(err: &(dyn std::error::Error + 'static), input: &[u8]) -> Result<(), String> {
    let mut parts = vec![err.to_string()];
    let mut source = err.source();
    while let Some(inner) = source {
        parts.push(inner.to_string());
        source = inner.source();
    }
    let text = parts.join(": ");
    if !text.contains(SOURCE_NAME) {
        return Err(format!("the error does not name the file: {text}"));
    }
    // Text quoted from the input (a field name, a JSON string) may hold
    // `": "` and repeat whatever the input repeats: the check applies to
    // inputs that cannot put a separator into the message.
    let input_text = String::from_utf8_lossy(input);
    let input_can_split = input_text.contains(": ") || input_text.contains('\\');
    if let Some(repeated) = crate::error_text::repeated_segment(&text)
        && !input_can_split
    {
        return Err(format!("the error repeats `{repeated}`: {text}"));
    }
    Ok(())
}

/// Numbers decoded from fuzz bytes: each starts with a tag byte that
/// chooses a small dyadic value (most often, so that geometry meets), a
/// special value (zeros, infinities, NaN, the extremes) or raw bits. Past
/// the end of the bytes every number is 0.
pub struct Numbers<'a> {
    bytes: &'a [u8],
}

impl<'a> Numbers<'a> {
    /// Numbers from `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        Numbers { bytes }
    }

    /// The next byte (0 past the end).
    pub fn byte(&mut self) -> u8 {
        match self.bytes.split_first() {
            Some((&b, rest)) => {
                self.bytes = rest;
                b
            }
            None => 0,
        }
    }

    /// The next number.
    pub fn number(&mut self) -> f64 {
        const SPECIAL: [f64; 12] = [
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            1e-300,
            1e300,
            f64::EPSILON,
        ];
        match self.byte() % 8 {
            0..=4 => {
                let numerator = self.byte() as i8 as f64;
                numerator / f64::from(1u32 << (self.byte() % 8))
            }
            5 => SPECIAL[self.byte() as usize % SPECIAL.len()],
            _ => f64::from_bits(u64::from_le_bytes([0; 8].map(|_: u8| self.byte()))),
        }
    }

    /// The next three numbers.
    pub fn point(&mut self) -> [f64; 3] {
        [self.number(), self.number(), self.number()]
    }
}
