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
    /// The loss became NaN or infinite; `last_good` holds the weights before that update.
    #[error("policy {method} (run {run}) diverged: {source}")]
    Diverged {
        method: String,
        run: u32,
        source: DqnError,
        last_good: Box<QNet>,
    },
}

/// The label of a from-scratch DQN in results: `dqn[100,100]`.
pub fn dqn_label(hidden: &[usize]) -> String {
    let layers: Vec<String> = hidden.iter().map(ToString::to_string).collect();
    format!("dqn[{}]", layers.join(","))
}
