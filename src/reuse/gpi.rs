//! Generalized policy improvement (Barreto et al., "Successor Features for Transfer in
//! Reinforcement Learning", NeurIPS 2017), on a library of DQN policies.
//!
//! The sources' policies stay frozen. A learner of the method's own, a fresh DQN, learns
//! from every step and joins the maximum, as SFQL's new task does: each step acts
//! ε-greedily (the learner's schedule) on
//!
//! ```text
//! π(s) ∈ argmax_a max( Q_L(s, a), max_i Q̂^{π_i}(s, a) )      (Barreto et al., eq. 10)
//! ```
//!
//! and the run hands over that policy, the learner with the library, for its greedy tests.
//!
//! GPI's guarantee is on each source's value **on the target task**, `Q^{π_i}`. A DQN
//! network is neither that nor even its own task's `Q*`: it is a biased estimate, and the
//! maximum over several picks the most over-estimated (on MountainCar, where every true
//! value is ≤ 0, sources output thousands). So, as SFQL keeps evaluating its sources on
//! the new task's data, the run keeps per source a value network `Q̂_i`, initialised from
//! the source's own and trained by TD on the run's replay with the target's γ,
//! bootstrapping on the source's (frozen) greedy policy:
//!
//! ```text
//! y = r + γ·Q̂_i⁻(s′, argmax_a Q_i(s′, a))
//! ```
//!
//! by default only the source whose value won the maximum at the step's state, as SFQL
//! updates the winner's successor features (`evaluate: Winner`), or every source
//! (`evaluate: All`). `evaluate: Off` takes the networks as they are: the reading before
//! the evaluation, kept to show what it changes.
//!
//! Choices a DQN library forced (docs/BASELINES.md):
//! - SFQL learns successor features ψ and reward weights w; a library of Q-networks holds
//!   no ψ, so each `Q̂_i` is learned directly, a network of the source's shape;
//! - the estimates' target copies every `evaluation_target_interval` of their updates
//!   (100 by default: evaluating a fixed policy has no maximum to over-estimate, and with
//!   Table I's 10,000 an estimate that wins rarely would bootstrap on its initial
//!   over-estimate for the whole run);
//! - the learner's update is by default DQN's own (`max_a' Q_target(s', a')` of the
//!   learner), the config's learner as every method's; `learner_bootstrap: Gpi` (label
//!   `gpi-sfql`) bootstraps on the GPI action at `s'` as SFQL does, valued by the
//!   learner's target network;
//! - ties between Q-values go to the learner, then to the lowest source index.

use serde::{Deserialize, Serialize};

use rand::rngs::StdRng;

use super::definition::{check_label, MethodKind, ReuseMethod, Tested};
use super::{
    Actor, Combined, Evaluate, Learning, Library, ReuseError, ScoreColumn, Selector, SelectorView,
    StateValues,
};
use crate::sapnet::SapNetParams;

/// Which sources' values on the target task are estimated, and from which steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Evaluation {
    /// The source whose value won the maximum at the step's state learns from the step
    /// (SFQL's update of the winning policy).
    Winner,
    /// Every source learns from every step.
    All,
    /// None: the sources' networks taken as they are.
    Off,
}

/// What the learner's targets bootstrap on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum LearnerBootstrap {
    /// Its own maximum, `max_a' Q_L⁻(s′, a′)`: DQN's.
    Own,
    /// `Q_L⁻(s′, a*)` at GPI's action `a* = argmax_a max(Q_L(s′, a), max_i Q̂_i(s′, a))`:
    /// SFQL's bootstrap on the GPI action.
    Gpi,
}

/// GPI's knobs (`Gpi()` in `protocol.methods`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GpiKnobs {
    /// The learner's hidden layers: the paper's DQN baseline's by default.
    pub hidden: Vec<usize>,
    /// Which sources' values on the target task are estimated: `Winner` (default), `All`
    /// or `Off`.
    pub evaluate: Evaluation,
    /// The estimates' target copy interval, in their own updates.
    pub evaluation_target_interval: u64,
    /// `Own` (default): the learner's targets bootstrap on its own maximum, DQN's; `Gpi`:
    /// on the action GPI picks at `s′` from the learner's and the sources' values, SFQL's.
    pub learner_bootstrap: LearnerBootstrap,
    /// The label of results; default `gpi` (`gpi-all`, `gpi-unevaluated` for the other
    /// evaluations), or `gpi[64,64]` for another learner.
    pub label: Option<String>,
}

impl Default for GpiKnobs {
    fn default() -> Self {
        Self {
            hidden: vec![100],
            evaluate: Evaluation::Winner,
            evaluation_target_interval: 100,
            learner_bootstrap: LearnerBootstrap::Own,
            label: None,
        }
    }
}

/// GPI in `protocol.methods`, in teal.
pub const KIND: MethodKind = MethodKind {
    family: "Gpi",
    hue: 180,
    saturation: 60,
    reuses: true,
    tested: Tested::Combined,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for GpiKnobs {
    fn label(&self) -> String {
        let label = learner_label("gpi", &self.hidden, self.label.as_deref());
        let label = match (self.evaluate, &self.label) {
            (Evaluation::All, None) => format!("{label}-all"),
            (Evaluation::Off, None) => format!("{label}-unevaluated"),
            _ => label,
        };
        match (self.learner_bootstrap, &self.label) {
            (LearnerBootstrap::Gpi, None) => format!("{label}-sfql"),
            _ => label,
        }
    }

    fn source_evaluation(&self) -> Option<u64> {
        (self.evaluate != Evaluation::Off).then_some(self.evaluation_target_interval)
    }

    fn gpi_bootstrap(&self) -> bool {
        self.learner_bootstrap == LearnerBootstrap::Gpi
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn learner_hidden(&self) -> Option<&[usize]> {
        Some(&self.hidden)
    }

    fn validate(&self, field: &str) -> Result<(), String> {
        crate::ron_file::check(
            (1..=crate::limits::MAX_STEPS).contains(&self.evaluation_target_interval),
            &format!("{field}.evaluation_target_interval"),
            "at least 1 update",
            self.evaluation_target_interval,
        )?;
        check_learner(field, &self.hidden, self.label.as_deref())
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(Gpi::new(
            library.descriptions.len(),
            self.evaluate,
        )))
    }
}

/// `family` with the learner's layers when they are not the paper's `[100]`, or the given
/// label: the label rule of the methods with a learner of their own.
pub(super) fn learner_label(family: &str, hidden: &[usize], label: Option<&str>) -> String {
    if let Some(label) = label {
        return label.into();
    }
    if hidden == [100] {
        return family.into();
    }
    let layers: Vec<String> = hidden.iter().map(ToString::to_string).collect();
    format!("{family}[{}]", layers.join(","))
}

/// The checks of a learner's layers and a given label, `field` being where the knobs sit.
pub(super) fn check_learner(
    field: &str,
    hidden: &[usize],
    label: Option<&str>,
) -> Result<(), String> {
    crate::ron_file::check(
        !hidden.is_empty() && hidden.iter().all(|&u| u > 0),
        &format!("{field}.hidden"),
        "a non-empty list of layer sizes > 0",
        format!("{hidden:?}"),
    )?;
    match label {
        Some(label) => check_label(field, label),
        None => Ok(()),
    }
}

/// GPI's choice and its counts of whose Q-value won.
#[derive(Debug)]
pub struct Gpi {
    /// Steps whose action took its Q-value from each source, and from the learner.
    wins: FollowedCounts,
    evaluation: Evaluation,
    /// The source whose value won the maximum at the latest step's state, exploring or
    /// not: the one whose estimate learns from the step under `Winner`.
    winner: Option<usize>,
}

impl Gpi {
    pub fn new(n: usize, evaluation: Evaluation) -> Self {
        Self {
            wins: FollowedCounts::new(n),
            evaluation,
            winner: None,
        }
    }
}

/// `argmax_a max(Q_L(s, a), max_i Q_i(s, a))`, and whose Q-value is that maximum: the
/// learner on a tie, then the lowest source.
pub fn choose(learner: &[f32], sources: &[Vec<f32>]) -> Combined {
    let mut best = Combined {
        action: 0,
        followed: None,
    };
    let mut best_q = f32::NEG_INFINITY;
    for (a, &q) in learner.iter().enumerate() {
        if q > best_q {
            (best_q, best) = (
                q,
                Combined {
                    action: a,
                    followed: None,
                },
            );
        }
    }
    for (i, values) in sources.iter().enumerate() {
        for (a, &q) in values.iter().enumerate() {
            if q > best_q {
                best_q = q;
                best = Combined {
                    action: a,
                    followed: Some(i),
                };
            }
        }
    }
    best
}

/// GPI's score: the steps each source's value won the maximum.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "wins",
    meaning: "wins: steps its Q won the max; P: their share",
    counted: true,
};

impl Selector for Gpi {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    fn act(&mut self, _rng: &mut StdRng) -> Actor {
        Actor::Combined
    }

    /// ε-greedy around the maximum: an exploring step follows nobody.
    fn combine(&self, values: &StateValues<'_>) -> Combined {
        match values.explored {
            Some(action) => Combined {
                action,
                followed: None,
            },
            None => choose(values.learner, values.sources),
        }
    }

    fn on_combined(&mut self, values: &StateValues<'_>, choice: Combined) {
        self.wins.count(choice.followed);
        self.winner = choose(values.learner, values.sources).followed;
    }

    fn evaluate(&self) -> Evaluate {
        match (self.evaluation, self.winner) {
            (Evaluation::Winner, Some(i)) => Evaluate::Source(i),
            (Evaluation::All, _) => Evaluate::Every,
            _ => Evaluate::Nobody,
        }
    }

    /// Scores: the steps each source's Q-value won the maximum; probabilities: their share
    /// of all steps (the learner and exploring steps hold the rest).
    fn view(&self) -> SelectorView {
        self.wins.view(SCORE)
    }

    fn chosen(&self) -> Option<usize> {
        None
    }
}

/// Steps that followed each source and the learner, for the methods that combine.
#[derive(Debug)]
pub(super) struct FollowedCounts {
    sources: Vec<u64>,
    learner: u64,
}

impl FollowedCounts {
    pub fn new(n: usize) -> Self {
        Self {
            sources: vec![0; n],
            learner: 0,
        }
    }

    /// One step that followed `followed` (`None`: the learner).
    pub fn count(&mut self, followed: Option<usize>) {
        match followed {
            Some(i) => self.sources[i] += 1,
            None => self.learner += 1,
        }
    }

    /// The counts as the scores, their share of all steps as the probabilities.
    pub fn view(&self, score: ScoreColumn) -> SelectorView {
        let total = (self.sources.iter().sum::<u64>() + self.learner) as f64;
        let probabilities = self
            .sources
            .iter()
            .map(|&c| if total > 0.0 { c as f64 / total } else { 0.0 })
            .collect();
        let scores = self.sources.iter().map(|&c| c as f64).collect();
        SelectorView::unjudged(score, scores, probabilities)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acts_on_the_largest_q_value_of_any_network() {
        // Two actions, two sources. max over networks per action: a0 = max(1, 3, 2) = 3
        // (source 0), a1 = max(2, 0.5, 2.5) = 2.5 (source 1): a0 by source 0's value.
        let learner = [1.0, 2.0];
        let sources = vec![vec![3.0, 0.5], vec![2.0, 2.5]];
        assert_eq!(
            choose(&learner, &sources),
            Combined {
                action: 0,
                followed: Some(0)
            }
        );
        // The learner grows past them: its own greedy action, followed by nobody else.
        let learner = [1.0, 4.0];
        assert_eq!(
            choose(&learner, &sources),
            Combined {
                action: 1,
                followed: None
            }
        );
        // A tie goes to the learner, then to the lowest source.
        assert_eq!(choose(&[3.0, 0.0], &sources).followed, None);
        let sources = vec![vec![0.0, 5.0], vec![5.0, 0.0]];
        assert_eq!(
            choose(&[0.0, 0.0], &sources),
            Combined {
                action: 1,
                followed: Some(0)
            }
        );
    }

    #[test]
    fn explores_around_the_maximum_and_counts_whose_value_won() {
        let mut gpi = Gpi::new(2, Evaluation::Winner);
        let sources = vec![vec![3.0, 0.5], vec![2.0, 2.5]];
        let values = |explored| StateValues {
            learner: &[1.0, 2.0],
            sources: &sources,
            explored,
            attention: None,
        };
        assert_eq!(
            gpi.combine(&values(Some(1))),
            Combined {
                action: 1,
                followed: None
            }
        );
        for followed in [Some(0), Some(0), Some(1), None] {
            gpi.on_combined(
                &values(None),
                Combined {
                    action: 0,
                    followed,
                },
            );
        }
        let view = gpi.view();
        assert_eq!(view.scores, [2.0, 1.0]);
        assert_eq!(view.probabilities, [0.5, 0.25]);
        assert_eq!(gpi.chosen(), None);
    }

    #[test]
    fn the_label_names_a_learner_other_than_the_papers() {
        assert_eq!(GpiKnobs::default().label(), "gpi");
        let knobs = GpiKnobs {
            hidden: vec![64, 64],
            ..GpiKnobs::default()
        };
        assert_eq!(knobs.label(), "gpi[64,64]");
        let unevaluated = GpiKnobs {
            evaluate: Evaluation::Off,
            ..GpiKnobs::default()
        };
        assert_eq!(unevaluated.label(), "gpi-unevaluated");
        assert_eq!(unevaluated.source_evaluation(), None);
        assert_eq!(GpiKnobs::default().source_evaluation(), Some(100));
        let sfql = GpiKnobs {
            learner_bootstrap: LearnerBootstrap::Gpi,
            ..GpiKnobs::default()
        };
        assert_eq!(
            (sfql.label().as_str(), sfql.gpi_bootstrap()),
            ("gpi-sfql", true)
        );
        let err = GpiKnobs {
            hidden: vec![],
            ..GpiKnobs::default()
        }
        .validate("protocol.methods[3]")
        .unwrap_err();
        assert!(err.contains("protocol.methods[3].hidden"), "{err}");
    }
}
