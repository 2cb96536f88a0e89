//! The default layouts, with fixed ids.
//!
//! The SDK's `Blueprint::send` builds its messages in a fresh blueprint
//! stream with `RecordingId::random()`, and every container and view gets
//! `Uuid::new_v4()` (a crate-private field that also appears inside the data:
//! entity paths `container/<uuid>`, `view/<uuid>`, container contents
//! `view/<uuid>`, the viewport's root container). Here the same archetypes
//! are logged by hand, as `Blueprint::send` logs them, into messages of a
//! blueprint store whose id, container and view ids, row ids and chunk ids
//! all derive from the recording id and the [`Layout`], and are handed to
//! the recording with [`RecordingStream::send_blueprint`]. The same
//! recording id gives the same blueprint, byte for byte.
//!
//! Two layouts, over the same views:
//!
//! - [`Layout::FollowBall`], sent at the start: on top the view that follows
//!   the ball, the overview of the world and the edge frame; below them the
//!   plots (α, the quadratic, the face test, the divergence status); at the
//!   bottom the decisions.
//! - [`Layout::Divergences`], sent by [`super::Logger::finish`] when some
//!   sweep or contact query diverged from its expectation (a ghost contact
//!   too), as the active layout: the
//!   divergences log on top, then the same views.
//!
//! When the recording has contact queries, the layout sent by
//! [`super::Logger::finish`] (either) also plots the followed ball's
//! contacts and ghost contacts per query, beside the divergence status
//! (the queries are drawn after the sweeps, so only the end knows of them).
//!
//! Every plot shows the same window of frames around the time cursor
//! (`TimeAxis` with a cursor-relative view range), so a frame reads across
//! them.
//!
//! ```text
//! container/<uuid>                 ContainerBlueprint (vertical, then horizontal rows)
//! view/<uuid>, view/<uuid>/ViewContents   ViewBlueprint and ViewContents of each view
//! view/<uuid>/EyeControls3D        the followed ball's camera, in the ball's frame
//! view/<uuid>/TimeAxis             each plot's time range around the cursor
//! viewport                         ViewportBlueprint (root container)
//! blueprint_panel, selection_panel PanelBlueprint (collapsed)
//! time_panel                       TimePanelBlueprint (collapsed, `frame`, 10 fps)
//! ```

use rerun::blueprint::components::{
    ColumnShare, ContainerKind, Eye3DKind, Fps, IncludedContent, LinkAxis, PanelState,
    QueryExpression, RootContainer, RowShare, TimelineName, ViewClass,
};
use rerun::components::{Name, Position3D, Vector3D};
use rerun::datatypes::{Float32, Float64, TimeInt, TimeRange, TimeRangeBoundary};
use rerun::external::re_log_types::{
    BlueprintActivationCommand, LogMsg, RecordingId, SetStoreInfo, StoreId, StoreInfo, StoreKind,
};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    ContainerBlueprint, EyeControls3D, PanelBlueprint, TimeAxis, TimePanelBlueprint, ViewBlueprint,
    ViewContents, ViewportBlueprint,
};
use rerun::log::{Chunk, ChunkId, RowId};
use rerun::{AsComponents, RecordingStream, RecordingStreamError, TimePoint, Timeline};
use uuid::Uuid;

use super::{FRAME_TIMELINE, IdHasher, paths};

/// Time part of the blueprint's row and chunk ids: 2020-01-01T00:00:00Z in
/// nanoseconds (as for the recording's rows).
const ID_BASE_NANOS: u64 = 1_577_836_800_000_000_000;

/// How long [`send_blueprint`] waits for the blueprint to reach the sink.
const FLUSH_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(10);

/// Frames shown before and after the time cursor in every plot.
pub const PLOT_WINDOW_FRAMES: i64 = 60;

/// Where the followed ball's camera sits, in the ball's frame (one unit is
/// about four ball radii, see `rows::focus_rows`): in front, to the side
/// and above, looking at the ball.
const FOLLOW_EYE: [f32; 3] = [0.8, -1.7, 1.0];

/// Which default layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Leads with the view that follows the ball.
    FollowBall,
    /// Leads with the log of divergent sweeps.
    Divergences,
}

impl Layout {
    /// The name the layout's ids derive from (a layout with the contacts'
    /// plot is another blueprint, with ids of its own).
    fn name(self, contacts: bool) -> &'static str {
        match (self, contacts) {
            (Layout::FollowBall, false) => "blueprint",
            (Layout::Divergences, false) => "blueprint-divergences",
            (Layout::FollowBall, true) => "blueprint-contacts",
            (Layout::Divergences, true) => "blueprint-divergences-contacts",
        }
    }
}

/// Sends `layout` (following ball `follow_ball`, with the plot of its
/// contact queries when `contacts`) to `rec` as its active and default
/// blueprint, with ids that depend only on the recording id and the layout.
pub fn send_blueprint(
    rec: &RecordingStream,
    layout: Layout,
    follow_ball: u32,
    contacts: bool,
) -> Result<(), RecordingStreamError> {
    let Some(info) = rec.store_info() else {
        // A disabled stream: nothing is recorded.
        return Ok(());
    };
    let (msgs, activation) = blueprint_messages(&info, layout, follow_ball, contacts)?;
    rec.send_blueprint(msgs, activation);
    // The blueprint's messages go to the sink through the stream's command
    // channel, the recording's chunks through its batcher; the thread that
    // forwards both picks whichever is ready, so without this flush the
    // place of the blueprint among the first chunks would vary from run to
    // run. With it, the blueprint comes before every chunk logged later.
    // Bounded, so that a slow viewer connection cannot hold up the start;
    // an error only means the order is not guaranteed (nothing is lost).
    let _ = rec.flush_with_timeout(FLUSH_TIMEOUT);
    Ok(())
}

/// The messages of `layout` for the recording `info` (store info first,
/// then one chunk per blueprint entity), and the command that makes it the
/// active and default blueprint. `contacts`: with the plot of the followed
/// ball's contact queries.
pub fn blueprint_messages(
    info: &StoreInfo,
    layout: Layout,
    follow_ball: u32,
    contacts: bool,
) -> Result<(Vec<LogMsg>, BlueprintActivationCommand), RecordingStreamError> {
    let recording_id = info.store_id.recording_id().to_string();
    let ids = Ids::new(&recording_id, layout.name(contacts));
    let store_id = StoreId::new(
        StoreKind::Blueprint,
        info.store_id.application_id().clone(),
        RecordingId::from(ids.store_recording_id()),
    );
    let mut b = Builder {
        store_id: store_id.clone(),
        msgs: vec![LogMsg::SetStoreInfo(SetStoreInfo {
            row_id: *row_id(0),
            info: StoreInfo::new(store_id.clone(), info.store_source.clone()),
        })],
        ids,
        next: 0,
        items: 0,
    };

    let ball = follow_ball;
    let follow = b.view(
        "3D",
        &format!("Ball {ball} (the view follows it)"),
        &paths::focus(ball),
        &["/world/**"],
    )?;
    b.property(
        follow,
        "EyeControls3D",
        &EyeControls3D::new()
            .with_kind(Eye3DKind::Orbital)
            .with_position(Position3D::from(FOLLOW_EYE))
            .with_look_target(Position3D::from([0.0, 0.0, 0.0]))
            .with_eye_up(Vector3D::from([0.0, 0.0, 1.0])),
    )?;
    let world = b.view("3D", "World (overview)", paths::WORLD, &["$origin/**"])?;
    let edge = b.view(
        "3D",
        &format!("Edge frame: ball {ball}'s decisive or nearest edge test"),
        &paths::edge_frame(ball, 0),
        &["$origin/**"],
    )?;
    let alpha = b.plot(&format!("α (ball {ball})"), &paths::alpha(ball))?;
    let quadratic = b.plot(
        &format!("Quadratic A, B, C, disc, s0, s1 (ball {ball})"),
        &paths::quadratic(ball),
    )?;
    let face = b.plot(&format!("Face h0, h1, β (ball {ball})"), &paths::face(ball))?;
    let status = b.plot(
        "Divergent (1) and fragile decisions (…/fragile) per ball",
        paths::STATUS,
    )?;
    let contact_plot = if contacts {
        Some(b.plot(
            &format!("Contacts and ghost contacts per contact query (ball {ball})"),
            &paths::contact_plot(ball),
        )?)
    } else {
        None
    };
    let log = b.view("TextLog", "Decisions", paths::LOG, &["$origin/**"])?;

    let top = b.container(
        ContainerKind::Horizontal,
        &[follow, world, edge],
        Some(&[3.0, 2.2, 2.0]),
        None,
    )?;
    let root = match layout {
        Layout::FollowBall => {
            let plots: Vec<Item> = [alpha, quadratic, face, status]
                .into_iter()
                .chain(contact_plot)
                .collect();
            let plots = b.container(ContainerKind::Horizontal, &plots, None, None)?;
            b.container(
                ContainerKind::Vertical,
                &[top, plots, log],
                None,
                Some(&[3.0, 1.4, 1.2]),
            )?
        }
        Layout::Divergences => {
            let divergences = b.view(
                "TextLog",
                "Divergences from the expected outcomes",
                paths::DIVERGENCES,
                &["$origin/**"],
            )?;
            let plots: Vec<Item> = std::iter::once(status)
                .chain(contact_plot)
                .chain([alpha, quadratic, face])
                .collect();
            let plots = b.container(ContainerKind::Horizontal, &plots, None, None)?;
            b.container(
                ContainerKind::Vertical,
                &[divergences, top, plots, log],
                None,
                Some(&[1.0, 3.0, 1.3, 1.0]),
            )?
        }
    };

    let root_uuid = match root {
        Item::Container(uuid) => uuid,
        Item::View(_) => unreachable!("the root is a container"),
    };
    b.log(
        "viewport",
        &ViewportBlueprint::new().with_root_container(RootContainer(rerun::datatypes::Uuid {
            bytes: root_uuid.into_bytes(),
        })),
    )?;
    b.log(
        "blueprint_panel",
        &PanelBlueprint::new().with_state(PanelState::Collapsed),
    )?;
    b.log(
        "selection_panel",
        &PanelBlueprint::new().with_state(PanelState::Collapsed),
    )?;
    b.log(
        "time_panel",
        &TimePanelBlueprint::new()
            .with_state(PanelState::Collapsed)
            .with_timeline(TimelineName(FRAME_TIMELINE.into()))
            .with_fps(Fps(Float64(10.0))),
    )?;

    let activation = BlueprintActivationCommand {
        blueprint_id: store_id,
        make_active: true,
        make_default: true,
    };
    Ok((b.msgs, activation))
}

/// The ids of one blueprint: hashes of the recording id and a name.
struct Ids {
    recording_id: String,
    layout: &'static str,
}

impl Ids {
    fn new(recording_id: &str, layout: &'static str) -> Ids {
        Ids {
            recording_id: recording_id.to_string(),
            layout,
        }
    }

    fn hash(&self, what: &str, n: u64) -> u128 {
        let mut h = IdHasher::new();
        for part in [
            self.recording_id.as_bytes(),
            self.layout.as_bytes(),
            what.as_bytes(),
            &n.to_le_bytes(),
        ] {
            h.update(&(part.len() as u64).to_le_bytes());
            h.update(part);
        }
        h.value()
    }

    /// The blueprint store's recording id.
    fn store_recording_id(&self) -> String {
        format!(
            "sweeptrace-{}-{:032x}",
            self.layout,
            self.hash("blueprint", 0)
        )
    }

    /// The `n`-th container or view id: a version 4 UUID whose "random"
    /// bits are a hash.
    fn uuid(&self, n: u64) -> Uuid {
        uuid::Builder::from_random_bytes(self.hash("uuid", n).to_be_bytes()).into_uuid()
    }
}

/// A container or a view, by its id.
#[derive(Clone, Copy)]
enum Item {
    Container(Uuid),
    View(Uuid),
}

impl Item {
    fn path(self) -> String {
        match self {
            Item::Container(uuid) => format!("container/{uuid}"),
            Item::View(uuid) => format!("view/{uuid}"),
        }
    }
}

/// The row id of the `n`-th message of the blueprint (0 is the store info).
fn row_id(n: u64) -> RowId {
    RowId::from_u128(((ID_BASE_NANOS as u128) << 64) | (n as u128 + 1))
}

struct Builder {
    store_id: StoreId,
    msgs: Vec<LogMsg>,
    ids: Ids,
    /// Rows (and chunks) logged so far.
    next: u64,
    /// Containers and views made so far.
    items: u64,
}

impl Builder {
    /// Logs one row of `archetype` at `path`, on the `blueprint` timeline
    /// at 0 (which the viewer expects of blueprint data), as one chunk.
    fn log(
        &mut self,
        path: &str,
        archetype: &dyn AsComponents,
    ) -> Result<(), RecordingStreamError> {
        self.next += 1;
        let n = self.next;
        let id = ChunkId::from_u128(((ID_BASE_NANOS as u128) << 64) | n as u128);
        let time = TimePoint::from([(Timeline::new_sequence("blueprint"), 0)]);
        let chunk = Chunk::builder_with_id(id, path)
            .with_archetype(row_id(n), time, archetype)
            .build()
            .map_err(RecordingStreamError::Chunk)?;
        let msg = chunk.to_arrow_msg().map_err(RecordingStreamError::Chunk)?;
        self.msgs.push(LogMsg::ArrowMsg(self.store_id.clone(), msg));
        Ok(())
    }

    /// The id of the next container or view: numbered in the order they
    /// are made, so the same layout gets the same ids.
    fn next_uuid(&mut self) -> Uuid {
        self.items += 1;
        self.ids.uuid(self.items)
    }

    /// A view of class `class` named `name` showing `origin/**`, logged as
    /// `Blueprint::send` logs a view: its `ViewContents`, then its
    /// `ViewBlueprint`.
    fn view(
        &mut self,
        class: &str,
        name: &str,
        origin: &str,
        contents: &[&str],
    ) -> Result<Item, RecordingStreamError> {
        let view = Item::View(self.next_uuid());
        let path = view.path();
        self.log(
            &format!("{path}/ViewContents"),
            &ViewContents::new(contents.iter().map(|q| QueryExpression((*q).into()))),
        )?;
        let origin = rerun::EntityPath::from(origin).to_string();
        self.log(
            &path,
            &ViewBlueprint::new(ViewClass(class.into()))
                .with_display_name(Name(name.into()))
                .with_space_origin(origin),
        )?;
        Ok(view)
    }

    /// A time-series view of `origin/**` whose time axis shows
    /// [`PLOT_WINDOW_FRAMES`] frames either side of the time cursor.
    fn plot(&mut self, name: &str, origin: &str) -> Result<Item, RecordingStreamError> {
        let view = self.view("TimeSeries", name, origin, &["$origin/**"])?;
        let window = TimeRange {
            start: TimeRangeBoundary::CursorRelative(TimeInt(-PLOT_WINDOW_FRAMES)),
            end: TimeRangeBoundary::CursorRelative(TimeInt(PLOT_WINDOW_FRAMES)),
        };
        self.property(
            view,
            "TimeAxis",
            &TimeAxis::new()
                .with_link(LinkAxis::Independent)
                .with_view_range(window),
        )?;
        Ok(view)
    }

    /// A property archetype of a view (logged at `view/<uuid>/<name>`, as
    /// the SDK logs view properties).
    fn property(
        &mut self,
        view: Item,
        name: &str,
        archetype: &dyn AsComponents,
    ) -> Result<(), RecordingStreamError> {
        self.log(&format!("{}/{name}", view.path()), archetype)
    }

    /// A container of `kind` holding `contents` (already logged).
    fn container(
        &mut self,
        kind: ContainerKind,
        contents: &[Item],
        column_shares: Option<&[f32]>,
        row_shares: Option<&[f32]>,
    ) -> Result<Item, RecordingStreamError> {
        let container = Item::Container(self.next_uuid());
        let mut arch = ContainerBlueprint::new(kind).with_contents(
            contents
                .iter()
                .map(|c| IncludedContent(rerun::EntityPath::from(c.path()).to_string().into())),
        );
        if let Some(shares) = column_shares {
            arch = arch.with_col_shares(shares.iter().map(|&s| ColumnShare(Float32(s))));
        }
        if let Some(shares) = row_shares {
            arch = arch.with_row_shares(shares.iter().map(|&s| RowShare(Float32(s))));
        }
        self.log(&container.path(), &arch)?;
        Ok(container)
    }
}
