//! A protocol run in the UI (`sapnet` without `--headless`): the workbench's views of the
//! folder it writes, and the Run view of one run followed live (today's dashboard), with
//! the keys that launch (`L`), stop (`S`, `q`) and resume (`R`) protocols. What it keeps
//! and what its keys ask for; no thread, no drawing ([`super::session_view`] draws it,
//! [`super::live`] runs the loop that owns the protocol's thread).
//!
//! Every run of the protocol gets a [`Dashboard`] of its own when it starts, fed its own
//! events: following another run (Enter on it in the Runs view, `m` in the Run view)
//! shows its dashboard, its curve since its start. The followed run streams every step
//! (the step line): following another moves the stream to it (`Command::Stream`); the
//! others send what headless runs send, an episode's end and the sources' state then
//! (every step while paused or slowed).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use super::picker::{Picked, Picker};
use super::recorded;
use super::state::{View, Workbench};
use crate::experiment::Watched;
use crate::report::Report;
use crate::results::folder_state::{FolderState, RunStatus};
use crate::results::Status;
use crate::trainer::{Command, Commands, Event};
use crate::tui::dashboard::{Action as DashboardAction, Dashboard, Mode};
use crate::tui::reference::Band;

/// The session's keys in the views' overlay (`?`).
const HOST_KEYS: [(&str, &str); 5] = [
    (
        "Enter",
        "Runs: follow the run under the cursor in the Run view (pause, step and speed act \
         on it; the others train at full speed); a run that ended before, its dashboard \
         read from its files",
    ),
    (
        "f",
        "the Run view: the followed run's dashboard (r and c come back here)",
    ),
    (
        "L",
        "launch a protocol: pick a config (assets/*.ron, or type a path) into a new folder",
    ),
    (
        "S",
        "stop the protocol training (asked once; the folder stays resumable)",
    ),
    ("R", "resume the stopped protocol of this folder"),
];

/// A run of the protocol: its method's label and its index.
pub type RunKey = (String, u32);

/// Which screen is up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Screen {
    /// The followed run's dashboard.
    Run,
    /// The workbench's views of the folder (Runs, Comparison).
    Views,
}

/// Where the session's protocol is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Phase {
    /// No protocol runs in this session (a folder opened, or one that ended before).
    Idle,
    /// Training (or loading its library first).
    Running,
    /// Asked to stop: the runs finish their step and the files are written.
    Stopping,
    /// It ended, as its `summary.json` says.
    Ended(Status),
    /// It could not go on: why.
    Failed(String),
}

/// A question or a panel over the screen, which takes the keys while it is up.
pub enum Overlay {
    /// "protocol running: stop it?"; `then_quit`: the UI closes once it has stopped.
    Stop { then_quit: bool },
    /// The configs to launch.
    Picker(Picker),
}

/// What the loop must do after a key.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Request {
    None,
    Quit,
    /// Stop the protocol (the folder stays resumable); then quit if `then_quit`.
    Stop {
        then_quit: bool,
    },
    /// Start the protocol of this config into a new folder.
    Launch(PathBuf),
    /// Resume the stopped protocol of the folder shown.
    Resume,
}

/// One run's dashboard and, while it trains, its commands.
pub struct LiveRun {
    pub dashboard: Dashboard,
    pub commands: Option<Commands>,
}

/// The protocol run in the UI, and what the screen shows of it.
pub struct Session {
    /// The folder the protocol writes (or the one opened).
    pub dir: PathBuf,
    /// The task's name, for each run's dashboard.
    pub task: String,
    /// `--compare`'s bands, under every run's curves.
    pub reference: Vec<Band>,
    /// The workbench on the folder, once it has been read.
    pub workbench: Option<Workbench>,
    /// Why the folder cannot be read yet (before the protocol wrote its summary.json).
    pub read_error: Option<String>,
    pub screen: Screen,
    pub phase: Phase,
    /// The runs started in this session, each with its dashboard.
    pub runs: BTreeMap<RunKey, LiveRun>,
    /// The run the Run view shows, and pause, step and speed steer.
    pub followed: Option<RunKey>,
    /// The run that streams every step: the one followed, once it trains.
    pub live: Option<RunKey>,
    /// The protocol's methods by their index, as their runs started: whose a step is.
    methods: BTreeMap<usize, String>,
    pub overlay: Option<Overlay>,
    /// What the last key did or why it did nothing, shown until the next key.
    pub notice: Option<String>,
}

impl Session {
    /// A session on `dir`, following `followed` (which streams its steps) once it starts.
    pub fn new(dir: &Path, task: &str, followed: Option<RunKey>, phase: Phase) -> Self {
        Self {
            dir: dir.to_path_buf(),
            task: task.to_string(),
            reference: Vec::new(),
            workbench: None,
            read_error: None,
            screen: if followed.is_some() {
                Screen::Run
            } else {
                Screen::Views
            },
            phase,
            runs: BTreeMap::new(),
            live: followed.clone(),
            methods: BTreeMap::new(),
            followed,
            overlay: None,
            notice: None,
        }
    }

    /// The same screen on a new protocol's folder (`L`, `R`): its runs start afresh.
    pub fn restart(&mut self, dir: &Path, task: &str, followed: Option<RunKey>) {
        let reference = std::mem::take(&mut self.reference);
        let screen = self.screen;
        *self = Self::new(dir, task, followed, Phase::Running);
        self.reference = reference;
        self.screen = screen;
    }

    /// Whether a protocol of this session is training or stopping.
    pub fn is_running(&self) -> bool {
        matches!(self.phase, Phase::Running | Phase::Stopping)
    }

    /// A new read of the folder, as [`Workbench::refreshed`] takes it.
    pub fn refreshed(&mut self, folder: FolderState, report: Option<Option<Report>>) {
        self.read_error = None;
        match &mut self.workbench {
            Some(workbench) => workbench.refreshed(folder, report),
            None => self.workbench = Some(Workbench::new(folder, report.flatten())),
        }
        self.sync_host_keys();
    }

    /// Gives the workbench the session's keys for its status bar and overlay, as the
    /// phase allows them now.
    pub fn sync_host_keys(&mut self) {
        let controls = self.phase_keys();
        if let Some(workbench) = &mut self.workbench {
            workbench.host_controls = controls;
            workbench.host_bar = vec![("⏎", "follow"), ("f", "run view")];
            workbench.host_overlay = HOST_KEYS.to_vec();
            workbench.host_runs_protocols = true;
        }
    }

    /// A read that failed: before the first good one the screen says why; after it, the
    /// workbench keeps the last good read and says it.
    pub fn read_failed(&mut self, error: String) {
        match &mut self.workbench {
            Some(workbench) => workbench.read_error = Some(error),
            None => self.read_error = Some(error),
        }
    }

    /// The dashboard the Run view shows.
    pub fn followed_run(&self) -> Option<&LiveRun> {
        self.runs.get(self.followed.as_ref()?)
    }

    fn followed_run_mut(&mut self) -> Option<&mut LiveRun> {
        self.runs.get_mut(self.followed.as_ref()?)
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
        let key = |method: &crate::trainer::MethodId, run: u32| (method.label().to_string(), run);
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

    /// What `key` does.
    pub fn on_key(&mut self, key: KeyEvent) -> Request {
        let ctrl_c =
            key.code == KeyCode::Char('c') && key.modifiers.contains(KeyModifiers::CONTROL);
        self.notice = None;
        if let Some(overlay) = self.overlay.take() {
            return self.on_overlay_key(overlay, key, ctrl_c);
        }
        if ctrl_c {
            return self.quit();
        }
        match self.screen {
            Screen::Run => self.on_run_key(key),
            Screen::Views => self.on_views_key(key),
        }
    }

    fn on_overlay_key(&mut self, overlay: Overlay, key: KeyEvent, ctrl_c: bool) -> Request {
        match overlay {
            Overlay::Stop { then_quit } => match key.code {
                // Ctrl-C twice stops, as `y` does.
                KeyCode::Char('y') | KeyCode::Enter => Request::Stop { then_quit },
                _ if ctrl_c => Request::Stop { then_quit },
                _ => {
                    self.notice = Some("the protocol goes on".into());
                    Request::None
                }
            },
            Overlay::Picker(mut picker) => {
                if ctrl_c {
                    return Request::None;
                }
                match picker.on_key(key) {
                    Picked::Nothing => {
                        self.overlay = Some(Overlay::Picker(picker));
                        Request::None
                    }
                    Picked::Closed => Request::None,
                    Picked::Config(path) => {
                        // Kept up until the loop says whether the config was taken.
                        self.overlay = Some(Overlay::Picker(picker));
                        Request::Launch(path)
                    }
                }
            }
        }
    }

    /// `q`, Esc or Ctrl-C: asks first while a protocol trains.
    fn quit(&mut self) -> Request {
        match self.phase {
            Phase::Running => {
                self.overlay = Some(Overlay::Stop { then_quit: true });
                Request::None
            }
            _ => Request::Quit,
        }
    }

    /// The keys of the protocol itself, on every screen: `L`, `S`, `R`; `None` if `key` is
    /// none of them.
    fn protocol_key(&mut self, key: KeyEvent) -> Option<Request> {
        Some(match key.code {
            KeyCode::Char('L') => {
                if self.is_running() {
                    self.notice = Some("a protocol is running: S stops it first".into());
                } else {
                    self.overlay = Some(Overlay::Picker(Picker::open()));
                }
                Request::None
            }
            KeyCode::Char('S') => {
                if self.phase == Phase::Running {
                    self.overlay = Some(Overlay::Stop { then_quit: false });
                } else {
                    self.notice = Some("no protocol is training".into());
                }
                Request::None
            }
            KeyCode::Char('R') => match self.resumable() {
                Ok(()) => Request::Resume,
                Err(why) => {
                    self.notice = Some(why);
                    Request::None
                }
            },
            _ => return None,
        })
    }

    /// Whether `R` can resume the folder shown, and if not why.
    pub fn resumable(&self) -> Result<(), String> {
        if self.is_running() {
            return Err("the protocol is training: nothing to resume".into());
        }
        let Some(workbench) = &self.workbench else {
            return Err("the folder holds no protocol yet".into());
        };
        let folder = &workbench.folder;
        if let Some(writer) = &folder.writer {
            return Err(format!("{} writes this folder", writer.describe()));
        }
        match folder.status {
            Some(Status::Stopped | Status::Failed | Status::Running | Status::Interrupted) => {
                Ok(())
            }
            None | Some(Status::Complete) => {
                Err("this protocol is complete: nothing to resume (L launches another)".into())
            }
        }
    }

    fn on_run_key(&mut self, key: KeyEvent) -> Request {
        let teaching = self
            .followed_run()
            .is_some_and(|r| r.dashboard.mode == Mode::Teach || r.dashboard.help);
        if !teaching {
            match key.code {
                KeyCode::Char('q') | KeyCode::Esc => return self.quit(),
                KeyCode::Char('r') => {
                    self.show_view(View::Runs);
                    return Request::None;
                }
                KeyCode::Char('c') => {
                    self.show_view(View::Comparison);
                    return Request::None;
                }
                _ => {}
            }
            if let Some(request) = self.protocol_key(key) {
                return request;
            }
        }
        let Some(run) = self.followed_run_mut() else {
            self.notice = Some("no run followed yet: r lists the runs, Enter follows one".into());
            return Request::None;
        };
        match run.dashboard.on_key(key) {
            DashboardAction::None => Request::None,
            DashboardAction::Quit => self.quit(),
            DashboardAction::Send(command) | DashboardAction::SendAll(command) => {
                if let Some(commands) = &run.commands {
                    let _ = commands.send(command);
                }
                Request::None
            }
            DashboardAction::FollowNext => {
                self.follow_next();
                Request::None
            }
        }
    }

    fn show_view(&mut self, view: View) {
        self.screen = Screen::Views;
        if let Some(workbench) = &mut self.workbench {
            workbench.view = view;
        }
    }

    fn on_views_key(&mut self, key: KeyEvent) -> Request {
        let Some(workbench) = &mut self.workbench else {
            return match key.code {
                KeyCode::Char('q') | KeyCode::Esc => self.quit(),
                KeyCode::Char('f') => {
                    self.screen = Screen::Run;
                    Request::None
                }
                _ => self.protocol_key(key).unwrap_or(Request::None),
            };
        };
        if workbench.help {
            workbench.on_key(key);
            return Request::None;
        }
        match key.code {
            KeyCode::Char('q') | KeyCode::Esc => return self.quit(),
            KeyCode::Char('f') => {
                self.screen = Screen::Run;
                return Request::None;
            }
            KeyCode::Enter if workbench.view == View::Runs => {
                self.follow_cursor();
                return Request::None;
            }
            _ => {}
        }
        if let Some(request) = self.protocol_key(key) {
            return request;
        }
        if let Some(workbench) = &mut self.workbench {
            workbench.on_key(key);
        }
        Request::None
    }

    /// Enter in the Runs view: the run under the cursor, followed in the Run view if it
    /// trains (or trained) in this session.
    fn follow_cursor(&mut self) {
        let Some(workbench) = &self.workbench else {
            return;
        };
        let Some(row) = workbench.folder.runs.get(workbench.run_cursor) else {
            return;
        };
        let key = (row.method.label().to_string(), row.run);
        if self.runs.contains_key(&key) {
            self.follow(key);
            self.screen = Screen::Run;
            return;
        }
        let method = row.method.clone();
        self.notice = match row.status {
            RunStatus::Queued => Some(format!("{} run {} has not started yet", key.0, key.1)),
            RunStatus::Done | RunStatus::Stopped
                if workbench.folder.finished(&method, key.1).is_some() =>
            {
                match recorded::dashboard(
                    &workbench.folder,
                    &method,
                    key.1,
                    &self.task,
                    &self.reference,
                ) {
                    Ok(dashboard) => {
                        self.show_recorded(key, dashboard);
                        None
                    }
                    Err(error) => Some(format!("{error:#}")),
                }
            }
            status => Some(format!("{} run {} is {}", key.0, key.1, status.name())),
        };
    }

    /// Shows a run that ended before this session, its dashboard made from its files.
    fn show_recorded(&mut self, key: RunKey, dashboard: Dashboard) {
        // Made afresh each time: the files of a finished run do not change.
        self.runs.insert(
            key.clone(),
            LiveRun {
                dashboard,
                commands: None,
            },
        );
        self.follow(key);
        self.screen = Screen::Run;
    }

    /// `m`: the next run that trains now, after the followed one.
    fn follow_next(&mut self) {
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
            Some(key) if Some(&key) != self.followed.as_ref() => self.follow(key),
            _ => self.notice = Some("m: no other run is training".into()),
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

    /// The protocol's controls, as the phase allows them: first in the status bar, where
    /// a narrow terminal drops keys from the end.
    pub fn phase_keys(&self) -> Vec<(&'static str, &'static str)> {
        let mut keys = Vec::new();
        match self.phase {
            Phase::Running => keys.push(("S", "stop")),
            Phase::Stopping => {}
            _ => {
                keys.push(("L", "launch"));
                if self.resumable().is_ok() {
                    keys.push(("R", "resume"));
                }
            }
        }
        keys
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(c: char) -> KeyEvent {
        KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE)
    }

    #[test]
    fn quitting_a_training_protocol_asks_once_and_stops_it() {
        let mut session = Session::new(
            Path::new("out/x"),
            "CartPole-v1",
            Some(("sapnet".into(), 0)),
            Phase::Running,
        );
        assert_eq!(session.on_key(key('q')), Request::None);
        assert!(matches!(
            session.overlay,
            Some(Overlay::Stop { then_quit: true })
        ));
        assert_eq!(session.on_key(key('y')), Request::Stop { then_quit: true });
        // Answered no, the protocol goes on and nothing is asked again.
        session.on_key(key('q'));
        assert_eq!(session.on_key(key('n')), Request::None);
        assert!(session.overlay.is_none());
        // Ctrl-C asks, and a second one answers yes.
        let ctrl_c = KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL);
        assert_eq!(session.on_key(ctrl_c), Request::None);
        assert_eq!(session.on_key(ctrl_c), Request::Stop { then_quit: true });
    }

    /// A session following SAP-Net's run 0, with it and random's run 0 started; the runs'
    /// ends of their command channels.
    fn two_runs_started() -> (Session, Vec<crate::trainer::CommandReceiver>) {
        use crate::reuse::Method;
        use crate::trainer::{command_channel, MethodId};
        let mut session = Session::new(
            Path::new("out/x"),
            "CartPole-v1",
            Some(("sapnet".into(), 0)),
            Phase::Running,
        );
        let mut receivers = Vec::new();
        for (i, method) in [Method::SapNet, Method::Random].iter().enumerate() {
            let (commands, receiver) = command_channel();
            receivers.push(receiver);
            session.on_watched(Watched::Started {
                method: MethodId::new(i, method),
                run: 0,
                commands,
            });
        }
        (session, receivers)
    }

    #[test]
    fn a_run_left_is_let_go_at_full_speed() {
        let (mut session, _receivers) = two_runs_started();
        // Space pauses the followed run; `-` slows it.
        session.on_key(key(' '));
        session.on_key(key('-'));
        let board = |s: &Session, label: &str| {
            let run = &s.runs[&(label.to_string(), 0)];
            (run.dashboard.mode, run.dashboard.speed)
        };
        assert_eq!(board(&session, "sapnet"), (Mode::Paused, 1));
        // `m` follows the other run training; the one left runs again at full speed.
        session.on_key(key('m'));
        assert_eq!(session.followed, Some(("random".to_string(), 0)));
        assert_eq!(board(&session, "sapnet"), (Mode::Running, 0));
        // Following the run already followed changes nothing.
        session.on_key(key(' '));
        session.follow(("random".to_string(), 0));
        assert_eq!(board(&session, "random"), (Mode::Paused, 0));
    }

    /// The followed run streams its steps: following another moves the stream, and each
    /// step goes to its own run's dashboard, by its method and run, even one sent before
    /// the move.
    #[test]
    fn following_a_run_moves_the_step_stream_to_it() {
        use crate::trainer::StepRecord;
        let (mut session, receivers) = two_runs_started();
        // The run followed from the start streams as its spec says: no command needed.
        assert!(receivers.iter().all(|r| r.pending().is_empty()));
        let step = |method: usize, step: u64| {
            Watched::Event(Event::Step(StepRecord {
                method,
                run: 0,
                step,
                episode: 1,
                policy: None,
                action: 0,
                reward: 1.0,
                update: None,
                judgment: None,
                deposit: None,
                warm_up: false,
            }))
        };
        session.on_watched(step(0, 7));
        session.follow(("random".to_string(), 0));
        assert_eq!(receivers[0].pending(), [Command::Stream(false)]);
        assert_eq!(receivers[1].pending(), [Command::Stream(true)]);
        assert_eq!(session.live, Some(("random".to_string(), 0)));
        // A step SAP-Net sent before it heard, then random's first.
        session.on_watched(step(0, 8));
        session.on_watched(step(1, 3));
        let last = |s: &Session, label: &str| {
            let run = &s.runs[&(label.to_string(), 0)];
            run.dashboard.last_step.map(|s| s.step)
        };
        assert_eq!(last(&session, "sapnet"), Some(8));
        assert_eq!(last(&session, "random"), Some(3));
        // Back: the stream moves back.
        session.follow(("sapnet".to_string(), 0));
        assert_eq!(receivers[1].pending(), [Command::Stream(false)]);
        assert_eq!(receivers[0].pending(), [Command::Stream(true)]);
    }

    #[test]
    fn an_ended_protocol_quits_at_once_and_launches_only_when_idle() {
        let mut session = Session::new(Path::new("out/x"), "CartPole-v1", None, Phase::Running);
        assert_eq!(session.on_key(key('L')), Request::None);
        assert!(session.overlay.is_none());
        assert_eq!(
            session.notice.as_deref(),
            Some("a protocol is running: S stops it first")
        );
        session.phase = Phase::Ended(Status::Complete);
        assert_eq!(session.on_key(key('q')), Request::Quit);
        assert_eq!(session.on_key(key('R')), Request::None);
        assert_eq!(
            session.notice.as_deref(),
            Some("the folder holds no protocol yet")
        );
    }
}
