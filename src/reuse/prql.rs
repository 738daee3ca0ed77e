//! PRQ-learning (Fernández & Veloso, "Probabilistic policy reuse in a reinforcement
//! learning agent", AAMAS 2006), on DQN.
//!
//! A new learner Π_Ω (a DQN of its own) learns from every step. Each episode one policy of
//! {Π_Ω, Π_1 … Π_n} is picked with `P(Π_j) = exp(τ·W_j) / Σ_p exp(τ·W_p)`:
//! - Π_Ω: the learner acts ε-greedily for the whole episode;
//! - a source Π_k: π-reuse, at every step its greedy action with probability ψ_h, else the
//!   learner's ε-greedy action, with `ψ_{h+1} = ψ_h·υ` (ψ_0 = ψ each episode).
//!
//! After the episode, `W_k ← (W_k·U_k + R)/(U_k + 1)`, `U_k ← U_k + 1`, where R is the
//! episode's discounted return scaled to [0, 1] by the task's range of discounted returns,
//! and `τ ← τ + Δτ`. The result of a run is the learner.
//!
//! The scaling is this project's: the paper's tasks pay 1 at the goal and nothing else, so
//! its W lie in [0, 1] and Δτ = 0.05 was chosen for that scale. On CartPole's raw
//! discounted returns (up to ≈ 99) the same Δτ made one source hold P > 0.99 within a few
//! episodes of every run; UCB1 scales its rewards the same way.

use rand::rngs::StdRng;
use rand::Rng;
use serde::{Deserialize, Serialize};

use super::definition::{check_label, MethodKind, ReuseMethod, Tested};
use super::{
    Actor, EpisodeEnd, Learning, Library, ReuseError, ScoreColumn, Selector, SelectorView,
};
use crate::ron_file::Got;
use crate::sapnet::SapNetParams;

/// PRQ-learning's parameters (`Prql(...)` in `protocol.methods`). Defaults: the paper's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PrqlKnobs {
    /// The learner's hidden layers.
    pub hidden: Vec<usize>,
    /// ψ: the probability of following the reused source at an episode's first step.
    pub psi: f64,
    /// υ in (0, 1]: ψ's decay per step.
    pub upsilon: f64,
    /// τ₀ ≥ 0: the initial inverse temperature of the choice among policies.
    pub tau0: f64,
    /// Δτ ≥ 0: τ's growth per episode.
    pub delta_tau: f64,
    /// The label of results; default: built from the knobs that differ from the paper's.
    pub label: Option<String>,
}

impl Default for PrqlKnobs {
    fn default() -> Self {
        Self {
            hidden: vec![100],
            psi: 1.0,
            upsilon: 0.95,
            tau0: 0.0,
            delta_tau: 0.05,
            label: None,
        }
    }
}

/// PRQ-learning in `protocol.methods`, in the palette's purple.
pub const KIND: MethodKind = MethodKind {
    family: "Prql",
    hue: 280,
    saturation: 50,
    reuses: true,
    tested: Tested::Learner,
    picks_by_probability: true,
    spreads: false,
};

impl ReuseMethod for PrqlKnobs {
    /// The given label, else `prql` with what differs from the paper's knobs:
    /// `prql[64,64]` for another learner, `-psi0.5`, `-upsilon0.9`, `-tau0.5`, `-dtau0.1`.
    fn label(&self) -> String {
        if let Some(label) = &self.label {
            return label.clone();
        }
        let paper = Self::default();
        let mut label = String::from("prql");
        if self.hidden != paper.hidden {
            let layers: Vec<String> = self.hidden.iter().map(ToString::to_string).collect();
            label.push_str(&format!("[{}]", layers.join(",")));
        }
        for (name, value, default) in [
            ("psi", self.psi, paper.psi),
            ("upsilon", self.upsilon, paper.upsilon),
            ("tau", self.tau0, paper.tau0),
            ("dtau", self.delta_tau, paper.delta_tau),
        ] {
            if value != default {
                label.push_str(&format!("-{name}{value}"));
            }
        }
        label
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn learner_hidden(&self) -> Option<&[usize]> {
        Some(&self.hidden)
    }

    /// The ranges serde cannot check; `field` is where the knobs sit in the config.
    fn validate(&self, field: &str) -> Result<(), String> {
        let fail = |name: &str, expected: &str, got: &dyn Got| {
            Err(format!(
                "field `{field}.{name}`: expected {expected}, got {}",
                got.got()
            ))
        };
        if self.hidden.is_empty() || self.hidden.contains(&0) {
            return fail(
                "hidden",
                "a non-empty list of layer sizes > 0",
                &format!("{:?}", self.hidden).as_str(),
            );
        }
        if !(0.0..=1.0).contains(&self.psi) {
            return fail("psi", "ψ in [0, 1]", &self.psi);
        }
        if !(self.upsilon > 0.0 && self.upsilon <= 1.0) {
            return fail("upsilon", "υ in (0, 1]", &self.upsilon);
        }
        if !(self.tau0 >= 0.0 && self.tau0.is_finite()) {
            return fail("tau0", "a finite τ₀ ≥ 0", &self.tau0);
        }
        if !(self.delta_tau >= 0.0 && self.delta_tau.is_finite()) {
            return fail("delta_tau", "a finite Δτ ≥ 0", &self.delta_tau);
        }
        if let Some(label) = &self.label {
            check_label(field, label)?;
        }
        Ok(())
    }

    fn selector(
        &self,
        library: Library<'_>,
        _sapnet: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(Prql::new(
            library.descriptions.len(),
            self,
            library.discounted_return_range,
        )))
    }
}

/// Which policy an episode follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pick {
    Learner,
    Source(usize),
}

#[derive(Debug)]
pub struct Prql {
    knobs: PrqlKnobs,
    /// W and U: index 0 the learner, k + 1 source k.
    w: Vec<f64>,
    u: Vec<u64>,
    tau: f64,
    /// The episode in progress: its policy and ψ_h.
    current: Option<Pick>,
    psi: f64,
    /// The largest `P(Π_k)` of a source, kept because W and τ change only between episodes
    /// while the run asks for it at every step.
    top_source: f64,
    /// The task's (lowest, highest) discounted return, which W's returns are scaled by.
    range: (f64, f64),
}

impl Prql {
    /// PRQ-learning over `n` sources, on a task whose discounted returns lie in `range`.
    pub fn new(n: usize, knobs: &PrqlKnobs, range: (f64, f64)) -> Self {
        let mut prql = Self {
            knobs: knobs.clone(),
            w: vec![0.0; n + 1],
            u: vec![0; n + 1],
            tau: knobs.tau0,
            current: None,
            psi: knobs.psi,
            top_source: 0.0,
            range,
        };
        prql.top_source = prql.top_source_probability();
        prql
    }

    fn top_source_probability(&self) -> f64 {
        self.probabilities()[1..]
            .iter()
            .copied()
            .fold(0.0, f64::max)
    }

    /// `P(Π_j)` over the learner (index 0) and the sources.
    fn probabilities(&self) -> Vec<f64> {
        let max = self.w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let terms: Vec<f64> = self
            .w
            .iter()
            .map(|&w| (self.tau * (w - max)).exp())
            .collect();
        let total: f64 = terms.iter().sum();
        terms.iter().map(|t| t / total).collect()
    }

    fn pick(&self, rng: &mut StdRng) -> Pick {
        let probabilities = self.probabilities();
        let target = rng.random::<f64>();
        let mut running = 0.0;
        for (j, p) in probabilities.iter().enumerate() {
            running += p;
            if target < running {
                return if j == 0 {
                    Pick::Learner
                } else {
                    Pick::Source(j - 1)
                };
            }
        }
        Pick::Source(probabilities.len() - 2)
    }
}

/// PRQ-learning's score: each source's mean scaled discounted return.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "W",
    meaning: "W: mean scaled discounted return; P: softmax(τ·W)",
    counted: false,
};

impl Selector for Prql {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    fn act(&mut self, rng: &mut StdRng) -> Actor {
        let pick = match self.current {
            Some(pick) => pick,
            None => {
                let pick = self.pick(rng);
                self.current = Some(pick);
                self.psi = self.knobs.psi;
                pick
            }
        };
        match pick {
            Pick::Learner => Actor::Learner,
            Pick::Source(k) => {
                let follow = rng.random::<f64>() < self.psi;
                self.psi *= self.knobs.upsilon;
                if follow {
                    Actor::SourceGreedy(k)
                } else {
                    Actor::Learner
                }
            }
        }
    }

    fn on_episode_end(&mut self, end: &EpisodeEnd) {
        let Some(pick) = self.current.take() else {
            return;
        };
        let j = match pick {
            Pick::Learner => 0,
            Pick::Source(k) => k + 1,
        };
        let (low, high) = self.range;
        let reward = ((end.discounted_return - low) / (high - low)).clamp(0.0, 1.0);
        self.w[j] = (self.w[j] * self.u[j] as f64 + reward) / (self.u[j] + 1) as f64;
        self.u[j] += 1;
        self.tau += self.knobs.delta_tau;
        self.top_source = self.top_source_probability();
    }

    /// Scores: W of each source, in [0, 1] (the learner's is not a source's).
    fn view(&self) -> SelectorView {
        SelectorView::unjudged(
            SCORE,
            self.w[1..].to_vec(),
            self.probabilities()[1..].to_vec(),
        )
    }

    fn top_probability(&self) -> Option<f64> {
        Some(self.top_source)
    }

    /// The learner is the result.
    fn chosen(&self) -> Option<usize> {
        None
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    const UNIT: (f64, f64) = (0.0, 1.0);

    fn end(discounted_return: f64) -> EpisodeEnd {
        EpisodeEnd {
            episode_return: 0.0,
            discounted_return,
        }
    }

    #[test]
    fn psi_decays_by_upsilon_each_step_and_restarts_each_episode() {
        let knobs = PrqlKnobs {
            psi: 0.8,
            upsilon: 0.5,
            ..PrqlKnobs::default()
        };
        let mut prql = Prql::new(2, &knobs, UNIT);
        let mut rng = StdRng::seed_from_u64(1);
        prql.current = Some(Pick::Source(1));
        prql.psi = 0.8;
        for expected in [0.4, 0.2, 0.1] {
            prql.act(&mut rng);
            assert_eq!(prql.psi, expected);
        }
        prql.on_episode_end(&end(1.0));
        // The next episode starts again from ψ.
        prql.act(&mut rng);
        assert!(prql.psi == 0.8 || prql.psi == 0.4, "{}", prql.psi);
    }

    #[test]
    fn w_is_the_running_mean_of_discounted_returns_and_tau_grows() {
        let mut prql = Prql::new(2, &PrqlKnobs::default(), (-8.0, 8.0));
        // Discounted returns in [−8, 8]: 3 and 6 scale to 11/16 and 14/16, −1 to 7/16, and
        // 30 (beyond the range) to 1.
        for r in [3.0, 6.0] {
            prql.current = Some(Pick::Source(0));
            prql.on_episode_end(&end(r));
        }
        prql.current = Some(Pick::Learner);
        prql.on_episode_end(&end(-1.0));
        assert_eq!(prql.w, [7.0 / 16.0, 12.5 / 16.0, 0.0]);
        prql.current = Some(Pick::Source(1));
        prql.on_episode_end(&end(30.0));
        assert_eq!(prql.w[2], 1.0);
        assert_eq!(prql.u, [1, 2, 1]);
        assert!((prql.tau - 0.2).abs() < 1e-15);
        // τ₀ = 0: the first choice is uniform over the learner and the sources.
        assert_eq!(
            Prql::new(3, &PrqlKnobs::default(), UNIT).probabilities(),
            [0.25; 4]
        );
    }

    #[test]
    fn follows_the_source_with_probability_psi() {
        let knobs = PrqlKnobs {
            psi: 1.0,
            upsilon: 1.0,
            ..PrqlKnobs::default()
        };
        let mut prql = Prql::new(1, &knobs, UNIT);
        let mut rng = StdRng::seed_from_u64(3);
        prql.current = Some(Pick::Source(0));
        assert!((0..100).all(|_| prql.act(&mut rng) == Actor::SourceGreedy(0)));
        prql.psi = 0.0;
        prql.knobs.psi = 0.0;
        assert!((0..100).all(|_| prql.act(&mut rng) == Actor::Learner));
    }

    #[test]
    fn labels_name_what_differs_from_the_paper_or_are_given() {
        assert_eq!(PrqlKnobs::default().label(), "prql");
        let knobs = PrqlKnobs {
            hidden: vec![64, 64],
            psi: 0.5,
            ..PrqlKnobs::default()
        };
        assert_eq!(knobs.label(), "prql[64,64]-psi0.5");
        let named = PrqlKnobs {
            label: Some("prql-mine".into()),
            ..knobs
        };
        assert_eq!(named.label(), "prql-mine");
        let slash = PrqlKnobs {
            label: Some("a/b".into()),
            ..PrqlKnobs::default()
        };
        assert!(slash
            .validate("protocol.methods[4]")
            .unwrap_err()
            .starts_with("field `protocol.methods[4].label`: expected a name of letters, digits"));
    }

    #[test]
    fn bad_knobs_are_located() {
        let bad = |knobs: PrqlKnobs| knobs.validate("protocol.methods[4]").unwrap_err();
        assert_eq!(
            bad(PrqlKnobs {
                psi: 1.5,
                ..PrqlKnobs::default()
            }),
            "field `protocol.methods[4].psi`: expected ψ in [0, 1], got 1.5"
        );
        assert!(bad(PrqlKnobs {
            upsilon: 0.0,
            ..PrqlKnobs::default()
        })
        .contains("upsilon"));
        assert!(bad(PrqlKnobs {
            hidden: vec![],
            ..PrqlKnobs::default()
        })
        .contains("hidden"));
    }
}
