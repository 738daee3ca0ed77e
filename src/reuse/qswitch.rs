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
//! The proposals are where a DQN forces a choice. QMP's policies are stochastic (SAC): each
//! proposes a *sample*, and the learner's own sample is often not the best action of its
//! critic, so another policy's action can win. A DQN's greedy action is `argmax_a Q_L(s, a)`
//! itself, and `Q_L(s, argmax_a Q_L(s, a)) ≥ Q_L(s, a_i)` for every source: with the greedy
//! action as its proposal the learner always wins and the switch is DQN from scratch (a
//! test below shows it). So by default ([`Proposal::Sampled`]) every policy proposes a
//! sample of a stochastic policy made of its Q-values, as QMP's do: the learner a Boltzmann
//! sample of its own Q at `temperature`, each source a sample of the softmax of its Q; the
//! critic picks among them, and the learner's ε-greedy exploration is applied to the
//! switched action, so that it explores exactly as DQN does. [`Proposal::Greedy`] is the
//! switch read literally (greedy proposals, ε-greedy on top), kept to show the reduction;
//! [`Proposal::Behaviour`] (the learner proposes its ε-greedy action) was this project's
//! reading before: a source proposing the learner's greedy action overrules every
//! exploring step, so the learner hardly explores (0.04% of CartPole's steps against
//! DQN's 1.5%); kept to reproduce the episode-budget study.
//!
//! CUP also regularises its actor towards the source action the critic prefers; a DQN has
//! no actor, so that half has no counterpart here. Ties between proposals go to the
//! learner, then to the lowest source index.

use rand::rngs::StdRng;
use rand::Rng;
use serde::{Deserialize, Serialize};

use super::definition::{MethodKind, ReuseMethod, Tested};
use super::gpi::{check_learner, learner_label, FollowedCounts};
use super::{
    argmax_f32, Actor, Combined, Learning, Library, ReuseError, ScoreColumn, Selector,
    SelectorView, StateValues,
};
use crate::sapnet::SapNetParams;

/// What the policies propose to the switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Proposal {
    /// Samples of stochastic policies, QMP's: the learner's a Boltzmann sample of its Q,
    /// each source's a sample of the softmax of its Q; exploration after the switch.
    Sampled,
    /// The learner's ε-greedy action against the sources' greedy ones: cancels the
    /// learner's exploration (the reading of the episode-budget study).
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
    /// What the policies propose: `Sampled` (default), `Greedy` or `Behaviour`.
    pub proposal: Proposal,
    /// τ of the proposals' softmaxes under `Sampled`.
    pub temperature: f64,
    /// The label of results; default `qswitch` (`qswitch-greedy` for greedy proposals,
    /// `qswitch[64,64]` for another learner).
    pub label: Option<String>,
}

impl Default for QSwitchKnobs {
    fn default() -> Self {
        Self {
            hidden: vec![100],
            proposal: Proposal::Sampled,
            temperature: 1.0,
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
            (Proposal::Behaviour, None) => format!("{label}-behaviour"),
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
        if !(self.temperature > 0.0 && self.temperature.is_finite()) {
            return Err(format!(
                "field `{field}.temperature`: expected a finite τ > 0, got {}",
                crate::ron_file::Got::got(&self.temperature)
            ));
        }
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
            self.temperature,
        )))
    }
}

/// The switch and its counts of whose action was followed.
#[derive(Debug)]
pub struct QSwitch {
    proposal: Proposal,
    temperature: f64,
    followed: FollowedCounts,
    /// This step's uniform draws for the sampled proposals, the learner's first (made in
    /// `act` from the selector's stream, read in `combine`).
    draws: Vec<f64>,
}

impl QSwitch {
    pub fn new(n: usize, proposal: Proposal, temperature: f64) -> Self {
        Self {
            proposal,
            temperature,
            followed: FollowedCounts::new(n),
            draws: vec![0.0; n + 1],
        }
    }
}

/// The action a draw `u` of [0, 1) picks from `softmax(q / τ)` (inverse transform, in
/// f64, stable: the largest value subtracted first).
pub fn sample_softmax(q: &[f32], temperature: f64, u: f64) -> usize {
    let top = q.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let weights: Vec<f64> = q
        .iter()
        .map(|&v| ((f64::from(v) - f64::from(top)) / temperature).exp())
        .collect();
    let mut left = u * weights.iter().sum::<f64>();
    for (a, w) in weights.iter().enumerate() {
        if left < *w {
            return a;
        }
        left -= w;
    }
    q.len() - 1
}

/// QMP's switch over sampled proposals: each policy's sample (the learner's first), then
/// the one the learner's critic values most (the learner on a tie, then the lowest source).
fn switch_sampled(values: &StateValues<'_>, temperature: f64, draws: &[f64]) -> Combined {
    let own = sample_softmax(values.learner, temperature, draws[0]);
    let mut best = Combined {
        action: own,
        followed: None,
    };
    for (i, q) in values.sources.iter().enumerate() {
        let proposed = sample_softmax(q, temperature, draws[i + 1]);
        if values.learner[proposed] > values.learner[best.action] {
            best = Combined {
                action: proposed,
                followed: Some(i),
            };
        }
    }
    best
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

/// The Q-switch's score: the steps that took each source's proposal.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "followed",
    meaning: "followed: steps that took its action; P: their share",
    counted: true,
};

impl Selector for QSwitch {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    fn act(&mut self, rng: &mut StdRng) -> Actor {
        if self.proposal == Proposal::Sampled {
            self.draws.iter_mut().for_each(|u| *u = rng.random::<f64>());
        }
        Actor::Combined
    }

    fn combine(&self, values: &StateValues<'_>) -> Combined {
        let greedy = argmax_f32(values.learner);
        match (self.proposal, values.explored) {
            (Proposal::Behaviour, explored) => {
                choose(values.learner, explored.unwrap_or(greedy), values.sources)
            }
            // Exploration outside the switch: DQN's, on the switched action.
            (Proposal::Greedy | Proposal::Sampled, Some(action)) => Combined {
                action,
                followed: None,
            },
            (Proposal::Greedy, None) => choose(values.learner, greedy, values.sources),
            (Proposal::Sampled, None) => switch_sampled(values, self.temperature, &self.draws),
        }
    }

    fn on_combined(&mut self, _: &StateValues<'_>, choice: Combined) {
        self.followed.count(choice.followed);
    }

    /// Scores: the steps each source's action was followed; probabilities: their share of
    /// all steps (the learner's own actions hold the rest).
    fn view(&self) -> SelectorView {
        self.followed.view(SCORE)
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
        let switch = QSwitch::new(2, Proposal::Greedy, 1.0);
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
        let behaviour = QSwitch::new(2, Proposal::Behaviour, 1.0);
        assert_eq!(behaviour.combine(&values).followed, Some(1));
        // Greedy proposals explore around the switch: the random action is taken.
        let greedy = QSwitch::new(2, Proposal::Greedy, 1.0);
        assert_eq!(
            greedy.combine(&values),
            Combined {
                action: 0,
                followed: None
            }
        );
        // Sampled proposals too: the learner explores as DQN does.
        let sampled = QSwitch::new(2, Proposal::Sampled, 1.0);
        assert_eq!(sampled.combine(&values).action, 0);
    }

    /// softmax([0, ln 3]) = (¼, ¾): draws below ¼ pick a0, the others a1.
    #[test]
    fn a_proposal_samples_the_softmax_of_its_q_values() {
        let q = [0.0, 3f32.ln()];
        assert_eq!(sample_softmax(&q, 1.0, 0.2), 0);
        assert_eq!(sample_softmax(&q, 1.0, 0.26), 1);
        assert_eq!(sample_softmax(&q, 1.0, 0.999), 1);
        // A temperature flattens it: τ = ∞ would be uniform; τ = ln 3 / ln 1.0001 ≈ ½-½.
        let flat = f64::from(3f32.ln()) / 1e-4f64.ln_1p();
        assert_eq!(sample_softmax(&q, flat, 0.49), 0);
        assert_eq!(sample_softmax(&q, flat, 0.51), 1);
    }

    /// With sampled proposals another policy's action wins where the learner's own sample
    /// is not its critic's best: here the learner samples a0 (draw 0.1 of softmax
    /// [0.5, 2, 1] puts ≈ 14% on a0), source 1 samples a2 (its softmax is almost all a2),
    /// and Q_L(a2) = 1 > Q_L(a0) = 0.5.
    #[test]
    fn sampled_proposals_let_a_source_win_where_the_learners_sample_is_poor() {
        let mut switch = QSwitch::new(2, Proposal::Sampled, 1.0);
        switch.draws = vec![0.1, 0.99, 0.5];
        let learner = [0.5, 2.0, 1.0];
        let values = StateValues {
            learner: &learner,
            sources: &sources(),
            explored: None,
            attention: None,
        };
        // Source 0's softmax of [9, 1, 0] at 0.99: a0 (≈ 99.95%).
        assert_eq!(
            switch.combine(&values),
            Combined {
                action: 2,
                followed: Some(1)
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
        let behaviour = QSwitchKnobs {
            proposal: Proposal::Behaviour,
            ..QSwitchKnobs::default()
        };
        assert_eq!(behaviour.label(), "qswitch-behaviour");
    }
}
