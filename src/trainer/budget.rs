//! How much experience a run is given: the paper's episodes, or the field's environment
//! steps.

use serde::{Deserialize, Serialize};

use crate::limits::MAX_EPISODES;

/// How much experience each run of a protocol is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Budget {
    /// Training episodes per run: the paper's protocol (Table I: 5000 CartPole, 10000
    /// MountainCar). A method whose episodes last longer is given more experience.
    Episodes(u32),
    /// Environment steps per run, the episode in progress cut at the budget: the field's
    /// sample-efficiency protocol (rliable, openrlbenchmark, rl-baselines3-zoo), where
    /// every method sees the same number of transitions. Scores and curves of such a
    /// protocol are taken on the environment-step axis ([`crate::report::scores`]).
    Steps(u64),
}

impl Budget {
    /// The episodes a run may run: all it is given, or unbounded under a step budget.
    pub fn episodes(self) -> u32 {
        match self {
            Budget::Episodes(n) => n,
            Budget::Steps(_) => MAX_EPISODES,
        }
    }

    /// The steps a run may take: its budget, or unbounded under an episode budget.
    pub fn steps(self) -> Option<u64> {
        match self {
            Budget::Episodes(_) => None,
            Budget::Steps(n) => Some(n),
        }
    }

    /// What the budget counts, as a column or an axis names it: `episode` or `step`.
    pub fn unit(self) -> &'static str {
        match self {
            Budget::Episodes(_) => "episode",
            Budget::Steps(_) => "step",
        }
    }

    /// `1/divisor` of the budget, at least 1: a smoke run's.
    pub fn cut(self, divisor: u64) -> Budget {
        match self {
            Budget::Episodes(n) => Budget::Episodes((n / divisor as u32).max(1)),
            Budget::Steps(n) => Budget::Steps((n / divisor).max(1)),
        }
    }
}

impl std::fmt::Display for Budget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Budget::Episodes(n) => write!(f, "{n} episodes"),
            Budget::Steps(n) => write!(f, "{n} environment steps"),
        }
    }
}
