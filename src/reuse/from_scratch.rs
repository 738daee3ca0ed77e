//! DQN from scratch (the paper's baselines): no library, one learner that always acts.

use rand::rngs::StdRng;

use super::definition::{MethodKind, ReuseMethod, Tested};
use super::{Actor, Learning, Library, ReuseError, ScoreColumn, Selector, SelectorView};
use crate::sapnet::SapNetParams;

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
        SelectorView::unjudged(ScoreColumn::NONE, Vec::new(), Vec::new())
    }

    fn chosen(&self) -> Option<usize> {
        None
    }
}

/// DQN from scratch in `protocol.methods` (`Dqn(hidden: [100])`), grey in plots.
pub struct FromScratch<'a> {
    pub hidden: &'a [usize],
}

/// What DQN from scratch is: no library, its own learner tested.
pub const KIND: MethodKind = MethodKind {
    family: "Dqn",
    hue: 0,
    saturation: 0,
    reuses: false,
    tested: Tested::Learner,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for FromScratch<'_> {
    fn label(&self) -> String {
        let layers: Vec<String> = self.hidden.iter().map(ToString::to_string).collect();
        format!("dqn[{}]", layers.join(","))
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn learner_hidden(&self) -> Option<&[usize]> {
        Some(self.hidden)
    }

    fn validate(&self, field: &str) -> Result<(), String> {
        crate::ron_file::check(
            !self.hidden.is_empty() && self.hidden.iter().all(|&u| u > 0),
            &format!("{field}.hidden"),
            "a non-empty list of layer sizes > 0",
            format!("{:?}", self.hidden),
        )
    }

    fn selector(&self, _: Library<'_>, _: &SapNetParams) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(Scratch))
    }
}
