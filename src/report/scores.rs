//! What each run scored, in the task's own return units: the numbers every comparison is
//! computed from, and `scores.csv`.
//!
//! - the **test score**: the mean return of the run's greedy test episodes;
//! - the **training return**: under an episode budget, the mean return over all its
//!   training episodes (the area under its learning curve per episode); under a step
//!   budget, the area under its curve on the step axis ([`super::step_axis`]);
//! - the **final return** (step budgets): the step curve's last point;
//! - per threshold, the **episode** (or, under a step budget, the **step**) at which the
//!   moving average of returns first reached it, or none: a run that never reached it is
//!   *censored* at its end (it might have later), never dropped.
//!
//! Normalised scores map the task's range of returns (`EnvConfig::return_range`: 0 to 500
//! on CartPole-v1, −200 to 0 on MountainCar-v0) onto [0, 1], so that tasks can be pooled.

use serde::Serialize;

use super::runs::{moving_average, RunSummary, TrainingEpisodes};
use super::step_axis;
use crate::config::Budget;

/// One run's scores.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunScores {
    pub method: String,
    pub run: u32,
    /// The task it ran on, as results label it.
    pub task: String,
    /// The mean greedy test return; `None` for a run stopped before its tests.
    pub test: Option<f64>,
    /// The mean training return (per episode, or per step of the step curve); `None` for
    /// a run without a finished episode.
    pub training_return: Option<f64>,
    /// The step curve's last point, under a step budget.
    pub final_return: Option<f64>,
    /// Training episodes it finished.
    pub episodes: usize,
    /// Environment steps and gradient updates of its training: what it was given.
    pub steps: u64,
    pub updates: u64,
    /// What `reached` counts: `episode` or `step`, the budget's unit.
    pub unit: &'static str,
    /// Per threshold of the protocol, the threshold and the 1-based episode (or the step)
    /// at which the moving average first reached it, `None` if it never did.
    pub reached: Vec<(f64, Option<u64>)>,
}

impl RunScores {
    /// The scores of `run`, from its training `episodes`, under `budget`; `window` is the
    /// moving average's.
    pub fn of(
        run: &RunSummary,
        task: &str,
        episodes: &TrainingEpisodes,
        thresholds: &[f64],
        window: usize,
        budget: Budget,
    ) -> Self {
        let returns = &episodes.returns;
        let mut scores = Self {
            method: run.record.method.label().to_string(),
            run: run.record.run,
            task: task.to_string(),
            test: run.mean_test_return,
            training_return: None,
            final_return: None,
            episodes: returns.len(),
            steps: run.record.steps,
            updates: run.record.updates,
            unit: budget.unit(),
            reached: Vec::new(),
        };
        match budget {
            Budget::Episodes(_) => {
                let averages = moving_average(returns, window);
                scores.training_return = (!returns.is_empty())
                    .then(|| returns.iter().sum::<f64>() / returns.len() as f64);
                scores.reached = thresholds
                    .iter()
                    .map(|&t| {
                        let at = averages.iter().position(|&a| a >= t);
                        (t, at.map(|i| (i + window) as u64))
                    })
                    .collect();
            }
            Budget::Steps(budget) => {
                let points = step_axis::points(budget, super::sample_efficiency::POINTS);
                let curve = step_axis::curve(episodes, window, &points);
                scores.training_return = step_axis::area(&curve);
                scores.final_return = curve.last().copied().flatten();
                scores.reached = thresholds
                    .iter()
                    .map(|&t| (t, step_axis::step_reached(episodes, window, t)))
                    .collect();
            }
        }
        scores
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
            &episodes(&returns, 10),
            &[40.0, 60.0, 99.0],
            2,
            Budget::Episodes(6),
        );
        assert_eq!(s.test, Some(150.0));
        // (10 + 30 + 50 + 70 + 20 + 20) / 6 = 200 / 6.
        assert_eq!(s.training_return, Some(200.0 / 6.0));
        // MA2: 20, 40, 60, 45, 20 → 40 first at episode 3, 60 at 4, 99 never.
        assert_eq!(s.reached, [(40.0, Some(3)), (60.0, Some(4)), (99.0, None)]);
        assert_eq!(s.episodes, 6);
        assert_eq!((s.method.as_str(), s.run), ("ucb1", 3));
        assert_eq!((s.final_return, s.unit), (None, "episode"));
    }

    fn episodes(returns: &[f64], length: u32) -> TrainingEpisodes {
        let mut episodes = TrainingEpisodes::default();
        for &r in returns {
            episodes.push(r, length);
        }
        episodes
    }

    /// The same six episodes of 10 steps each, under a budget of 60 steps read at 200
    /// points (one per step from 1 to 60): a point's value is the MA2 of the episodes ended
    /// by it (one episode alone before step 20). Steps 1–9: none ended; 10–19: 10;
    /// 20–29: 20; 30–39: 40; 40–49: 60; 50–59: 45; 60: 20.
    #[test]
    fn under_a_step_budget_the_scores_are_read_on_the_step_axis() {
        let returns = [10.0, 30.0, 50.0, 70.0, 20.0, 20.0];
        let s = RunScores::of(
            &summary(vec![100.0]),
            "cartpole",
            &episodes(&returns, 10),
            &[40.0, 60.0, 99.0],
            2,
            Budget::Steps(60),
        );
        let area =
            (10.0 * 10.0 + 20.0 * 10.0 + 40.0 * 10.0 + 60.0 * 10.0 + 45.0 * 10.0 + 20.0) / 51.0;
        assert!((s.training_return.unwrap() - area).abs() < 1e-12);
        assert_eq!(s.final_return, Some(20.0));
        // MA2 40 first over episodes 2–3, ended at step 30; 60 over 3–4, at 40.
        assert_eq!(
            s.reached,
            [(40.0, Some(30)), (60.0, Some(40)), (99.0, None)]
        );
        assert_eq!(s.unit, "step");
    }

    #[test]
    fn normalised_scores_map_the_range_of_returns_to_the_unit_interval() {
        assert_eq!(normalise(250.0, (0.0, 500.0)), 0.5);
        assert_eq!(normalise(-200.0, (-200.0, 0.0)), 0.0);
        assert_eq!(normalise(-110.0, (-200.0, 0.0)), 0.45);
    }
}
