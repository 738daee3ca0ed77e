//! The methods a protocol compares (`protocol.methods`). Each is defined by its own file of
//! `reuse/`, through [`ReuseMethod`]: its label, what it is ([`MethodKind`]), its learner,
//! its knobs' checks and its selector. So adding a method is its file, a variant of
//! [`Method`] and its arm in [`Method::definition`], and nothing outside `reuse/` branches
//! on which method a run is: front ends, results and plots ask its [`MethodKind`].

use std::fmt;

use serde::{Deserialize, Serialize, Serializer};

use super::best_source::Oracle;
use super::from_scratch::FromScratch;
use super::prql::PrqlKnobs;
use super::random::{PerEpisode, PerStep};
use super::sapnet::SapNetKnobs;
use super::ucb1::Bandit;
use super::{Library, ReuseError, Selector};
use crate::sapnet::SapNetParams;

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
    /// Fine-tune the library's best source by its recorded score: the selection oracle.
    BestSource,
    /// DQN from scratch with these hidden layers (the paper's baselines: `[100]`,
    /// `[100, 100]`, `[100, 100, 100]`).
    Dqn { hidden: Vec<usize> },
}

impl Method {
    /// What the method's file says of it: one arm per method.
    pub fn definition(&self) -> Box<dyn ReuseMethod + '_> {
        match self {
            Self::SapNet => Box::new(SapNetKnobs::default()),
            Self::SapNetWith(knobs) => Box::new(knobs.clone()),
            Self::Random => Box::new(PerStep),
            Self::RandomPerEpisode => Box::new(PerEpisode),
            Self::Ucb1 => Box::new(Bandit),
            Self::Prql(knobs) => Box::new(knobs.clone()),
            Self::BestSource => Box::new(Oracle),
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

    /// The hidden layers of the method's own learner, if it has one.
    pub fn learner_hidden(&self) -> Option<Vec<usize>> {
        self.definition().learner_hidden().map(<[usize]>::to_vec)
    }
}

/// What a method's file defines. See the [module](self) documentation.
pub trait ReuseMethod {
    /// Its name in results, naming its runs' files.
    fn label(&self) -> String;

    /// What front ends, results and plots know of it.
    fn kind(&self) -> MethodKind;

    /// The hidden layers of its own learner, a fresh DQN, if it has one.
    fn learner_hidden(&self) -> Option<&[usize]> {
        None
    }

    /// The ranges of its knobs that serde cannot check; `field` is where it sits in the
    /// config (`protocol.methods[2]`).
    fn validate(&self, _field: &str) -> Result<(), String> {
        Ok(())
    }

    /// The selector of one of its runs over `library`; `sapnet` is the config's SAP-Net
    /// section.
    fn selector(
        &self,
        library: Library<'_>,
        sapnet: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError>;
}

/// What kind of learner a method is, without its knobs: what front ends, results and plots
/// read of it, each method's file saying its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MethodKind {
    /// Its family, as results name it (`SapNet`, `Ucb1`, `Dqn`…): variants of one method
    /// share it, and plots draw them in shades of one hue.
    pub family: &'static str,
    /// The family's hue in plots, in degrees, and its saturation in percent (0: grey).
    pub hue: u16,
    pub saturation: u8,
    /// Whether it draws on the source library.
    pub reuses: bool,
    /// What its runs hand over to be tested greedily.
    pub tested: Tested,
    /// Whether it picks sources with probabilities, so that lock-in (one source above
    /// 0.99) is measured; a rule (UCB1's index, a draw per episode) has none.
    pub picks_by_probability: bool,
    /// Whether it spreads activation over SAP-Net's graph: its runs trace their walks and
    /// teach mode can step them.
    pub spreads: bool,
}

impl Serialize for MethodKind {
    /// As its family's name, as results have always written a method's kind.
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.family)
    }
}

impl fmt::Display for MethodKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.family)
    }
}

/// What a method's run hands over for its greedy tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Tested {
    /// The source with the highest activation when the run ends (Algorithm 3).
    HighestActivation,
    /// A source drawn uniformly when the run starts, whatever the run then does: a random
    /// selector has no preference to hand over. (Handing over the source that acted most
    /// would select by return: the longest episodes are the best source's.)
    DrawnAtStart,
    /// The source played in most episodes: a bandit's recommendation.
    MostPlayed,
    /// The source with the best recorded score: the oracle's pick, made before training.
    BestRecorded,
    /// The method's own learner, not a source.
    Learner,
}

impl Tested {
    /// The rule's name in `comparison.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Self::HighestActivation => "highest-activation",
            Self::DrawnAtStart => "drawn-at-start",
            Self::MostPlayed => "most-played",
            Self::BestRecorded => "best-recorded",
            Self::Learner => "learner",
        }
    }
}

/// A method's own `label` names its run's files and its chosen policy in the library: one
/// that is not a portable name would fail the protocol after training, so it is refused
/// with its field first.
pub fn check_label(field: &str, label: &str) -> Result<(), String> {
    if crate::safe_io::is_portable_name(label) {
        Ok(())
    } else {
        Err(format!(
            "field `{field}.label`: expected a name of {} (it names the run's files and \
             columns), got {label:?}",
            crate::safe_io::PORTABLE_NAME
        ))
    }
}
