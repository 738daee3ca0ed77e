//! The trainer: owns all training state on its own thread and reports through [`Event`]s.
//! Front ends (headless, later the TUI) consume the same stream and know nothing of each
//! other.

mod dqn_run;
mod events;

pub use dqn_run::{test_greedy, train, DqnRunOutcome, DqnRunSpec};
pub use events::{Command, EpisodeRecord, Event, MethodLabel, RunRecord};

use crate::dqn::{DqnError, QNet};

/// Why a run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum TrainerError {
    #[error(transparent)]
    Dqn(#[from] DqnError),
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

/// The label of a from-scratch DQN in results: `dqn[100,100]`.
pub fn dqn_label(hidden: &[usize]) -> String {
    let layers: Vec<String> = hidden.iter().map(ToString::to_string).collect();
    format!("dqn[{}]", layers.join(","))
}
