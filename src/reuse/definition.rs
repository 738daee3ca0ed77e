//! What each method's file of `reuse/` defines ([`ReuseMethod`]) and the facts a front end
//! reads of a method ([`MethodKind`], [`Tested`]); [`super::method::Method`] lists the
//! methods, one arm each.

use std::fmt;

use serde::{Serialize, Serializer};

use super::{Library, ReuseError, Selector};
use crate::sapnet::SapNetParams;

/// What a method's file defines. See [`Method`](super::Method) for how a method is added.
pub trait ReuseMethod {
    /// Its name in results, naming its runs' files.
    fn label(&self) -> String;

    /// What front ends, results and plots know of it.
    fn kind(&self) -> MethodKind;

    /// The hidden layers of its own learner, a fresh DQN, if it has one.
    fn learner_hidden(&self) -> Option<&[usize]> {
        None
    }

    /// The hidden layers of an attention network over the sources and its learner, if it
    /// has one (A2T's).
    fn attention_hidden(&self) -> Option<&[usize]> {
        None
    }

    /// For a method that acts on its sources' values of the target task (GPI): the target
    /// copy interval, in updates, of the estimate of each source's value that the run
    /// trains by TD from the source's own network ([`super::Selector::evaluate`]).
    fn source_evaluation(&self) -> Option<u64> {
        None
    }

    /// Whether its learner's targets bootstrap on the action its combination (GPI's
    /// maximum over the learner and the sources' values) picks at `s′`, SFQL's, rather than
    /// on the learner's own maximum.
    fn gpi_bootstrap(&self) -> bool {
        false
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
    /// Whether its probabilities of picking a source are learned during the run, so that
    /// lock-in (one source above 0.99) means something ([`super::lock_in`]); a rule
    /// (UCB1's index, a draw per episode) or fixed odds (random's 1/N, the oracle's 1)
    /// have none.
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
    /// The method's learner combined with the sources as the method acts greedily (GPI's
    /// `argmax_a max(Q_L, max_i Q_i)`): the library and the learner together.
    Combined,
    /// Nothing: a run of another tool (`sapnet compare`) has no greedy test, and the mean
    /// return of its last episodes stands in the test score's place.
    LastEpisodes,
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
            Self::Combined => "combined",
            Self::LastEpisodes => "last-episodes",
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
