//! Interval estimates over the scores of independent runs, as Agarwal et al., "Deep RL at
//! the Edge of the Statistical Precipice" (NeurIPS 2021), recommend and their `rliable`
//! library computes: aggregates of a method's runs ([`aggregate`]: mean, median,
//! interquartile mean, optimality gap) with 95% stratified bootstrap intervals
//! ([`bootstrap`]), the probability that one method's run beats another's
//! ([`improvement`]), performance profiles ([`profile`]), and the share of runs that
//! reached a level ([`proportion`]).
//!
//! Beside the intervals, what a separation rule needs: rank tests of "X's runs score
//! like Y's" ([`rank_test`]: Mann–Whitney on one task, van Elteren over several), Holm's
//! adjustment of their p-values for the number of comparisons ([`multiplicity`]), the runs
//! per method that would detect an observed effect ([`power`]), and the standard normal's
//! tail and quantile they use ([`normal`]).
//!
//! Pure functions over plain numbers: no I/O, no candle, no threads. A method's scores are
//! one list of runs per task ([`Scores`]); a protocol on one task has one list, a sweep
//! over tasks one per task, and the bootstrap resamples runs within each task (the
//! strata), never across them.

pub mod aggregate;
pub mod bootstrap;
pub mod episodes;
pub mod improvement;
pub mod multiplicity;
pub mod normal;
pub mod power;
pub mod profile;
pub mod proportion;
pub mod rank_test;
pub mod separation;

use serde::Serialize;

/// The runs' scores of one method, per task: `tasks[t][r]` is run r's score on task t.
/// Every task holds at least one run.
#[derive(Debug, Clone, PartialEq)]
pub struct Scores {
    tasks: Vec<Vec<f64>>,
}

impl Scores {
    /// The scores of runs on one task.
    pub fn one_task(runs: Vec<f64>) -> Option<Self> {
        Self::per_task(vec![runs])
    }

    /// Scores on several tasks, runs listed per task; `None` if there is no task or a task
    /// without runs (nothing to estimate from).
    pub fn per_task(tasks: Vec<Vec<f64>>) -> Option<Self> {
        (!tasks.is_empty() && tasks.iter().all(|t| !t.is_empty())).then_some(Self { tasks })
    }

    /// The runs of each task.
    pub fn tasks(&self) -> &[Vec<f64>] {
        &self.tasks
    }

    /// Every run's score, task after task.
    pub fn pooled(&self) -> Vec<f64> {
        self.tasks.concat()
    }

    /// How many runs, over all tasks.
    pub fn runs(&self) -> usize {
        self.tasks.iter().map(Vec::len).sum()
    }
}

/// A point estimate and its 95% interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    pub point: f64,
    pub lo: f64,
    pub hi: f64,
}

impl Estimate {
    /// Whether the intervals of `self` and `other` share a value: two methods whose
    /// intervals overlap are not separated by these runs.
    pub fn overlaps(&self, other: &Estimate) -> bool {
        self.lo <= other.hi && other.lo <= self.hi
    }
}
