//! UCB1 (Auer, Cesa-Bianchi & Fischer, 2002) over the sources, one pull per episode: the
//! source with the highest `mean + √(2 ln n / n_k)` acts for the whole episode and
//! fine-tunes while it acts; its reward is the episode's return scaled to [0, 1] by the
//! task's range of returns. Every source is played once first, in order.

use rand::rngs::StdRng;

use super::definition::{MethodKind, ReuseMethod, Tested};
use super::{
    Actor, EpisodeEnd, Learning, Library, ReuseError, ScoreColumn, Selector, SelectorView,
};
use crate::sapnet::SapNetParams;

#[derive(Debug)]
pub struct Ucb1 {
    /// The task's (lowest, highest) return.
    range: (f64, f64),
    /// Per source: the mean scaled return and the episodes it acted.
    means: Vec<f64>,
    pulls: Vec<u64>,
    /// The source of the episode in progress, once chosen.
    current: Option<usize>,
}

impl Ucb1 {
    pub fn new(n: usize, return_range: (f64, f64)) -> Self {
        Self {
            range: return_range,
            means: vec![0.0; n],
            pulls: vec![0; n],
            current: None,
        }
    }

    /// The UCB1 index of every source (infinite for a source never played).
    pub fn indices(&self) -> Vec<f64> {
        let total: u64 = self.pulls.iter().sum();
        self.means
            .iter()
            .zip(&self.pulls)
            .map(|(&mean, &pulls)| {
                if pulls == 0 {
                    f64::INFINITY
                } else {
                    mean + (2.0 * (total as f64).ln() / pulls as f64).sqrt()
                }
            })
            .collect()
    }

    fn scaled(&self, episode_return: f64) -> f64 {
        let (low, high) = self.range;
        ((episode_return - low) / (high - low)).clamp(0.0, 1.0)
    }
}

/// UCB1's score: the mean scaled return of each source's pulls.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "mean",
    meaning: "mean: scaled return of its pulls; P: 1 on the next",
    counted: false,
};

impl Selector for Ucb1 {
    fn learning(&self) -> Learning {
        Learning::ActingSource
    }

    fn act(&mut self, _rng: &mut StdRng) -> Actor {
        let i = match self.current {
            Some(i) => i,
            None => super::argmax(&self.indices()),
        };
        self.current = Some(i);
        Actor::Source(i)
    }

    fn on_episode_end(&mut self, end: &EpisodeEnd) {
        let Some(i) = self.current.take() else {
            return; // an episode spent in the warm-up pulled no arm
        };
        let reward = self.scaled(end.episode_return);
        self.pulls[i] += 1;
        self.means[i] += (reward - self.means[i]) / self.pulls[i] as f64;
    }

    /// Scores: the mean scaled return of each source.
    fn view(&self) -> SelectorView {
        let n = self.means.len();
        let mut probabilities = vec![0.0; n];
        let next = self
            .current
            .unwrap_or_else(|| super::argmax(&self.indices()));
        probabilities[next] = 1.0;
        SelectorView::unjudged(SCORE, self.means.clone(), probabilities)
    }

    /// The source played most (the best mean on a tie).
    fn chosen(&self) -> Option<usize> {
        let most = *self.pulls.iter().max()?;
        let candidates: Vec<f64> = self
            .means
            .iter()
            .zip(&self.pulls)
            .map(|(&m, &p)| if p == most { m } else { f64::NEG_INFINITY })
            .collect();
        Some(super::argmax(&candidates))
    }
}

/// UCB1 in `protocol.methods` (`Ucb1`), in the palette's green.
pub struct Bandit;

/// What UCB1 is: its pick is a rule (the highest index), so no lock-in is measured.
pub const KIND: MethodKind = MethodKind {
    family: "Ucb1",
    hue: 125,
    saturation: 55,
    reuses: true,
    tested: Tested::MostPlayed,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for Bandit {
    fn label(&self) -> String {
        "ucb1".into()
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(Ucb1::new(
            library.descriptions.len(),
            library.return_range,
        )))
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    fn episode(ucb: &mut Ucb1, rng: &mut StdRng, episode_return: f64) -> usize {
        let i = ucb.act(rng).source().unwrap();
        // The whole episode stays with the source chosen at its first step.
        assert_eq!(ucb.act(rng).source(), Some(i));
        ucb.on_episode_end(&EpisodeEnd {
            episode_return,
            discounted_return: 0.0,
        });
        i
    }

    #[test]
    fn plays_every_source_once_then_follows_the_index() {
        let mut rng = StdRng::seed_from_u64(0);
        let mut ucb = Ucb1::new(3, (0.0, 500.0));
        // Returns 100, 500, 250 → scaled 0.2, 1.0, 0.5.
        let first: Vec<usize> = [100.0, 500.0, 250.0]
            .iter()
            .map(|&r| episode(&mut ucb, &mut rng, r))
            .collect();
        assert_eq!(first, [0, 1, 2]);
        assert_eq!(ucb.means, [0.2, 1.0, 0.5]);
        // n = 3, each played once: index = mean + √(2 ln 3) = mean + 1.4823: source 1 leads.
        let bonus = (2.0 * 3f64.ln()).sqrt();
        assert_eq!(ucb.indices(), [0.2 + bonus, 1.0 + bonus, 0.5 + bonus]);
        assert_eq!(episode(&mut ucb, &mut rng, 0.0), 1);
        // Source 1: mean 0.5 over 2 pulls; n = 4: 0.5 + √(2 ln 4 / 2) = 1.6774 against
        // source 2's 0.5 + √(2 ln 4) = 2.1651 and source 0's 0.2 + 1.6651 = 1.8651.
        assert_eq!(episode(&mut ucb, &mut rng, 0.0), 2);
    }

    #[test]
    fn returns_are_scaled_into_the_tasks_range() {
        let mut ucb = Ucb1::new(1, (-200.0, 0.0));
        assert_eq!(ucb.scaled(-200.0), 0.0);
        assert_eq!(ucb.scaled(-50.0), 0.75);
        assert_eq!(ucb.scaled(10.0), 1.0);
        // An episode the warm-up spent pulls nothing.
        ucb.on_episode_end(&EpisodeEnd {
            episode_return: 0.0,
            discounted_return: 0.0,
        });
        assert_eq!(ucb.pulls, [0]);
    }
}
