//! What a caller chooses about a replay: which sweeps, how much is
//! explained, and the engine's conventions it computes the reference under.

use crate::conventions::{EngineConventions, MarginRule, NormalRule};
use crate::core::{Facing, Options};

/// Trace events per batch of [`super::replay_events_parallel`] unless told otherwise.
pub const DEFAULT_BATCH_EVENTS: usize = 4096;

/// How many test records each sweep keeps.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    strum::IntoStaticStr,
    strum::Display,
    strum::EnumString,
)]
#[strum(serialize_all = "snake_case")]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Detail {
    /// The tests that report the primary collision (the primary test first,
    /// then every other hit tied with it
    /// ([`crate::core::Outcome::ties_with`]), which share the averaged
    /// normal); when nothing hits, the one test that came nearest
    /// ([`crate::core::explain::miss_distance`]) among the BVH candidates.
    #[default]
    #[cfg_attr(
        feature = "cli",
        value(
            help = "The tests that report the primary collision (the primary test first, \
                      then every other hit tied with it, which share the averaged normal); \
                      when nothing hits, the one test that came nearest among the BVH candidates"
        )
    )]
    Primary,
    /// Every test of every triangle the BVH visited.
    Candidates,
    /// Every test of every triangle ([`crate::core::Broadphase::Exhaustive`]).
    #[cfg_attr(
        feature = "cli",
        value(help = "Every test of every triangle (no broadphase)")
    )]
    All,
}

impl Detail {
    /// The name used on the command line.
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// Trace events per batch of a parallel replay at this detail: a batch's
    /// results are in memory together, and at `candidates` and `all` each
    /// sweep keeps the record of every test it ran (many for a ball rolling
    /// on a fine mesh, far more at `all` on a large one), so those batches
    /// are shorter: a full batch of `candidates` records on a large terrain
    /// held far more memory than the rest of the replay (BENCHMARKS.md).
    pub fn batch_events(self) -> usize {
        match self {
            Detail::Primary => DEFAULT_BATCH_EVENTS,
            Detail::Candidates => 256,
            Detail::All => 16,
        }
    }
}

/// A half-open range of frames `start..end`; either end may be open.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FrameRange {
    /// First frame included.
    pub start: Option<u64>,
    /// First frame excluded.
    pub end: Option<u64>,
}

impl FrameRange {
    /// Whether `frame` lies in the range.
    pub fn contains(&self, frame: u64) -> bool {
        self.start.is_none_or(|s| frame >= s) && self.end.is_none_or(|e| frame < e)
    }
}

impl std::fmt::Display for FrameRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(s) = self.start {
            write!(f, "{s}")?;
        }
        f.write_str("..")?;
        if let Some(e) = self.end {
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::str::FromStr for FrameRange {
    type Err = String;
    /// `A..B` (A included, B excluded), `A..`, `..B`, `A..=B`, or one frame `A`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bound = |t: &str| -> Result<Option<u64>, String> {
            let t = t.trim();
            if t.is_empty() {
                return Ok(None);
            }
            t.parse::<u64>()
                .map(Some)
                .map_err(|_| format!("`{t}` is not a frame number"))
        };
        let range = if let Some((a, b)) = s.split_once("..=") {
            let end = bound(b)?.ok_or_else(|| format!("`{s}`: `..=` needs an end frame"))?;
            FrameRange {
                start: bound(a)?,
                end: Some(end.saturating_add(1)),
            }
        } else if let Some((a, b)) = s.split_once("..") {
            FrameRange {
                start: bound(a)?,
                end: bound(b)?,
            }
        } else if let Some((a, b)) = s.split_once(['-', ':']).filter(|(a, b)| {
            bound(a).is_ok_and(|a| a.is_some()) && bound(b).is_ok_and(|b| b.is_some())
        }) {
            let (a, b) = (a.trim(), b.trim());
            return Err(format!(
                "`{s}` is not a frame range: did you mean `{a}..{b}` (frames {a} to {b}, \
                 {b} excluded) or `{a}..={b}` ({b} included)?"
            ));
        } else {
            let f = bound(s)?.ok_or_else(|| "empty frame range".to_string())?;
            FrameRange {
                start: Some(f),
                end: Some(f.saturating_add(1)),
            }
        };
        if let (Some(a), Some(b)) = (range.start, range.end)
            && b <= a
        {
            return Err(format!(
                "frame range `{s}` is empty (A..B includes A and excludes B)"
            ));
        }
        Ok(range)
    }
}

/// Options of a replay.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReplayOptions {
    /// Only sweeps whose frame lies in this range.
    pub frames: FrameRange,
    /// Only this ball.
    pub ball: Option<u32>,
    /// Whether each sweep is explained, and how much: `None` runs the fast
    /// [`crate::core::sweep_mesh`] and results carry no records (what
    /// `--outcomes`, `check` and `bless` need); `Some(detail)` runs the
    /// explained query and keeps `detail`'s records (what a recording needs).
    pub explain: Option<Detail>,
    /// The engine's conventions, whole (the rules by default): the
    /// reference answer is computed under the margin, facing rule, sides,
    /// initial overlap and normal they declare (a declared margin or facing
    /// rule overrides every scene's), and judged under their precision and
    /// tie rule.
    pub conventions: EngineConventions,
}

impl ReplayOptions {
    /// The core's options for a scene whose own margin and facing rule are
    /// `margin` and `facing`: the overrides where set, and the engine
    /// conventions the core applies (sides, initial overlap).
    pub fn core_options(&self, margin: f64, facing: Facing) -> Options {
        let c = &self.conventions;
        Options {
            margin: match c.margin {
                MarginRule::Scene => margin,
                MarginRule::Fixed(m) => m,
            },
            facing: c.facing.facing().unwrap_or(facing),
            initial_overlap: c.initial_overlap,
            sides: c.sides,
        }
    }

    /// An explicit, stable text of every option (`frames=10..20;ball=*;
    /// detail=primary;explain=1;margin=scene;facing=scene`), for hashing into
    /// recording ids: unlike `Debug` output it does not change when a field
    /// is renamed or added with its default.
    pub fn stable_encoding(&self) -> String {
        let or_star = |v: Option<String>, none: &str| v.unwrap_or_else(|| none.to_string());
        let c = &self.conventions;
        let mut text = format!(
            "frames={};ball={};detail={};explain={};margin={};facing={}",
            self.frames,
            or_star(self.ball.map(|b| b.to_string()), "*"),
            self.explain.unwrap_or_default(),
            u8::from(self.explain.is_some()),
            match c.margin {
                MarginRule::Scene => "scene".to_string(),
                MarginRule::Fixed(m) => format!("{m:e}"),
            },
            or_star(c.facing.facing().map(|f| f.to_string()), "scene"),
        );
        // The conventions only when declared, so that the ids of recordings
        // under the rules stay what they were (the precision and the tie
        // rule change no recorded value).
        if !c.initial_overlap.is_rules() {
            text.push_str(&format!(";initial_overlap={}", c.initial_overlap));
        }
        if !c.sides.is_rules() {
            text.push_str(&format!(";sides={}", c.sides));
        }
        if c.normal != NormalRule::Face {
            text.push_str(&format!(";normal={}", c.normal));
        }
        text
    }

    /// The frame and ball filters in words (`frames 100..200, ball 0`), or
    /// `None` when there is none.
    pub fn filter_text(&self) -> Option<String> {
        let mut parts = Vec::new();
        if self.frames != FrameRange::default() {
            parts.push(format!("frames {}", self.frames));
        }
        if let Some(b) = self.ball {
            parts.push(format!("ball {b}"));
        }
        (!parts.is_empty()).then(|| parts.join(", "))
    }

    /// Trace events per batch of a parallel replay with these options
    /// ([`Detail::batch_events`]; the fast query keeps no records, so it
    /// takes the default batch).
    pub fn batch_events(&self) -> usize {
        self.explain
            .map_or(DEFAULT_BATCH_EVENTS, Detail::batch_events)
    }

    /// Whether the frame and ball filters keep the sweep of `ball` at `frame`.
    pub fn wants(&self, frame: u64, ball: u32) -> bool {
        self.frames.contains(frame) && self.ball.is_none_or(|b| b == ball)
    }
}
