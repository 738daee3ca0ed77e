//! The contract between the trainer and the front ends: the trainer only *sends* [`Event`]s,
//! front ends only render them and send [`Command`]s.

use serde::Serialize;

/// Which learner a run trains, as it appears in results (`dqn[100,100]`, `sapnet`).
pub type MethodLabel = String;

/// One finished training episode: a row of `episodes.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeRecord {
    /// Index of the independent run (0-based).
    pub run: u32,
    pub method: MethodLabel,
    /// 1-based, as the paper counts.
    pub episode: u32,
    pub reward: f64,
    pub steps: u32,
    /// Raw loss of the policy's latest update at the end of the episode (empty before
    /// learning starts; with `update_interval` > 1 it may come from an earlier episode).
    pub loss: Option<f64>,
    /// The statistic loss E at the end of the episode.
    pub statistic_loss: f64,
    /// ε at the end of the episode.
    pub epsilon: f64,
    /// Seconds since the run started.
    pub wall_s: f64,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunRecord {
    pub run: u32,
    pub method: MethodLabel,
    /// The seed of this run's random streams, derived from the config's run seed, the
    /// method's index and the run's index (`seeds::derive(seed, &[method, run])`).
    pub seed: u64,
    /// Training episodes completed (a step budget may cut a last, partial episode, which is
    /// not counted; `steps` counts its steps).
    pub episodes: u32,
    pub steps: u64,
    pub updates: u64,
    /// Returns of the greedy test episodes after training (empty if stopped before).
    pub test_returns: Vec<f64>,
    /// Stopped by the user before the planned episodes were done.
    pub stopped: bool,
    pub wall_s: f64,
}

/// What the trainer tells the front ends.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    RunStarted {
        run: u32,
        method: MethodLabel,
        planned_episodes: u32,
    },
    EpisodeEnded(EpisodeRecord),
    RunEnded(RunRecord),
}

/// What a front end can ask of the trainer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Finish the current step, then end the run as stopped.
    Stop,
}
