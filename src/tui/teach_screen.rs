//! Stand-alone teach mode (`sapnet teach`) as a [`Screen`] of the one loop: the session's
//! walk advances between frames while it runs (`r`), keys go to its prompt first, `?`
//! shows its keys and any key closes them.

use std::time::{Duration, Instant};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use ratatui::Frame;

use super::dashboard::apply_teach_key;
use super::event_loop::{Flow, Screen};
use super::teach_view;
use super::theme::Theme;
use super::FRAME;
use crate::teach::session::CALLS_PER_FRAME;
use crate::teach::Teach;

pub struct TeachScreen {
    teach: Teach,
    help: bool,
    theme: Theme,
}

impl TeachScreen {
    pub fn new(teach: Teach, theme: Theme) -> Self {
        Self {
            teach,
            help: false,
            theme,
        }
    }
}

impl Screen for TeachScreen {
    /// No thread sends teach mode anything: its walk runs here, between frames.
    fn drain(&mut self) -> (bool, Flow) {
        (false, Flow::Continue)
    }

    /// A long `r` runs in slices between frames, so that keys are read between them.
    fn tick(&mut self, _now: Instant) {
        self.teach.advance(CALLS_PER_FRAME);
    }

    fn animated(&self) -> bool {
        self.teach.is_running()
    }

    fn wait(&self) -> Duration {
        if self.teach.is_running() {
            Duration::ZERO
        } else {
            FRAME
        }
    }

    fn draw(&self, frame: &mut Frame) {
        teach_view::draw(frame, &self.teach, self.help, self.theme);
    }

    fn on_key(&mut self, key: KeyEvent) -> Flow {
        let ctrl_c =
            key.code == KeyCode::Char('c') && key.modifiers.contains(KeyModifiers::CONTROL);
        // A line being typed (`w`, `E`) takes q and Esc too.
        if self.teach.prompt().is_some() && !ctrl_c {
            apply_teach_key(&mut self.teach, key);
            return Flow::Continue;
        }
        if ctrl_c || key.code == KeyCode::Char('q') {
            return Flow::Quit;
        }
        if self.help {
            // Any key closes the keys' overlay; Esc never quits from it.
            self.help = false;
        } else if key.code == KeyCode::Char('?') {
            self.help = true;
        } else if key.code == KeyCode::Esc {
            return Flow::Quit;
        } else {
            apply_teach_key(&mut self.teach, key);
        }
        Flow::Continue
    }

    fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        if self.help || mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return;
        }
        if let Some(i) = teach_view::clicked(&self.teach, screen, mouse.column, mouse.row) {
            self.teach.pick(i);
        }
    }
}
