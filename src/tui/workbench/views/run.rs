//! The Run view: one run's dashboard — followed live while it trains in this session
//! (pause, step and speed act on it; the others train at full speed), or made from its
//! files once it ended ([`crate::tui::workbench::recorded`]). Its keys are the
//! dashboard's table ([`dashboard::KEYS`]); teach mode on the live graph takes the keys
//! while it is on.
//!
//! Every run of a protocol gets a [`Dashboard`] of its own when it starts, fed its own
//! events: following another run (Enter on it in the Runs view, `m` here) shows its
//! dashboard, its curve since its start. The followed run streams every step (the step
//! line): following another moves the stream to it (`Command::Stream`); the others send
//! what headless runs send, an episode's end and the sources' state then (every step while
//! paused or slowed).

use std::collections::BTreeMap;
use std::convert::Infallible;
use std::time::{Duration, Instant};

use crossterm::event::{KeyEvent, MouseButton, MouseEvent, MouseEventKind};
use ratatui::backend::TestBackend;
use ratatui::layout::{Position, Rect};
use ratatui::widgets::{Block, Paragraph, Wrap};
use ratatui::{Frame, Terminal};

use crate::experiment::Watched;
use crate::trainer::{Command, Commands, Event, MethodId};
use crate::tui::dashboard::{self, Action, Dashboard, DashboardCommand, Mode};
use crate::tui::dashboard_view;
use crate::tui::keys::Binding;
use crate::tui::reference::Band;
use crate::tui::teach_view;
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};

/// A run of the protocol: its method's label and its index.
pub type RunKey = (String, u32);

/// One run's dashboard and, while it trains, its commands.
pub struct LiveRun {
    pub dashboard: Dashboard,
    pub commands: Option<Commands>,
}

/// The runs shown, the one followed, and which of them streams its steps.
pub struct RunView {
    /// The task's name, for each run's dashboard.
    pub task: String,
    /// `--compare`'s bands, under every run's curves.
    pub reference: Vec<Band>,
    /// The runs started in this session (and those shown from their files), each with its
    /// dashboard.
    pub runs: BTreeMap<RunKey, LiveRun>,
    /// The run shown, which pause, step and speed steer.
    pub followed: Option<RunKey>,
    /// The run that streams every step: the one followed, once it trains.
    pub live: Option<RunKey>,
    /// The protocol's methods by their index, as their runs started: whose a step is.
    methods: BTreeMap<usize, String>,
}

impl RunView {
    /// The Run view of `task`'s runs, following `followed` (which streams its steps) once
    /// it starts.
    pub fn new(task: &str, followed: Option<RunKey>) -> Self {
        Self {
            task: task.to_string(),
            reference: Vec::new(),
            runs: BTreeMap::new(),
            live: followed.clone(),
            followed,
            methods: BTreeMap::new(),
        }
    }

    /// The dashboard shown.
    pub fn followed_run(&self) -> Option<&LiveRun> {
        self.runs.get(self.followed.as_ref()?)
    }

    fn followed_run_mut(&mut self) -> Option<&mut LiveRun> {
        self.runs.get_mut(self.followed.as_ref()?)
    }

    /// Whether teach mode takes the keys.
    pub fn teaching(&self) -> bool {
        self.followed_run()
            .is_some_and(|r| r.dashboard.mode == Mode::Teach)
    }

    /// What the protocol's thread told.
    pub fn on_watched(&mut self, watched: Watched) {
        match watched {
            Watched::Started {
                method,
                run,
                commands,
            } => {
                let key = (method.label().to_string(), run);
                self.methods.insert(method.index, key.0.clone());
                // A run followed before it started takes the stream when it starts.
                if self.followed.as_ref() == Some(&key) {
                    self.stream_to(&key, &commands);
                }
                self.run_entry(&key).commands = Some(commands);
            }
            Watched::Event(event) => {
                let Some(key) = self.key_of(&event) else {
                    return;
                };
                let ended = matches!(event, Event::RunEnded(_) | Event::RunFailed { .. });
                let run = self.run_entry(&key);
                run.dashboard.on_event(event);
                if ended {
                    run.commands = None;
                }
            }
        }
    }

    /// The run an event is of.
    fn key_of(&self, event: &Event) -> Option<RunKey> {
        let key = |method: &MethodId, run: u32| (method.label().to_string(), run);
        Some(match event {
            Event::RunStarted { run, method, .. } | Event::RunFailed { run, method, .. } => {
                key(method, *run)
            }
            Event::Step(step) => (self.methods.get(&step.method)?.clone(), step.run),
            Event::Activations(snapshot) => key(&snapshot.method, snapshot.run),
            Event::Trace(record) => key(&record.method, record.run),
            Event::EpisodeEnded(record) => key(&record.method, record.run),
            Event::RunEnded(record) => key(&record.method, record.run),
        })
    }

    fn run_entry(&mut self, key: &RunKey) -> &mut LiveRun {
        let (task, reference) = (&self.task, &self.reference);
        self.runs.entry(key.clone()).or_insert_with(|| {
            let mut dashboard = Dashboard::new(task.clone());
            dashboard.reference = reference.clone();
            dashboard.follow(&key.0);
            LiveRun {
                dashboard,
                commands: None,
            }
        })
    }

    /// Once a frame: the followed run's speed, and teach mode's walk.
    pub fn tick(&mut self, now: Instant) {
        if let Some(run) = self.followed_run_mut() {
            run.dashboard.tick(now);
        }
    }

    /// Whether any run of the session trains now.
    pub fn training(&self) -> bool {
        self.runs.values().any(|r| r.commands.is_some())
    }

    /// Shows a run that ended before this session, its dashboard made from its files.
    pub fn show_recorded(&mut self, key: RunKey, dashboard: Dashboard) {
        // Made afresh each time: the files of a finished run do not change.
        self.runs.insert(
            key.clone(),
            LiveRun {
                dashboard,
                commands: None,
            },
        );
        self.follow(key);
    }

    /// `m`: the next run that trains now, after the followed one.
    fn follow_next(&mut self) -> Outcome<Infallible> {
        let training: Vec<RunKey> = self
            .runs
            .iter()
            .filter(|(_, r)| r.commands.is_some())
            .map(|(k, _)| k.clone())
            .collect();
        let next = match &self.followed {
            Some(now) => training
                .iter()
                .find(|k| *k > now)
                .or(training.first())
                .cloned(),
            None => training.first().cloned(),
        };
        match next {
            Some(key) if Some(&key) != self.followed.as_ref() => {
                self.follow(key);
                Outcome::Done
            }
            _ => Outcome::Said("m: no other run is training".into()),
        }
    }

    /// Follows `key`: the run followed so far is let go at full speed (a run left paused
    /// would hold the protocol up for ever), and the step stream moves to `key` if it
    /// trains (else when it starts).
    pub fn follow(&mut self, key: RunKey) {
        if self.followed.as_ref() == Some(&key) {
            return;
        }
        if let Some(left) = self.followed_run_mut() {
            let board = &mut left.dashboard;
            if board.mode != Mode::Running || board.speed != 0 {
                board.mode = Mode::Running;
                board.teach = None;
                board.speed = 0;
                if let Some(commands) = &left.commands {
                    let _ = commands.send(Command::Throttle(Duration::ZERO));
                    let _ = commands.send(Command::Resume);
                }
            }
        }
        if let Some(commands) = self.runs.get(&key).and_then(|r| r.commands.clone()) {
            self.stream_to(&key, &commands);
        }
        self.followed = Some(key);
    }

    /// Moves the step stream to the training run `key` (`commands` its own), from the run
    /// that had it.
    fn stream_to(&mut self, key: &RunKey, commands: &Commands) {
        if self.live.as_ref() == Some(key) {
            return;
        }
        let streaming = self.live.as_ref().and_then(|l| self.runs.get(l));
        if let Some(old) = streaming.and_then(|r| r.commands.as_ref()) {
            let _ = old.send(Command::Stream(false));
        }
        let _ = commands.send(Command::Stream(true));
        self.live = Some(key.clone());
    }
}

impl View for RunView {
    /// The dashboards are the view's own; the screen's line says where the protocol is.
    type Model = ();
    type Command = DashboardCommand;
    type Intent = Infallible;

    fn keys(&self) -> &'static [Binding<DashboardCommand>] {
        dashboard::KEYS
    }

    fn apply(&mut self, _: &(), command: DashboardCommand) -> Outcome<Infallible> {
        let Some(run) = self.followed_run_mut() else {
            return Outcome::Said(
                "no run followed yet: r lists the runs, Enter follows one".into(),
            );
        };
        // Pause, step and speed go to the followed run only; a run that ended, or was
        // read from its files, takes them nowhere.
        match run.dashboard.apply(command) {
            Action::None => Outcome::Done,
            Action::Send(command) | Action::SendAll(command) => {
                if let Some(commands) = &run.commands {
                    let _ = commands.send(command);
                }
                Outcome::Done
            }
            Action::FollowNext => self.follow_next(),
        }
    }

    fn draw(&self, _: &(), frame: &mut Frame, area: Rect, theme: Theme) {
        let Some(run) = self.followed_run() else {
            let text = match &self.followed {
                Some((method, run)) => format!(
                    "{method} run {run} has not started: its library is loading, or it waits \
                     for a free job. r lists the runs; Enter on a running one follows it."
                ),
                None => "No run is followed: r lists the runs; Enter on one shows it (a \
                         running one followed, a finished one from its files)."
                    .to_string(),
            };
            frame.render_widget(
                Paragraph::new(text)
                    .wrap(Wrap { trim: true })
                    .block(Block::bordered().border_style(theme.dim())),
                area,
            );
            return;
        };
        draw_dashboard_at(frame, area, &run.dashboard, theme);
    }

    /// The top line offers `m` while a run trains; the dashboard's own line offers the
    /// rest of the table (space, n, t) as its mode allows.
    fn offers(&self, _: &(), command: DashboardCommand) -> bool {
        command == DashboardCommand::FollowNext && self.training()
    }

    /// Teach mode, and the line it types, take the keys first; every key clears the
    /// dashboard's notice.
    fn capture(&mut self, _: &(), key: &KeyEvent) -> Option<Outcome<Infallible>> {
        let run = self.followed_run_mut()?;
        run.dashboard.notice = None;
        run.dashboard.teach_key(key).map(|_| Outcome::Done)
    }

    fn mode_help(&self, _: &()) -> Option<Vec<(&'static str, &'static str)>> {
        let run = self.followed_run()?;
        let teach = run.dashboard.teach.as_ref()?;
        (run.dashboard.mode == Mode::Teach).then(|| teach_view::teach_help(teach, true))
    }

    fn legend(&self, _: &()) -> Vec<(&'static str, &'static str)> {
        let score = self
            .followed_run()
            .and_then(|r| r.dashboard.library.as_ref())
            .map(|l| l.score);
        dashboard_view::legend(score)
    }

    fn on_mouse(&mut self, _: &(), mouse: MouseEvent, area: Rect) -> Outcome<Infallible> {
        if mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return Outcome::Ignored;
        }
        let Some(run) = self.followed_run_mut() else {
            return Outcome::Ignored;
        };
        match dashboard_view::clicked(&run.dashboard, area, mouse.column, mouse.row) {
            Some(clicked) => {
                run.dashboard.on_click(clicked);
                Outcome::Done
            }
            None => Outcome::Ignored,
        }
    }
}

/// `dashboard` in `below`, drawn off screen at that size and copied in (the dashboard fills
/// whatever frame it is given).
fn draw_dashboard_at(frame: &mut Frame, below: Rect, dashboard: &Dashboard, theme: Theme) {
    let Ok(mut off_screen) = Terminal::new(TestBackend::new(below.width, below.height));
    if off_screen
        .draw(|f| dashboard_view::draw_dashboard(f, dashboard, theme))
        .is_err()
    {
        return;
    }
    let drawn = off_screen.backend().buffer();
    let buffer = frame.buffer_mut();
    for y in 0..below.height {
        for x in 0..below.width {
            if let (Some(from), Some(to)) = (
                drawn.cell(Position::new(x, y)),
                buffer.cell_mut(Position::new(below.x + x, below.y + y)),
            ) {
                *to = from.clone();
            }
        }
    }
}
