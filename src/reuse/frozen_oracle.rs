//! The frozen oracle, a control: the library's best source by its recorded score acts
//! greedily on the target task and never learns. Beside the oracle ([`super::best_source`],
//! the same source fine-tuned by the config's DQN) it shows what fine-tuning adds to a
//! source, or destroys; beside any reusing method, what the library alone is worth.

use rand::rngs::StdRng;

use super::best_source::BestSource;
use super::definition::{MethodKind, ReuseMethod, Tested};
use super::{Actor, Learning, Library, ReuseError, Selector, SelectorView};
use crate::sapnet::SapNetParams;

/// The frozen oracle in `protocol.methods` (`FrozenOracle`).
pub struct FrozenOracle;

/// What it is: the oracle's pick, in the oracle's hue, paler; it learns nothing, so its
/// probability of 1 is given, not learned.
pub const KIND: MethodKind = MethodKind {
    family: "FrozenOracle",
    hue: 30,
    saturation: 35,
    reuses: true,
    tested: Tested::BestRecorded,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for FrozenOracle {
    fn label(&self) -> String {
        "frozen-oracle".into()
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(Frozen(BestSource::new(library.scores)?)))
    }
}

/// The oracle's pick, acting as recorded.
#[derive(Debug)]
pub struct Frozen(BestSource);

impl Selector for Frozen {
    fn learning(&self) -> Learning {
        Learning::Frozen
    }

    /// The pick's greedy action, every step: as it was recorded, without the learner's
    /// exploration (nothing would learn from it).
    fn act(&mut self, rng: &mut StdRng) -> Actor {
        match self.0.act(rng) {
            Actor::Source(i) => Actor::SourceGreedy(i),
            other => other,
        }
    }

    fn view(&self) -> SelectorView {
        self.0.view()
    }

    fn chosen(&self) -> Option<usize> {
        self.0.chosen()
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn the_best_recorded_source_acts_greedily_and_nothing_learns() {
        let mut frozen = Frozen(BestSource::new(&[Some(12.0), Some(500.0), Some(31.0)]).unwrap());
        let mut rng = StdRng::seed_from_u64(0);
        assert!((0..10).all(|_| frozen.act(&mut rng) == Actor::SourceGreedy(1)));
        assert_eq!(frozen.learning(), Learning::Frozen);
        assert_eq!(frozen.chosen(), Some(1));
        assert_eq!(FrozenOracle.label(), "frozen-oracle");
    }
}
