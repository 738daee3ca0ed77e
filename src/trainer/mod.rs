//! The trainer: owns all training state on its own thread and reports through [`Event`]s.
//! Front ends (headless, the TUI) consume the same stream and know nothing of each other.
//!
//! - [`train`]: DQN from scratch (the paper's baselines, and the source policies);
//! - [`train_transfer`]: transfer with SAP-Net (Algorithm 3);
//! - [`spawn`]: either one on a thread of its own, with its command channel.

mod control;
mod dqn_run;
mod events;
mod transfer_run;

use std::sync::mpsc::{self, Receiver, Sender};
use std::thread::{self, JoinHandle};

pub use dqn_run::{test_greedy, train, DqnRunSpec};
pub use events::{
    ActivationSnapshot, ChosenPolicy, Command, EpisodeRecord, Event, MethodLabel, RunRecord,
    SapNetStart, SourceSummary, StepRecord, StreamOptions, TraceRecord,
};
pub use transfer_run::{train_transfer, SourcePolicy, TransferRunSpec};

use crate::dqn::{DqnError, QNet};
use crate::sapnet::SapNetError;

/// Why a run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum TrainerError {
    #[error(transparent)]
    Dqn(#[from] DqnError),
    #[error("building SAP-Net over the source policies: {0}")]
    SapNet(#[from] SapNetError),
    /// The loss or a gradient became NaN or infinite.
    #[error("policy {} (run {}) diverged: {}", .0.method, .0.run, .0.source)]
    Diverged(Box<Divergence>),
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

/// Any run the protocol lists.
#[derive(Debug, Clone)]
pub enum RunSpec {
    Dqn(DqnRunSpec),
    Transfer(TransferRunSpec),
}

impl RunSpec {
    pub fn run(&self) -> u32 {
        match self {
            Self::Dqn(s) => s.run,
            Self::Transfer(s) => s.run,
        }
    }

    pub fn method(&self) -> &str {
        match self {
            Self::Dqn(s) => &s.method,
            Self::Transfer(s) => &s.method,
        }
    }

    pub fn episodes(&self) -> u32 {
        match self {
            Self::Dqn(s) => s.episodes,
            Self::Transfer(s) => s.episodes,
        }
    }

    pub fn seed(&self) -> u64 {
        match self {
            Self::Dqn(s) => s.seed,
            Self::Transfer(s) => s.seed,
        }
    }

    /// Trains on this thread.
    pub fn train(
        &self,
        events: &Sender<Event>,
        commands: &Receiver<Command>,
    ) -> Result<RunOutcome, TrainerError> {
        match self {
            Self::Dqn(spec) => train(spec, events, commands),
            Self::Transfer(spec) => train_transfer(spec, events, commands),
        }
    }
}

/// A run on its own thread: send it commands, join it for the outcome.
#[derive(Debug)]
pub struct RunHandle {
    pub commands: Sender<Command>,
    pub thread: JoinHandle<Result<RunOutcome, TrainerError>>,
}

/// Starts `spec` on a thread of its own that sends its events to `events`.
pub fn spawn(spec: RunSpec, events: Sender<Event>) -> std::io::Result<RunHandle> {
    let (commands, receiver) = mpsc::channel();
    let thread = thread::Builder::new()
        .name(format!("trainer {} run {}", spec.method(), spec.run()))
        .spawn(move || {
            let outcome = spec.train(&events, &receiver);
            if let Err(err) = &outcome {
                let _ = events.send(Event::RunFailed {
                    run: spec.run(),
                    method: spec.method().to_string(),
                    error: err.to_string(),
                });
            }
            outcome
        })?;
    Ok(RunHandle { commands, thread })
}

/// The label of a from-scratch DQN in results: `dqn[100,100]`.
pub fn dqn_label(hidden: &[usize]) -> String {
    let layers: Vec<String> = hidden.iter().map(ToString::to_string).collect();
    format!("dqn[{}]", layers.join(","))
}

/// The label of SAP-Net transfer runs in results.
pub const SAPNET_LABEL: &str = "sapnet";
