//! The Q-switch of CUP (Zhang, Li & Zhang, "CUP: Critic-Guided Policy Reuse", NeurIPS 2022)
//! and QMP (Zhang et al., "Efficient Multi-Task Reinforcement Learning via Selective
//! Behavior Sharing", ICLR 2025), on a library of DQN policies.
//!
//! The sources stay frozen; a learner of the method's own, a fresh DQN, learns from every
//! step. Each policy proposes an action and the learner's critic picks one:
//!
//! ```text
//! j* = argmax_{j ∈ {learner, 1..N}} Q_L(s, a_j)         a_i = argmax_a Q_i(s, a) (sources)
//! ```
//!
//! and the run hands over the learner.
//!
//! The learner's proposal is where a DQN forces a choice. QMP's policies are stochastic
//! (SAC): each proposes a *sample*, and the learner's own sample is often not the best
//! action of its critic, so another policy's action can win. A DQN's greedy action is
//! `argmax_a Q_L(s, a)` itself, and `Q_L(s, argmax_a Q_L(s, a)) ≥ Q_L(s, a_i)` for every
//! source: with the greedy action as its proposal the learner always wins and the switch is
//! DQN from scratch (a test below shows it). So by default ([`Proposal::Behaviour`]) the
//! learner proposes what its behaviour policy samples, its ε-greedy action: on a greedy
//! step it wins, on an exploring step its random action competes with the sources'
//! actions under its critic — the library steers exploration. [`Proposal::Greedy`] is the
//! switch read literally (greedy proposals, ε-greedy on top), kept to show the reduction.
//!
//! CUP also regularises its actor towards the source action the critic prefers; a DQN has
//! no actor, so that half has no counterpart here. Ties between proposals go to the
//! learner, then to the lowest source index.

use rand::rngs::StdRng;
use serde::{Deserialize, Serialize};

use super::definition::{MethodKind, ReuseMethod, Tested};
use super::gpi::{check_learner, learner_label, FollowedCounts};
use super::{
    argmax_f32, Actor, Combined, Learning, Library, ReuseError, Selector, SelectorView, StateValues,
};
use crate::sapnet::SapNetParams;

/// What the learner proposes to the switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Proposal {
    /// Its ε-greedy action, as QMP's policies propose samples of their behaviour.
    Behaviour,
    /// Its greedy action, ε-greedy exploration applied to the switch's pick: the formula
    /// read literally, which always picks the learner's action.
    Greedy,
}

/// The Q-switch's knobs (`QSwitch()` in `protocol.methods`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QSwitchKnobs {
    /// The learner's hidden layers: the paper's DQN baseline's by default.
    pub hidden: Vec<usize>,
    /// What the learner proposes: `Behaviour` (default) or `Greedy`.
    pub proposal: Proposal,
    /// The label of results; default `qswitch` (`qswitch-greedy` for greedy proposals,
    /// `qswitch[64,64]` for another learner).
    pub label: Option<String>,
}

impl Default for QSwitchKnobs {
    fn default() -> Self {
        Self {
            hidden: vec![100],
            proposal: Proposal::Behaviour,
            label: None,
        }
    }
}

/// The Q-switch in `protocol.methods`, in gold.
pub const KIND: MethodKind = MethodKind {
    family: "QSwitch",
    hue: 50,
    saturation: 70,
    reuses: true,
    tested: Tested::Learner,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for QSwitchKnobs {
    fn label(&self) -> String {
        let label = learner_label("qswitch", &self.hidden, self.label.as_deref());
        match (self.proposal, &self.label) {
            (Proposal::Greedy, None) => format!("{label}-greedy"),
            _ => label,
        }
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn learner_hidden(&self) -> Option<&[usize]> {
        Some(&self.hidden)
    }

    fn validate(&self, field: &str) -> Result<(), String> {
        check_learner(field, &self.hidden, self.label.as_deref())
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(QSwitch::new(
            library.descriptions.len(),
            self.proposal,
        )))
    }
}

/// The switch and its counts of whose action was followed.
#[derive(Debug)]
pub struct QSwitch {
    proposal: Proposal,
    followed: FollowedCounts,
}

impl QSwitch {
    pub fn new(n: usize, proposal: Proposal) -> Self {
        Self {
            proposal,
            followed: FollowedCounts::new(n),
        }
    }
}

/// `argmax_{j ∈ {learner, 1..N}} Q_L(s, a_j)` for the learner's proposal `own` and each
/// source's greedy action: the learner on a tie, then the lowest source.
pub fn choose(learner: &[f32], own: usize, sources: &[Vec<f32>]) -> Combined {
    let mut best = Combined {
        action: own,
        followed: None,
    };
    for (i, values) in sources.iter().enumerate() {
        let proposed = argmax_f32(values);
        if learner[proposed] > learner[best.action] {
            best = Combined {
                action: proposed,
                followed: Some(i),
            };
        }
    }
    best
}

impl Selector for QSwitch {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    fn act(&mut self, _rng: &mut StdRng) -> Actor {
        Actor::Combined
    }

    fn combine(&self, values: &StateValues<'_>) -> Combined {
        let greedy = argmax_f32(values.learner);
        match (self.proposal, values.explored) {
            (Proposal::Behaviour, explored) => {
                choose(values.learner, explored.unwrap_or(greedy), values.sources)
            }
            (Proposal::Greedy, Some(action)) => Combined {
                action,
                followed: None,
            },
            (Proposal::Greedy, None) => choose(values.learner, greedy, values.sources),
        }
    }

    fn on_combined(&mut self, _: &StateValues<'_>, choice: Combined) {
        self.followed.count(choice.followed);
    }

    /// Scores: the steps each source's action was followed; probabilities: their share of
    /// all steps (the learner's own actions hold the rest).
    fn view(&self) -> SelectorView {
        self.followed.view("followed")
    }

    fn chosen(&self) -> Option<usize> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Q_L over three actions; source 0 proposes a0, source 1 proposes a2.
    fn sources() -> Vec<Vec<f32>> {
        vec![vec![9.0, 1.0, 0.0], vec![0.0, 1.0, 7.0]]
    }

    #[test]
    fn the_critic_picks_the_proposal_it_values_most() {
        let learner = [0.5, 2.0, 1.0];
        // The learner proposes a0 (Q_L 0.5); source 1's a2 (Q_L 1.0) beats source 0's a0
        // (0.5, a tie with the learner's own, which keeps it).
        assert_eq!(
            choose(&learner, 0, &sources()),
            Combined {
                action: 2,
                followed: Some(1)
            }
        );
        // Proposing its greedy a1 (Q_L 2.0), the learner beats every source.
        assert_eq!(
            choose(&learner, 1, &sources()),
            Combined {
                action: 1,
                followed: None
            }
        );
    }

    #[test]
    fn greedy_proposals_reduce_the_switch_to_the_learners_greedy_action() {
        // Whatever the sources propose, Q_L(s, argmax Q_L) is the largest of Q_L's values.
        let switch = QSwitch::new(2, Proposal::Greedy);
        for learner in [[0.5, 2.0, 1.0], [3.0, -1.0, 2.9], [0.0, 0.0, 4.0]] {
            let chosen = switch.combine(&StateValues {
                learner: &learner,
                sources: &sources(),
                explored: None,
                attention: None,
            });
            assert_eq!(chosen.action, argmax_f32(&learner));
            assert_eq!(chosen.followed, None);
        }
    }

    #[test]
    fn an_exploring_step_lets_the_sources_compete_with_the_random_action() {
        let learner = [0.5, 2.0, 1.0];
        let values = StateValues {
            learner: &learner,
            sources: &sources(),
            explored: Some(0),
            attention: None,
        };
        // Behaviour proposals: the random a0 loses to source 1's a2 under Q_L.
        let behaviour = QSwitch::new(2, Proposal::Behaviour);
        assert_eq!(behaviour.combine(&values).followed, Some(1));
        // Greedy proposals explore around the switch: the random action is taken.
        let greedy = QSwitch::new(2, Proposal::Greedy);
        assert_eq!(
            greedy.combine(&values),
            Combined {
                action: 0,
                followed: None
            }
        );
    }

    #[test]
    fn labels_say_the_proposal_and_the_learner() {
        assert_eq!(QSwitchKnobs::default().label(), "qswitch");
        let greedy = QSwitchKnobs {
            proposal: Proposal::Greedy,
            ..QSwitchKnobs::default()
        };
        assert_eq!(greedy.label(), "qswitch-greedy");
    }
}
