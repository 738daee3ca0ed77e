//! The loop of a protocol run in the UI: it owns the protocol's thread and the thread
//! that reads its folder, feeds the [`Session`] what they tell, draws it, and does what
//! its keys ask (stop, launch, resume). The UI thread only drains, draws and reads keys:
//! training never waits for it.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

use anyhow::{Context, Result};
use crossterm::event::{self as term, KeyEventKind, MouseButton, MouseEventKind};

use super::protocol::ProtocolRun;
use super::session::{Overlay, Phase, Request, RunKey, Screen, Session};
use super::stderr_capture::StderrCapture;
use super::{read_on, session_view, Read};
use crate::config::Config;
use crate::env::PythonSettings;
use crate::experiment::{self, OpenedOutput, OutputOptions, RunOptions};
use crate::results::folder_state::FolderReader;
use crate::results::Summary;
use crate::trainer::MethodId;
use crate::tui::reference::Band;
use crate::tui::theme::Theme;
use crate::tui::{follow, FRAME};

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

/// The protocol the UI opens on: its config, and the folder already taken for it.
pub struct Start {
    pub config: Config,
    pub output: OutputOptions,
    pub opened: OpenedOutput,
    /// The run followed from its start (`--follow`, `--follow-run`).
    pub followed: Option<RunKey>,
}

/// How the session's last protocol ended, and its folder: what the command line says
/// after the screen closes. `None`: the user quit while none had ended.
pub type Ended = Option<(Result<Summary>, PathBuf)>;

/// The folder-reading thread of one folder; dropping it ends the thread.
struct FolderReads {
    reads: mpsc::Receiver<Read>,
    _stop: mpsc::Sender<()>,
}

impl FolderReads {
    fn start(dir: &Path) -> Result<Self> {
        let reader = FolderReader::new(dir);
        let looked = crate::results::folder_changes::look(dir);
        let (reads_tx, reads) = mpsc::channel();
        let (stop_tx, stop) = mpsc::channel::<()>();
        std::thread::Builder::new()
            .name("workbench: reading".into())
            .spawn(move || read_on(reader, looked, &reads_tx, &stop))
            .context("starting the thread that reads the folder")?;
        Ok(Self {
            reads,
            _stop: stop_tx,
        })
    }
}

/// Runs `start`'s protocol in the UI until the user quits (after it ended, or stopping
/// it); `L` and `R` start others in the same screen.
pub fn run(start: Start, settings: &Settings) -> Result<Ended> {
    let task = start.config.env.gym_id();
    let dir = start.output.dir.clone();
    let followed = start.followed.clone();
    let capture = StderrCapture::start();
    let (mut terminal, guard) = crate::tui::open_terminal()?;
    let protocol = ProtocolRun::start(
        start.config,
        start.output,
        start.opened,
        settings.options.clone(),
        followed.clone(),
    )?;
    let mut session = Session::new(&dir, &task, followed, Phase::Running);
    session.reference = settings.reference.clone();
    let reads = FolderReads::start(&dir)?;
    let mut running = Running {
        protocol: Some(protocol),
        reads,
        quit_when_stopped: false,
        ended: None,
    };
    let result = running.drive(&mut session, &mut terminal, settings);
    drop(guard);
    // A signal, or an error of the screen's: the protocol stops, its folder resumable.
    if let Some(protocol) = running.protocol.take() {
        protocol.stop();
        let dir = protocol.dir.clone();
        running.ended = Some((protocol.join(), dir));
    }
    drop(capture);
    result.map(|()| running.ended)
}

/// What the loop owns besides the session.
struct Running {
    protocol: Option<ProtocolRun>,
    reads: FolderReads,
    /// `q` answered yes: the screen closes once the protocol has stopped.
    quit_when_stopped: bool,
    ended: Ended,
}

impl Running {
    fn drive(
        &mut self,
        session: &mut Session,
        terminal: &mut ratatui::DefaultTerminal,
        settings: &Settings,
    ) -> Result<()> {
        let theme = Theme::from_env();
        let mut dirty = true;
        loop {
            if let Some(protocol) = &self.protocol {
                for watched in protocol.watched.try_iter() {
                    session.on_watched(watched);
                }
            }
            if self.protocol.as_ref().is_some_and(ProtocolRun::is_finished) {
                self.protocol_ended(session);
                dirty = true;
                if self.quit_when_stopped {
                    return Ok(());
                }
            }
            for read in self.reads.reads.try_iter() {
                match read {
                    Ok((folder, report)) => session.refreshed(folder, report),
                    Err(error) => session.read_failed(error),
                }
                dirty = true;
            }
            // SIGTERM or SIGHUP (or SIGINT from outside): stop as `q` then `y` does.
            if crate::signals::received().is_some() {
                let Some(protocol) = &self.protocol else {
                    return Ok(());
                };
                if !self.quit_when_stopped {
                    protocol.stop();
                    session.phase = Phase::Stopping;
                    self.quit_when_stopped = true;
                }
            }
            session.tick(Instant::now());
            if dirty || session.screen == Screen::Run {
                session.sync_host_keys();
                terminal
                    .draw(|frame| session_view::draw(frame, session, theme))
                    .context("drawing the workbench")?;
                dirty = false;
            }
            if !term::poll(FRAME).context("reading the keyboard")? {
                continue;
            }
            dirty = true;
            let key = match term::read().context("reading the keyboard")? {
                term::Event::Key(key) => key,
                term::Event::Mouse(mouse) => {
                    if mouse.kind == MouseEventKind::Down(MouseButton::Left) {
                        let size = terminal.size().context("reading the terminal's size")?;
                        if let Some(clicked) =
                            session_view::clicked(session, size.into(), mouse.column, mouse.row)
                        {
                            if let Some(run) = session
                                .followed
                                .clone()
                                .and_then(|key| session.runs.get_mut(&key))
                            {
                                run.dashboard.on_click(clicked);
                            }
                        }
                    }
                    continue;
                }
                _ => continue, // a resize redraws
            };
            if key.kind != KeyEventKind::Press {
                continue;
            }
            match session.on_key(key) {
                Request::None => {}
                Request::Quit => return Ok(()),
                Request::Stop { then_quit } => {
                    if let Some(protocol) = &self.protocol {
                        protocol.stop();
                        session.phase = Phase::Stopping;
                    }
                    self.quit_when_stopped |= then_quit;
                }
                Request::Launch(path) => self.launch(session, &path, settings),
                Request::Resume => self.resume(session, settings),
            }
        }
    }

    /// The protocol's thread ended: its outcome is kept for the command line, the screen
    /// stays on its results.
    fn protocol_ended(&mut self, session: &mut Session) {
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
        self.ended = Some((outcome, dir));
    }

    /// `L` picked `path`: its protocol starts into a new folder, or the picker says why
    /// it cannot.
    fn launch(&mut self, session: &mut Session, path: &Path, settings: &Settings) {
        match self.start_config(path, settings) {
            Ok((dir, task, followed)) => {
                session.restart(&dir, &task, followed);
                session.notice = Some(format!("{} started into {}", path.display(), dir.display()));
            }
            Err(error) => {
                if let Some(Overlay::Picker(picker)) = &mut session.overlay {
                    picker.error = Some(format!("{error:#}"));
                }
            }
        }
    }

    fn start_config(
        &mut self,
        path: &Path,
        settings: &Settings,
    ) -> Result<(PathBuf, String, Option<RunKey>)> {
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
        self.reads = FolderReads::start(&dir)?;
        self.protocol = Some(protocol);
        Ok((dir, task, followed))
    }

    /// `R`: the folder shown, resumed as `--headless --resume` would; the run followed is
    /// the first not finished of the method the UI follows by default.
    fn resume(&mut self, session: &mut Session, settings: &Settings) {
        let Some(workbench) = &session.workbench else {
            return;
        };
        let folder = &workbench.folder;
        let ids = MethodId::all(&folder.config.protocol.methods);
        let preferred = follow::followed_method(&ids, None).ok().flatten();
        let unfinished = |method: Option<&MethodId>| {
            folder
                .runs
                .iter()
                .filter(|r| r.status != crate::results::folder_state::RunStatus::Done)
                .find(|r| method.is_none_or(|m| *m == r.method))
                .map(|r| (r.method.label().to_string(), r.run))
        };
        let followed = unfinished(preferred.as_ref()).or_else(|| unfinished(None));
        let (dir, task) = (folder.dir.clone(), folder.config.env.gym_id());
        match ProtocolRun::resume(
            &dir,
            settings.python.clone(),
            settings.options.clone(),
            followed.clone(),
        )
        .and_then(|protocol| Ok((protocol, FolderReads::start(&dir)?)))
        {
            Ok((protocol, reads)) => {
                self.protocol = Some(protocol);
                self.reads = reads;
                session.restart(&dir, &task, followed);
                session.notice = Some(format!("resuming {}", dir.display()));
            }
            Err(error) => session.notice = Some(format!("{error:#}")),
        }
    }
}

/// The run a new protocol is followed in: run 0 of the method the UI follows by default.
pub fn default_followed(config: &Config) -> Result<Option<RunKey>> {
    let ids = MethodId::all(&config.protocol.methods);
    follow::followed_run(&ids, None, None, config.protocol.runs)
}
