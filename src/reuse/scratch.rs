//! DQN from scratch (the paper's baselines): no library, one learner that always acts.

use rand::rngs::StdRng;

use super::{Actor, Learning, Selector, SelectorView};

/// The learner acts and learns at every step.
#[derive(Debug)]
pub struct Scratch;

impl Selector for Scratch {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    fn act(&mut self, _rng: &mut StdRng) -> Actor {
        Actor::Learner
    }

    fn view(&self) -> SelectorView {
        SelectorView {
            score_name: "",
            scores: Vec::new(),
            probabilities: Vec::new(),
            positive: Vec::new(),
            negative: Vec::new(),
            excluded: Vec::new(),
        }
    }

    fn chosen(&self) -> Option<usize> {
        None
    }
}
