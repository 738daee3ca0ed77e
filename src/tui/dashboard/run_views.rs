//! What the dashboard keeps of each run it shows: the followed run's selector over the
//! library ([`LibraryView`]), and each run's progress and curve ([`RunView`]).

use std::collections::VecDeque;

use crate::config::Budget;
use crate::reuse::ScoreColumn;
use crate::sapnet::{PolicyDescription, Prototype, SapNet};
use crate::teach::labels::short_task;
use crate::trainer::{MethodId, RunRecord};

use super::live_curve::LiveCurve;

/// Episodes of scores kept for the table's sparklines.
pub const HISTORY: usize = 40;

/// Steps a policy's edges stay highlighted after it spread activation.
const SPREAD_GLOW_STEPS: u64 = 8;

/// A source policy as the table shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyRow {
    pub name: String,
    pub description: PolicyDescription,
    pub final_score: Option<f64>,
}

/// The followed reusing run's live state: SAP-Net's, or another selector's drawn on the
/// library's graph.
#[derive(Debug, Clone, PartialEq)]
pub struct LibraryView {
    /// The method whose selector this is (`sapnet`, `ucb1`…).
    pub method: String,
    /// What the scores are: `A` for SAP-Net's activations, else the selector's own.
    pub score: ScoreColumn,
    pub policies: Vec<PolicyRow>,
    /// The graph and parameters, with the activations of the latest snapshot.
    pub net: SapNet,
    pub probabilities: Vec<f64>,
    pub selections: Vec<u64>,
    pub positive: Vec<u64>,
    pub negative: Vec<u64>,
    /// Per policy, whether its category is out of the candidates now (empty: none is).
    pub excluded: Vec<bool>,
    /// The policy that acted at the latest step.
    pub acting: Option<usize>,
    /// The last policy that activated and spread, and the step it did.
    pub spread: Option<(usize, u64)>,
    /// The policy that has held P > [`LOCK_IN`](crate::trainer::LOCK_IN) since the step given, while it does: the
    /// softmax has collapsed onto it. Never for a method that picks by rule (as in the
    /// headless comparison, [`crate::reuse::MethodKind::picks_by_probability`]).
    pub locked: Option<(usize, u64)>,
    /// The scores at the end of each of the last [`HISTORY`] episodes, oldest first: the
    /// table's sparklines.
    pub history: VecDeque<Vec<f64>>,
}

impl LibraryView {
    /// Whether policy `i` is out of the candidates now.
    pub fn is_excluded(&self, i: usize) -> bool {
        self.excluded.get(i).copied().unwrap_or(false)
    }

    /// The category of each policy under the config's first prototype, numbered in order
    /// of appearance.
    pub fn categories(&self) -> Vec<usize> {
        let prototype = self
            .net
            .params()
            .prototypes
            .first()
            .map_or(Prototype::HiddenLayers, |p| p.prototype.clone());
        prototype.group_indices(self.policies.iter().map(|p| &p.description))
    }

    /// The name of each group of [`categories`](Self::categories) when the graph groups
    /// by source task over a library of several tasks (the task labels), else none.
    pub fn task_groups(&self) -> Vec<String> {
        let by_task = self
            .net
            .params()
            .prototypes
            .first()
            .is_some_and(|p| p.prototype == Prototype::SourceTask);
        let mut names: Vec<String> = Vec::new();
        for policy in &self.policies {
            let task = short_task(&policy.description.source_task);
            if !names.iter().any(|n| n == task) {
                names.push(task.to_string());
            }
        }
        if by_task && names.len() > 1 {
            names
        } else {
            Vec::new()
        }
    }

    /// Whether `policy`'s edges are still lit from a recent spread.
    pub fn glows(&self, policy: usize, step: u64) -> bool {
        matches!(self.spread, Some((p, at)) if p == policy && step.saturating_sub(at) < SPREAD_GLOW_STEPS)
    }
}

/// One training run as the dashboard follows it.
#[derive(Debug, Clone, PartialEq)]
pub struct RunView {
    pub method: MethodId,
    /// Which run of its method (from 0; `--follow-run` picks another than the first).
    pub run: u32,
    /// The episodes or environment steps the run is given.
    pub budget: Budget,
    pub episode: u32,
    /// Environment steps of the episodes that ended.
    pub steps: u64,
    pub curve: LiveCurve,
    pub epsilon: f64,
    pub statistic_loss: Vec<f64>,
    pub ended: Option<RunRecord>,
    /// Why the run stopped with an error, if it did.
    pub failed: Option<String>,
}

impl RunView {
    pub(super) fn new(method: MethodId, run: u32, budget: Budget) -> Self {
        Self {
            method,
            run,
            budget,
            episode: 0,
            steps: 0,
            curve: LiveCurve::default(),
            epsilon: 0.0,
            statistic_loss: Vec::new(),
            ended: None,
            failed: None,
        }
    }
}
