//! The one event loop every screen runs in (ratatui demo2's `App::run`, gitui's
//! `run_app`): drain what the screen's threads sent, leave on a signal, draw when
//! something changed (at most [`FRAME`]ly), then wait up to a frame for a key or a click.
//! A screen says what it does with each of those ([`Screen`]); the loop owns the terminal's
//! events and the pace, nothing else.
//!
//! The screen's threads (a protocol's runs, the folder's reader) never wait for it: each
//! frame takes every message they sent, never parking on their channels. A view's work in
//! the background ([`super::background`]) is drawn every frame while it runs.

use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use crossterm::event::{self as term, KeyEvent, KeyEventKind, MouseEvent};
use ratatui::layout::Rect;
use ratatui::Frame;

use super::FRAME;

/// Whether the screen goes on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    Continue,
    Quit,
}

/// A screen the loop runs: `sapnet open`'s, a protocol's, a sweep's.
pub trait Screen {
    /// Takes in what the screen's threads sent since the last frame, all of it, never
    /// waiting: whether anything changed, and whether the screen is done.
    fn drain(&mut self) -> (bool, Flow);

    /// SIGINT, SIGTERM or SIGHUP came (checked every frame): leave at once, unless there
    /// is something to finish first (a protocol stops after its step).
    fn on_signal(&mut self) -> Flow {
        Flow::Quit
    }

    /// Once a frame, before drawing.
    fn tick(&mut self, _now: Instant) {}

    /// Drawn every frame, not only after a change (a live dashboard's step line).
    fn animated(&self) -> bool {
        false
    }

    /// How long to wait for a key: a frame, or nothing while something runs between
    /// frames.
    fn wait(&self) -> Duration {
        FRAME
    }

    fn draw(&self, frame: &mut Frame);

    /// A key pressed (not released or repeated by the terminal's report of releases).
    fn on_key(&mut self, key: KeyEvent) -> Flow;

    /// A mouse event on a terminal of `screen`'s size.
    fn on_mouse(&mut self, _mouse: MouseEvent, _screen: Rect) {}
}

/// Runs `screen` on `terminal` until it quits, or fails to draw or read the keyboard.
pub fn run(terminal: &mut ratatui::DefaultTerminal, screen: &mut impl Screen) -> Result<()> {
    let mut dirty = true;
    let mut ended = super::background::ended();
    loop {
        let (changed, flow) = screen.drain();
        dirty |= changed;
        // A view's work in the background: drawn while it runs (its sign of work), and
        // once more when a piece ends (its result).
        let now_ended = super::background::ended();
        dirty |= now_ended != ended || super::background::busy();
        ended = now_ended;
        if flow == Flow::Quit {
            return Ok(());
        }
        if crate::signals::received().is_some() && screen.on_signal() == Flow::Quit {
            return Ok(());
        }
        screen.tick(Instant::now());
        if dirty || screen.animated() {
            terminal
                .draw(|frame| screen.draw(frame))
                .context("drawing the screen")?;
            dirty = false;
        }
        if !term::poll(screen.wait()).context("reading the keyboard")? {
            continue;
        }
        dirty = true;
        let flow = match term::read().context("reading the keyboard")? {
            // A key pressed, not one released (reported by some terminals).
            term::Event::Key(key) if key.kind == KeyEventKind::Press => screen.on_key(key),
            term::Event::Mouse(mouse) => {
                let size = terminal.size().context("reading the terminal's size")?;
                screen.on_mouse(mouse, size.into());
                Flow::Continue
            }
            // A resize: drawn again.
            _ => Flow::Continue,
        };
        if flow == Flow::Quit {
            return Ok(());
        }
    }
}

/// Takes the terminal (raw mode, the alternate screen, the mouse), runs `screen` until it
/// quits, and gives the terminal back however it ends.
pub fn show(screen: &mut impl Screen) -> Result<()> {
    let (mut terminal, _guard) = super::open_terminal()?;
    run(&mut terminal, screen)
}
