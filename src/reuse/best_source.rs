//! The selection oracle: fine-tune the library's best source by its recorded score, the
//! one thing SAP-Net never looks at.

use rand::rngs::StdRng;

use super::definition::{MethodKind, ReuseMethod, Tested};
use super::{Actor, Learning, Library, ReuseError, ScoreColumn, Selector, SelectorView};
use crate::sapnet::SapNetParams;

/// Always the source with the highest recorded score (the lowest index on a tie).
#[derive(Debug)]
pub struct BestSource {
    best: usize,
    scores: Vec<f64>,
}

impl BestSource {
    /// Needs every source's score.
    pub fn new(scores: &[Option<f64>]) -> Result<Self, ReuseError> {
        let scores: Vec<f64> = scores
            .iter()
            .enumerate()
            .map(|(i, s)| {
                s.ok_or_else(|| {
                    ReuseError::Library(format!(
                        "BestSource picks by the library's recorded scores, and source {i} \
                         has none (its metadata's `final_score` is empty)"
                    ))
                })
            })
            .collect::<Result<_, _>>()?;
        if scores.is_empty() {
            return Err(ReuseError::Library("BestSource needs a library".into()));
        }
        Ok(Self {
            best: super::argmax(&scores),
            scores,
        })
    }
}

/// The oracle's score: each source's recorded score.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "score",
    meaning: "score: its recorded score; P: 1 on the best",
    counted: false,
};

impl Selector for BestSource {
    fn learning(&self) -> Learning {
        Learning::ActingSource
    }

    fn act(&mut self, _rng: &mut StdRng) -> Actor {
        Actor::Source(self.best)
    }

    /// Scores: the library's.
    fn view(&self) -> SelectorView {
        let n = self.scores.len();
        let mut probabilities = vec![0.0; n];
        probabilities[self.best] = 1.0;
        SelectorView::unjudged(SCORE, self.scores.clone(), probabilities)
    }

    fn top_probability(&self) -> Option<f64> {
        Some(1.0)
    }

    fn chosen(&self) -> Option<usize> {
        Some(self.best)
    }
}

/// The oracle in `protocol.methods` (`BestSource`), in the palette's orange.
pub struct Oracle;

/// What the oracle is: its one source has probability 1 from the start, given, not
/// learned: no lock-in to measure ([`super::lock_in`]).
pub const KIND: MethodKind = MethodKind {
    family: "BestSource",
    hue: 30,
    saturation: 80,
    reuses: true,
    tested: Tested::BestRecorded,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for Oracle {
    fn label(&self) -> String {
        "best-source".into()
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        Ok(Box::new(BestSource::new(library.scores)?))
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn picks_the_highest_score_and_refuses_a_library_without_scores() {
        let mut s = BestSource::new(&[Some(12.0), Some(500.0), Some(31.0), Some(500.0)]).unwrap();
        let mut rng = StdRng::seed_from_u64(0);
        assert!((0..10).all(|_| s.act(&mut rng) == Actor::Source(1)));
        assert_eq!(s.chosen(), Some(1));
        let err = BestSource::new(&[Some(1.0), None]).unwrap_err().to_string();
        assert!(err.contains("source 1 has none"), "{err}");
    }
}
