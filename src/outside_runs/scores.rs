//! What an outside run scores, in the same terms as sapnet's own runs.

use std::num::NonZeroUsize;

use super::OutsideRun;
use crate::stats::episodes::TrainingEpisodes;

impl OutsideRun {
    /// The episodes' returns, in order.
    pub fn returns(&self) -> impl Iterator<Item = f64> + '_ {
        self.episodes.returns.iter().copied()
    }

    /// The environment steps the run took by its last episode's end, when its file places
    /// episodes by step or gives their lengths.
    pub fn steps(&self) -> Option<u64> {
        self.steps
    }

    /// Its episodes as sapnet keeps its own, when every episode's length is known (see
    /// [`OutsideRun::lengths_known`]): what a step axis reads.
    pub fn placed(&self) -> Option<&TrainingEpisodes> {
        self.lengths_known.then_some(&self.episodes)
    }

    /// The training return: the plain mean of every episode's return, as sapnet scores its
    /// own runs (`RunScores::of` in `report/scores.rs`: the sum of the training returns
    /// over their count, the area under the learning curve per episode). No moving
    /// average enters it: sapnet's window only smooths the curves and places the episode
    /// at which a threshold was reached.
    pub fn training_return(&self) -> f64 {
        // A run has at least one episode (reading refuses an empty one).
        self.returns().sum::<f64>() / self.episodes.len() as f64
    }

    /// The mean return of the last `k` episodes, or of all of them if the run has fewer.
    pub fn final_score(&self, k: NonZeroUsize) -> f64 {
        let returns = &self.episodes.returns;
        let last = &returns[returns.len().saturating_sub(k.get())..];
        last.iter().sum::<f64>() / last.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Axis, Format, Gathered};
    use super::*;

    fn run(returns: &[f64]) -> OutsideRun {
        let mut episodes = Gathered::new(Axis::Episodes);
        for (i, &r) in returns.iter().enumerate() {
            episodes.push(i as i64 + 1, r, None);
        }
        episodes.into_run("run.csv".as_ref(), Format::Csv, "return".into())
    }

    #[test]
    fn the_training_return_is_the_mean_of_every_episode_as_sapnet_scores_its_own() {
        // sapnet's own scores test: (10 + 30 + 50 + 70 + 20 + 20) / 6 = 200 / 6.
        let r = run(&[10.0, 30.0, 50.0, 70.0, 20.0, 20.0]);
        assert_eq!(r.training_return(), 200.0 / 6.0);
        // The last two: (20 + 20) / 2; the last four: (50 + 70 + 20 + 20) / 4 = 40.
        assert_eq!(r.final_score(NonZeroUsize::new(2).unwrap()), 20.0);
        assert_eq!(r.final_score(NonZeroUsize::new(4).unwrap()), 40.0);
        // More than the run has: all of them.
        assert_eq!(
            r.final_score(NonZeroUsize::new(100).unwrap()),
            r.training_return()
        );
    }
}
