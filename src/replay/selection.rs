//! What a trace holds (its frames and balls) and what the frame and ball
//! filters of a replay kept of it: a filter that keeps nothing is an error
//! naming what the trace has, one that keeps part says how much.

use std::collections::BTreeSet;
use std::fmt;

use super::ReplayOptions;
use crate::numbers::plural;

/// Distinct balls remembered; beyond this only their range is kept.
const MAX_DISTINCT_BALLS: usize = 1024;
/// Distinct balls listed one by one when they are not consecutive.
const LISTED_BALLS: usize = 8;

/// The frames and balls of the sweeps read from a trace, filtered out or not.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SweepExtent {
    /// Sweeps read.
    pub sweeps: u64,
    /// Smallest and largest frame.
    pub frames: Option<(u64, u64)>,
    /// Smallest and largest ball.
    pub balls: Option<(u32, u32)>,
    /// The distinct balls (at most 1,024; `balls_truncated` past that).
    pub distinct_balls: BTreeSet<u32>,
    /// Whether more balls were seen than `distinct_balls` holds.
    pub balls_truncated: bool,
}

impl SweepExtent {
    /// Counts the sweep of `ball` at `frame`.
    pub fn add(&mut self, frame: u64, ball: u32) {
        self.sweeps += 1;
        self.frames = Some(match self.frames {
            None => (frame, frame),
            Some((lo, hi)) => (lo.min(frame), hi.max(frame)),
        });
        self.balls = Some(match self.balls {
            None => (ball, ball),
            Some((lo, hi)) => (lo.min(ball), hi.max(ball)),
        });
        if self.distinct_balls.len() < MAX_DISTINCT_BALLS || self.distinct_balls.contains(&ball) {
            self.distinct_balls.insert(ball);
        } else {
            self.balls_truncated = true;
        }
    }
}

/// `ball 0, frames 0..=591`, `balls 0..=3, frames 10..=20`, `balls 0, 2, 7,
/// frame 4`, or `no sweep`. Ranges are written as `--frames` reads them
/// (`A..=B` includes B).
impl fmt::Display for SweepExtent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (Some((f_lo, f_hi)), Some((b_lo, b_hi))) = (self.frames, self.balls) else {
            return f.write_str("no sweep");
        };
        let distinct = self.distinct_balls.len() as u64;
        let consecutive = !self.balls_truncated && distinct == u64::from(b_hi - b_lo) + 1;
        if b_lo == b_hi {
            write!(f, "ball {b_lo}")?;
        } else if consecutive {
            write!(f, "balls {b_lo}..={b_hi}")?;
        } else if !self.balls_truncated && self.distinct_balls.len() <= LISTED_BALLS {
            let list: Vec<String> = self.distinct_balls.iter().map(u32::to_string).collect();
            write!(f, "balls {}", list.join(", "))?;
        } else {
            let more = if self.balls_truncated { "over " } else { "" };
            write!(f, "balls {b_lo}..={b_hi} ({more}{distinct} distinct)")?;
        }
        if f_lo == f_hi {
            write!(f, ", frame {f_lo}")
        } else {
            write!(f, ", frames {f_lo}..={f_hi}")
        }
    }
}

/// What the frame and ball filters of a replay kept.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Selection {
    /// No filter: every sweep.
    Everything,
    /// The filters kept `kept` of the trace's `of` sweeps (at least one).
    Part {
        /// The filters, in words (`frames 100..200, ball 0`).
        filter: String,
        /// Sweeps kept.
        kept: u64,
        /// Sweeps read.
        of: u64,
    },
    /// The filters kept no sweep of a trace holding `seen`.
    Nothing {
        /// The filters, in words.
        filter: String,
        /// What the trace holds.
        seen: SweepExtent,
    },
}

impl Selection {
    /// What `options`' filters kept of a trace holding `seen`, of which
    /// `kept` sweeps passed.
    pub fn of(options: &ReplayOptions, seen: &SweepExtent, kept: u64) -> Selection {
        let Some(filter) = options.filter_text() else {
            return Selection::Everything;
        };
        if kept == 0 {
            Selection::Nothing {
                filter,
                seen: seen.clone(),
            }
        } else {
            Selection::Part {
                filter,
                kept,
                of: seen.sweeps,
            }
        }
    }

    /// Whether nothing was kept.
    pub fn is_nothing(&self) -> bool {
        matches!(self, Selection::Nothing { .. })
    }
}

/// `the filter (ball 99) selects no sweep of the trace; it has 2103 sweeps:
/// balls 0..=3, frames 0..=591`, or `the filter (frames 100..200) kept 412 of
/// 2103 sweeps`; nothing for [`Selection::Everything`].
impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Selection::Everything => Ok(()),
            Selection::Part { filter, kept, of } => {
                write!(
                    f,
                    "the filter ({filter}) kept {kept} of {of} {}",
                    plural(*of, "sweep")
                )
            }
            Selection::Nothing { filter, seen } if seen.sweeps == 0 => {
                write!(
                    f,
                    "the filter ({filter}) selects nothing: the trace has no sweep"
                )
            }
            Selection::Nothing { filter, seen } => write!(
                f,
                "the filter ({filter}) selects none of the trace's {} {}: it has {seen}",
                seen.sweeps,
                plural(seen.sweeps, "sweep")
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::replay::FrameRange;

    fn extent(sweeps: &[(u64, u32)]) -> SweepExtent {
        let mut e = SweepExtent::default();
        for &(frame, ball) in sweeps {
            e.add(frame, ball);
        }
        e
    }

    #[test]
    fn extent_names_balls_and_frames() {
        assert_eq!(extent(&[]).to_string(), "no sweep");
        assert_eq!(extent(&[(4, 0)]).to_string(), "ball 0, frame 4");
        assert_eq!(
            extent(&[(0, 3), (591, 0), (7, 1), (9, 2)]).to_string(),
            "balls 0..=3, frames 0..=591"
        );
        assert_eq!(
            extent(&[(1, 0), (2, 2), (3, 7)]).to_string(),
            "balls 0, 2, 7, frames 1..=3"
        );
        let many: Vec<(u64, u32)> = (0..20).map(|b| (0, b * 3)).collect();
        assert_eq!(
            extent(&many).to_string(),
            "balls 0..=57 (20 distinct), frame 0"
        );
    }

    #[test]
    fn selection_of_filters() {
        let seen = extent(&[(0, 0), (10, 1)]);
        let none = ReplayOptions::default();
        assert_eq!(Selection::of(&none, &seen, 0), Selection::Everything);
        let ball = ReplayOptions {
            ball: Some(9),
            ..ReplayOptions::default()
        };
        let nothing = Selection::of(&ball, &seen, 0);
        assert!(nothing.is_nothing());
        assert_eq!(
            nothing.to_string(),
            "the filter (ball 9) selects none of the trace's 2 sweeps: it has balls 0..=1, frames 0..=10"
        );
        let frames = ReplayOptions {
            frames: FrameRange {
                start: Some(5),
                end: None,
            },
            ..ReplayOptions::default()
        };
        assert_eq!(
            Selection::of(&frames, &seen, 1).to_string(),
            "the filter (frames 5..) kept 1 of 2 sweeps"
        );
        assert_eq!(
            Selection::of(&frames, &SweepExtent::default(), 0).to_string(),
            "the filter (frames 5..) selects nothing: the trace has no sweep"
        );
    }
}
