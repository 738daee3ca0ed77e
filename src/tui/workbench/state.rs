//! What the workbench keeps between frames: the folder as last read, the report of its
//! finished runs, the view shown and what each view's keys chose. Drawing nothing: the
//! views ([`super::view`]) draw this.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use crate::report::Report;
use crate::results::folder_state::FolderState;

/// The views, each a key away.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// Every planned run: its status, progress, curve and source.
    Runs,
    /// The methods side by side: aggregates with intervals, whiskers, pairs.
    Comparison,
    /// Each method's learning curve over its runs, with its band ([`super::curves`]).
    Curves,
}

impl View {
    pub const ALL: [View; 3] = [View::Runs, View::Comparison, View::Curves];

    /// The key that shows it, and its name in the status bar.
    pub fn key(self) -> (char, &'static str) {
        match self {
            View::Runs => ('r', "runs"),
            View::Comparison => ('c', "comparison"),
            View::Curves => ('v', "curves"),
        }
    }
}

/// Which aggregate over runs the Comparison view shows, as `comparison.csv` names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aggregate {
    Iqm,
    Mean,
    Median,
    OptimalityGap,
}

impl Aggregate {
    const ORDER: [Aggregate; 4] = [
        Aggregate::Iqm,
        Aggregate::Mean,
        Aggregate::Median,
        Aggregate::OptimalityGap,
    ];

    /// As the table's header says it (`IQM`, as the stdout table does).
    pub fn name(self) -> &'static str {
        match self {
            Aggregate::Iqm => "IQM",
            Aggregate::Mean => "mean",
            Aggregate::Median => "median",
            Aggregate::OptimalityGap => "optimality gap",
        }
    }

    fn next(self) -> Self {
        let i = Self::ORDER.iter().position(|&a| a == self).unwrap_or(0);
        Self::ORDER[(i + 1) % Self::ORDER.len()]
    }
}

/// A score of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Score {
    /// The training return: the headline, which pairs are ranked by.
    Return,
    /// The greedy test score of what a run hands over.
    Test,
}

impl Score {
    /// As `improvement.csv`'s `score` column says it.
    pub fn column(self) -> &'static str {
        match self {
            Score::Return => "return",
            Score::Test => "test",
        }
    }
}

/// What the loop does after a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    None,
    Quit,
}

/// The workbench over one results folder.
pub struct Workbench {
    pub folder: FolderState,
    /// The report of the folder's finished runs; `None` until one has finished.
    pub report: Option<Report>,
    /// The report of newly finished runs is being made (the one shown is older, or none).
    pub computing: bool,
    pub view: View,
    /// The keys' overlay is shown.
    pub help: bool,
    pub aggregate: Aggregate,
    /// The score whose pairs the Comparison view lists (and the only one it shows on a
    /// terminal too narrow for both).
    pub score: Score,
    /// The picked row of the Runs view (a run) and of the Comparison view (a method).
    pub run_cursor: usize,
    pub method_cursor: usize,
    /// The last refresh's failure, shown until a read succeeds again: the views keep the
    /// last good read.
    pub read_error: Option<String>,
    /// The keys a protocol run in the UI adds (hook for [`super::session`]): its controls
    /// (stop, launch, resume), listed before the view's keys so that a narrow terminal
    /// keeps them; the others, listed after; and the overlay's. The session handles them
    /// before the views do.
    pub host_controls: Vec<(&'static str, &'static str)>,
    pub host_bar: Vec<(&'static str, &'static str)>,
    pub host_overlay: Vec<(&'static str, &'static str)>,
    /// The host runs protocols (a session), so that quitting may stop one; else the
    /// folder is only read (`sapnet open`).
    pub host_runs_protocols: bool,
    /// The Curves view's choices.
    pub curves: super::curves::Curves,
}

impl Workbench {
    pub fn new(folder: FolderState, report: Option<Report>) -> Self {
        Self {
            folder,
            report,
            computing: false,
            view: View::Runs,
            help: false,
            aggregate: Aggregate::Iqm,
            score: Score::Return,
            run_cursor: 0,
            method_cursor: 0,
            read_error: None,
            host_controls: Vec::new(),
            host_bar: Vec::new(),
            host_overlay: Vec::new(),
            host_runs_protocols: false,
            curves: super::curves::Curves::default(),
        }
    }

    /// A new read of the folder; `report` is `Some` when its finished runs changed (the
    /// report of those, or `Some(None)` when none finished).
    pub fn refreshed(&mut self, folder: FolderState, report: Option<Option<Report>>) {
        self.folder = folder;
        if let Some(report) = report {
            self.report = report;
            self.computing = false;
        }
        self.read_error = None;
        self.run_cursor = self
            .run_cursor
            .min(self.folder.runs.len().saturating_sub(1));
        self.method_cursor = self.method_cursor.min(self.methods().saturating_sub(1));
    }

    /// The protocol's methods, as many as the Comparison view lists.
    pub fn methods(&self) -> usize {
        self.folder.config.protocol.methods.len()
    }

    pub fn on_key(&mut self, key: KeyEvent) -> Action {
        let ctrl_c =
            key.code == KeyCode::Char('c') && key.modifiers.contains(KeyModifiers::CONTROL);
        if ctrl_c || key.code == KeyCode::Char('q') {
            return Action::Quit;
        }
        if self.help {
            // Any key closes the overlay, as the dashboard's does.
            self.help = false;
            return Action::None;
        }
        if self.view == View::Curves && self.curves.on_key(key, &self.folder) {
            return Action::None;
        }
        match key.code {
            KeyCode::Esc => return Action::Quit,
            KeyCode::Char('?') => self.help = true,
            KeyCode::Char('r') => self.view = View::Runs,
            KeyCode::Char('c') => self.view = View::Comparison,
            KeyCode::Char('v') => self.view = View::Curves,
            KeyCode::Char('a') if self.view == View::Comparison => {
                self.aggregate = self.aggregate.next();
            }
            KeyCode::Char('s') if self.view == View::Comparison => {
                self.score = match self.score {
                    Score::Return => Score::Test,
                    Score::Test => Score::Return,
                };
            }
            KeyCode::Up | KeyCode::Char('k') => self.move_cursor(-1),
            KeyCode::Down | KeyCode::Char('j') => self.move_cursor(1),
            KeyCode::PageUp => self.move_cursor(-10),
            KeyCode::PageDown => self.move_cursor(10),
            _ => {}
        }
        Action::None
    }

    fn move_cursor(&mut self, by: isize) {
        let methods = self.methods();
        let (cursor, rows) = match self.view {
            View::Runs => (&mut self.run_cursor, self.folder.runs.len()),
            View::Comparison => (&mut self.method_cursor, methods),
            View::Curves => return,
        };
        let last = rows.saturating_sub(1) as isize;
        *cursor = (*cursor as isize + by).clamp(0, last) as usize;
    }

    /// Every key, for the overlay: the views' first, then what each view adds.
    pub fn keys(&self) -> Vec<(&'static str, &'static str)> {
        let mut keys = vec![
            (
                "r",
                "Runs: every planned run, its status, episodes, MA10 and source",
            ),
            (
                "c",
                "Comparison: each method's aggregates of both scores with 95% intervals, \
                 and P(X > Y) by the separation rule",
            ),
            (
                "↑ ↓ j k, PgUp PgDn",
                "pick a run (Runs) or a method (Comparison)",
            ),
            (
                "a",
                "Comparison: the next aggregate (IQM, mean, median, optimality gap)",
            ),
            (
                "s",
                "Comparison: the pairs of the other score (training return or test score)",
            ),
        ];
        keys.extend(super::curves::KEYS);
        keys.extend(self.host_overlay.iter().copied());
        keys.push(("?", "every key"));
        keys.push(if !self.host_runs_protocols {
            (
                "q, Esc, Ctrl-C",
                "quit (the folder is only read: nothing in it changes)",
            )
        } else {
            (
                "q, Esc, Ctrl-C",
                "quit; while a protocol trains, asks first (stopped, its folder stays \
                 resumable)",
            )
        });
        keys
    }

    /// The keys the status bar lists after the views' names: a protocol's controls, the
    /// shown view's keys, then the host's others.
    pub fn view_commands(&self) -> Vec<(&'static str, &'static str)> {
        let own: &[(&str, &str)] = match self.view {
            View::Runs => &[("↑↓", "run")],
            View::Comparison => &[("↑↓", "method"), ("a", "aggregate"), ("s", "score")],
            View::Curves => &super::curves::COMMANDS,
        };
        let mut keys = self.host_controls.clone();
        keys.extend(own);
        keys.extend(self.host_bar.iter().copied());
        keys
    }
}
