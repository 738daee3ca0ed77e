//! How a walk's calls are made without a key per call: `r` one at a time at a speed a
//! student can follow on the graph, `R` as fast as it goes in slices of
//! [`CALLS_PER_FRAME`], so that a walk of millions of calls leaves the screen and the keys
//! responsive.

use std::time::{Duration, Instant};

use super::Teach;

/// Calls `R` makes between two frames: a few milliseconds' worth.
pub const CALLS_PER_FRAME: usize = 50_000;

/// Calls a second `r` makes along the edges (`<` and `>` choose).
pub const SPEEDS: [f64; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];
/// `r`'s speed at the start: two calls a second, slow enough to follow on the graph.
const DEFAULT_SPEED: usize = 2;

/// Whether calls are being made between frames, and how fast.
#[derive(Debug, Clone)]
pub(super) struct Playback {
    /// `R`: the front end calls [`Teach::advance`] between frames.
    running: bool,
    /// `r`: calls made one at a time at [`SPEEDS`]`[speed]`, the next when this is due.
    animation: Option<Instant>,
    /// Index into [`SPEEDS`].
    speed: usize,
}

impl Default for Playback {
    fn default() -> Self {
        Self {
            running: false,
            animation: None,
            speed: DEFAULT_SPEED,
        }
    }
}

impl Playback {
    /// A key that acts on the walk stops both `r` and `R` where they are.
    pub(super) fn stop(&mut self) {
        self.running = false;
        self.animation = None;
    }

    /// `R` stops where it is; `r` is left as it was (a line typed does so).
    pub(super) fn stop_running(&mut self) {
        self.running = false;
    }
}

impl Teach {
    /// `r`'s speed, in calls a second.
    pub fn speed(&self) -> f64 {
        SPEEDS[self.playback.speed]
    }

    /// `<` / `>`: `r` slower or faster.
    pub fn change_speed(&mut self, faster: bool) {
        let speed = &mut self.playback.speed;
        *speed = if faster {
            (*speed + 1).min(SPEEDS.len() - 1)
        } else {
            speed.saturating_sub(1)
        };
        self.notice = Some(format!("r walks {} calls a second", self.speed()));
    }

    /// `r`: the walk's calls made one at a time at [`speed`](Self::speed), lit on the
    /// graph as they go; `r` again pauses.
    pub fn animate(&mut self) {
        self.playback.running = false;
        let going = self.walk.as_ref().is_some_and(|w| !w.is_done());
        self.playback.animation = match self.playback.animation {
            Some(_) => None,
            None if going => Some(Instant::now()),
            None => None,
        };
    }

    /// Whether `r` is walking.
    pub fn is_animating(&self) -> bool {
        self.playback.animation.is_some()
    }

    /// `R` in a front end: the remaining calls are made by [`advance`](Self::advance), as
    /// fast as it goes.
    pub fn run(&mut self) {
        self.playback.animation = None;
        self.playback.running = self.walk.as_ref().is_some_and(|w| !w.is_done());
        self.ask_at_walk_end();
    }

    /// Whether `R` is still making calls.
    pub fn is_running(&self) -> bool {
        self.playback.running
    }

    /// Makes up to `calls` of the remaining calls while running; returns how many.
    pub fn advance(&mut self, calls: usize) -> usize {
        self.advance_at(calls, Instant::now())
    }

    /// [`advance`](Self::advance) at the time `now`: `r`'s walk makes the calls due by
    /// then at its speed (at most one a frame, so each is seen on the graph).
    pub fn advance_at(&mut self, calls: usize, now: Instant) -> usize {
        if let Some(due) = self.playback.animation {
            if now < due {
                return 0;
            }
            let made = usize::from(self.call().is_some());
            self.sync();
            let going = self.walk.as_ref().is_some_and(|w| !w.is_done());
            self.playback.animation =
                going.then(|| now + Duration::from_secs_f64(1.0 / self.speed()));
            self.ask_at_walk_end();
            return made;
        }
        if !self.playback.running {
            return 0;
        }
        let mut made = 0;
        while made < calls && self.call().is_some() {
            made += 1;
        }
        if made < calls {
            self.playback.running = false;
        }
        self.sync();
        self.ask_at_walk_end();
        made
    }
}
