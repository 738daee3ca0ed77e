//! What a report reads of a finished run: its record with the measures of its training
//! returns, and the library it drew on.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::trainer::{MethodId, RunRecord};

pub use crate::stats::episodes::TrainingEpisodes;

/// Every run's training episodes, by method and run: shared, since a folder's returns are
/// its largest data and a reader keeps them beside its views of the runs.
pub type TrainingRuns = BTreeMap<(MethodId, u32), Arc<TrainingEpisodes>>;

/// A source policy as `summary.json` lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LibraryEntry {
    pub name: String,
    pub hidden: Vec<usize>,
    /// The task it was trained on, with what differs from the task's defaults.
    #[serde(default)]
    pub task: String,
    /// Its hidden layers' activation function: with `hidden` and `task`, the categories its
    /// place in SAP-Net's graph is made of. Folders older than the field held ReLU
    /// networks only.
    #[serde(default = "relu")]
    pub activation: String,
    pub final_score: Option<f64>,
}

fn relu() -> String {
    "relu".to_string()
}

impl LibraryEntry {
    /// The description its graph's categories come from (eq. 3–5).
    pub fn description(&self) -> crate::sapnet::PolicyDescription {
        crate::sapnet::PolicyDescription {
            hidden: self.hidden.clone(),
            activation: self.activation.clone(),
            source_task: self.task.clone(),
        }
    }
}

/// One run in `summary.json` (and in `runs/<run>/run.json`); `M` as in [`RunRecord`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunSummary<M = MethodId> {
    #[serde(flatten)]
    pub record: RunRecord<M>,
    /// Mean of the greedy test returns (absent when the run was stopped before testing).
    pub mean_test_return: Option<f64>,
    /// Moving average of the last `window` training returns.
    pub final_moving_average: Option<f64>,
    /// Best moving average over the run.
    pub best_moving_average: Option<f64>,
    /// First episode (1-based) whose moving average reached the best value.
    pub best_moving_average_episode: Option<u32>,
    /// Where the chosen source, fine-tuned, was added to the policy library (its metadata
    /// file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub library_copy: Option<std::path::PathBuf>,
}

impl RunSummary<String> {
    /// The summary read back from disk, its method known again by its id.
    pub fn with_method(self, method: MethodId) -> RunSummary {
        RunSummary {
            record: self.record.with_method(method),
            mean_test_return: self.mean_test_return,
            final_moving_average: self.final_moving_average,
            best_moving_average: self.best_moving_average,
            best_moving_average_episode: self.best_moving_average_episode,
            library_copy: self.library_copy,
        }
    }
}

impl RunSummary {
    pub fn new(record: RunRecord, rewards: &[f64], window: usize) -> Self {
        let averages = moving_average(rewards, window);
        let best = averages
            .iter()
            .enumerate()
            .fold(None, |best: Option<(usize, f64)>, (i, &a)| match best {
                Some((_, b)) if b >= a => best,
                _ => Some((i, a)),
            });
        let mean_test_return = (!record.test_returns.is_empty())
            .then(|| record.test_returns.iter().sum::<f64>() / record.test_returns.len() as f64);
        Self {
            record,
            mean_test_return,
            final_moving_average: averages.last().copied(),
            best_moving_average: best.map(|(_, a)| a),
            best_moving_average_episode: best.map(|(i, _)| (i + window) as u32),
            library_copy: None,
        }
    }
}

/// Means of every full window of `window` consecutive values (the paper's learning curves
/// average 10 episodes). Element `i` covers values `i ..= i + window - 1`.
pub fn moving_average(values: &[f64], window: usize) -> Vec<f64> {
    if window == 0 || values.len() < window {
        return Vec::new();
    }
    values
        .windows(window)
        .map(|w| w.iter().sum::<f64>() / window as f64)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_covers_full_windows_only() {
        // (1+2+3)/3 = 2, (2+3+4)/3 = 3, (3+4+5)/3 = 4
        assert_eq!(
            moving_average(&[1.0, 2.0, 3.0, 4.0, 5.0], 3),
            vec![2.0, 3.0, 4.0]
        );
        assert!(moving_average(&[1.0, 2.0], 3).is_empty());
    }

    #[test]
    fn the_best_window_is_dated_by_its_last_episode() {
        let method = MethodId::new(0, &crate::reuse::Method::Dqn { hidden: vec![4] });
        let mut record = RunRecord::new(0, method, 0);
        record.episodes = 5;
        record.test_returns = vec![10.0, 20.0];
        let s = RunSummary::new(record, &[1.0, 5.0, 3.0, 9.0, 1.0], 2);
        // windows: 3, 4, 6, 5 → best 6 over episodes 3–4.
        assert_eq!(s.best_moving_average, Some(6.0));
        assert_eq!(s.best_moving_average_episode, Some(4));
        assert_eq!(s.final_moving_average, Some(5.0));
        assert_eq!(s.mean_test_return, Some(15.0));
    }
}
