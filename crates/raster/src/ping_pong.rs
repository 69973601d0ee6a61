//! The frame-to-frame state of a stateful method (`feedback`, `cubemap`): two sets of
//! textures of this view written in turn (ping-pong), the set a previous view left
//! (carried), and which set the next frame reads. See `FrameEncoder::advance` and
//! `FrameEncoder::history` ([`crate::timing`]).
//!
//! A frame reads one source and writes the other own set; every `encode` of the same state
//! draws the same frame (timed frames are one frame), and `advance` makes the set just
//! written the one the next frame reads. The reflections a set holds are counted: a frame
//! reading a set of k reflections writes one of k + 1.

use crate::timing::FrameHistory;
use std::cell::Cell;
use std::sync::Arc;

/// The `FrameEncoder` methods of a frame that keeps its [`PingPong`] in `self.state`:
/// pre-roll, advance and the reflections of the frame drawn (`history` is the method's: it
/// names what its sets hold).
#[macro_export]
macro_rules! ping_pong_frame {
    () => {
        fn preroll_frames(&self) -> u32 {
            self.state.preroll()
        }

        fn advance(&self) {
            self.state.advance()
        }

        fn drawn_depth(&self) -> Option<usize> {
            Some(self.state.drawn_depth())
        }
    };
}

/// The textures a frame reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// None yet (the first frame): mirrors inside a texture show the depth cap.
    Nothing,
    /// The previous view's (a sequence's previous frame).
    Carried,
    /// This view's set 0 or 1.
    Own(usize),
}

impl Source {
    /// The own set a frame reading `self` writes.
    pub fn written(self) -> usize {
        match self {
            Source::Own(0) => 1,
            _ => 0,
        }
    }
}

/// A method's carried state: its own history type `H` and the reflections it holds.
pub struct Carried<H> {
    pub history: Arc<H>,
    pub levels: usize,
}

/// Which set the next frame reads, what each holds, and the carried set.
pub struct PingPong<H> {
    read: Cell<Source>,
    own_levels: [Cell<usize>; 2],
    drawn: Cell<usize>,
    carried: Option<Carried<H>>,
    preroll: u32,
}

/// What a stateful method hands the next view: its history and its reflection count.
pub struct Handed<H> {
    pub history: H,
    pub levels: usize,
}

impl<H: Send + Sync + 'static> PingPong<H> {
    /// Starts from `carried` (a previous view's state), or afresh after `history` pre-roll
    /// frames ([`crate::timing::preroll`]).
    pub fn new(carried: Option<Carried<H>>, history: u32) -> Self {
        let read = if carried.is_some() {
            Source::Carried
        } else {
            Source::Nothing
        };
        PingPong {
            read: Cell::new(read),
            own_levels: [Cell::new(0), Cell::new(0)],
            drawn: Cell::new(0),
            preroll: if carried.is_some() { 0 } else { history },
            carried,
        }
    }

    /// A previous view's state, if `history` is this method's and `fits` it.
    pub fn carried_from(history: FrameHistory, fits: impl Fn(&H) -> bool) -> Option<Carried<H>> {
        let handed = history.0.downcast::<Handed<Arc<H>>>().ok()?;
        fits(&handed.history).then(|| Carried {
            history: handed.history.clone(),
            levels: handed.levels,
        })
    }

    pub fn carried(&self) -> Option<&Arc<H>> {
        self.carried.as_ref().map(|c| &c.history)
    }

    /// Reflections the frame built first will show (a configured view's `FrameStats::depth`).
    pub fn first_depth(&self) -> usize {
        match &self.carried {
            Some(c) => c.levels + 1,
            None => self.preroll as usize + 1,
        }
    }

    pub fn preroll(&self) -> u32 {
        self.preroll
    }

    fn levels(&self, source: Source) -> usize {
        match source {
            Source::Nothing => 0,
            Source::Carried => self.carried.as_ref().map_or(0, |c| c.levels),
            Source::Own(i) => self.own_levels[i].get(),
        }
    }

    /// Begins a frame: the source it reads and the own set it writes.
    pub fn begin_frame(&self) -> (Source, usize) {
        let read = self.read.get();
        let write = read.written();
        self.own_levels[write].set(self.levels(read) + 1);
        self.drawn.set(write);
        (read, write)
    }

    /// Commits the frame last drawn: the next one reads what it wrote.
    pub fn advance(&self) {
        self.read.set(Source::Own(self.read.get().written()));
    }

    /// Reflections the frame last drawn shows.
    pub fn drawn_depth(&self) -> usize {
        self.own_levels[self.drawn.get()].get()
    }

    /// The state the next view continues from: own set `i` as `own(i)` makes it, or what
    /// was carried in.
    pub fn history(&self, own: impl FnOnce(usize) -> Arc<H>) -> Option<FrameHistory> {
        let handed = match self.read.get() {
            Source::Nothing => return None,
            Source::Carried => {
                let c = self.carried.as_ref()?;
                Handed {
                    history: c.history.clone(),
                    levels: c.levels,
                }
            }
            Source::Own(i) => Handed {
                history: own(i),
                levels: self.own_levels[i].get(),
            },
        };
        Some(FrameHistory(Arc::new(handed)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_alternate_sets_and_count_reflections() {
        let p: PingPong<u32> = PingPong::new(None, 3);
        assert_eq!((p.preroll(), p.first_depth()), (3, 4));
        assert_eq!(p.begin_frame(), (Source::Nothing, 0));
        assert_eq!(
            p.begin_frame(),
            (Source::Nothing, 0),
            "redrawn, not advanced"
        );
        p.advance();
        assert_eq!(p.begin_frame(), (Source::Own(0), 1));
        assert_eq!(p.drawn_depth(), 2);
        p.advance();
        assert_eq!(p.begin_frame(), (Source::Own(1), 0));
        assert_eq!(p.drawn_depth(), 3);
        p.advance();
        let h = p.history(|i| Arc::new(i as u32 + 10)).unwrap();
        let next = PingPong::new(PingPong::carried_from(h.clone(), |v: &u32| *v == 10), 7);
        assert_eq!((next.preroll(), next.first_depth()), (0, 4));
        assert_eq!(next.begin_frame(), (Source::Carried, 0));
        assert!(
            PingPong::carried_from(h, |v: &u32| *v == 11).is_none(),
            "does not fit"
        );
        let other = FrameHistory(Arc::new(5_u64));
        assert!(
            PingPong::<u32>::carried_from(other, |_| true).is_none(),
            "another method's"
        );
    }
}
