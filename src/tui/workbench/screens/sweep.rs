//! `sapnet open SWEEP_DIR`: a sweep folder in the Sweep view, its one view, in the same
//! frame as the workbench's; the folder re-read on a thread of its own every
//! [`REFRESH`], the comparisons made again when its done cells changed.

use std::convert::Infallible;
use std::path::Path;
use std::sync::mpsc;

use anyhow::{Context, Result};
use crossterm::event::KeyEvent;
use ratatui::Frame;

use crate::tui::event_loop::{self, Flow, Screen};
use crate::tui::keys::{self, ch, Binding, OnHelp};
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::folder::REFRESH;
use crate::tui::workbench::frame::{self, Chrome};
use crate::tui::workbench::sweep_folder::{comparisons, SweepState, ValueComparison};
use crate::tui::workbench::views::sweep::{header_line, SweepView};

/// What the sweep screen's own keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SweepScreenCommand {
    Help,
    Quit,
}

const QUIT_KEYS: [(keys::Key, SweepScreenCommand); 3] = keys::quit_keys(SweepScreenCommand::Quit);

/// The sweep screen's keys (one view: no tabs).
pub const SWEEP_KEYS: &[Binding<SweepScreenCommand>] = &[
    Binding {
        keys: &[(ch('?'), SweepScreenCommand::Help)],
        help: keys::HELP_LINE,
        bar: Some(keys::HELP_BAR),
    },
    Binding {
        keys: &QUIT_KEYS,
        help: keys::QUIT_READING,
        bar: Some(keys::QUIT_BAR),
    },
];

/// What the reading thread sends: the sweep as read, with the comparisons when its done
/// cells changed; or why the read failed.
type Read = Result<(SweepState, Option<Vec<ValueComparison>>), String>;

/// The Sweep view, with `?` over it.
pub struct SweepScreen {
    pub view: SweepView,
    pub help: bool,
}

impl SweepScreen {
    pub fn new(view: SweepView) -> Self {
        Self { view, help: false }
    }

    /// What `key` does: `?`'s overlay takes it first, then the view, then the screen.
    pub fn on_key(&mut self, key: KeyEvent) -> Flow {
        if self.help {
            self.help = false;
            return match keys::on_help(&key) {
                OnHelp::Quit => Flow::Quit,
                OnHelp::Close => Flow::Continue,
            };
        }
        if self.view.on_key(&(), &key) != Outcome::<Infallible>::Ignored {
            return Flow::Continue;
        }
        match keys::command(SWEEP_KEYS, &key) {
            Some(SweepScreenCommand::Help) => self.help = true,
            Some(SweepScreenCommand::Quit) => return Flow::Quit,
            None => {}
        }
        Flow::Continue
    }

    pub fn draw(&self, frame: &mut Frame, theme: Theme) {
        let mut help = keys::help_lines(self.view.keys());
        help.extend(keys::help_lines(SWEEP_KEYS));
        let chrome = Chrome {
            header: header_line(&self.view, theme),
            tabs: Vec::new(),
            commands: self.view.bar(&()),
            over_the_top: false,
            help: self.help.then_some(help),
            notice: None,
        };
        let body = |frame: &mut Frame, area| self.view.draw(&(), frame, area, theme);
        frame::draw(frame, &chrome, theme, body, |_, _| {});
    }
}

/// The screen on the loop: the view, and the thread that reads the sweep again.
pub(crate) struct Running {
    screen: SweepScreen,
    reads: mpsc::Receiver<Read>,
    /// Dropped (however the screen ends), it wakes the thread and ends it.
    _stop: mpsc::Sender<()>,
    theme: Theme,
}

impl Screen for Running {
    fn drain(&mut self) -> (bool, Flow) {
        let mut changed = false;
        for read in self.reads.try_iter() {
            match read {
                Ok((sweep, values)) => self.screen.view.refreshed(sweep, values),
                Err(error) => self.screen.view.read_error = Some(error),
            }
            changed = true;
        }
        (changed, Flow::Continue)
    }

    fn draw(&self, frame: &mut Frame) {
        self.screen.draw(frame, self.theme);
    }

    fn on_key(&mut self, key: KeyEvent) -> Flow {
        self.screen.on_key(key)
    }
}

/// Opens the sweep folder `dir` in the Sweep view until the user quits.
pub fn run(dir: &Path) -> Result<()> {
    event_loop::show(&mut Running::start(dir)?)
}

impl Running {
    /// The Sweep view on `dir`, read once (a done cell that cannot be read is refused),
    /// and the thread that reads it on.
    pub(crate) fn start(dir: &Path) -> Result<Self> {
        let sweep =
            SweepState::read(dir).with_context(|| format!("sapnet open {}", dir.display()))?;
        let done = sweep.done();
        let values =
            comparisons(dir, &done).with_context(|| format!("sapnet open {}", dir.display()))?;
        let (reads_tx, reads) = mpsc::channel();
        let (stop_tx, stop) = mpsc::channel::<()>();
        let owned = dir.to_path_buf();
        std::thread::Builder::new()
            .name("sapnet open: reading the sweep".into())
            .spawn(move || read_on(&owned, done, &reads_tx, &stop))
            .context("starting the thread that reads the sweep")?;
        Ok(Running {
            screen: SweepScreen::new(SweepView::new(sweep, values)),
            reads,
            _stop: stop_tx,
            theme: Theme::from_env(),
        })
    }
}

/// Reads the sweep every [`REFRESH`] until `stop` is dropped, with the comparisons made
/// again when its done cells changed.
fn read_on(
    dir: &Path,
    mut reported: Vec<usize>,
    reads: &mpsc::Sender<Read>,
    stop: &mpsc::Receiver<()>,
) {
    loop {
        match stop.recv_timeout(REFRESH) {
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            _ => return,
        }
        let read = SweepState::read(dir).and_then(|sweep| {
            let done = sweep.done();
            if done == reported {
                Ok((sweep, None))
            } else {
                let values = comparisons(dir, &done)?;
                reported = done;
                Ok((sweep, Some(values)))
            }
        });
        if reads.send(read.map_err(|e| format!("{e:#}"))).is_err() {
            return;
        }
    }
}
