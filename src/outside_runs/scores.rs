//! What an outside run's scores are read from: its returns, its steps, its episodes placed
//! on the step axis (the scores themselves are the report's, `report/scored.rs`).

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
}
