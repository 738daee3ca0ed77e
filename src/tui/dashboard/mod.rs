//! The dashboard's state: what the UI keeps of the trainer's event stream, and what the
//! keys do to it. No drawing here (see `dashboard_view`), so scripted events and keys can
//! be checked without a terminal.
//!
//! Memory stays bounded over any run: steps are folded into counters as they arrive, and
//! the curves keep one point per episode, thinned by half whenever they pass
//! [`CURVE_POINTS`].

mod keys;
mod live_curve;
mod run_views;

use std::collections::VecDeque;
use std::time::{Duration, Instant};

pub use keys::{apply_teach_key, Action, Clicked, DashboardCommand, KEYS};
pub use live_curve::{LiveCurve, CURVE_POINTS};
pub use run_views::{LibraryView, PolicyRow, RunView, HISTORY};

use crate::config::Budget;
use crate::teach::session::CALLS_PER_FRAME;
use crate::teach::Teach;
use crate::trainer::{ActivationSnapshot, Command, Event, MethodId, StepRecord, LOCK_IN};

use super::reference::Band;

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

/// Everything the dashboard draws.
#[derive(Debug, Clone)]
pub struct Dashboard {
    pub task: String,
    pub mode: Mode,
    pub focus: Focus,
    /// The table shows A − max(A) instead of A (`d`): readable once A saturates.
    pub relative: bool,
    /// The focused panel fills the screen (`z`).
    pub zoom: bool,
    /// The policy the arrows point at.
    pub cursor: usize,
    pub speed: usize,
    /// The followed reusing run (first) and the baselines, in the order they started.
    pub runs: Vec<RunView>,
    pub library: Option<LibraryView>,
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
    /// Made from a finished run's files ([`crate::results::recorded_run`]), not followed
    /// while it trained.
    pub from_files: Option<FromFiles>,
}

/// What the files of a run shown after it ended kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FromFiles {
    /// Whether its selector's scores and probabilities were on file (`activations.csv`).
    pub activations: bool,
    /// Whether each episode's ε and losses were (`docs/` ships `episodes.csv` without).
    pub learner: bool,
}

impl Dashboard {
    pub fn new(task: impl Into<String>) -> Self {
        Self {
            task: task.into(),
            mode: Mode::Running,
            focus: Focus::Table,
            relative: false,
            zoom: false,
            cursor: 0,
            speed: 0,
            runs: Vec::new(),
            library: None,
            step: 0,
            last_step: None,
            episode_return: (0, 0.0),
            steps_per_second: None,
            speedometer: VecDeque::new(),
            notice: None,
            teach: None,
            followed: None,
            reference: Vec::new(),
            from_files: None,
        }
    }

    /// Follows the run of `method` from now on: the run followed so far leaves the screen
    /// (its late events are left out), the new one takes its place when it starts.
    pub fn follow(&mut self, method: &str) {
        if self.library.take().is_some() && !self.runs.is_empty() {
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
                budget,
                library,
            } => {
                if self.is_stale(&method, library.is_some()) {
                    return;
                }
                let run = RunView::new(method, run, budget);
                if let Some(start) = library {
                    let n = start.net.len();
                    self.library = Some(LibraryView {
                        method: run.method.label().to_string(),
                        score: start.score,
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
                if let Some(view) = &mut self.library {
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
                let follows_steps = self.library.is_some();
                if let Some(view) = self
                    .library
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
                    run.steps += u64::from(record.steps);
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
                        let mut run = RunView::new(method, run, Budget::Episodes(0));
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
        let Some(view) = &mut self.library else {
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
}
