//! The workbench of a results folder, which `sapnet open DIR` ([`super::opened`]) and a
//! protocol run in the UI ([`super::session`]) both are: the folder's views and the Run
//! view a tab apart, in one frame ([`crate::tui::workbench::frame`]); and of a `sapnet
//! compare` folder ([`super::compared`]), its Comparison and Curves only. It routes keys
//! and clicks — `?`'s overlay, then the view shown (its table), then the screen's table
//! (the tabs, `?`, quitting, a protocol's controls) — and hands the screen what is its
//! own. The tabs are the screen's table's: a view it lists no key for is never shown.

use std::convert::Infallible;

use crossterm::event::{KeyCode, KeyEvent, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Wrap};
use ratatui::Frame;

use crate::report::Report;
use crate::results::folder_state::{FolderState, RunStatus};
use crate::tui::keys::{self, ch, Binding, OnHelp};
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::compare_folder::CompareFolder;
use crate::tui::workbench::folder::{Compared, Folder};
use crate::tui::workbench::frame::{self, Chrome};
use crate::tui::workbench::recorded;
use crate::tui::workbench::views::comparison::ComparisonView;
use crate::tui::workbench::views::curves::CurvesView;
use crate::tui::workbench::views::run::RunView;
use crate::tui::workbench::views::runs::RunsView;
use crate::tui::workbench::views::Intent;

/// The views, each a tab.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tab {
    Runs,
    Comparison,
    Curves,
    Run,
}

/// What the screens' own keys do (the views' keys are the views').
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScreenCommand {
    Show(Tab),
    Help,
    Quit,
    /// A protocol's controls, in a session: `L`, `S`, `R`.
    Launch,
    Stop,
    Resume,
}

use ScreenCommand as S;

impl Tab {
    /// As the status bar names it.
    pub fn name(self) -> &'static str {
        match self {
            Tab::Runs => "runs",
            Tab::Comparison => "comparison",
            Tab::Curves => "curves",
            Tab::Run => "run",
        }
    }
}

/// The tabs: the views' letters as they have always been, and numbered as gitui's are.
/// The status bar names each tab by its first key here.
const TABS: Binding<ScreenCommand> = Binding {
    keys: &[
        (ch('r'), S::Show(Tab::Runs)),
        (ch('c'), S::Show(Tab::Comparison)),
        (ch('v'), S::Show(Tab::Curves)),
        (ch('f'), S::Show(Tab::Run)),
        (ch('1'), S::Show(Tab::Runs)),
        (ch('2'), S::Show(Tab::Comparison)),
        (ch('3'), S::Show(Tab::Curves)),
        (ch('4'), S::Show(Tab::Run)),
    ],
    help: ("r c v f, 1–4", "the Runs, Comparison, Curves and Run views"),
    bar: None,
};

const HELP: Binding<ScreenCommand> = Binding {
    keys: &[(ch('?'), S::Help)],
    help: keys::HELP_LINE,
    bar: Some(keys::HELP_BAR),
};

/// `q`, Esc and Ctrl-C quit, from a view (Esc closes an overlay or leaves a mode first).
const QUIT_KEYS: [(keys::Key, ScreenCommand); 3] = keys::quit_keys(S::Quit);

/// A session's `R`.
const RESUME: Binding<ScreenCommand> = Binding {
    keys: &[(ch('R'), S::Resume)],
    help: ("R", "resume the stopped protocol of this folder"),
    bar: Some(("R", "resume")),
};

/// `sapnet open`'s keys: it only reads, until `R` asks it to resume the folder.
pub const OPEN_KEYS: &[Binding<ScreenCommand>] = &[
    TABS,
    Binding {
        keys: &[(ch('R'), S::Resume)],
        help: (
            "R",
            "resume the stopped protocol here, as `sapnet --resume` would (or say why not)",
        ),
        bar: Some(("R", "resume")),
    },
    HELP,
    Binding {
        keys: &QUIT_KEYS,
        help: (
            keys::QUIT_KEYS_SAID,
            "quit (the folder is only read: nothing in it changes unless R resumes it)",
        ),
        bar: Some(keys::QUIT_BAR),
    },
];

/// A compare folder's keys: its Comparison and Curves, the runs being other tools' (no
/// Runs view, no run's dashboard, nothing to resume).
pub const COMPARE_KEYS: &[Binding<ScreenCommand>] = &[
    Binding {
        keys: &[
            (ch('c'), S::Show(Tab::Comparison)),
            (ch('v'), S::Show(Tab::Curves)),
            (ch('1'), S::Show(Tab::Comparison)),
            (ch('2'), S::Show(Tab::Curves)),
        ],
        help: (
            "c v, 1 2",
            "the Comparison and Curves views (runs from elsewhere have no dashboard)",
        ),
        bar: None,
    },
    HELP,
    Binding {
        keys: &QUIT_KEYS,
        help: keys::QUIT_READING,
        bar: Some(keys::QUIT_BAR),
    },
];

/// A protocol's session's keys: its controls too.
pub const SESSION_KEYS: &[Binding<ScreenCommand>] = &[
    TABS,
    Binding {
        keys: &[(ch('L'), S::Launch)],
        help: ("L", "launch a protocol into a new folder (none training)"),
        bar: Some(("L", "launch")),
    },
    Binding {
        keys: &[(ch('S'), S::Stop)],
        help: ("S", "stop the protocol (asked once; its folder resumable)"),
        bar: Some(("S", "stop")),
    },
    RESUME,
    HELP,
    Binding {
        keys: &QUIT_KEYS,
        help: (
            keys::QUIT_KEYS_SAID,
            "quit; asks first while a protocol trains",
        ),
        bar: Some(keys::QUIT_BAR),
    },
];

/// What the screen around the workbench says and offers.
pub struct Host {
    /// Its table.
    pub keys: &'static [Binding<ScreenCommand>],
    /// Its keys the bar offers now, before the view's (a protocol's controls: a narrow
    /// terminal keeps them).
    pub controls: Vec<ScreenCommand>,
    /// The folder, before it can be read.
    pub dir: String,
    /// Where the protocol stands, for the Run view's line; whether it trains.
    pub state: String,
    pub active: bool,
    /// What the folder's views say before the folder can be read.
    pub waiting: String,
}

/// A results folder's views and the Run view, with what is over them.
pub struct Workbench {
    /// The folder as last read; `None` before a protocol started here wrote its
    /// summary.json, and on a compare folder.
    pub folder: Option<Folder>,
    /// The compare folder shown, in the Comparison and Curves views only.
    pub compare: Option<CompareFolder>,
    /// Why the folder cannot be read yet.
    pub unread: Option<String>,
    pub tab: Tab,
    pub runs: RunsView,
    pub comparison: ComparisonView,
    pub curves: CurvesView,
    pub run: RunView,
    /// `?`'s overlay is up.
    pub help: bool,
    /// What the last key did or why it did nothing, shown until the next key.
    pub notice: Option<String>,
}

impl Workbench {
    pub fn new(folder: Option<Folder>, run: RunView, tab: Tab) -> Self {
        Self {
            folder,
            compare: None,
            unread: None,
            tab,
            runs: RunsView::default(),
            comparison: ComparisonView::default(),
            curves: CurvesView::default(),
            run,
            help: false,
            notice: None,
        }
    }

    /// The workbench on a compare folder, its Comparison shown.
    pub fn of_compare(compare: CompareFolder) -> Self {
        let run = RunView::new(&compare.scoring.task, None);
        let mut workbench = Self::new(None, run, Tab::Comparison);
        workbench.compare = Some(compare);
        workbench
    }

    /// A new read of the folder, as [`Folder::refreshed`] takes it.
    pub fn refreshed(&mut self, state: FolderState, report: Option<Option<Report>>) {
        self.unread = None;
        let folder = match &mut self.folder {
            Some(folder) => {
                folder.refreshed(state, report);
                folder
            }
            None => self.folder.insert(Folder::new(state, report.flatten())),
        };
        self.runs.refreshed(folder);
        self.comparison.refreshed(folder);
    }

    /// A read that failed: before the first good one the screen says why; after it, the
    /// views keep the last good read and say it.
    pub fn read_failed(&mut self, error: String) {
        match &mut self.folder {
            Some(folder) => folder.read_error = Some(error),
            None => self.unread = Some(error),
        }
    }

    /// What `key` does, `keys` being the screen's table: `Some` of the screen's command it
    /// is, once the overlay, the view and the tabs have had it.
    pub fn on_key(
        &mut self,
        key: &KeyEvent,
        keys: &[Binding<ScreenCommand>],
    ) -> Option<ScreenCommand> {
        self.notice = None;
        if self.help {
            self.help = false;
            return (keys::on_help(key) == OnHelp::Quit).then_some(S::Quit);
        }
        match self.view_key(key) {
            Outcome::Ignored => {}
            outcome => {
                self.done(outcome);
                return None;
            }
        }
        match keys::command(keys, key)? {
            S::Show(tab) => self.tab = tab,
            S::Help => self.help = true,
            command => return Some(command),
        }
        None
    }

    fn view_key(&mut self, key: &KeyEvent) -> Outcome<Intent> {
        let compared = compared(&self.folder, &self.compare);
        match (self.tab, &self.folder, compared) {
            (Tab::Run, _, _) => lift(self.run.on_key(&(), key)),
            (Tab::Runs, Some(folder), _) => self.runs.on_key(folder, key),
            (Tab::Comparison, _, Some(shown)) => self.comparison.on_key(shown, key),
            (Tab::Curves, _, Some(shown)) => self.curves.on_key(shown, key),
            _ => Outcome::Ignored,
        }
    }

    /// What a view did, seen to: its words shown, its intent followed.
    fn done(&mut self, outcome: Outcome<Intent>) {
        match outcome {
            Outcome::Said(said) => self.notice = Some(said),
            Outcome::Intent(Intent::ShowRun(row)) => self.show_run(row),
            Outcome::Ignored | Outcome::Done => {}
        }
    }

    /// Enter on the Runs view's row `row`: the run in the Run view, followed if it trains
    /// (or trained) in this session, else its dashboard read afresh from its files once it
    /// finished.
    pub fn show_run(&mut self, row: usize) {
        let Some(folder) = &self.folder else {
            return;
        };
        let state = &folder.state;
        let Some(run) = state.runs.get(row) else {
            return;
        };
        let key = (run.method.label().to_string(), run.run);
        let live = self.run.runs.get(&key);
        if live.is_some_and(|r| r.dashboard.from_files.is_none()) {
            self.run.follow(key);
            self.tab = Tab::Run;
            return;
        }
        if state.finished(&run.method, run.run).is_none() {
            self.notice = Some(match run.status {
                RunStatus::Queued => format!("{} run {} has not started yet", key.0, key.1),
                status => format!(
                    "{} run {} is {}: a run's dashboard is made from the files of its end",
                    key.0,
                    key.1,
                    status.name()
                ),
            });
            return;
        }
        let (task, reference) = (&self.run.task, &self.run.reference);
        match recorded::dashboard(state, &run.method, run.run, task, reference) {
            Ok(dashboard) => {
                self.run.show_recorded(key, dashboard);
                self.tab = Tab::Run;
            }
            Err(error) => self.notice = Some(format!("{error:#}")),
        }
    }

    /// A mouse event on a terminal of `screen`'s size: a left click on a tab's name in the
    /// status bar shows it; the view shown has the rest. Whether it changed anything.
    pub fn on_mouse(
        &mut self,
        mouse: MouseEvent,
        screen: Rect,
        keys: &[Binding<ScreenCommand>],
    ) -> bool {
        if self.help {
            return false;
        }
        let over_the_top = self.tab == Tab::Run;
        let click = mouse.kind == MouseEventKind::Down(MouseButton::Left);
        if click && !over_the_top && mouse.row + 1 == screen.height {
            let Some(i) = frame::tab_at(&self.tabs(keys), mouse.column, screen.width) else {
                return false;
            };
            self.tab = tab_keys(keys)[i].0;
            return true;
        }
        let body = frame::body_area(screen, over_the_top);
        let compared = compared(&self.folder, &self.compare);
        let outcome = match (self.tab, &self.folder, compared) {
            (Tab::Run, _, _) => lift(self.run.on_mouse(&(), mouse, body)),
            (Tab::Runs, Some(folder), _) => self.runs.on_mouse(folder, mouse, body),
            (Tab::Comparison, _, Some(shown)) => self.comparison.on_mouse(shown, mouse, body),
            (Tab::Curves, _, Some(shown)) => self.curves.on_mouse(shown, mouse, body),
            _ => Outcome::Ignored,
        };
        let changed = outcome != Outcome::Ignored;
        self.done(outcome);
        changed
    }

    /// The tabs as the status bar shows them, the one shown marked.
    fn tabs(&self, keys: &[Binding<ScreenCommand>]) -> Vec<frame::Tab> {
        tab_keys(keys)
            .into_iter()
            .map(|(tab, key)| (key.to_string(), tab.name(), tab == self.tab))
            .collect()
    }

    /// `?`'s lines: the view's keys (or, while a mode takes the keys, the mode's only),
    /// the screen's, then what the view adds (the mouse, its symbols).
    fn help_lines(&self, keys: &[Binding<ScreenCommand>]) -> Vec<(&'static str, &'static str)> {
        if let Some(lines) = self.run_in_mode() {
            return lines;
        }
        let compared = compared(&self.folder, &self.compare);
        let (own, legend) = match (self.tab, &self.folder, compared) {
            (Tab::Run, _, _) => (keys::help_lines(self.run.keys()), self.run.legend(&())),
            (Tab::Runs, Some(f), _) => (keys::help_lines(self.runs.keys()), self.runs.legend(f)),
            (Tab::Comparison, _, Some(f)) => (
                keys::help_lines(self.comparison.keys()),
                self.comparison.legend(f),
            ),
            (Tab::Curves, _, Some(f)) => {
                (keys::help_lines(self.curves.keys()), self.curves.legend(f))
            }
            _ => (Vec::new(), Vec::new()),
        };
        let mut lines = own;
        lines.extend(keys::help_lines(keys));
        lines.extend(legend);
        lines
    }

    /// The keys of teach mode, while it takes the Run view's.
    fn run_in_mode(&self) -> Option<Vec<(&'static str, &'static str)>> {
        (self.tab == Tab::Run)
            .then(|| self.run.mode_help(&()))
            .flatten()
    }

    /// What the bar offers now: the screen's controls, then the view's keys.
    fn commands(&self, host: &Host) -> Vec<(&'static str, &'static str)> {
        let mut commands: Vec<(&'static str, &'static str)> = host
            .controls
            .iter()
            .filter_map(|&c| keys::binding(host.keys, c)?.bar)
            .collect();
        let compared = compared(&self.folder, &self.compare);
        commands.extend(match (self.tab, &self.folder, compared) {
            (Tab::Run, _, _) => self.run.bar(&()),
            (Tab::Runs, Some(folder), _) => self.runs.bar(folder),
            (Tab::Comparison, _, Some(shown)) => self.comparison.bar(shown),
            (Tab::Curves, _, Some(shown)) => self.curves.bar(shown),
            _ => Vec::new(),
        });
        commands
    }

    /// The workbench with `host`'s line and keys, and `overlay` (the screen's own) over it.
    pub fn draw(
        &self,
        frame: &mut Frame,
        theme: Theme,
        host: &Host,
        overlay: impl FnOnce(&mut Frame, Rect),
    ) {
        let over_the_top = self.tab == Tab::Run;
        // A mode that takes the keys (teach mode) offers none of the screen's.
        let free = self.run_in_mode().is_none();
        let width = usize::from(frame.area().width);
        let chrome = Chrome {
            header: match (over_the_top, &self.folder, &self.compare) {
                (true, _, _) => self.run_line(host, theme),
                (false, Some(folder), _) => frame::folder_line(folder, theme, width),
                (false, None, Some(compare)) => frame::compare_line(compare, theme, width),
                (false, None, None) => Line::from(vec![
                    Span::styled(format!(" {} ", host.dir), theme.title()),
                    Span::raw(format!("· {}", host.state)),
                ]),
            },
            tabs: if free {
                self.tabs(host.keys)
            } else {
                Vec::new()
            },
            commands: if free {
                self.commands(host)
            } else {
                Vec::new()
            },
            over_the_top,
            help: self.help.then(|| self.help_lines(host.keys)),
            notice: self.notice.as_deref(),
        };
        let compared = compared(&self.folder, &self.compare);
        let body = |frame: &mut Frame, area: Rect| match (self.tab, &self.folder, compared) {
            (Tab::Run, _, _) => self.run.draw(&(), frame, area, theme),
            (Tab::Runs, Some(folder), _) => self.runs.draw(folder, frame, area, theme),
            (Tab::Comparison, _, Some(shown)) => self.comparison.draw(shown, frame, area, theme),
            (Tab::Curves, _, Some(shown)) => self.curves.draw(shown, frame, area, theme),
            _ => self.draw_waiting(frame, area, host, theme),
        };
        frame::draw(frame, &chrome, theme, body, overlay);
    }

    /// The Run view's line: which run, where the protocol stands, how far it is.
    fn run_line(&self, host: &Host, theme: Theme) -> Line<'static> {
        let followed = match &self.run.followed {
            Some((method, run)) => format!(" ▶ {method} run {run} "),
            None => " no run followed ".into(),
        };
        let mut state = host.state.clone();
        if let Some(folder) = &self.folder {
            let state_now = &folder.state;
            state.push_str(&format!(
                " · {}",
                crate::tui::workbench::cells::runs_finished(
                    state_now.finished_runs(),
                    state_now.runs.len()
                )
            ));
        }
        let from_files = self
            .run
            .followed_run()
            .is_some_and(|r| r.dashboard.from_files.is_some());
        if from_files {
            state.push_str(" · read from its files");
        }
        Line::from(vec![
            Span::styled(followed, theme.title()),
            Span::raw("· "),
            Span::styled(
                state,
                if host.active {
                    theme.active()
                } else {
                    Style::new()
                },
            ),
        ])
    }

    /// Before the folder can be read: what the screen says of it, and why it cannot be.
    fn draw_waiting(&self, frame: &mut Frame, area: Rect, host: &Host, theme: Theme) {
        let mut lines = vec![Line::from(""), Line::from(host.waiting.clone())];
        if let Some(error) = &self.unread {
            lines.push(Line::from(""));
            lines.push(Line::from(Span::styled(error.clone(), theme.dim())));
        }
        frame.render_widget(Paragraph::new(lines).wrap(Wrap { trim: true }), area);
    }
}

/// What the Comparison and Curves views show: the results folder, else the compare
/// folder (fields apart, so that a view may be borrowed beside it).
fn compared<'a>(
    folder: &'a Option<Folder>,
    compare: &'a Option<CompareFolder>,
) -> Option<&'a (dyn Compared + 'static)> {
    match (folder, compare) {
        (Some(folder), _) => Some(folder),
        (None, Some(compare)) => Some(compare),
        (None, None) => None,
    }
}

/// The tabs of `keys`, in their order, each with the first letter that shows it.
fn tab_keys(keys: &[Binding<ScreenCommand>]) -> Vec<(Tab, char)> {
    let mut tabs: Vec<(Tab, char)> = Vec::new();
    for &(key, command) in keys.iter().flat_map(|b| b.keys) {
        if let (S::Show(tab), KeyCode::Char(c)) = (command, key.code) {
            if !tabs.iter().any(|&(t, _)| t == tab) {
                tabs.push((tab, c));
            }
        }
    }
    tabs
}

/// A view that asks nothing of its screen, as one that may.
fn lift(outcome: Outcome<Infallible>) -> Outcome<Intent> {
    match outcome {
        Outcome::Ignored => Outcome::Ignored,
        Outcome::Done => Outcome::Done,
        Outcome::Said(said) => Outcome::Said(said),
        Outcome::Intent(never) => match never {},
    }
}
