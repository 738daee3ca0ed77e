//! The frozen sources' Q-values of every stored transition, kept slot for slot beside the
//! replay buffer, so that A2T's update reads `Q_i(s, ·)` and `Q_i(s', ·)` of its minibatch
//! instead of running each source on it twice.
//!
//! A source is frozen, so its values of a stored transition never change: each is computed
//! once, when the transition arrives. The kernels compute every output of a batch as one
//! chain of fused multiply-adds per row, whatever the batch's size (`kernels`' "same bits"),
//! so a value computed alone is bit for bit the one the minibatch's pass would give: the
//! update's arithmetic is unchanged (`attention`'s test checks it against the uncached path).

use super::backprop::Workspace;
use super::kernels::Isa;
use super::{Batch, DqnError, QNet, ReplayBuffer};

/// Rows of the buffer computed per pass when the cache is filled from scratch.
const REFILL_ROWS: usize = 256;

/// The sources' Q-values `[slot][source][action]` at each stored transition's observation
/// and next observation.
#[derive(Debug, Default)]
pub(crate) struct SourceValues {
    /// Values per slot: sources × actions.
    width: usize,
    /// The buffer's pushes the cache has followed.
    pushes: u64,
    at_obs: Vec<f32>,
    at_next: Vec<f32>,
    /// The latest transition's next observation, and its slot: the state the run acts on
    /// next, unless the episode ended.
    latest_next: Vec<f32>,
    latest_slot: usize,
    /// The observations and next observations of the rows being filled.
    rows: (Vec<f32>, Vec<f32>),
    work: Workspace,
}

impl SourceValues {
    /// Brings the cache up to `replay`'s pushes (one buffer, followed from step to step):
    /// the latest transition alone after one step, every slot again after anything else
    /// (the first call, a buffer that was not followed).
    pub fn follow(
        &mut self,
        isa: Isa,
        replay: &ReplayBuffer,
        sources: &[&QNet],
    ) -> Result<(), DqnError> {
        let actions = sources.first().map_or(0, |s| s.architecture().action_count);
        let width = sources.len() * actions;
        if width != self.width {
            *self = Self {
                width,
                ..Self::default()
            };
        }
        // A buffer with fewer pushes than followed is another buffer: filled again.
        match replay.pushes().checked_sub(self.pushes) {
            Some(0) => {}
            Some(1) if self.at_obs.len() >= replay.latest_slot() * width => {
                self.fill_latest(isa, replay, sources)?;
            }
            _ => {
                for start in (0..replay.len()).step_by(REFILL_ROWS) {
                    let rows = REFILL_ROWS.min(replay.len() - start);
                    self.fill(isa, replay, start, rows, sources)?;
                }
            }
        }
        self.pushes = replay.pushes();
        if let Some(latest) = replay.latest() {
            self.latest_slot = replay.latest_slot();
            self.latest_next.clear();
            self.latest_next.extend_from_slice(latest.next_obs);
        }
        Ok(())
    }

    /// The sources' values `[source][action]` of `obs`, if it is the latest transition's
    /// next observation (the step after it acts on them: no need to run the sources again).
    pub fn of_latest_next(&self, obs: &[f32]) -> Option<&[f32]> {
        let same = self.pushes > 0
            && obs.len() == self.latest_next.len()
            && obs
                .iter()
                .zip(&self.latest_next)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        let at = self.latest_slot * self.width;
        same.then(|| &self.at_next[at..at + self.width])
    }

    /// The buffer's pushes the cache has followed.
    #[cfg(test)]
    pub fn pushes(&self) -> u64 {
        self.pushes
    }

    /// Computes the latest slot. Within an episode its observation is the previous
    /// transition's next one, whose values are kept: only its next observation's are
    /// computed. (Equal bits are equal values, so an observation met again elsewhere is
    /// kept as rightly.)
    fn fill_latest(
        &mut self,
        isa: Isa,
        replay: &ReplayBuffer,
        sources: &[&QNet],
    ) -> Result<(), DqnError> {
        let slot = replay.latest_slot();
        let previous = (slot + replay.capacity() - 1) % replay.capacity();
        let continues = replay.pushes() > 1 && replay.capacity() > 1 && {
            let (obs, before) = (replay.get(slot).obs, replay.get(previous).next_obs);
            obs.iter()
                .zip(before)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        };
        if !continues {
            return self.fill(isa, replay, slot, 1, sources);
        }
        let width = self.width;
        if self.at_obs.len() < (slot + 1) * width {
            self.at_obs.resize((slot + 1) * width, 0.0);
            self.at_next.resize((slot + 1) * width, 0.0);
        }
        let kept = previous * width..(previous + 1) * width;
        self.at_obs[slot * width..(slot + 1) * width].copy_from_slice(&self.at_next[kept]);
        self.compute(isa, replay.get(slot).next_obs, slot, 1, sources, true)
    }

    /// Computes the slots `start..start + rows` from `replay`, growing the cache to them.
    fn fill(
        &mut self,
        isa: Isa,
        replay: &ReplayBuffer,
        start: usize,
        rows: usize,
        sources: &[&QNet],
    ) -> Result<(), DqnError> {
        let end = (start + rows) * self.width;
        if self.at_obs.len() < end {
            self.at_obs.resize(end, 0.0);
            self.at_next.resize(end, 0.0);
        }
        let (mut obs, mut next) = std::mem::take(&mut self.rows);
        replay.observations_into(start..start + rows, &mut obs, &mut next);
        let computed = self
            .compute(isa, &obs, start, rows, sources, false)
            .and_then(|()| self.compute(isa, &next, start, rows, sources, true));
        self.rows = (obs, next);
        computed
    }

    /// Each source's values of `observations` (`rows` of them) into the slots from `start`,
    /// of next observations or not.
    fn compute(
        &mut self,
        isa: Isa,
        observations: &[f32],
        start: usize,
        rows: usize,
        sources: &[&QNet],
        next: bool,
    ) -> Result<(), DqnError> {
        let actions = self.width / sources.len().max(1);
        let cache = if next {
            &mut self.at_next
        } else {
            &mut self.at_obs
        };
        for (i, source) in sources.iter().enumerate() {
            let q = source.forward_with(isa, observations, rows, &mut self.work)?;
            for r in 0..rows {
                let at = (start + r) * self.width + i * actions;
                cache[at..at + actions].copy_from_slice(&q[r * actions..(r + 1) * actions]);
            }
        }
        Ok(())
    }

    /// Each source's values of `batch` (sampled from the followed buffer) at its
    /// observations, or at its next ones, into `values[i]` as `[batch × actions]`; `None`
    /// if the batch does not say its slots.
    pub fn gather(&self, batch: &Batch, next: bool, values: &mut [Vec<f32>]) -> Option<()> {
        let slots = batch.slots()?;
        let cache = if next { &self.at_next } else { &self.at_obs };
        let actions = self.width / values.len().max(1);
        for (i, out) in values.iter_mut().enumerate() {
            out.resize(slots.len() * actions, 0.0);
            for (row, &slot) in out.chunks_exact_mut(actions).zip(slots) {
                let at = slot * self.width + i * actions;
                row.copy_from_slice(&cache[at..at + actions]);
            }
        }
        Some(())
    }
}
