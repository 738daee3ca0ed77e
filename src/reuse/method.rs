//! The methods a protocol compares (`protocol.methods`). Each is defined by its own file of
//! `reuse/`, through [`ReuseMethod`]: its label, what it is ([`MethodKind`]), its learner,
//! its knobs' checks and its selector. So adding a method is its file, a variant of
//! [`Method`] and its arm in [`Method::definition`], and nothing outside `reuse/` branches
//! on which method a run is: front ends, results and plots ask its [`MethodKind`].

use serde::{Deserialize, Serialize};

use super::a2t::A2tKnobs;
use super::best_source::Oracle;
use super::definition::{MethodKind, ReuseMethod};
use super::from_scratch::FromScratch;
use super::frozen_oracle::FrozenOracle;
use super::gpi::GpiKnobs;
use super::prql::PrqlKnobs;
use super::qdagger::QDaggerKnobs;
use super::qswitch::QSwitchKnobs;
use super::random::{PerEpisode, PerStep};
use super::sapnet::SapNetKnobs;
use super::ucb1::Bandit;

/// A learner an experiment compares, as a config lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Method {
    /// Transfer learning with SAP-Net over the source library (Algorithm 3), as the paper
    /// specifies it.
    SapNet,
    /// SAP-Net with knobs beyond the paper: a temperature schedule, another judgment
    /// (`Episode`, `KSteps(k)`, `TdChange`, `Advantage`, `EpisodeAndLoss`: docs/REUSE.md,
    /// docs/FUTURE_WORK.md), activation decay (`SapNetWith(judgment: Episode)`; every knob
    /// left out is the paper's).
    SapNetWith(SapNetKnobs),
    /// A uniformly random source acts (and fine-tunes) at every step.
    Random,
    /// A uniformly random source acts (and fine-tunes) for a whole episode.
    RandomPerEpisode,
    /// UCB1 over the sources, one pull per episode, on the return scaled to [0, 1].
    Ucb1,
    /// PRQ-learning: a new learner, guided by sources through π-reuse
    /// (`Prql()` for the paper's defaults).
    Prql(PrqlKnobs),
    /// Generalized policy improvement (Barreto et al., 2017): a new learner joins the frozen
    /// sources, acting ε-greedily on the largest Q-value of any of them (`Gpi()`).
    Gpi(GpiKnobs),
    /// The Q-switch of CUP and QMP: a new learner's critic picks, each step, whose proposed
    /// action is followed (`QSwitch()`; `QSwitch(proposal: Greedy)` the literal reading).
    QSwitch(QSwitchKnobs),
    /// QDagger (Agarwal et al., 2022): a student distils the library's best source while it
    /// learns, after an offline phase on that teacher's data (`QDagger()`).
    QDagger(QDaggerKnobs),
    /// A2T (Rajendran et al., 2017): a base network and a state-dependent softmax attention
    /// over the sources and the base, acting on their mixture of Q-values (`A2t()`).
    A2t(A2tKnobs),
    /// Fine-tune the library's best source by its recorded score: the selection oracle.
    BestSource,
    /// The control beside it: that source acting greedily as recorded, never learning.
    FrozenOracle,
    /// DQN from scratch with these hidden layers (the paper's baselines: `[100]`,
    /// `[100, 100]`, `[100, 100, 100]`).
    Dqn { hidden: Vec<usize> },
}

impl Method {
    /// The method the paper proposes: SAP-Net as it specifies it. Comparisons draw the
    /// others against it when it ran.
    pub fn the_papers() -> Self {
        Self::SapNet
    }

    /// What the method's file says of it: one arm per method.
    pub fn definition(&self) -> Box<dyn ReuseMethod + '_> {
        match self {
            Self::SapNet => Box::new(SapNetKnobs::default()),
            Self::SapNetWith(knobs) => Box::new(knobs.clone()),
            Self::Random => Box::new(PerStep),
            Self::RandomPerEpisode => Box::new(PerEpisode),
            Self::Ucb1 => Box::new(Bandit),
            Self::Prql(knobs) => Box::new(knobs.clone()),
            Self::Gpi(knobs) => Box::new(knobs.clone()),
            Self::QSwitch(knobs) => Box::new(knobs.clone()),
            Self::QDagger(knobs) => Box::new(knobs.clone()),
            Self::A2t(knobs) => Box::new(knobs.clone()),
            Self::BestSource => Box::new(Oracle),
            Self::FrozenOracle => Box::new(FrozenOracle),
            Self::Dqn { hidden } => Box::new(FromScratch { hidden }),
        }
    }

    pub fn kind(&self) -> MethodKind {
        self.definition().kind()
    }

    /// The method's name in results: `sapnet`, `ucb1`, `dqn[100,100]`…
    pub fn label(&self) -> String {
        self.definition().label()
    }

    /// The hidden layers of the method's attention network, if it has one.
    pub fn attention_hidden(&self) -> Option<Vec<usize>> {
        self.definition().attention_hidden().map(<[usize]>::to_vec)
    }

    /// The target copy interval of the method's estimates of its sources' values on the
    /// target task, if it makes them.
    pub fn source_evaluation(&self) -> Option<u64> {
        self.definition().source_evaluation()
    }

    /// The hidden layers of the method's own learner, if it has one.
    pub fn learner_hidden(&self) -> Option<Vec<usize>> {
        self.definition().learner_hidden().map(<[usize]>::to_vec)
    }
}
