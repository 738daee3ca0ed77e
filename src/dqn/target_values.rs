//! `max_a Q_target(s′, a)` of the replay buffer's transitions, kept while the target network
//! stays the same.
//!
//! The target network changes only when the online one is copied into it (every
//! `target_update_interval` steps: 10,000 in the paper's settings), yet every update ran
//! it on all 32 next observations of its minibatch, a quarter of the update's arithmetic.
//! A transition is drawn again and again while one target network lasts (≈ 32 × 10,000 / N
//! times in a buffer of N), so its bootstrap value is kept by slot and computed once.
//!
//! **The same bits.** A forward pass computes each transition's Q-values in a column of
//! its own (one FMA chain a unit, no sum across the minibatch, `kernels/mod.rs`), so a
//! transition's values do not depend on which minibatch, or which column of it, computed
//! them: a kept value is the value a full pass would give.
//!
//! A value is valid for one target network (an *epoch*, counted up at each copy) and one
//! record: a slot the ring buffer overwrites is forgotten ([`TargetValues::follow`]).

use super::ReplayBuffer;

/// Bytes a learner keeps a stored transition's value in (the protocol's memory check).
pub const BYTES_PER_TRANSITION: usize = std::mem::size_of::<Kept>();

/// A slot's value and the epoch it was computed in, side by side: one cache line to read.
#[derive(Debug, Clone, Copy, Default)]
struct Kept {
    value: f32,
    epoch: u32,
}

/// The kept values of one learner's target network.
#[derive(Debug)]
pub(crate) struct TargetValues {
    /// The buffer the slots are of ([`ReplayBuffer::id`]); 0 before the first.
    replay: u64,
    /// That buffer's [`ReplayBuffer::pushes`] when last followed.
    pushes: u64,
    /// The target network's epoch: 1 for the first, one more at each copy; 0 marks a slot
    /// with no value.
    epoch: u32,
    /// Each slot's value and the epoch it was computed in.
    slots: Vec<Kept>,
}

impl TargetValues {
    pub(crate) fn new() -> Self {
        Self {
            replay: 0,
            pushes: 0,
            epoch: 1,
            slots: Vec::new(),
        }
    }

    /// The target network was replaced: every value kept is stale.
    pub(crate) fn forget(&mut self) {
        self.epoch = match self.epoch.checked_add(1) {
            Some(next) => next,
            None => {
                self.forget_all();
                1
            }
        };
    }

    /// Catches up with `replay`: slots pushed since the last call are forgotten (a ring
    /// buffer overwrites its oldest), and a buffer other than the last one forgets all.
    pub(crate) fn follow(&mut self, replay: &ReplayBuffer) {
        if replay.id() != self.replay {
            self.replay = replay.id();
            self.pushes = 0;
            self.slots.clear();
        }
        self.slots.resize(replay.len(), Kept::default());
        let capacity = replay.capacity() as u64;
        let pushes = replay.pushes();
        // Push number n wrote slot n mod capacity; the first `capacity` wrote new slots.
        let overwrites = self.pushes.max(capacity)..pushes.max(capacity);
        if overwrites.end - overwrites.start >= capacity {
            self.forget_all();
        } else {
            for n in overwrites {
                self.slots[(n % capacity) as usize].epoch = 0;
            }
        }
        self.pushes = pushes;
    }

    /// Slot `slot`'s value under the current target network, if computed.
    pub(crate) fn get(&self, slot: usize) -> Option<f32> {
        let kept = self.slots.get(slot)?;
        (kept.epoch == self.epoch).then_some(kept.value)
    }

    /// Keeps `value` for `slot` (a slot of the buffer last followed).
    pub(crate) fn set(&mut self, slot: usize, value: f32) {
        self.slots[slot] = Kept {
            value,
            epoch: self.epoch,
        };
    }

    fn forget_all(&mut self) {
        self.slots.iter_mut().for_each(|kept| kept.epoch = 0);
    }

    /// Bytes held.
    #[cfg(test)]
    fn bytes(&self) -> usize {
        self.slots.len() * BYTES_PER_TRANSITION
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::Transition;

    fn push(replay: &mut ReplayBuffer, x: f32) {
        replay.push(Transition {
            obs: &[x],
            action: 0,
            reward: 0.0,
            next_obs: &[x],
            terminated: false,
            truncated: false,
        });
    }

    #[test]
    fn a_value_lasts_until_the_target_is_copied() {
        let mut replay = ReplayBuffer::new(4, 1);
        push(&mut replay, 1.0);
        let mut kept = TargetValues::new();
        kept.follow(&replay);
        assert_eq!(kept.get(0), None);
        kept.set(0, 2.5);
        assert_eq!(kept.get(0), Some(2.5));
        push(&mut replay, 2.0);
        kept.follow(&replay);
        assert_eq!((kept.get(0), kept.get(1)), (Some(2.5), None));
        kept.forget();
        assert_eq!(kept.get(0), None);
    }

    #[test]
    fn an_overwritten_slot_is_forgotten_and_the_others_kept() {
        let mut replay = ReplayBuffer::new(3, 1);
        for x in 0..3 {
            push(&mut replay, x as f32);
        }
        let mut kept = TargetValues::new();
        kept.follow(&replay);
        for slot in 0..3 {
            kept.set(slot, slot as f32);
        }
        // Push 3 overwrites slot 0, push 4 slot 1.
        push(&mut replay, 3.0);
        push(&mut replay, 4.0);
        kept.follow(&replay);
        assert_eq!(
            [kept.get(0), kept.get(1), kept.get(2)],
            [None, None, Some(2.0)]
        );
        // A whole lap of the ring since: nothing kept.
        kept.set(0, 9.0);
        for x in 0..3 {
            push(&mut replay, x as f32);
        }
        kept.follow(&replay);
        assert_eq!([kept.get(0), kept.get(1), kept.get(2)], [None; 3]);
        assert_eq!(kept.bytes(), 3 * BYTES_PER_TRANSITION);
    }

    #[test]
    fn another_buffer_and_a_clone_share_no_values() {
        let mut replay = ReplayBuffer::new(4, 1);
        push(&mut replay, 1.0);
        let mut kept = TargetValues::new();
        kept.follow(&replay);
        kept.set(0, 1.0);
        let copy = replay.clone();
        kept.follow(&copy);
        assert_eq!(kept.get(0), None, "a clone may diverge from its original");
        let mut other = ReplayBuffer::new(4, 1);
        push(&mut other, 1.0);
        kept.set(0, 1.0);
        kept.follow(&other);
        assert_eq!(kept.get(0), None);
    }

    #[test]
    fn the_epoch_wrapping_forgets_everything() {
        let mut replay = ReplayBuffer::new(2, 1);
        push(&mut replay, 1.0);
        let mut kept = TargetValues::new();
        kept.follow(&replay);
        kept.epoch = u32::MAX;
        kept.set(0, 1.0);
        kept.forget();
        assert_eq!(kept.epoch, 1);
        assert_eq!(kept.get(0), None);
    }
}
