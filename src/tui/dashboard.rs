//! The dashboard's state: what the UI keeps of the trainer's event stream, and what the
//! keys do to it. No drawing here (see `dashboard_view`), so scripted events and keys can
//! be checked without a terminal.
//!
//! Memory stays bounded over any run: steps are folded into counters as they arrive, and
//! the curves keep one point per episode, thinned by half whenever they pass
//! [`CURVE_POINTS`].

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use crate::sapnet::{PolicyDescription, Prototype, SapNet};
use crate::teach::knobs::Knob;
use crate::teach::labels::short_task;
use crate::teach::session::CALLS_PER_FRAME;
use crate::teach::Teach;
use crate::trainer::{
    ActivationSnapshot, Command, Event, MethodId, RunRecord, StepRecord, LOCK_IN,
};

use super::graph_layout;
use super::reference::Band;

/// Points kept per curve; beyond it every other point is dropped and the stride doubles.
pub const CURVE_POINTS: usize = 4096;

/// The delays between trainer steps that `+` and `-` move through; the first is full
/// speed.
pub const SPEEDS: [Duration; 6] = [
    Duration::ZERO,
    Duration::from_millis(1),
    Duration::from_millis(10),
    Duration::from_millis(50),
    Duration::from_millis(200),
    Duration::from_millis(1000),
];

/// Episodes of scores kept for the table's sparklines.
pub const HISTORY: usize = 40;

/// Steps a policy's edges stay highlighted after it spread activation.
const SPREAD_GLOW_STEPS: u64 = 8;

/// Episodes averaged by the reward chart's moving average (the paper's 10).
const WINDOW: usize = 10;

/// What the user is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Running,
    Paused,
    Teach,
}

/// Which panel the arrows move in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Focus {
    Table,
    Graph,
}

/// What the UI loop must do after a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    None,
    /// Send this to the followed run (or the only run).
    Send(Command),
    /// Pause or resume every run.
    SendAll(Command),
    /// Stop following this method's run and follow the next method's same run instead.
    FollowNext,
    Quit,
}

/// One learning curve: episode returns, their moving average, thinned as it grows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Curve {
    /// `(episode, return)` of the kept episodes.
    pub returns: Vec<(f64, f64)>,
    /// `(episode, MA10)`.
    pub average: Vec<(f64, f64)>,
    window: VecDeque<f64>,
    stride: u32,
    seen: u32,
}

impl Curve {
    fn push(&mut self, episode: u32, reward: f64) {
        self.window.push_back(reward);
        if self.window.len() > WINDOW {
            self.window.pop_front();
        }
        self.seen += 1;
        if self.stride == 0 {
            self.stride = 1;
        }
        if !self.seen.is_multiple_of(self.stride) {
            return;
        }
        let mean = self.window.iter().sum::<f64>() / self.window.len() as f64;
        self.returns.push((f64::from(episode), reward));
        self.average.push((f64::from(episode), mean));
        if self.returns.len() > CURVE_POINTS {
            thin(&mut self.returns);
            thin(&mut self.average);
            self.stride *= 2;
        }
    }

    /// The latest moving average.
    pub fn last_average(&self) -> Option<f64> {
        (!self.window.is_empty())
            .then(|| self.window.iter().sum::<f64>() / self.window.len() as f64)
    }
}

fn thin(points: &mut Vec<(f64, f64)>) {
    let mut i = 0;
    points.retain(|_| {
        i += 1;
        i % 2 == 0
    });
}

/// A source policy as the table shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyRow {
    pub name: String,
    pub description: PolicyDescription,
    pub final_score: Option<f64>,
}

/// The followed reusing run's live state: SAP-Net's, or another selector's drawn on the
/// library's graph.
#[derive(Debug, Clone, PartialEq)]
pub struct SapNetView {
    /// The method whose selector this is (`sapnet`, `ucb1`…).
    pub method: String,
    /// What the scores are: `A` for SAP-Net's activations, else the selector's own.
    pub score_name: &'static str,
    pub policies: Vec<PolicyRow>,
    /// The graph and parameters, with the activations of the latest snapshot.
    pub net: SapNet,
    pub probabilities: Vec<f64>,
    pub selections: Vec<u64>,
    pub positive: Vec<u64>,
    pub negative: Vec<u64>,
    /// Per policy, whether its category is out of the candidates now (empty: none is).
    pub excluded: Vec<bool>,
    /// The policy that acted at the latest step.
    pub acting: Option<usize>,
    /// The last policy that activated and spread, and the step it did.
    pub spread: Option<(usize, u64)>,
    /// The policy that has held P > [`LOCK_IN`] since the step given, while it does: the
    /// softmax has collapsed onto it. Never for a method that picks by rule (as in the
    /// headless comparison, [`crate::reuse::MethodKind::picks_by_probability`]).
    pub locked: Option<(usize, u64)>,
    /// The scores at the end of each of the last [`HISTORY`] episodes, oldest first: the
    /// table's sparklines.
    pub history: VecDeque<Vec<f64>>,
}

impl SapNetView {
    /// Whether policy `i` is out of the candidates now.
    pub fn is_excluded(&self, i: usize) -> bool {
        self.excluded.get(i).copied().unwrap_or(false)
    }

    /// The category of each policy under the config's first prototype, numbered in order
    /// of appearance.
    pub fn categories(&self) -> Vec<usize> {
        let prototype = self
            .net
            .params()
            .prototypes
            .first()
            .map_or(Prototype::HiddenLayers, |p| p.prototype.clone());
        prototype.group_indices(self.policies.iter().map(|p| &p.description))
    }

    /// The name of each group of [`categories`](Self::categories) when the graph groups
    /// by source task over a library of several tasks (the task labels), else none.
    pub fn task_groups(&self) -> Vec<String> {
        let by_task = self
            .net
            .params()
            .prototypes
            .first()
            .is_some_and(|p| p.prototype == Prototype::SourceTask);
        let mut names: Vec<String> = Vec::new();
        for policy in &self.policies {
            let task = short_task(&policy.description.source_task);
            if !names.iter().any(|n| n == task) {
                names.push(task.to_string());
            }
        }
        if by_task && names.len() > 1 {
            names
        } else {
            Vec::new()
        }
    }

    /// Whether `policy`'s edges are still lit from a recent spread.
    pub fn glows(&self, policy: usize, step: u64) -> bool {
        matches!(self.spread, Some((p, at)) if p == policy && step.saturating_sub(at) < SPREAD_GLOW_STEPS)
    }
}

/// One training run as the dashboard follows it.
#[derive(Debug, Clone, PartialEq)]
pub struct RunView {
    pub method: MethodId,
    /// Which run of its method (from 0; `--follow-run` picks another than the first).
    pub run: u32,
    pub planned_episodes: u32,
    pub episode: u32,
    pub curve: Curve,
    pub epsilon: f64,
    pub statistic_loss: Vec<f64>,
    pub ended: Option<RunRecord>,
    /// Why the run stopped with an error, if it did.
    pub failed: Option<String>,
}

impl RunView {
    fn new(method: MethodId, run: u32, planned_episodes: u32) -> Self {
        Self {
            method,
            run,
            planned_episodes,
            episode: 0,
            curve: Curve::default(),
            epsilon: 0.0,
            statistic_loss: Vec::new(),
            ended: None,
            failed: None,
        }
    }
}

/// What a left click landed on, as the view that drew the screen tells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clicked {
    /// The policy table, on a policy's row or elsewhere in the panel.
    Table(Option<usize>),
    /// The graph, on a policy's node or between them.
    Graph(Option<usize>),
    /// A policy of teach mode's panels.
    Teach(usize),
}

/// Everything the dashboard draws.
#[derive(Debug, Clone)]
pub struct Dashboard {
    pub task: String,
    pub mode: Mode,
    pub focus: Focus,
    pub help: bool,
    /// The table shows A − max(A) instead of A (`v`): readable once A saturates.
    pub relative: bool,
    /// The focused panel fills the screen (`z`).
    pub zoom: bool,
    /// The policy the arrows point at.
    pub cursor: usize,
    pub speed: usize,
    /// The followed reusing run (first) and the baselines, in the order they started.
    pub runs: Vec<RunView>,
    pub sapnet: Option<SapNetView>,
    /// Steps of the followed run (SAP-Net if any).
    pub step: u64,
    /// The followed run's latest step, for the step line: who acted, the update, its
    /// judgment (eq. 7) and what it deposited.
    pub last_step: Option<StepRecord>,
    /// The episode of the followed run in progress and its return so far.
    pub episode_return: (u32, f64),
    /// Measured training speed, once there is enough to measure.
    pub steps_per_second: Option<f64>,
    speedometer: VecDeque<(Instant, u64)>,
    pub teach: Option<Teach>,
    /// The method whose run the dashboard follows, once the UI has said which: events of
    /// a run it stopped following are then left out.
    pub followed: Option<String>,
    /// A finished protocol's bands (`--compare DIR`), one per method, drawn under the live
    /// curves of the same methods.
    pub reference: Vec<Band>,
    /// Why the last key did nothing, or what it left (training still paused after teach
    /// mode): shown in the status line in place of the keys until the next key.
    pub notice: Option<&'static str>,
}

impl Dashboard {
    pub fn new(task: impl Into<String>) -> Self {
        Self {
            task: task.into(),
            mode: Mode::Running,
            focus: Focus::Table,
            help: false,
            relative: false,
            zoom: false,
            cursor: 0,
            speed: 0,
            runs: Vec::new(),
            sapnet: None,
            step: 0,
            last_step: None,
            episode_return: (0, 0.0),
            steps_per_second: None,
            speedometer: VecDeque::new(),
            notice: None,
            teach: None,
            followed: None,
            reference: Vec::new(),
        }
    }

    /// Follows the run of `method` from now on: the run followed so far leaves the screen
    /// (its late events are left out), the new one takes its place when it starts.
    pub fn follow(&mut self, method: &str) {
        if self.sapnet.take().is_some() && !self.runs.is_empty() {
            self.runs.remove(0);
        }
        self.followed = Some(method.to_string());
        self.step = 0;
        self.last_step = None;
        self.episode_return = (0, 0.0);
        self.steps_per_second = None;
        self.speedometer.clear();
        self.cursor = 0;
    }

    /// What the followed run must be told so that it runs as the screen says: paused, and at
    /// the chosen speed.
    pub fn settings(&self) -> Vec<Command> {
        let mut commands = vec![Command::Throttle(SPEEDS[self.speed])];
        if self.mode == Mode::Paused {
            commands.push(Command::Pause);
        }
        commands
    }

    /// A run of a method the dashboard no longer follows.
    fn is_stale(&self, method: &MethodId, reuses: bool) -> bool {
        reuses && self.followed.as_ref().is_some_and(|f| f != method.label())
    }

    /// The panel that fills the screen, if one is zoomed (`z`).
    pub fn zoomed(&self) -> Option<Focus> {
        self.zoom.then_some(self.focus)
    }

    /// The run the status bar follows: SAP-Net's if there is one, else the first.
    pub fn main_run(&self) -> Option<&RunView> {
        self.runs.first()
    }

    /// Folds one trainer event into the state.
    pub fn on_event(&mut self, event: Event) {
        match event {
            Event::RunStarted {
                run,
                method,
                planned_episodes,
                sapnet,
            } => {
                if self.is_stale(&method, sapnet.is_some()) {
                    return;
                }
                let run = RunView::new(method, run, planned_episodes);
                if let Some(start) = sapnet {
                    let n = start.net.len();
                    self.sapnet = Some(SapNetView {
                        method: run.method.label().to_string(),
                        score_name: start.score_name,
                        policies: start
                            .policies
                            .into_iter()
                            .map(|p| PolicyRow {
                                name: p.name,
                                description: p.description,
                                final_score: p.final_score,
                            })
                            .collect(),
                        probabilities: start.net.probabilities(),
                        net: start.net,
                        selections: vec![0; n],
                        positive: vec![0; n],
                        negative: vec![0; n],
                        excluded: Vec::new(),
                        acting: None,
                        spread: None,
                        locked: None,
                        history: VecDeque::new(),
                    });
                    self.runs.insert(0, run);
                } else {
                    self.runs.push(run);
                }
            }
            Event::Step(step) => {
                if let Some(view) = &mut self.sapnet {
                    view.acting = step.policy;
                    if let (Some(policy), Some(true)) = (step.policy, step.judgment) {
                        view.spread = Some((policy, step.step));
                    }
                }
                self.step = step.step;
                if self.episode_return.0 != step.episode {
                    self.episode_return = (step.episode, 0.0);
                }
                self.episode_return.1 += step.reward;
                self.last_step = Some(step);
            }
            Event::Activations(snapshot) => self.on_snapshot(snapshot),
            Event::Trace(_) => {}
            Event::EpisodeEnded(record) => {
                let follows_steps = self.sapnet.is_some();
                if let Some(view) = self
                    .sapnet
                    .as_mut()
                    .filter(|v| v.method == record.method.label())
                {
                    if view.history.len() == HISTORY {
                        view.history.pop_front();
                    }
                    view.history.push_back(view.net.activations().to_vec());
                }
                if let Some(run) = self.runs.iter_mut().find(|r| r.method == record.method) {
                    run.episode = record.episode;
                    run.epsilon = record.epsilon;
                    run.curve.push(record.episode, record.reward);
                    run.statistic_loss.push(record.statistic_loss);
                    if run.statistic_loss.len() > CURVE_POINTS {
                        run.statistic_loss.drain(..CURVE_POINTS / 2);
                    }
                }
                if !follows_steps && self.runs.first().is_some_and(|r| r.method == record.method) {
                    self.step += u64::from(record.steps);
                }
            }
            Event::RunEnded(record) => {
                if let Some(run) = self.runs.iter_mut().find(|r| r.method == record.method) {
                    run.ended = Some(record);
                }
            }
            Event::RunFailed { run, method, error } => {
                match self.runs.iter_mut().find(|r| r.method == method) {
                    Some(run) => run.failed = Some(error),
                    // It failed before it started (its networks would not build): it still
                    // gets its row, SAP-Net's first, so that the failure is seen.
                    None => {
                        let mut run = RunView::new(method, run, 0);
                        run.failed = Some(error);
                        if run.method.kind.spreads {
                            self.runs.insert(0, run);
                        } else {
                            self.runs.push(run);
                        }
                    }
                }
            }
        }
    }

    fn on_snapshot(&mut self, snapshot: ActivationSnapshot) {
        let Some(view) = &mut self.sapnet else {
            return;
        };
        // A late snapshot of a run no longer followed.
        if snapshot.method.label() != view.method {
            return;
        }
        // A snapshot always comes from the net announced at the start, so the counts agree.
        if view.net.set_activations(snapshot.activations).is_ok() {
            view.probabilities = snapshot.probabilities;
            view.selections = snapshot.selections;
            view.positive = snapshot.positive;
            view.negative = snapshot.negative;
            view.excluded = snapshot.excluded;
            // Lock-in as the headless comparison measures it: only for a method that
            // picks by probabilities. UCB1's view gives its next pick probability 1, which
            // is a rule, not a softmax that collapsed.
            let top = view
                .probabilities
                .iter()
                .position(|&p| p > LOCK_IN)
                .filter(|_| snapshot.method.kind.picks_by_probability);
            // The trainer dates the first lock-in at its step (the headless results' figure);
            // a frame sees it only when it is drawn. A later one, after the first let go, is
            // dated from the first snapshot that shows it.
            view.locked = match (top, view.locked, snapshot.lock_in) {
                (Some(i), _, Some(first)) if first.source == i => Some((i, first.step)),
                (Some(i), Some((held, since)), _) if i == held => Some((held, since)),
                (Some(i), _, _) => Some((i, snapshot.step)),
                (None, _, _) => None,
            };
        }
        self.step = self.step.max(snapshot.step);
    }

    /// Records the step count at `now` for the steps/s figure (over the last 2 s).
    pub fn tick(&mut self, now: Instant) {
        if let Some(teach) = &mut self.teach {
            teach.advance(CALLS_PER_FRAME);
        }
        // A count that went back belongs to a new run (`m`): measure it afresh.
        if self
            .speedometer
            .back()
            .is_some_and(|&(_, step)| step > self.step)
        {
            self.speedometer.clear();
            self.steps_per_second = None;
        }
        self.speedometer.push_back((now, self.step));
        while self
            .speedometer
            .front()
            .is_some_and(|(t, _)| now.duration_since(*t) > Duration::from_secs(2))
        {
            self.speedometer.pop_front();
        }
        if let (Some((t0, s0)), Some((t1, s1))) =
            (self.speedometer.front(), self.speedometer.back())
        {
            let seconds = t1.duration_since(*t0).as_secs_f64();
            if seconds >= 0.5 {
                self.steps_per_second = Some((s1 - s0) as f64 / seconds);
            }
        }
    }

    /// The number of policies the arrows move over.
    fn policy_count(&self) -> usize {
        self.sapnet.as_ref().map_or(0, |v| v.policies.len())
    }

    /// What `key` does. Keys in teach mode go to [`Teach`]; `t` or Esc leaves it.
    pub fn on_key(&mut self, key: KeyEvent) -> Action {
        let ctrl_c =
            key.code == KeyCode::Char('c') && key.modifiers.contains(KeyModifiers::CONTROL);
        if ctrl_c || key.code == KeyCode::Char('q') {
            return Action::Quit;
        }
        self.notice = None;
        if self.help {
            // Any key closes the help overlay.
            self.help = false;
            return Action::None;
        }
        if self.mode == Mode::Teach {
            return self.on_teach_key(key);
        }
        match key.code {
            KeyCode::Esc => Action::Quit,
            KeyCode::Char('?') => {
                self.help = true;
                Action::None
            }
            KeyCode::Char(' ') => match self.mode {
                Mode::Running => {
                    self.mode = Mode::Paused;
                    Action::SendAll(Command::Pause)
                }
                _ => {
                    self.mode = Mode::Running;
                    Action::SendAll(Command::Resume)
                }
            },
            KeyCode::Char('n') if self.mode == Mode::Paused => Action::Send(Command::Step),
            KeyCode::Char('m') => Action::FollowNext,
            KeyCode::Char('+') | KeyCode::Char('=') if self.speed == 0 => {
                self.notice = Some("already at full speed");
                Action::None
            }
            KeyCode::Char('-') if self.speed == SPEEDS.len() - 1 => {
                self.notice = Some("already at the slowest speed");
                Action::None
            }
            KeyCode::Char('+') | KeyCode::Char('=') => self.set_speed(self.speed - 1),
            KeyCode::Char('-') => self.set_speed(self.speed + 1),
            KeyCode::Tab => {
                self.focus = match self.focus {
                    Focus::Table => Focus::Graph,
                    Focus::Graph => Focus::Table,
                };
                Action::None
            }
            KeyCode::Up | KeyCode::Char('k') => self.move_toward(-1, (0.0, 1.0)),
            KeyCode::Down | KeyCode::Char('j') => self.move_toward(1, (0.0, -1.0)),
            KeyCode::Left | KeyCode::Char('h') => self.move_toward(-1, (-1.0, 0.0)),
            KeyCode::Right | KeyCode::Char('l') => self.move_toward(1, (1.0, 0.0)),
            KeyCode::Char('t') => self.enter_teach(),
            KeyCode::Char('v') => {
                self.relative = !self.relative;
                Action::None
            }
            KeyCode::Char('z') => {
                self.zoom = !self.zoom;
                Action::None
            }
            _ => Action::None,
        }
    }

    fn set_speed(&mut self, speed: usize) -> Action {
        self.speed = speed;
        Action::Send(Command::Throttle(SPEEDS[speed]))
    }

    /// An arrow: in the table the previous or next row (`delta`), in the graph the
    /// nearest node in `direction` on screen.
    fn move_toward(&mut self, delta: isize, direction: (f64, f64)) -> Action {
        match (&self.sapnet, self.focus) {
            (Some(view), Focus::Graph) => {
                let positions =
                    graph_layout::positions(view.policies.len(), Some(&view.categories()));
                if let Some(next) = graph_layout::nearest_ahead(&positions, self.cursor, direction)
                {
                    self.cursor = next;
                }
            }
            _ => self.move_cursor(delta),
        }
        Action::None
    }

    /// A left click, found by the view under the mouse ([`super::click`]): picks the
    /// policy clicked, if any, and focuses its panel.
    pub fn on_click(&mut self, clicked: Clicked) {
        if self.help {
            return;
        }
        match clicked {
            Clicked::Teach(i) => {
                if let Some(teach) = &mut self.teach {
                    teach.pick(i);
                }
            }
            Clicked::Table(row) => {
                self.cursor = row.unwrap_or(self.cursor);
                self.focus = Focus::Table;
            }
            Clicked::Graph(node) => {
                self.cursor = node.unwrap_or(self.cursor);
                self.focus = Focus::Graph;
            }
        }
    }

    fn move_cursor(&mut self, delta: isize) {
        let n = self.policy_count() as isize;
        if n > 0 {
            self.cursor = (self.cursor as isize + delta).rem_euclid(n) as usize;
        }
    }

    /// `t`: pauses training and steps spreading by hand on a copy of the live net.
    fn enter_teach(&mut self) -> Action {
        let Some(view) = &self.sapnet else {
            return Action::None;
        };
        let names = view.policies.iter().map(|p| p.name.clone()).collect();
        let mut teach = Teach::new(names, view.net.clone())
            .with_groups(view.categories())
            .with_excluded(view.excluded.clone());
        teach.move_cursor(self.cursor as isize);
        self.teach = Some(teach);
        let was_running = self.mode == Mode::Running;
        self.mode = Mode::Teach;
        if was_running {
            Action::SendAll(Command::Pause)
        } else {
            Action::None
        }
    }

    fn on_teach_key(&mut self, key: KeyEvent) -> Action {
        let Some(teach) = &mut self.teach else {
            self.mode = Mode::Paused;
            return Action::None;
        };
        if !apply_teach_key(teach, key) {
            match key.code {
                KeyCode::Char('t') | KeyCode::Esc => {
                    // Back to the paused dashboard: the copy's activations are discarded,
                    // training resumes from its own on space.
                    self.teach = None;
                    self.mode = Mode::Paused;
                    self.notice = Some("training is still paused: space resumes it");
                }
                KeyCode::Char('?') => self.help = true,
                _ => {}
            }
        }
        Action::None
    }
}

/// Applies a teach-mode key (arrows, `a`, `s`, `r`, `u`, `c`, `p`, and the edits `1`…`5`,
/// `+`, `−`, `e`); `false` if it is not one.
pub fn apply_teach_key(teach: &mut Teach, key: KeyEvent) -> bool {
    match key.code {
        KeyCode::Char(c) if Knob::from_key(c).is_some() => {
            teach.choose_knob(Knob::from_key(c).expect("checked"));
        }
        KeyCode::Char('+') | KeyCode::Char('=') => teach.edit(true),
        KeyCode::Char('-') => teach.edit(false),
        KeyCode::Char('e') => teach.next_edge(),
        KeyCode::Up | KeyCode::Char('k') | KeyCode::Left | KeyCode::Char('h') => {
            teach.move_cursor(-1)
        }
        KeyCode::Down | KeyCode::Char('j') | KeyCode::Right | KeyCode::Char('l') => {
            teach.move_cursor(1)
        }
        KeyCode::Char('a') => teach.activate(),
        KeyCode::Char('s') => {
            teach.step();
        }
        KeyCode::Char('r') => teach.run(),
        KeyCode::Char('u') => teach.undo(),
        KeyCode::Char('c') => teach.reset(),
        KeyCode::Char('p') => {
            teach.toggle_numbering();
        }
        _ => return false,
    }
    true
}
