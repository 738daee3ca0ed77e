//! The chance baselines: a uniformly random source, drawn every step or once per episode.
//! The acting source fine-tunes as in SAP-Net; only the choice differs. What a run hands
//! over for testing is drawn uniformly too, at its first choice
//! ([`crate::reuse::Tested::DrawnAtStart`]), so that nothing the run saw selects it.

use rand::rngs::StdRng;
use rand::Rng;

use super::definition::{MethodKind, ReuseMethod, Tested};
use super::{
    Actor, EpisodeEnd, Learning, Library, ReuseError, ScoreColumn, Selector, SelectorView,
};
use crate::sapnet::SapNetParams;

/// A uniform draw over the sources.
#[derive(Debug)]
pub struct Random {
    n: usize,
    per_episode: bool,
    /// The source of the episode in progress (per episode only).
    current: Option<usize>,
    acted: Vec<u64>,
    /// The source handed over for testing, drawn before the first choice.
    handover: Option<usize>,
}

impl Random {
    /// A new source every step.
    pub fn per_step(n: usize) -> Self {
        Self::new(n, false)
    }

    /// A new source at the first step of every episode.
    pub fn per_episode(n: usize) -> Self {
        Self::new(n, true)
    }

    fn new(n: usize, per_episode: bool) -> Self {
        Self {
            n,
            per_episode,
            current: None,
            acted: vec![0; n],
            handover: None,
        }
    }
}

/// Random's score: the steps each source acted.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "acted",
    meaning: "acted: steps it acted; P: 1/N (per episode: 1 drawn)",
    counted: true,
};

impl Selector for Random {
    fn learning(&self) -> Learning {
        Learning::ActingSource
    }

    fn act(&mut self, rng: &mut StdRng) -> Actor {
        if self.handover.is_none() {
            self.handover = Some(rng.random_range(0..self.n));
        }
        let i = match self.current {
            Some(i) if self.per_episode => i,
            _ => rng.random_range(0..self.n),
        };
        self.current = Some(i);
        self.acted[i] += 1;
        Actor::Source(i)
    }

    fn on_episode_end(&mut self, _end: &EpisodeEnd) {
        self.current = None;
    }

    /// Scores: the steps each source acted.
    fn view(&self) -> SelectorView {
        let mut probabilities = vec![1.0 / self.n as f64; self.n];
        if let (true, Some(i)) = (self.per_episode, self.current) {
            probabilities.iter_mut().for_each(|p| *p = 0.0);
            probabilities[i] = 1.0;
        }
        SelectorView::unjudged(
            SCORE,
            self.acted.iter().map(|&n| n as f64).collect(),
            probabilities,
        )
    }

    /// The source drawn at the first choice (source 0 for a run that never chose, which
    /// a run with a library always does after its warm-up).
    fn chosen(&self) -> Option<usize> {
        Some(self.handover.unwrap_or(0))
    }
}

/// The chance baselines in `protocol.methods`, in the palette's blue.
const KIND: MethodKind = MethodKind {
    family: "Random",
    hue: 212,
    saturation: 65,
    reuses: true,
    tested: Tested::DrawnAtStart,
    // Its odds are 1/N, fixed: no lock-in to measure ([`super::lock_in`]).
    picks_by_probability: false,
    spreads: false,
};

/// `Random`: a random source every step.
pub struct PerStep;

/// `RandomPerEpisode`: a random source every episode.
pub struct PerEpisode;

impl ReuseMethod for PerStep {
    fn label(&self) -> String {
        "random".into()
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(Random::per_step(library.descriptions.len())))
    }
}

impl ReuseMethod for PerEpisode {
    fn label(&self) -> String {
        "random-episode".into()
    }

    fn kind(&self) -> MethodKind {
        MethodKind {
            family: "RandomPerEpisode",
            ..KIND
        }
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(Random::per_episode(library.descriptions.len())))
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn per_step_draws_every_source_and_per_episode_keeps_one() {
        let mut rng = StdRng::seed_from_u64(5);
        let mut every_step = Random::per_step(4);
        let drawn: Vec<usize> = (0..400)
            .map(|_| every_step.act(&mut rng).source().unwrap())
            .collect();
        for i in 0..4 {
            let share = drawn.iter().filter(|&&d| d == i).count();
            // Binomial(400, 1/4): mean 100, sd 8.7.
            assert!((60..140).contains(&share), "{i}: {share}");
        }
        let mut per_episode = Random::per_episode(4);
        let end = EpisodeEnd {
            episode_return: 0.0,
            discounted_return: 0.0,
        };
        let mut picks = Vec::new();
        for _ in 0..20 {
            let first = per_episode.act(&mut rng);
            assert!((0..50).all(|_| per_episode.act(&mut rng) == first));
            picks.push(first);
            per_episode.on_episode_end(&end);
        }
        assert!(picks.iter().any(|&p| p != picks[0]), "{picks:?}");
    }

    #[test]
    fn the_tested_source_is_drawn_before_the_run_not_picked_by_it() {
        // Over many seeds, the handed-over source is uniform however the acting goes; and
        // it does not follow which source acted most.
        let mut handed = [0u32; 4];
        let mut differs_from_most_acted = 0;
        for seed in 0..400 {
            let mut rng = StdRng::seed_from_u64(seed);
            let mut random = Random::per_step(4);
            for _ in 0..30 {
                random.act(&mut rng);
            }
            let chosen = random.chosen().unwrap();
            handed[chosen] += 1;
            let most = super::super::argmax(&random.view().scores);
            differs_from_most_acted += u32::from(chosen != most);
        }
        // Binomial(400, 1/4) each: mean 100, sd 8.7.
        assert!(handed.iter().all(|&n| (60..140).contains(&n)), "{handed:?}");
        assert!(differs_from_most_acted > 200, "{differs_from_most_acted}");
    }
}
