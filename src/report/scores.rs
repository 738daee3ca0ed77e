//! What each run scored, in the task's own return units: the numbers every comparison is
//! computed from, and `scores.csv`.
//!
//! - the **test score**: the mean return of the run's greedy test episodes;
//! - the **training return**: the mean return over all its training episodes (the area
//!   under its learning curve per episode);
//! - per threshold, the **episode** at which the moving average of returns first reached
//!   it, or none: a run that never reached it is *censored* at its last episode (it might
//!   have later), never dropped.
//!
//! Normalised scores map the task's range of returns (`EnvConfig::return_range`: 0 to 500
//! on CartPole-v1, −200 to 0 on MountainCar-v0) onto [0, 1], so that tasks can be pooled.

use serde::Serialize;

use super::runs::{moving_average, RunSummary};

/// One run's scores.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunScores {
    pub method: String,
    pub run: u32,
    /// The task it ran on, as results label it.
    pub task: String,
    /// The mean greedy test return; `None` for a run stopped before its tests.
    pub test: Option<f64>,
    /// The mean training return; `None` for a run without a finished episode.
    pub training_return: Option<f64>,
    /// Training episodes it ran: where a threshold it never reached is censored.
    pub episodes: usize,
    /// Per threshold of the protocol, the threshold and the 1-based episode whose moving
    /// average first reached it, `None` if none did.
    pub reached: Vec<(f64, Option<usize>)>,
}

impl RunScores {
    /// The scores of `run`, from its training `returns`; `window` is the moving average's.
    pub fn of(
        run: &RunSummary,
        task: &str,
        returns: &[f64],
        thresholds: &[f64],
        window: usize,
    ) -> Self {
        let averages = moving_average(returns, window);
        Self {
            method: run.record.method.label().to_string(),
            run: run.record.run,
            task: task.to_string(),
            test: run.mean_test_return,
            training_return: (!returns.is_empty())
                .then(|| returns.iter().sum::<f64>() / returns.len() as f64),
            episodes: returns.len(),
            reached: thresholds
                .iter()
                .map(|&t| (t, averages.iter().position(|&a| a >= t).map(|i| i + window)))
                .collect(),
        }
    }
}

/// `x` on the task's `range` of returns mapped to [0, 1] (not clamped: a return outside
/// the range stays visible as such).
pub fn normalise(x: f64, (low, high): (f64, f64)) -> f64 {
    (x - low) / (high - low)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reuse::Method;
    use crate::trainer::{MethodId, RunRecord};

    fn summary(tests: Vec<f64>) -> RunSummary {
        let mut record = RunRecord::new(3, MethodId::new(0, &Method::Ucb1), 0);
        record.episodes = 6;
        record.test_returns = tests;
        RunSummary::new(record, &[], 2)
    }

    #[test]
    fn scores_by_hand_and_a_threshold_never_reached_is_censored() {
        let returns = [10.0, 30.0, 50.0, 70.0, 20.0, 20.0];
        let s = RunScores::of(
            &summary(vec![100.0, 200.0]),
            "cartpole",
            &returns,
            &[40.0, 60.0, 99.0],
            2,
        );
        assert_eq!(s.test, Some(150.0));
        // (10 + 30 + 50 + 70 + 20 + 20) / 6 = 200 / 6.
        assert_eq!(s.training_return, Some(200.0 / 6.0));
        // MA2: 20, 40, 60, 45, 20 → 40 first at episode 3, 60 at 4, 99 never.
        assert_eq!(s.reached, [(40.0, Some(3)), (60.0, Some(4)), (99.0, None)]);
        assert_eq!(s.episodes, 6);
        assert_eq!((s.method.as_str(), s.run), ("ucb1", 3));
    }

    #[test]
    fn normalised_scores_map_the_range_of_returns_to_the_unit_interval() {
        assert_eq!(normalise(250.0, (0.0, 500.0)), 0.5);
        assert_eq!(normalise(-200.0, (-200.0, 0.0)), 0.0);
        assert_eq!(normalise(-110.0, (-200.0, 0.0)), 0.45);
    }
}
