//! Where the rows of one sweep go ([`Out`]), what they leave shown for
//! their ball ([`Shown`]), the component sets of the rows ([`set`]) and
//! what the rows depend on besides the sweep ([`PrepareOptions`]): the
//! ground that `rows` and `edge_frame` both draw on.

use rerun::Clear;
use rerun::components::ClearIsRecursive;

use super::MAX_EDGE_FRAMES;
use super::columns::{self, row::Row};
use super::paths::Entity;
use crate::judge::Tolerances;

/// What the rows of a sweep depend on besides the sweep: the same for every
/// sweep of a recording ([`Logger::prepare_options`](super::Logger::prepare_options)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrepareOptions {
    /// At most this many edge tests per sweep get an edge frame.
    pub max_edge_frames: usize,
    /// When a sweep diverges from its expectation: `check`'s comparison
    /// with these tolerances.
    pub tolerances: Tolerances,
    /// The ball the "follow" view follows: only it gets a focus transform.
    pub follow_ball: u32,
}

impl Default for PrepareOptions {
    fn default() -> Self {
        PrepareOptions {
            max_edge_frames: MAX_EDGE_FRAMES,
            tolerances: Tolerances::default(),
            follow_ball: 0,
        }
    }
}

/// Component sets: the rows of one entity with the same set number have the
/// same components (see `columns::Columns::row`).
pub(crate) mod set {
    /// A ball's sweep: balls, swept volume, contact, normal.
    pub const BALL: u8 = 0;
    pub const CLEAR: u8 = 4;
    /// The primary triangle, its outline and decisive edge, its vertex.
    pub const PRIMARY: u8 = 5;
    pub const SCALAR: u8 = 12;
    pub const KIND: u8 = 13;
    pub const TEXT_LOG: u8 = 14;
    pub const FOCUS: u8 = 15;
    /// An edge frame: its transform, its test's numbers and what is drawn
    /// in it.
    pub const EDGE_FRAME: u8 = 16;
    /// [`EDGE_FRAME`] with the frame's axes (slot 0).
    pub const EDGE_FRAME_AXES: u8 = 17;
    pub const EXPECTED: u8 = 21;
    pub const TUNNEL: u8 = 22;
    /// A ghost contact's mark: its point and two arrows.
    pub const GHOST: u8 = 23;
    /// Labelled points: a contact query's contacts, or the places its
    /// answer leaves out.
    pub const CONTACT_POINTS: u8 = 24;
    /// Arrows: a contact query's normals, or the normals expected.
    pub const ARROWS: u8 = 25;
}

/// What a sweep's rows leave shown for its ball, of the entities that are
/// cleared when a sweep no longer logs them: the primary triangle, the edge
/// frames, the plot series, the expected outcome, the tunnel marker, the
/// ghost contact's mark. A
/// ball's rows clear one of them only when the ball's previous sweep showed
/// it, right after the sweep's own rows (so that a clear keeps its place
/// among the sweeps of one frame). (The contact, the normal, the decisive
/// edge and vertex are parts of rows logged at every sweep that can show
/// them, logged empty when not shown.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Shown {
    bits: u8,
    /// Edge slots logged.
    pub(crate) edge_slots: u8,
    /// Plot entities that got a value (bits of `rows::plot_entity`).
    pub(crate) plotted: u16,
}

impl Shown {
    pub(crate) const PRIMARY: u8 = 1;
    pub(crate) const EXPECTED: u8 = 2;
    pub(crate) const TUNNEL: u8 = 4;
    pub(crate) const GHOST: u8 = 8;

    pub(crate) fn has(self, bit: u8) -> bool {
        self.bits & bit != 0
    }

    /// What the rows drawn for a sweep show: `edge_slots` edge frames, the
    /// `plotted` plot entities, whether the primary triangle, the expected
    /// outcome, a tunnel marker and a ghost contact's mark were drawn.
    pub(crate) fn drawn(
        edge_slots: usize,
        plotted: u16,
        primary: bool,
        expected: bool,
        tunnel: bool,
        ghost: bool,
    ) -> Shown {
        let bit = |on: bool, b: u8| if on { b } else { 0 };
        Shown {
            bits: bit(primary, Shown::PRIMARY)
                | bit(expected, Shown::EXPECTED)
                | bit(tunnel, Shown::TUNNEL)
                | bit(ghost, Shown::GHOST),
            edge_slots: u8::try_from(edge_slots).unwrap_or(u8::MAX),
            plotted,
        }
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

    pub(crate) fn clear(&mut self, entity: Entity, recursive: bool) {
        self.row(entity, set::CLEAR)
            .put::<ClearIsRecursive>(Clear::descriptor_is_recursive, [recursive.into()]);
    }
}
