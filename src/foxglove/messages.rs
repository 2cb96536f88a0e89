//! The Foxglove messages this output writes, as serde types with the field
//! names of Foxglove's JSON Schemas (`schemas/foxglove/`, from the npm
//! package `@foxglove/schemas`): every field the schemas require is
//! present, and no other. Plus this project's own plot message,
//! [`SweepNumbers`] (`schemas/sweep_numbers.schema.json`).

use serde::Serialize;

/// `time`: a point in time as seconds and nanoseconds (both non-negative).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: u32,
    /// Nanoseconds, `0..1_000_000_000`.
    pub nsec: u32,
}

impl Time {
    /// A `log_time` in nanoseconds as a [`Time`] (seconds beyond `u32` are
    /// saturated: year 2106).
    pub fn from_nanos(log_time_nanos: u64) -> Time {
        Time {
            sec: u32::try_from(log_time_nanos / 1_000_000_000).unwrap_or(u32::MAX),
            nsec: (log_time_nanos % 1_000_000_000) as u32,
        }
    }
}

/// `duration`: a length of time; zero means "forever" for a lifetime.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Duration {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, `0..1_000_000_000`.
    pub nsec: u32,
}

/// `foxglove.Vector3`, also used for sizes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Vector3 {
    /// x component.
    pub x: f64,
    /// y component.
    pub y: f64,
    /// z component.
    pub z: f64,
}

/// `foxglove.Point3`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Point3 {
    /// x coordinate.
    pub x: f64,
    /// y coordinate.
    pub y: f64,
    /// z coordinate.
    pub z: f64,
}

/// `foxglove.Quaternion`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Quaternion {
    /// x value.
    pub x: f64,
    /// y value.
    pub y: f64,
    /// z value.
    pub z: f64,
    /// w value.
    pub w: f64,
}

impl Quaternion {
    /// No rotation.
    pub const IDENTITY: Quaternion = Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    };
}

/// `foxglove.Pose`: a position and an orientation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Pose {
    /// Position.
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `foxglove.Color`, each channel in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Color {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
    /// Alpha (opacity).
    pub a: f64,
}

/// `foxglove.KeyValuePair`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyValuePair {
    /// Key.
    pub key: String,
    /// Value.
    pub value: String,
}

/// `foxglove.SpherePrimitive`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpherePrimitive {
    /// Center and orientation.
    pub pose: Pose,
    /// Diameter along each axis.
    pub size: Vector3,
    /// Color.
    pub color: Color,
}

/// `foxglove.ArrowPrimitive`: identity orientation points along +x.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ArrowPrimitive {
    /// The tail and the orientation.
    pub pose: Pose,
    /// Length of the shaft.
    pub shaft_length: f64,
    /// Diameter of the shaft.
    pub shaft_diameter: f64,
    /// Length of the head.
    pub head_length: f64,
    /// Diameter of the head.
    pub head_diameter: f64,
    /// Color.
    pub color: Color,
}

/// `foxglove.LineType` (the variants are named as in the schema).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(clippy::enum_variant_names)]
pub enum LineType {
    /// Connected segments 0-1, 1-2, ...
    LineStrip = 0,
    /// A closed polygon (never written; kept so that the values are the
    /// schema's).
    #[allow(dead_code)]
    LineLoop = 1,
    /// Separate segments 0-1, 2-3, ...
    LineList = 2,
}

impl Serialize for LineType {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_u8(*self as u8)
    }
}

/// `foxglove.LinePrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LinePrimitive {
    /// How the points are joined.
    #[serde(rename = "type")]
    pub line_type: LineType,
    /// Origin of the points.
    pub pose: Pose,
    /// Thickness.
    pub thickness: f64,
    /// Whether `thickness` is in screen pixels (true) or world units.
    pub scale_invariant: bool,
    /// The points.
    pub points: Vec<Point3>,
    /// Solid color.
    pub color: Color,
    /// Per-point colors (empty: the solid color).
    pub colors: Vec<Color>,
    /// Indices into `points` (empty: the points in order).
    pub indices: Vec<u32>,
}

/// `foxglove.TriangleListPrimitive`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TriangleListPrimitive {
    /// Origin of the points.
    pub pose: Pose,
    /// The vertices.
    pub points: Vec<Point3>,
    /// Solid color.
    pub color: Color,
    /// Per-vertex colors (empty: the solid color).
    pub colors: Vec<Color>,
    /// Three indices into `points` per triangle.
    pub indices: Vec<u32>,
}

/// `foxglove.TextPrimitive`: a label.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TextPrimitive {
    /// Where the text box's center is (identity orientation: the text in
    /// the xy-plane, flowing along +x).
    pub pose: Pose,
    /// Whether it always faces the camera (ignoring the orientation).
    pub billboard: bool,
    /// Height of one line of text.
    pub font_size: f64,
    /// Whether `font_size` is in screen pixels (else world units).
    pub scale_invariant: bool,
    /// Color.
    pub color: Color,
    /// The text.
    pub text: String,
}

/// `foxglove.SceneEntity`. The primitive kinds this output never draws
/// (cubes, cylinders, models) are written as empty lists, which the
/// schema requires.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneEntity {
    /// Timestamp.
    pub timestamp: Time,
    /// Frame of reference.
    pub frame_id: String,
    /// Identifier: replaces an earlier entity with the same id on the topic.
    pub id: String,
    /// Removed after this long; zero: kept until replaced or deleted.
    pub lifetime: Duration,
    /// Whether it stays fixed in its frame as the frame moves.
    pub frame_locked: bool,
    /// Key-value pairs shown with the entity.
    pub metadata: Vec<KeyValuePair>,
    /// Arrows.
    pub arrows: Vec<ArrowPrimitive>,
    /// Always empty.
    pub cubes: [(); 0],
    /// Spheres.
    pub spheres: Vec<SpherePrimitive>,
    /// Always empty.
    pub cylinders: [(); 0],
    /// Lines.
    pub lines: Vec<LinePrimitive>,
    /// Triangle lists.
    pub triangles: Vec<TriangleListPrimitive>,
    /// Texts.
    pub texts: Vec<TextPrimitive>,
    /// Always empty.
    pub models: [(); 0],
}

impl SceneEntity {
    /// An entity without primitives, kept until replaced (lifetime zero).
    pub fn new(timestamp: Time, frame_id: &str, id: String) -> SceneEntity {
        SceneEntity {
            timestamp,
            frame_id: frame_id.to_string(),
            id,
            lifetime: Duration::default(),
            frame_locked: false,
            metadata: Vec::new(),
            arrows: Vec::new(),
            cubes: [],
            spheres: Vec::new(),
            cylinders: [],
            lines: Vec::new(),
            triangles: Vec::new(),
            texts: Vec::new(),
            models: [],
        }
    }
}

/// `foxglove.SceneEntityDeletionType`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeletionType {
    /// The entity with the deletion's `id`.
    MatchingId = 0,
    /// Every entity of the topic.
    All = 1,
}

impl Serialize for DeletionType {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_u8(*self as u8)
    }
}

/// `foxglove.SceneEntityDeletion`: entities older than `timestamp` are
/// removed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneEntityDeletion {
    /// Only entities earlier than this are deleted.
    pub timestamp: Time,
    /// Which.
    #[serde(rename = "type")]
    pub deletion_type: DeletionType,
    /// The id, for [`DeletionType::MatchingId`] (empty otherwise).
    pub id: String,
}

/// `foxglove.SceneUpdate`: deletions first, then entities added or
/// replaced.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SceneUpdate {
    /// Entities to delete.
    pub deletions: Vec<SceneEntityDeletion>,
    /// Entities to add or replace.
    pub entities: Vec<SceneEntity>,
}

/// `foxglove.LogLevel`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogLevel {
    /// A decision that agrees with the expectation, or has none.
    Info = 2,
    /// A sweep that `check` fails: it diverges from its expectation, or the
    /// ball tunnels.
    Warning = 3,
}

impl Serialize for LogLevel {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_u8(*self as u8)
    }
}

/// `foxglove.Log`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Log {
    /// Timestamp.
    pub timestamp: Time,
    /// Level.
    pub level: LogLevel,
    /// The text.
    pub message: String,
    /// "Process or node name": here `ball N`, so the Log panel can filter by
    /// ball.
    pub name: String,
    /// "Filename": here the trace's file name.
    pub file: String,
    /// "Line number in the file": traces have no lines; always 0.
    pub line: u32,
}

/// The decisive edge or vertex test's quadratic in `s` (the fraction of
/// the path), as the viewer's plots show it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct QuadraticNumbers {
    /// Coefficient of `s²`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<f64>,
    /// Coefficient of `s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<f64>,
    /// Constant term.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c: Option<f64>,
    /// `b² - 4ac`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub discriminant: Option<f64>,
    /// The smaller root, when there are real roots.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub s0: Option<f64>,
    /// The larger root, when there are real roots.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub s1: Option<f64>,
}

/// The decisive face test's numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FaceNumbers {
    /// Signed distance of `p0` from the plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h0: Option<f64>,
    /// Signed distance of `p1` from the plane.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h1: Option<f64>,
    /// `(h0 - ρ) / -(n · d)`, when computed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
}

/// `sweeptrace.SweepNumbers`: one sweep's numbers for the Plot panel (the
/// message path `/numbers{ball==0}.alpha`). A number that is not finite, or
/// does not exist for this sweep, is left out.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SweepNumbers {
    /// Timestamp (the sweep's `log_time`).
    pub timestamp: Time,
    /// Frame.
    pub frame: u64,
    /// Ball.
    pub ball: u32,
    /// The chosen `α` (1 when nothing is hit).
    pub alpha: f64,
    /// `none`, `face`, `edge` or `vertex`.
    pub kind: &'static str,
    /// 1 when `check` fails this sweep (diverges or tunnels), else 0.
    pub failed: u8,
    /// 1 when the decision is fragile, else 0.
    pub fragile: u8,
    /// The expectation's `α`, when the trace has one for this sweep.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expected_alpha: Option<f64>,
    /// The decisive test (`edge 12.1`), or the nearest miss.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub test: Option<String>,
    /// The decisive edge or vertex test's quadratic.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quadratic: Option<QuadraticNumbers>,
    /// The decisive face test's numbers.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub face: Option<FaceNumbers>,
}
