//! A protocol run in the UI (`sapnet` without `--headless`): the workbench on the folder
//! it writes, its Run view following one run live, and the controls that launch (`L`),
//! stop (`S`, `q`) and resume (`R`) protocols. What it keeps and what its keys ask for; no
//! thread ([`live`] runs the screen that owns the protocol's), no drawing ([`overlays`]).
//!
//! - [`picker`]: `L`'s configs; [`protocol`]: the protocol's thread (the experiment
//!   layer's runner, tapped); `stderr_capture`: stderr held aside while the screen is up.

pub mod live;
pub mod overlays;
pub mod picker;
pub mod protocol;
mod stderr_capture;

use std::path::{Path, PathBuf};
use std::time::Instant;

use crossterm::event::{KeyEvent, MouseEvent};
use ratatui::layout::Rect;

use super::workbench::{ScreenCommand, Tab, Workbench, SESSION_KEYS};
use crate::experiment::Watched;
use crate::report::Report;
use crate::results::folder_state::FolderState;
use crate::results::Status;
use crate::tui::keys::ctrl;
use crate::tui::workbench::views::run::{RunKey, RunView};
use picker::{Picked, Picker};

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

/// The protocol run in the UI, and what the screen shows of it.
pub struct Session {
    /// The folder the protocol writes (or the one opened).
    pub dir: PathBuf,
    /// The folder's views and the Run view.
    pub workbench: Workbench,
    pub phase: Phase,
    pub overlay: Option<Overlay>,
}

impl Session {
    /// A session on `dir`, following `followed` (which streams its steps) once it starts,
    /// in the Run view if it follows one.
    pub fn new(dir: &Path, task: &str, followed: Option<RunKey>, phase: Phase) -> Self {
        let tab = if followed.is_some() {
            Tab::Run
        } else {
            Tab::Runs
        };
        Self {
            dir: dir.to_path_buf(),
            workbench: Workbench::new(None, RunView::new(task, followed), tab),
            phase,
            overlay: None,
        }
    }

    /// The same screen on a new protocol's folder (`L`, `R`): its runs start afresh.
    pub fn restart(&mut self, dir: &Path, task: &str, followed: Option<RunKey>) {
        let reference = std::mem::take(&mut self.workbench.run.reference);
        let tab = self.workbench.tab;
        *self = Self::new(dir, task, followed, Phase::Running);
        self.workbench.run.reference = reference;
        self.workbench.tab = tab;
    }

    /// Whether a protocol of this session is training or stopping.
    pub fn is_running(&self) -> bool {
        matches!(self.phase, Phase::Running | Phase::Stopping)
    }

    /// A new read of the folder.
    pub fn refreshed(&mut self, state: FolderState, report: Option<Option<Report>>) {
        self.workbench.refreshed(state, report);
    }

    pub fn read_failed(&mut self, error: String) {
        self.workbench.read_failed(error);
    }

    /// What the protocol's thread told.
    pub fn on_watched(&mut self, watched: Watched) {
        self.workbench.run.on_watched(watched);
    }

    /// Once a frame: the followed run's speed, and teach mode's walk.
    pub fn tick(&mut self, now: Instant) {
        self.workbench.run.tick(now);
    }

    /// What the last key did or why it did nothing.
    pub fn notice(&self) -> Option<&str> {
        self.workbench.notice.as_deref()
    }

    /// What `key` does: the question or picker over the screen takes it first, then the
    /// workbench (`?`, the view, the tabs); what is left is the protocol's.
    pub fn on_key(&mut self, key: KeyEvent) -> Request {
        if let Some(overlay) = self.overlay.take() {
            self.workbench.notice = None;
            return self.on_overlay_key(overlay, &key);
        }
        match self.workbench.on_key(&key, SESSION_KEYS) {
            None => Request::None,
            Some(ScreenCommand::Quit) => self.quit(),
            Some(ScreenCommand::Launch) => {
                if self.is_running() {
                    self.say("a protocol is running: S stops it first");
                } else {
                    self.overlay = Some(Overlay::Picker(Picker::open()));
                }
                Request::None
            }
            Some(ScreenCommand::Stop) => {
                if self.phase == Phase::Running {
                    self.overlay = Some(Overlay::Stop { then_quit: false });
                } else {
                    self.say("no protocol is training");
                }
                Request::None
            }
            Some(ScreenCommand::Resume) => match self.resumable() {
                Ok(()) => Request::Resume,
                Err(why) => {
                    self.say(&why);
                    Request::None
                }
            },
            // The workbench shows tabs and `?` itself.
            Some(ScreenCommand::Show(_) | ScreenCommand::Help) => Request::None,
        }
    }

    fn say(&mut self, notice: &str) {
        self.workbench.notice = Some(notice.to_string());
    }

    fn on_overlay_key(&mut self, overlay: Overlay, key: &KeyEvent) -> Request {
        let ctrl_c = ctrl('c').matches(key);
        match overlay {
            Overlay::Stop { then_quit } => match key.code {
                // Ctrl-C twice stops, as `y` does.
                crossterm::event::KeyCode::Char('y') | crossterm::event::KeyCode::Enter => {
                    Request::Stop { then_quit }
                }
                _ if ctrl_c => Request::Stop { then_quit },
                _ => {
                    self.say("the protocol goes on");
                    Request::None
                }
            },
            Overlay::Picker(mut picker) => {
                if ctrl_c {
                    return Request::None;
                }
                match picker.on_key(*key) {
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

    /// A mouse event on a `screen`-sized terminal: the question or picker over the screen
    /// takes no click; the workbench takes the rest.
    pub fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        if self.overlay.is_none() {
            self.workbench.on_mouse(mouse, screen, SESSION_KEYS);
        }
    }

    /// Whether `R` can resume the folder shown, and if not why.
    pub fn resumable(&self) -> Result<(), String> {
        if self.is_running() {
            return Err("the protocol is training: nothing to resume".into());
        }
        match (&self.workbench.folder, &self.phase) {
            (Some(folder), _) => crate::tui::workbench::folder::resumable(&folder.state),
            // Not read yet (stopped within a second of its start): how this session's own
            // protocol ended says it.
            (None, Phase::Ended(status)) if *status != Status::Complete => Ok(()),
            (None, _) => Err("the folder holds no protocol yet".into()),
        }
    }

    /// The protocol's controls the status bar offers, as the phase allows them: first,
    /// where a narrow terminal drops keys from the end.
    pub fn controls(&self) -> Vec<ScreenCommand> {
        match self.phase {
            Phase::Running => vec![ScreenCommand::Stop],
            Phase::Stopping => Vec::new(),
            _ if self.resumable().is_ok() => vec![ScreenCommand::Launch, ScreenCommand::Resume],
            _ => vec![ScreenCommand::Launch],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trainer::{Command, Event};
    use crate::tui::dashboard::Mode;
    use crossterm::event::{KeyCode, KeyModifiers};

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
            let run = &s.workbench.run.runs[&(label.to_string(), 0)];
            (run.dashboard.mode, run.dashboard.speed)
        };
        assert_eq!(board(&session, "sapnet"), (Mode::Paused, 1));
        // `m` follows the other run training; the one left runs again at full speed.
        session.on_key(key('m'));
        assert_eq!(
            session.workbench.run.followed,
            Some(("random".to_string(), 0))
        );
        assert_eq!(board(&session, "sapnet"), (Mode::Running, 0));
        // Following the run already followed changes nothing.
        session.on_key(key(' '));
        session.workbench.run.follow(("random".to_string(), 0));
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
        session.workbench.run.follow(("random".to_string(), 0));
        assert_eq!(receivers[0].pending(), [Command::Stream(false)]);
        assert_eq!(receivers[1].pending(), [Command::Stream(true)]);
        assert_eq!(session.workbench.run.live, Some(("random".to_string(), 0)));
        // A step SAP-Net sent before it heard, then random's first.
        session.on_watched(step(0, 8));
        session.on_watched(step(1, 3));
        let last = |s: &Session, label: &str| {
            let run = &s.workbench.run.runs[&(label.to_string(), 0)];
            run.dashboard.last_step.map(|s| s.step)
        };
        assert_eq!(last(&session, "sapnet"), Some(8));
        assert_eq!(last(&session, "random"), Some(3));
        // Back: the stream moves back.
        session.workbench.run.follow(("sapnet".to_string(), 0));
        assert_eq!(receivers[1].pending(), [Command::Stream(false)]);
        assert_eq!(receivers[0].pending(), [Command::Stream(true)]);
    }

    #[test]
    fn an_ended_protocol_quits_at_once_and_launches_only_when_idle() {
        let mut session = Session::new(Path::new("out/x"), "CartPole-v1", None, Phase::Running);
        assert_eq!(session.on_key(key('L')), Request::None);
        assert!(session.overlay.is_none());
        assert_eq!(
            session.notice(),
            Some("a protocol is running: S stops it first")
        );
        session.phase = Phase::Ended(Status::Complete);
        assert_eq!(session.on_key(key('q')), Request::Quit);
        assert_eq!(session.on_key(key('R')), Request::None);
        assert_eq!(session.notice(), Some("the folder holds no protocol yet"));
    }
}
