//! `sapnet open DIR`: a results folder — finished, stopped, or live and being written by
//! another process — in the workbench's views, followed as its runs end; Enter on a
//! finished run shows its dashboard in the Run view, made from its files. Nothing is
//! written: the folder is only read ([`crate::tui::workbench::folder`]).

use std::path::Path;

use anyhow::{Context, Result};
use crossterm::event::{KeyEvent, MouseEvent};
use ratatui::layout::Rect;
use ratatui::Frame;

use super::workbench::{Host, ScreenCommand, Tab, Workbench, OPEN_KEYS};
use crate::report::Report;
use crate::results::folder_changes;
use crate::results::folder_state::{FolderReader, FolderState};
use crate::tui::event_loop::{self, Flow, Screen};
use crate::tui::theme::Theme;
use crate::tui::workbench::folder::{Folder, FolderReads};
use crate::tui::workbench::frame::protocol_state;
use crate::tui::workbench::views::run::RunView;

/// The workbench on a folder opened.
pub struct Opened {
    pub workbench: Workbench,
}

impl Opened {
    pub fn new(state: FolderState, report: Option<Report>) -> Self {
        let run = RunView::new(&state.config.env.gym_id(), None);
        Self {
            workbench: Workbench::new(Some(Folder::new(state, report)), run, Tab::Runs),
        }
    }

    /// The folder, read before the screen opened.
    pub fn folder(&self) -> &Folder {
        self.workbench
            .folder
            .as_ref()
            .expect("read before the screen opens")
    }

    pub fn folder_mut(&mut self) -> &mut Folder {
        self.workbench
            .folder
            .as_mut()
            .expect("read before the screen opens")
    }

    pub fn on_key(&mut self, key: KeyEvent) -> Flow {
        match self.workbench.on_key(&key, OPEN_KEYS) {
            Some(ScreenCommand::Quit) => Flow::Quit,
            _ => Flow::Continue,
        }
    }

    /// A mouse event on a `screen`-sized terminal; whether it changed anything.
    pub fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) -> bool {
        self.workbench.on_mouse(mouse, screen, OPEN_KEYS)
    }

    pub fn draw(&self, frame: &mut Frame, theme: Theme) {
        let folder = &self.folder().state;
        let host = Host {
            keys: OPEN_KEYS,
            controls: Vec::new(),
            dir: folder.dir.display().to_string(),
            state: protocol_state(folder),
            active: folder.writer.is_some(),
            waiting: String::new(),
        };
        self.workbench.draw(frame, theme, &host, |_, _| {});
    }
}

/// `sapnet open`'s screen: the workbench, and the thread that reads the folder again.
struct OpenScreen {
    opened: Opened,
    reads: FolderReads,
    theme: Theme,
}

impl Screen for OpenScreen {
    fn drain(&mut self) -> (bool, Flow) {
        let mut changed = false;
        for read in self.reads.reads.try_iter() {
            match read {
                Ok((state, report)) => self.opened.workbench.refreshed(state, report),
                Err(error) => self.opened.workbench.read_failed(error),
            }
            changed = true;
        }
        (changed, Flow::Continue)
    }

    fn draw(&self, frame: &mut Frame) {
        self.opened.draw(frame, self.theme);
    }

    fn on_key(&mut self, key: KeyEvent) -> Flow {
        self.opened.on_key(key)
    }

    fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        self.opened.on_mouse(mouse, screen);
    }
}

/// Opens `dir` in the workbench until the user quits. A folder that cannot be read is
/// refused before the terminal is taken; a read that fails later is shown, and the last
/// good one kept on screen.
pub fn run(dir: &Path) -> Result<()> {
    let mut reader = FolderReader::new(dir);
    // Looked at before the read: a change during it is seen at the next look.
    let looked = folder_changes::look(dir);
    let state = reader
        .read()
        .with_context(|| format!("sapnet open {}", dir.display()))?;
    // The report of the finished runs is made by the reading thread's first read.
    let computing = !state.finished_key().is_empty();
    let mut opened = Opened::new(state, None);
    opened.folder_mut().computing = computing;
    let mut screen = OpenScreen {
        opened,
        reads: FolderReads::of(reader, looked)?,
        theme: Theme::from_env(),
    };
    event_loop::show(&mut screen)
}
