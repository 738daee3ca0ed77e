//! `sapnet open PARENT` on a folder that holds sapnet's folders rather than being one: the
//! Folders view lists what is under it ([`crate::results::found`]: found before the
//! terminal is taken, never through a link), and Enter opens the one picked on the same
//! terminal — a results folder in the workbench's views ([`super::opened`], `R` included),
//! a sweep in the Sweep view ([`super::sweep`]), a compare folder in its Comparison and
//! Curves ([`super::compared`]); Esc there comes back to the list.

use std::path::Path;

use anyhow::Result;
use crossterm::event::{KeyCode, KeyEvent, MouseEvent};
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::Frame;

use super::compared::CompareScreen;
use super::opened::{self, OpenScreen};
use super::session::live::{Ended, Settings};
use super::sweep;
use crate::experiment::StoppedProtocol;
use crate::results::found::{self, Kind};
use crate::tui::event_loop::{self, Flow, Screen};
use crate::tui::keys::{self, ch, code, Binding, OnHelp};
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::frame::{self, Chrome};
use crate::tui::workbench::views::folders::{FolderList, FoldersIntent, FoldersView};

/// What the list's screen's own keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FoldersScreenCommand {
    Help,
    Quit,
}

const QUIT_KEYS: [(keys::Key, FoldersScreenCommand); 3] =
    keys::quit_keys(FoldersScreenCommand::Quit);

/// The list's screen's keys (one view: no tabs).
pub const FOLDERS_KEYS: &[Binding<FoldersScreenCommand>] = &[
    Binding {
        keys: &[(ch('?'), FoldersScreenCommand::Help)],
        help: keys::HELP_LINE,
        bar: Some(keys::HELP_BAR),
    },
    Binding {
        keys: &QUIT_KEYS,
        help: (
            keys::QUIT_KEYS_SAID,
            "quit (the folders are only read: nothing in them changes unless R resumes one)",
        ),
        bar: Some(keys::QUIT_BAR),
    },
];

/// A folder opened from the list.
enum Inside<'a> {
    Results(Box<OpenScreen<'a>>),
    Sweep(sweep::Running),
    Compare(Box<CompareScreen>),
}

/// The list, or the folder opened from it.
pub struct FoldersScreen<'a> {
    pub list: FolderList,
    pub view: FoldersView,
    pub help: bool,
    pub notice: Option<String>,
    inside: Option<Inside<'a>>,
    settings: &'a Settings<'a>,
    theme: Theme,
    /// The folder `R` took in a results folder opened from the list.
    resumed: Option<StoppedProtocol>,
}

impl<'a> FoldersScreen<'a> {
    pub fn new(list: FolderList, settings: &'a Settings<'a>) -> Self {
        Self {
            list,
            view: FoldersView::default(),
            help: false,
            notice: None,
            inside: None,
            settings,
            theme: Theme::from_env(),
            resumed: None,
        }
    }

    /// Whether a folder opened from the list is shown.
    pub fn is_inside(&self) -> bool {
        self.inside.is_some()
    }

    /// Opens the folder of the search's index `i` in its views, or says why it cannot be.
    fn open(&mut self, i: usize) {
        let Some(found) = self.list.search.found.get(i) else {
            return;
        };
        let dir = found.dir.clone();
        let inside = match found.kind {
            Kind::Protocol => {
                OpenScreen::start(&dir, self.settings).map(|s| Inside::Results(Box::new(s)))
            }
            Kind::Sweep => sweep::Running::start(&dir).map(Inside::Sweep),
            Kind::Compare => CompareScreen::start(&dir).map(|s| Inside::Compare(Box::new(s))),
        };
        match inside {
            Ok(inside) => self.inside = Some(inside),
            Err(error) => self.notice = Some(format!("{error:#}")),
        }
    }

    pub fn on_key(&mut self, key: KeyEvent) -> Flow {
        if let Some(inside) = &mut self.inside {
            let esc = code(KeyCode::Esc).matches(&key);
            let flow = match inside {
                Inside::Results(screen) => {
                    let flow = screen.on_key(key);
                    if let Some(stopped) = screen.resumed.take() {
                        self.resumed = Some(stopped);
                        return Flow::Quit;
                    }
                    flow
                }
                Inside::Sweep(screen) => screen.on_key(key),
                Inside::Compare(screen) => screen.on_key(key),
            };
            // Esc, where the folder's screen would quit, comes back to the list.
            if flow == Flow::Quit && esc {
                self.inside = None;
                return Flow::Continue;
            }
            return flow;
        }
        self.notice = None;
        if self.help {
            self.help = false;
            return match keys::on_help(&key) {
                OnHelp::Quit => Flow::Quit,
                OnHelp::Close => Flow::Continue,
            };
        }
        match self.view.on_key(&self.list, &key) {
            Outcome::Ignored => {}
            Outcome::Done => return Flow::Continue,
            Outcome::Said(said) => {
                self.notice = Some(said);
                return Flow::Continue;
            }
            Outcome::Intent(FoldersIntent::Open(i)) => {
                self.open(i);
                return Flow::Continue;
            }
        }
        match keys::command(FOLDERS_KEYS, &key) {
            Some(FoldersScreenCommand::Help) => self.help = true,
            Some(FoldersScreenCommand::Quit) => return Flow::Quit,
            None => {}
        }
        Flow::Continue
    }

    pub fn draw(&self, frame: &mut Frame, theme: Theme) {
        match &self.inside {
            Some(Inside::Results(screen)) => return screen.draw(frame),
            Some(Inside::Sweep(screen)) => return screen.draw(frame),
            Some(Inside::Compare(screen)) => return screen.draw(frame, theme),
            None => {}
        }
        let help = self.help.then(|| {
            let mut lines = self
                .view
                .mode_help(&self.list)
                .unwrap_or_else(|| keys::help_lines(self.view.keys()));
            lines.extend(keys::help_lines(FOLDERS_KEYS));
            lines.extend(self.view.legend(&self.list));
            lines
        });
        let chrome = Chrome {
            header: Line::from(vec![
                Span::styled(format!(" {} ", self.list.parent.display()), theme.title()),
                Span::raw(format!(
                    "· the folders sapnet wrote under it, {} deep at most",
                    found::MAX_DEPTH
                )),
            ]),
            tabs: Vec::new(),
            commands: self.view.bar(&self.list),
            over_the_top: false,
            help,
            notice: self.notice.as_deref(),
        };
        let body = |frame: &mut Frame, area| self.view.draw(&self.list, frame, area, theme);
        frame::draw(frame, &chrome, theme, body, |_, _| {});
    }
}

impl Screen for FoldersScreen<'_> {
    fn drain(&mut self) -> (bool, Flow) {
        match &mut self.inside {
            Some(Inside::Results(screen)) => screen.drain(),
            Some(Inside::Sweep(screen)) => screen.drain(),
            Some(Inside::Compare(screen)) => screen.drain(),
            None => (false, Flow::Continue),
        }
    }

    fn draw(&self, frame: &mut Frame) {
        FoldersScreen::draw(self, frame, self.theme);
    }

    fn on_key(&mut self, key: KeyEvent) -> Flow {
        FoldersScreen::on_key(self, key)
    }

    fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        match &mut self.inside {
            Some(Inside::Results(inside)) => inside.on_mouse(mouse, screen),
            Some(Inside::Sweep(inside)) => inside.on_mouse(mouse, screen),
            Some(Inside::Compare(inside)) => inside.on_mouse(mouse, screen),
            None => {
                if !self.help {
                    let body = frame::body_area(screen, false);
                    if let Outcome::Said(said) = self.view.on_mouse(&self.list, mouse, body) {
                        self.notice = Some(said);
                    }
                }
            }
        }
    }
}

/// Lists the folders sapnet wrote under `parent` until the user quits; refused before the
/// terminal is taken when there is none. `R` in a results folder opened from the list
/// resumes it on the same terminal, as `sapnet open DIR` does.
pub fn run(parent: &Path, settings: &Settings) -> Result<Ended> {
    let search = found::find(parent);
    if search.found.is_empty() {
        anyhow::bail!(
            "sapnet open {}: no folder sapnet wrote is there or under it (looked {} folders \
             down, links not followed): a results folder holds summary.json, a sweep folder \
             sweep.ron, a compare folder comparison.csv and runs.csv",
            parent.display(),
            found::MAX_DEPTH
        );
    }
    let list = FolderList {
        parent: parent.to_path_buf(),
        search,
    };
    let mut screen = FoldersScreen::new(list, settings);
    let (mut terminal, guard) = crate::tui::open_terminal()?;
    event_loop::run(&mut terminal, &mut screen)?;
    let resumed = screen.resumed.take();
    drop(screen);
    opened::resume(resumed, &mut terminal, guard, settings)
}
