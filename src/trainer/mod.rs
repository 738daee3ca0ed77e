//! The trainer: owns all training state on its own thread and reports through [`Event`]s.
//! Front ends (headless, the TUI) consume the same stream and know nothing of each other.
//!
//! - [`train`]: one run of any method (SAP-Net's Algorithm 3, the comparators, DQN from
//!   scratch; the source policies are trained as DQN from scratch);
//! - [`spawn`]: a run on a thread of its own, with its command channel.

mod budget;
mod control;
mod events;
pub mod memory;
mod networks;
mod run;
mod run_state;
pub mod scheduler;
mod spec;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::Arc;
use std::thread::{self, JoinHandle};

pub use budget::Budget;
pub use events::{
    ActivationSnapshot, ChosenPolicy, Command, CutEpisode, Deposit, EpisodeRecord, Event,
    LibraryStart, LockIn, MethodId, RunRecord, SourceSummary, StepRecord, StreamOptions,
    TraceRecord,
};
pub use run::train;
pub use run_state::{test_greedy, LOCK_IN};
pub use scheduler::{schedule, Observer};
pub use spec::{selector, RunSpec, SourcePolicy};

use crate::dqn::{DqnError, QNet};
use crate::reuse::ReuseError;

/// Why a run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum TrainerError {
    #[error(transparent)]
    Dqn(#[from] DqnError),
    // Not a `source`: the message says it, and a chain prints it once.
    #[error("building the selector over the source policies: {0}")]
    Reuse(ReuseError),
    /// The environment failed: a Gymnasium task's worker raised, died or could not start.
    #[error(transparent)]
    Env(#[from] crate::env::EnvError),
    /// The loss or a gradient became NaN or infinite.
    #[error("policy {} (run {}) diverged: {}", .0.method, .0.run, .0.source)]
    Diverged(Box<Divergence>),
}

impl From<ReuseError> for TrainerError {
    fn from(error: ReuseError) -> Self {
        TrainerError::Reuse(error)
    }
}

/// A run that diverged: what it had done, and the weights before the update that failed.
#[derive(Debug)]
pub struct Divergence {
    pub method: String,
    pub run: u32,
    pub source: DqnError,
    /// Complete episodes and steps before the failure.
    pub episodes: u32,
    pub steps: u64,
    pub last_good: QNet,
}

/// A finished run: its record and the trained network (for the policy library): the DQN's,
/// or SAP-Net's chosen policy.
#[derive(Debug)]
pub struct RunOutcome {
    pub record: RunRecord,
    pub net: QNet,
}

/// A run on its own thread: send it commands, join it for the outcome.
#[derive(Debug)]
pub struct RunHandle {
    pub commands: Commands,
    pub thread: JoinHandle<Result<RunOutcome, TrainerError>>,
}

/// The front end's end of a run's command channel. A [`Command::Stop`] also raises the
/// run's stop flag, which its learners read between the updates of a long round (they
/// cannot read the channel: the run's loop does, between steps).
#[derive(Debug, Clone)]
pub struct Commands {
    sender: Sender<Command>,
    stop: Arc<AtomicBool>,
}

impl Commands {
    pub fn send(&self, command: Command) -> Result<(), mpsc::SendError<Command>> {
        if command == Command::Stop {
            self.stop.store(true, Ordering::SeqCst);
        }
        self.sender.send(command)
    }
}

/// The run's end of its command channel: the commands, and the stop flag its learners
/// are given.
#[derive(Debug)]
pub struct CommandReceiver {
    receiver: Receiver<Command>,
    stop: Arc<AtomicBool>,
}

impl CommandReceiver {
    /// Raised by a `Stop` sent through [`Commands`].
    pub fn stop_flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.stop)
    }

    /// The commands sent and not yet read: what a front end's tests read (the key tables'
    /// walk sends the Run view's keys to runs of its own).
    pub fn pending(&self) -> Vec<Command> {
        self.receiver.try_iter().collect()
    }
}

/// A run's command channel.
pub fn command_channel() -> (Commands, CommandReceiver) {
    let (sender, receiver) = mpsc::channel();
    let stop = Arc::new(AtomicBool::new(false));
    (
        Commands {
            sender,
            stop: Arc::clone(&stop),
        },
        CommandReceiver { receiver, stop },
    )
}

/// Starts `spec` on a thread of its own that sends its events to `events`.
pub fn spawn(spec: RunSpec, events: Sender<Event>) -> std::io::Result<RunHandle> {
    let (commands, receiver) = command_channel();
    let thread = thread::Builder::new()
        .name(format!("trainer {} run {}", spec.method, spec.run))
        .spawn(move || {
            let outcome = train(&spec, &events, &receiver);
            if let Err(err) = &outcome {
                let _ = events.send(Event::RunFailed {
                    run: spec.run,
                    method: spec.method.clone(),
                    error: err.to_string(),
                });
            }
            outcome
        })?;
    Ok(RunHandle { commands, thread })
}
