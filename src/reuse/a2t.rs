//! A2T (Rajendran et al., "Attend, Adapt and Transfer: Attentive Deep Architecture for
//! Adaptive Transfer from multiple sources in the same domain", ICLR 2017), value transfer
//! on a library of DQN policies.
//!
//! The sources stay frozen. A base network (the method's own learner, a fresh DQN) and an
//! attention network learn; each step acts ε-greedily (the base's exploration) on
//!
//! ```text
//! Q_T(s, a) = Σ_i w_i(s)·Q_i(s, a) + w_B(s)·Q_B(s, a),      w(s) = softmax(f(s))
//! ```
//!
//! The attention learns by `Q_T`'s TD error, the base by its own, as a DQN
//! ([`crate::dqn::AttentionLearner`]); the run hands over `Q_T` (the base with the library and
//! the attention) for its greedy tests. Its weights are shown where SAP-Net's probabilities
//! are: `P_<source>` in `activations.csv` and the dashboard is `w_i(s)` of the latest step,
//! `A_<source>` the mean of `w_i` over the run's steps; a step "follows" the source of the
//! largest weight, when a source's weight is larger than the base's.
//!
//! Choices a DQN library forced (docs/BASELINES.md): the attention's TD target uses its own
//! target copy and the base's target network, copied every `target_update_interval` steps as
//! every learner here; the loss is the config's Huber loss; the base does not learn through
//! the mixture.

use rand::rngs::StdRng;
use serde::{Deserialize, Serialize};

use super::definition::{MethodKind, ReuseMethod, Tested};
use super::gpi::{check_learner, learner_label};
use super::{
    Actor, Combined, Learning, Library, ReuseError, ScoreColumn, Selector, SelectorView,
    StateValues,
};
use crate::sapnet::SapNetParams;

/// Where A2T's weights over the sources and the base come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Attention {
    /// A network of the state, learned by the mixture's TD error (the paper's).
    Learned,
    /// Fixed and equal, `1/(N + 1)` each, never learned: the control that shows what the
    /// learned attention adds.
    Uniform,
}

/// A2T's knobs (`A2t()` in `protocol.methods`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct A2tKnobs {
    /// The base network's hidden layers.
    pub hidden: Vec<usize>,
    /// The attention network's hidden layers.
    pub attention_hidden: Vec<usize>,
    /// `Learned` (default) or `Uniform`.
    pub attention: Attention,
    /// The label of results; default `a2t` (`a2t-uniform` for uniform attention,
    /// `a2t[64,64]` for another base).
    pub label: Option<String>,
}

impl Default for A2tKnobs {
    fn default() -> Self {
        Self {
            hidden: vec![100],
            attention_hidden: vec![100],
            attention: Attention::Learned,
            label: None,
        }
    }
}

/// A2T in `protocol.methods`, in brown.
pub const KIND: MethodKind = MethodKind {
    family: "A2t",
    hue: 25,
    saturation: 35,
    reuses: true,
    tested: Tested::Combined,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for A2tKnobs {
    fn label(&self) -> String {
        let label = learner_label("a2t", &self.hidden, self.label.as_deref());
        match (self.attention, &self.label) {
            (Attention::Uniform, None) => format!("{label}-uniform"),
            _ => label,
        }
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn learner_hidden(&self) -> Option<&[usize]> {
        Some(&self.hidden)
    }

    fn attention_hidden(&self) -> Option<&[usize]> {
        (self.attention == Attention::Learned).then_some(self.attention_hidden.as_slice())
    }

    fn validate(&self, field: &str) -> Result<(), String> {
        check_learner(field, &self.hidden, self.label.as_deref())?;
        crate::ron_file::check(
            !self.attention_hidden.is_empty() && self.attention_hidden.iter().all(|&u| u > 0),
            &format!("{field}.attention_hidden"),
            "a non-empty list of layer sizes > 0",
            format!("{:?}", self.attention_hidden),
        )
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        let n = library.descriptions.len();
        Ok(Box::new(match self.attention {
            Attention::Learned => A2t::new(n),
            Attention::Uniform => A2t::uniform(n),
        }))
    }
}

/// The mixture's choice, and the weights shown.
#[derive(Debug)]
pub struct A2t {
    /// The sources' weights at the latest step, and their sums over the run's steps.
    latest: Vec<f64>,
    sums: Vec<f64>,
    steps: u64,
    /// The fixed weights of uniform attention (N + 1 of `1/(N + 1)`); empty when learned.
    uniform: Vec<f32>,
}

impl A2t {
    pub fn new(n: usize) -> Self {
        Self {
            latest: vec![0.0; n],
            sums: vec![0.0; n],
            steps: 0,
            uniform: Vec::new(),
        }
    }

    /// With fixed and equal weights over the `n` sources and the base.
    pub fn uniform(n: usize) -> Self {
        Self {
            uniform: vec![1.0 / (n + 1) as f32; n + 1],
            ..Self::new(n)
        }
    }

    /// The weights of the state: the attention's, or the uniform ones.
    fn weights<'v>(&'v self, values: &StateValues<'v>) -> &'v [f32] {
        match values.attention {
            Some(weights) => weights,
            None if !self.uniform.is_empty() => &self.uniform,
            None => panic!("A2T's runs have an attention network or uniform weights"),
        }
    }
}

/// `argmax_a Σ_i w_i·Q_i(s, a) + w_B·Q_B(s, a)` (the lowest action on a tie), with
/// `weights` the sources' then the base's, and the source of the largest weight if a
/// source outweighs the base.
pub fn choose(weights: &[f32], base: &[f32], sources: &[Vec<f32>]) -> Combined {
    let base_weight = weights[sources.len()];
    let mixed = |a: usize| {
        let from_sources: f32 = sources.iter().zip(weights).map(|(q, w)| w * q[a]).sum();
        from_sources + base_weight * base[a]
    };
    let mut action = 0;
    for a in 1..base.len() {
        if mixed(a) > mixed(action) {
            action = a;
        }
    }
    let heaviest = super::argmax_f32(&weights[..sources.len()]);
    let followed = (!sources.is_empty() && weights[heaviest] > base_weight).then_some(heaviest);
    Combined { action, followed }
}

/// A2T's score: each source's mean attention weight.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "w̄",
    meaning: "w̄: mean attention weight; P: its weight now",
    counted: false,
};

impl Selector for A2t {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    fn act(&mut self, _rng: &mut StdRng) -> Actor {
        Actor::Combined
    }

    fn combine(&self, values: &StateValues<'_>) -> Combined {
        let greedy = choose(self.weights(values), values.learner, values.sources);
        match values.explored {
            Some(action) => Combined { action, ..greedy },
            None => greedy,
        }
    }

    fn on_combined(&mut self, values: &StateValues<'_>, _: Combined) {
        let n = self.latest.len();
        let weights: Vec<f64> = self.weights(values)[..n]
            .iter()
            .map(|&w| f64::from(w))
            .collect();
        for (i, w) in weights.into_iter().enumerate() {
            self.latest[i] = w;
            self.sums[i] += w;
        }
        self.steps += 1;
    }

    /// Scores: each source's mean weight over the run; probabilities: its weight at the
    /// latest step (the base holds the rest).
    fn view(&self) -> SelectorView {
        let steps = self.steps.max(1) as f64;
        SelectorView::unjudged(
            SCORE,
            self.sums.iter().map(|s| s / steps).collect(),
            self.latest.clone(),
        )
    }

    fn chosen(&self) -> Option<usize> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acts_on_the_attention_weighted_mixture() {
        // Two sources and the base over two actions; weights (½, ¼, ¼):
        // Q_T(a0) = ½·4 + ¼·0 + ¼·2 = 2.5, Q_T(a1) = ½·1 + ¼·8 + ¼·0 = 2.5:
        // a tie, the lowest action; source 0 outweighs the base.
        let sources = vec![vec![4.0, 1.0], vec![0.0, 8.0]];
        let base = [2.0, 0.0];
        assert_eq!(
            choose(&[0.5, 0.25, 0.25], &base, &sources),
            Combined {
                action: 0,
                followed: Some(0)
            }
        );
        // Weights (0.1, 0.6, 0.3): a0 = 0.4 + 0 + 0.6 = 1.0, a1 = 0.1 + 4.8 + 0 = 4.9.
        let chosen = choose(&[0.1, 0.6, 0.3], &base, &sources);
        assert_eq!((chosen.action, chosen.followed), (1, Some(1)));
        // The base's weight above every source's: nobody is followed.
        let chosen = choose(&[0.2, 0.2, 0.6], &base, &sources);
        assert_eq!((chosen.action, chosen.followed), (0, None));
    }

    #[test]
    fn shows_the_latest_weights_and_their_mean() {
        let mut a2t = A2t::new(2);
        let sources = vec![vec![0.0], vec![0.0]];
        for weights in [[0.5f32, 0.25, 0.25], [0.25, 0.25, 0.5]] {
            let values = StateValues {
                learner: &[0.0],
                sources: &sources,
                explored: None,
                attention: Some(&weights),
            };
            let choice = a2t.combine(&values);
            a2t.on_combined(&values, choice);
        }
        let view = a2t.view();
        assert_eq!(view.probabilities, [0.25, 0.25]);
        assert_eq!(view.scores, [0.375, 0.25]);
    }
}
