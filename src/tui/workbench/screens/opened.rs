//! `sapnet open DIR`: a results folder — finished, stopped, or live and being written by
//! another process — in the workbench's views, followed as its runs end; Enter on a
//! finished run shows its dashboard in the Run view, made from its files. Nothing is
//! written: the folder is only read ([`crate::tui::workbench::folder`]), until `R` asks
//! for its stopped protocol to be resumed: the folder is then taken as `sapnet --resume`
//! takes it, and the screen becomes that protocol's session ([`super::session`]), on the
//! same terminal.

use std::path::Path;

use anyhow::{Context, Result};
use crossterm::event::{KeyEvent, MouseEvent};
use ratatui::layout::Rect;
use ratatui::Frame;

use super::session::live::{self, Ended, Settings, Start};
use super::workbench::{Host, ScreenCommand, Tab, Workbench, OPEN_KEYS};
use crate::experiment::StoppedProtocol;
use crate::report::Report;
use crate::results::folder_changes;
use crate::results::folder_state::{FolderReader, FolderState};
use crate::tui::event_loop::{self, Flow, Screen};
use crate::tui::theme::Theme;
use crate::tui::workbench::folder::{resumable, Folder, FolderReads};
use crate::tui::workbench::frame::protocol_state;
use crate::tui::workbench::views::run::RunView;

/// The workbench on a folder opened.
pub struct Opened {
    pub workbench: Workbench,
    /// `R` asked, on a folder that can be resumed: the screen takes it.
    pub resume_asked: bool,
}

impl Opened {
    pub fn new(state: FolderState, report: Option<Report>) -> Self {
        let run = RunView::new(&state.config.env.gym_id(), None);
        Self {
            workbench: Workbench::new(Some(Folder::new(state, report)), run, Tab::Runs),
            resume_asked: false,
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
            Some(ScreenCommand::Resume) => {
                match resumable(&self.folder().state) {
                    Ok(()) => self.resume_asked = true,
                    Err(why) => self.workbench.notice = Some(why),
                }
                Flow::Continue
            }
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
            controls: if resumable(folder).is_ok() {
                vec![ScreenCommand::Resume]
            } else {
                Vec::new()
            },
            dir: folder.dir.display().to_string(),
            state: protocol_state(folder),
            active: folder.writer.is_some(),
            waiting: String::new(),
        };
        self.workbench.draw(frame, theme, &host, |_, _| {});
    }
}

/// `sapnet open`'s screen: the workbench, and the thread that reads the folder again.
pub(crate) struct OpenScreen<'a> {
    opened: Opened,
    reads: FolderReads,
    theme: Theme,
    /// What a protocol resumed by `R` runs with.
    settings: &'a Settings<'a>,
    /// The folder `R` took: the screen closes for its session.
    pub(crate) resumed: Option<StoppedProtocol>,
}

impl Screen for OpenScreen<'_> {
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
        let flow = self.opened.on_key(key);
        if !std::mem::take(&mut self.opened.resume_asked) {
            return flow;
        }
        let dir = self.opened.folder().state.dir.clone();
        match StoppedProtocol::take(&dir, None, None, &self.settings.python) {
            Ok(stopped) => {
                self.resumed = Some(stopped);
                Flow::Quit
            }
            // Taken by another process since the last read, or refused: why, and the
            // command that resumes it once it can be.
            Err(error) => {
                self.opened.workbench.notice = Some(format!(
                    "{error:#} (`sapnet --resume --out {}` resumes it from the command line)",
                    dir.display()
                ));
                Flow::Continue
            }
        }
    }

    fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        self.opened.on_mouse(mouse, screen);
    }
}

/// Opens `dir` in the workbench until the user quits. A folder that cannot be read is
/// refused before the terminal is taken; a read that fails later is shown, and the last
/// good one kept on screen. `R` on a stopped folder resumes it on the same terminal, with
/// `settings`: how its protocol ended is returned, as a session's is.
pub fn run(dir: &Path, settings: &Settings) -> Result<Ended> {
    let mut screen = OpenScreen::start(dir, settings)?;
    let (mut terminal, guard) = crate::tui::open_terminal()?;
    event_loop::run(&mut terminal, &mut screen)?;
    let resumed = screen.resumed.take();
    // The folder's reader stops before the session's starts.
    drop(screen);
    resume(resumed, &mut terminal, guard, settings)
}

/// The session of the folder `R` took, if it took one, on the terminal the screen had.
pub(crate) fn resume(
    resumed: Option<StoppedProtocol>,
    terminal: &mut ratatui::DefaultTerminal,
    guard: crate::tui::TerminalGuard,
    settings: &Settings,
) -> Result<Ended> {
    let Some(stopped) = resumed else {
        return Ok(Vec::new());
    };
    let start = Start::Resume {
        stopped,
        followed: None,
    };
    live::resume_in(terminal, guard, start, settings)
}

impl<'a> OpenScreen<'a> {
    /// The screen on `dir`, read once, and the thread that reads it on.
    pub(crate) fn start(dir: &Path, settings: &'a Settings<'a>) -> Result<Self> {
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
        Ok(OpenScreen {
            opened,
            reads: FolderReads::of(reader, looked)?,
            theme: Theme::from_env(),
            settings,
            resumed: None,
        })
    }
}
