//! The screen of a protocol run in the UI: it owns the protocol's thread and the thread
//! that reads its folder, feeds the [`Session`] what they tell, and does what its keys
//! ask (stop, launch, resume), on the one event loop ([`crate::tui::event_loop`]). The UI
//! thread only drains, draws and reads keys: training never waits for it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use crossterm::event::{KeyEvent, MouseEvent};
use ratatui::layout::Rect;
use ratatui::Frame;

use super::protocol::ProtocolRun;
use super::stderr_capture::StderrCapture;
use super::{overlays, Overlay, Phase, Request, Session};
use crate::config::Config;
use crate::env::PythonSettings;
use crate::experiment::{self, OpenedOutput, OutputOptions, RunOptions, StoppedProtocol};
use crate::results::folder_state::FolderReader;
use crate::results::Summary;
use crate::trainer::MethodId;
use crate::tui::event_loop::{self, Flow, Screen};
use crate::tui::follow;
use crate::tui::reference::Band;
use crate::tui::theme::Theme;
use crate::tui::workbench::folder::{first_unfinished, FolderReads};
use crate::tui::workbench::screens::workbench::Tab;
use crate::tui::workbench::views::run::RunKey;
use crate::tui::TerminalGuard;

/// What every protocol of the session is run with.
pub struct Settings<'a> {
    pub options: RunOptions,
    pub python: PythonSettings,
    /// A picked config, read with the session's flags applied (`--quick`, `--episodes`,
    /// `--runs`, `--seed`), or why it cannot run (its file, field and what was expected).
    pub load: &'a dyn Fn(&Path) -> Result<Config>,
    /// `--compare`'s bands, under every run's curves.
    pub reference: Vec<Band>,
}

/// The protocol the UI opens on.
pub enum Start {
    /// A new protocol of `config`, into the folder already taken for it; `followed` is the
    /// run followed from its start (`--follow`, `--follow-run`).
    New {
        config: Config,
        output: OutputOptions,
        opened: OpenedOutput,
        followed: Option<RunKey>,
    },
    /// A stopped protocol, its folder taken (`sapnet --resume --out DIR`, `R` in `sapnet
    /// open`); `followed` as for a new one, else the first run it has left.
    Resume {
        stopped: StoppedProtocol,
        followed: Option<RunKey>,
    },
}

/// How each protocol of the session ended, with its folder, in the order they ended: what
/// the command line says after the screen closes (every folder, `L`'s too). Empty: the
/// user quit while none had ended.
pub type Ended = Vec<(Result<Summary>, PathBuf)>;

/// Runs `start`'s protocol in the UI until the user quits (after it ended, or stopping
/// it); `L` and `R` start others in the same screen.
pub fn run(start: Start, settings: &Settings) -> Result<Ended> {
    let capture = StderrCapture::start();
    let (mut terminal, guard) = crate::tui::open_terminal()?;
    run_in(&mut terminal, guard, capture, start, settings)
}

/// [`run`] on a terminal a screen already holds (`sapnet open`'s, after `R`): the screen
/// changes, the terminal stays.
pub(crate) fn resume_in(
    terminal: &mut ratatui::DefaultTerminal,
    guard: TerminalGuard,
    start: Start,
    settings: &Settings,
) -> Result<Ended> {
    let capture = StderrCapture::start();
    run_in(terminal, guard, capture, start, settings)
}

fn run_in(
    terminal: &mut ratatui::DefaultTerminal,
    guard: TerminalGuard,
    capture: Option<StderrCapture>,
    start: Start,
    settings: &Settings,
) -> Result<Ended> {
    let (protocol, session) = match start {
        Start::New {
            config,
            output,
            opened,
            followed,
        } => {
            let task = config.env.gym_id();
            let dir = output.dir.clone();
            let protocol = ProtocolRun::start(
                config,
                output,
                opened,
                settings.options.clone(),
                followed.clone(),
            )?;
            (
                protocol,
                Session::new(&dir, &task, followed, Phase::Running),
            )
        }
        Start::Resume { stopped, followed } => {
            let dir = stopped.dir().to_path_buf();
            let task = stopped.config().env.gym_id();
            let followed = followed.or_else(|| {
                let state = FolderReader::new(&dir).read().ok()?;
                first_unfinished(&state)
            });
            let protocol =
                ProtocolRun::resume(stopped, settings.options.clone(), followed.clone())?;
            let mut session = Session::new(&dir, &task, followed, Phase::Running);
            session.workbench.notice = Some(format!("resuming {}", dir.display()));
            (protocol, session)
        }
    };
    let dir = protocol.dir.clone();
    let mut session = session;
    session.workbench.run.reference = settings.reference.clone();
    let mut live = Live {
        session,
        protocol: Some(protocol),
        reads: FolderReads::start(&dir)?,
        quit_when_stopped: false,
        ended: Vec::new(),
        settings,
        theme: Theme::from_env(),
    };
    let result = event_loop::run(terminal, &mut live);
    drop(guard);
    // A signal, or an error of the screen's: the protocol stops, its folder resumable.
    if let Some(protocol) = live.protocol.take() {
        protocol.stop();
        let dir = protocol.dir.clone();
        live.ended.push((protocol.join(), dir));
    }
    drop(capture);
    result.map(|()| live.ended)
}

/// The session, and what its screen owns besides: the protocol's thread, the folder's.
struct Live<'a> {
    session: Session,
    protocol: Option<ProtocolRun>,
    reads: FolderReads,
    /// `q` answered yes: the screen closes once the protocol has stopped.
    quit_when_stopped: bool,
    ended: Ended,
    settings: &'a Settings<'a>,
    theme: Theme,
}

impl Screen for Live<'_> {
    fn drain(&mut self) -> (bool, Flow) {
        let session = &mut self.session;
        if let Some(protocol) = &self.protocol {
            for watched in protocol.watched.try_iter() {
                session.on_watched(watched);
            }
        }
        let mut changed = false;
        if self.protocol.as_ref().is_some_and(ProtocolRun::is_finished) {
            self.protocol_ended();
            if self.quit_when_stopped {
                return (true, Flow::Quit);
            }
            changed = true;
        }
        for read in self.reads.reads.try_iter() {
            match read {
                Ok((folder, report)) => self.session.refreshed(folder, report),
                Err(error) => self.session.read_failed(error),
            }
            changed = true;
        }
        (changed, Flow::Continue)
    }

    /// SIGTERM or SIGHUP (or SIGINT from outside): stop as `q` then `y` does, and leave
    /// once the protocol has stopped.
    fn on_signal(&mut self) -> Flow {
        let Some(protocol) = &self.protocol else {
            return Flow::Quit;
        };
        if !self.quit_when_stopped {
            protocol.stop();
            self.session.phase = Phase::Stopping;
            self.quit_when_stopped = true;
        }
        Flow::Continue
    }

    fn tick(&mut self, now: Instant) {
        self.session.tick(now);
    }

    /// The Run view's step line and speed change every frame.
    fn animated(&self) -> bool {
        self.session.workbench.tab == Tab::Run
    }

    fn draw(&self, frame: &mut Frame) {
        overlays::draw(frame, &self.session, self.theme);
    }

    fn on_key(&mut self, key: KeyEvent) -> Flow {
        match self.session.on_key(key) {
            Request::None => {}
            Request::Quit => return Flow::Quit,
            Request::Stop { then_quit } => {
                if let Some(protocol) = &self.protocol {
                    protocol.stop();
                    self.session.phase = Phase::Stopping;
                }
                self.quit_when_stopped |= then_quit;
            }
            Request::Launch(path) => self.launch(&path),
            Request::Resume => self.resume(),
        }
        Flow::Continue
    }

    fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        self.session.on_mouse(mouse, screen);
    }
}

impl Live<'_> {
    /// The protocol's thread ended: its outcome is kept for the command line, the screen
    /// stays on its results.
    fn protocol_ended(&mut self) {
        let session = &mut self.session;
        let Some(protocol) = self.protocol.take() else {
            return;
        };
        for watched in protocol.watched.try_iter() {
            session.on_watched(watched);
        }
        let dir = protocol.dir.clone();
        let outcome = protocol.join();
        session.phase = match &outcome {
            Ok(summary) => Phase::Ended(summary.status),
            Err(error) => Phase::Failed(format!("{error:#}")),
        };
        // "resuming DIR" or "X started into DIR" said what began; the header now says how
        // it ended.
        session.workbench.notice = None;
        self.ended.push((outcome, dir));
    }

    /// `L` picked `path`: its protocol starts into a new folder, or the picker says why
    /// it cannot.
    fn launch(&mut self, path: &Path) {
        let session = &mut self.session;
        match start_config(path, self.settings) {
            Ok(Started {
                protocol,
                reads,
                dir,
                task,
                followed,
            }) => {
                self.protocol = Some(protocol);
                self.reads = reads;
                session.restart(&dir, &task, followed);
                session.workbench.notice =
                    Some(format!("{} started into {}", path.display(), dir.display()));
            }
            Err(error) => {
                if let Some(Overlay::Picker(picker)) = &mut session.overlay {
                    picker.error = Some(format!("{error:#}"));
                }
            }
        }
    }

    /// `R`: the session's folder, taken and resumed as `--headless --resume` would; the
    /// run followed is the first not finished of the method the UI follows by default.
    /// The folder is read afresh: the views' last read may be older than the stop.
    fn resume(&mut self) {
        let (session, settings) = (&mut self.session, self.settings);
        let dir = session.dir.clone();
        let started =
            StoppedProtocol::take(&dir, None, None, &settings.python).and_then(|stopped| {
                let task = stopped.config().env.gym_id();
                let followed = FolderReader::new(&dir)
                    .read()
                    .ok()
                    .and_then(|state| first_unfinished(&state));
                let protocol =
                    ProtocolRun::resume(stopped, settings.options.clone(), followed.clone())?;
                Ok((protocol, FolderReads::start(&dir)?, task, followed))
            });
        match started {
            Ok((protocol, reads, task, followed)) => {
                self.protocol = Some(protocol);
                self.reads = reads;
                session.restart(&dir, &task, followed);
                session.workbench.notice = Some(format!("resuming {}", dir.display()));
            }
            Err(error) => session.workbench.notice = Some(format!("{error:#}")),
        }
    }
}

/// The run a new protocol is followed in: run 0 of the method the UI follows by default.
pub fn default_followed(config: &Config) -> Result<Option<RunKey>> {
    let ids = MethodId::all(&config.protocol.methods);
    follow::followed_run(&ids, None, None, config.protocol.runs)
}

/// A protocol `L` started: its thread, its folder's reader, and what its session starts
/// on (the folder, the task, the run followed).
struct Started {
    protocol: ProtocolRun,
    reads: FolderReads,
    dir: PathBuf,
    task: String,
    followed: Option<RunKey>,
}

/// `L`'s config at `path`, started into a new folder.
fn start_config(path: &Path, settings: &Settings) -> Result<Started> {
    let config = (settings.load)(path)?;
    let followed = default_followed(&config)?;
    let output = OutputOptions {
        dir: experiment::default_out_dir(Some(path)),
        force: false,
    };
    let opened = OpenedOutput::open(&output)?;
    let dir = output.dir.clone();
    let task = config.env.gym_id();
    let protocol = ProtocolRun::start(
        config,
        output,
        opened,
        settings.options.clone(),
        followed.clone(),
    )?;
    Ok(Started {
        protocol,
        reads: FolderReads::start(&dir)?,
        dir,
        task,
        followed,
    })
}
