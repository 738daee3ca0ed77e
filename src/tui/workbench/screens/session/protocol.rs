//! A protocol trained behind the screen: the experiment layer's engine ([`experiment::run_opened`],
//! [`experiment::resume_taken`]: its scheduler, seeds and files) on a thread of its own,
//! tapped so that the screen sees every run's events and can steer the one it follows.

use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, Sender};
use std::thread::JoinHandle;

use anyhow::{Context, Result};

use crate::config::Config;
use crate::experiment::{
    self, OpenedOutput, OutputOptions, RunOptions, StoppedProtocol, Tap, Watched,
};
use crate::results::Summary;
use crate::trainer::Command;
use crate::tui::workbench::views::run::RunKey;

/// A protocol training on its thread.
pub struct ProtocolRun {
    pub dir: PathBuf,
    /// What its runs tell; drained by the screen every frame.
    pub watched: Receiver<Watched>,
    stop: Sender<Command>,
    thread: JoinHandle<Result<Summary>>,
}

impl ProtocolRun {
    /// Trains `config` into the folder `opened` took (see [`OpenedOutput::open`]);
    /// `live` streams every step.
    pub fn start(
        config: Config,
        output: OutputOptions,
        opened: OpenedOutput,
        options: RunOptions,
        live: Option<RunKey>,
    ) -> Result<Self> {
        let dir = output.dir.clone();
        Self::spawn(dir, live, move |commands, tap| {
            experiment::run_opened(&config, &output, opened, &options, commands, Some(tap))
        })
    }

    /// Resumes the stopped protocol of a folder taken for it, as `--headless --resume
    /// --out DIR` does; `live` streams every step.
    pub fn resume(
        stopped: StoppedProtocol,
        options: RunOptions,
        live: Option<RunKey>,
    ) -> Result<Self> {
        Self::spawn(stopped.dir().to_path_buf(), live, move |commands, tap| {
            experiment::resume_taken(stopped, &options, commands, Some(tap))
        })
    }

    fn spawn(
        dir: PathBuf,
        live: Option<RunKey>,
        protocol: impl FnOnce(&Receiver<Command>, &Tap) -> Result<Summary> + Send + 'static,
    ) -> Result<Self> {
        let (stop, commands) = mpsc::channel();
        let (to, watched) = mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("protocol".into())
            .spawn(move || protocol(&commands, &Tap { to, live }))
            .context("starting the protocol's thread")?;
        Ok(Self {
            dir,
            watched,
            stop,
            thread,
        })
    }

    /// Asks the runs to stop after their step: the files are then written as a stopped
    /// protocol's, which `R` (or `--headless --resume`) finishes.
    pub fn stop(&self) {
        let _ = self.stop.send(Command::Stop);
    }

    pub fn is_finished(&self) -> bool {
        self.thread.is_finished()
    }

    /// Its outcome, once it ended (waits for it otherwise).
    pub fn join(self) -> Result<Summary> {
        self.thread
            .join()
            .map_err(|_| anyhow::anyhow!("the protocol's thread panicked"))?
    }
}
