//! Experience replay: a ring buffer of transitions, sampled uniformly with replacement.
//!
//! Each transition is one fixed-size record of `2·obs_size + 2` f32 words, interleaved in
//! one array: the observation, the next observation, the reward, and a word holding the
//! action and the two flags as bits ([`tag`]). A minibatch's draw then touches one or two
//! cache lines per transition where six column arrays touched six, and the records of a
//! batch are prefetched as soon as their slots are drawn (the draws are the same, in the
//! same order: the same minibatches bit for bit). Records grow as transitions arrive, so a
//! 1e6-transition buffer costs only what it holds; once full, the oldest is overwritten.

use std::sync::atomic::{AtomicU64, Ordering};

use rand::Rng;

/// A number no other replay buffer made by this process has.
fn next_replay_id() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// One environment step, as stored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition<'a> {
    pub obs: &'a [f32],
    pub action: usize,
    pub reward: f64,
    pub next_obs: &'a [f32],
    /// The task ended: the value of `next_obs` is not bootstrapped.
    pub terminated: bool,
    /// The time limit ended the episode; `next_obs` still has a value (Gymnasium semantics).
    pub truncated: bool,
}

/// The record's last word: the action in the low bits, `terminated` in bit 31 and
/// `truncated` in bit 30. Kept as an `f32` of those bits so that a record is one slice of
/// `f32`; the bits are only ever moved, never computed with, and with the action below
/// 2²² they are never a NaN's (whose exponent bits 23–30 are all set), so every move keeps
/// them.
mod tag {
    /// Actions up to this many are stored.
    pub const ACTIONS: usize = 1 << 22;
    const TERMINATED: u32 = 1 << 31;
    const TRUNCATED: u32 = 1 << 30;

    pub fn pack(action: usize, terminated: bool, truncated: bool) -> f32 {
        assert!(
            action < ACTIONS,
            "action index {action} fits in a replay record"
        );
        let flags = if terminated { TERMINATED } else { 0 } | if truncated { TRUNCATED } else { 0 };
        f32::from_bits(action as u32 | flags)
    }

    pub fn action(word: f32) -> u32 {
        word.to_bits() & !(TERMINATED | TRUNCATED)
    }

    pub fn terminated(word: f32) -> bool {
        word.to_bits() & TERMINATED != 0
    }

    pub fn truncated(word: f32) -> bool {
        word.to_bits() & TRUNCATED != 0
    }
}

/// Bytes one stored transition takes: a record of `2·obs_size + 2` f32 words (two
/// observations, the reward, the action and flags). The protocol's memory check counts
/// replay memory with it.
pub fn transition_bytes(obs_size: usize) -> usize {
    (2 * obs_size + 2) * std::mem::size_of::<f32>()
}

/// A fixed-capacity ring buffer of transitions.
#[derive(Debug)]
pub struct ReplayBuffer {
    /// This buffer's own number ([`ReplayBuffer::id`]).
    id: u64,
    capacity: usize,
    obs_size: usize,
    /// f32 words per record: `2·obs_size + 2`.
    stride: usize,
    /// Records held.
    len: usize,
    /// Slot the next transition is written to once the buffer is full.
    next: usize,
    /// Transitions pushed since the buffer was made.
    pushes: u64,
    /// `len` records of `stride` words: obs, next obs, reward, [`tag`].
    records: Vec<f32>,
}

impl ReplayBuffer {
    /// # Panics
    /// If `capacity` or `obs_size` is 0.
    pub fn new(capacity: usize, obs_size: usize) -> Self {
        assert!(capacity > 0, "replay capacity must be at least 1");
        assert!(obs_size > 0, "observation size must be at least 1");
        Self {
            id: next_replay_id(),
            capacity,
            obs_size,
            stride: 2 * obs_size + 2,
            len: 0,
            next: 0,
            pushes: 0,
            records: Vec::new(),
        }
    }

    /// A number no other buffer of this process has, a clone's included: what a learner
    /// keeps about a buffer's slots (`target_values.rs`) is for one buffer only.
    pub fn id(&self) -> u64 {
        self.id
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn capacity(&self) -> usize {
        self.capacity
    }

    pub fn obs_size(&self) -> usize {
        self.obs_size
    }

    /// The record of slot `i`.
    #[inline]
    fn record(&self, i: usize) -> &[f32] {
        &self.records[i * self.stride..(i + 1) * self.stride]
    }

    /// Stores a transition, overwriting the oldest one when full.
    ///
    /// # Panics
    /// If an observation is not `obs_size` long or the action is 2²² or more (caller bugs).
    pub fn push(&mut self, t: Transition<'_>) {
        let n = self.obs_size;
        assert_eq!(t.obs.len(), n, "observation size");
        assert_eq!(t.next_obs.len(), n, "next observation size");
        let tag = tag::pack(t.action, t.terminated, t.truncated);
        if self.len < self.capacity {
            if self.records.len() == self.records.capacity() {
                // Doubling as a `Vec` does, but never past the capacity's records.
                let room = self.records.capacity().max(64 * self.stride);
                let most = self.capacity * self.stride - self.records.len();
                self.records.reserve_exact(room.min(most));
            }
            self.records.extend_from_slice(t.obs);
            self.records.extend_from_slice(t.next_obs);
            self.records.extend([t.reward as f32, tag]);
            self.len += 1;
        } else {
            let at = self.next * self.stride;
            let record = &mut self.records[at..at + self.stride];
            record[..n].copy_from_slice(t.obs);
            record[n..2 * n].copy_from_slice(t.next_obs);
            record[2 * n] = t.reward as f32;
            record[2 * n + 1] = tag;
        }
        self.next = (self.next + 1) % self.capacity;
        self.pushes += 1;
    }

    /// Transitions pushed since the buffer was made, overwritten ones included.
    pub fn pushes(&self) -> u64 {
        self.pushes
    }

    /// The slot of the transition pushed last (0 while empty).
    pub fn latest_slot(&self) -> usize {
        (self.next + self.capacity - 1) % self.capacity
    }

    /// The observations and next observations of the slots `slots`, row-major, into `obs`
    /// and `next` (emptied first).
    pub fn observations_into(
        &self,
        slots: std::ops::Range<usize>,
        obs: &mut Vec<f32>,
        next: &mut Vec<f32>,
    ) {
        obs.clear();
        next.clear();
        let n = self.obs_size;
        for slot in slots {
            let record = self.record(slot);
            obs.extend_from_slice(&record[..n]);
            next.extend_from_slice(&record[n..2 * n]);
        }
    }

    /// The `i`-th stored transition in slot order (not age order).
    pub fn get(&self, i: usize) -> Transition<'_> {
        let n = self.obs_size;
        let record = self.record(i);
        let tag = record[2 * n + 1];
        Transition {
            obs: &record[..n],
            action: tag::action(tag) as usize,
            reward: f64::from(record[2 * n]),
            next_obs: &record[n..2 * n],
            terminated: tag::terminated(tag),
            truncated: tag::truncated(tag),
        }
    }

    /// The transition stored last, if any.
    pub fn latest(&self) -> Option<Transition<'_>> {
        (!self.is_empty()).then(|| self.get(self.latest_slot()))
    }

    /// Fills `batch` with `size` transitions drawn uniformly with replacement, reusing its
    /// memory; the batch keeps their slots.
    ///
    /// Every slot is drawn first (the same draws, in the same order, as drawing each before
    /// copying it) and its record prefetched, so that the records' loads overlap; then the
    /// records are copied into the batch's columns.
    ///
    /// # Panics
    /// If the buffer is empty.
    pub fn sample_into(&self, size: usize, batch: &mut Batch, rng: &mut impl Rng) {
        assert!(
            !self.is_empty(),
            "cannot sample from an empty replay buffer"
        );
        batch.clear(self.obs_size);
        for _ in 0..size {
            let slot = rng.random_range(0..self.len());
            self.prefetch(slot);
            batch.slots.push(slot);
        }
        // The tasks' widths get a copy of constant length (moves in registers, where a
        // length known only at run time calls `memcpy` twice per transition).
        match self.obs_size {
            1 => self.gather::<1>(batch),
            2 => self.gather::<2>(batch),
            3 => self.gather::<3>(batch),
            4 => self.gather::<4>(batch),
            6 => self.gather::<6>(batch),
            8 => self.gather::<8>(batch),
            _ => self.gather::<0>(batch),
        }
    }

    /// Copies the records of `batch`'s slots into its columns; `N` is the observation size,
    /// or 0 for "`obs_size`, whatever it is".
    #[inline(always)]
    fn gather<const N: usize>(&self, batch: &mut Batch) {
        let n = if N == 0 { self.obs_size } else { N };
        debug_assert_eq!(n, self.obs_size);
        let Batch {
            obs,
            next_obs,
            actions,
            rewards,
            terminated,
            truncated,
            slots,
            ..
        } = batch;
        for &slot in slots.iter() {
            let record = self.record(slot);
            let tag = record[2 * n + 1];
            obs.extend_from_slice(&record[..n]);
            next_obs.extend_from_slice(&record[n..2 * n]);
            rewards.push(record[2 * n]);
            actions.push(tag::action(tag));
            terminated.push(tag::terminated(tag));
            truncated.push(tag::truncated(tag));
        }
    }

    /// Asks the CPU to bring slot `slot`'s record into the caches (every cache line it
    /// spans); a hint that changes no value, and nothing where there is no such hint.
    #[inline]
    fn prefetch(&self, slot: usize) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let bytes = self.stride * std::mem::size_of::<f32>();
            let start = self.record(slot).as_ptr().cast::<i8>();
            // SAFETY (each prefetch): a prefetch is a hint: it reads nothing the program
            // sees and cannot fault; every address is within the record.
            let mut offset = 0;
            while offset < bytes {
                unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset)) };
                offset += 64;
            }
            // The line of the last byte, where the record straddles two.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(bytes - 1)) };
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = slot;
    }
}

impl Clone for ReplayBuffer {
    /// A copy with an id of its own: the two may be pushed to differently from now on.
    fn clone(&self) -> Self {
        Self {
            id: next_replay_id(),
            capacity: self.capacity,
            obs_size: self.obs_size,
            stride: self.stride,
            len: self.len,
            next: self.next,
            pushes: self.pushes,
            records: self.records.clone(),
        }
    }
}

/// A minibatch in the same column layout as the buffer, reused between updates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Batch {
    obs_size: usize,
    obs: Vec<f32>,
    next_obs: Vec<f32>,
    actions: Vec<u32>,
    rewards: Vec<f32>,
    terminated: Vec<bool>,
    truncated: Vec<bool>,
    /// The buffer's slot of each transition, when every one was sampled from a buffer.
    slots: Vec<usize>,
}

impl Batch {
    /// An empty batch; its observation size is set by its first [`Batch::push`] or sample.
    pub fn new() -> Self {
        Self::default()
    }

    /// Empties the batch, keeping its memory.
    pub fn clear(&mut self, obs_size: usize) {
        self.obs_size = obs_size;
        self.obs.clear();
        self.next_obs.clear();
        self.actions.clear();
        self.rewards.clear();
        self.terminated.clear();
        self.truncated.clear();
        self.slots.clear();
    }

    /// # Panics
    /// If the observation size differs from the batch's.
    pub fn push(&mut self, t: Transition<'_>) {
        if self.is_empty() {
            self.obs_size = t.obs.len();
        }
        assert_eq!(t.obs.len(), self.obs_size, "observation size");
        assert_eq!(t.next_obs.len(), self.obs_size, "next observation size");
        self.obs.extend_from_slice(t.obs);
        self.next_obs.extend_from_slice(t.next_obs);
        self.actions
            .push(u32::try_from(t.action).expect("action index fits in u32"));
        self.rewards.push(t.reward as f32);
        self.terminated.push(t.terminated);
        self.truncated.push(t.truncated);
    }

    pub fn len(&self) -> usize {
        self.actions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }

    pub fn obs_size(&self) -> usize {
        self.obs_size
    }

    /// Observations, row-major `[len, obs_size]`.
    pub fn obs(&self) -> &[f32] {
        &self.obs
    }

    /// Next observations, row-major `[len, obs_size]`.
    pub fn next_obs(&self) -> &[f32] {
        &self.next_obs
    }

    pub fn actions(&self) -> &[u32] {
        &self.actions
    }

    pub fn rewards(&self) -> &[f32] {
        &self.rewards
    }

    pub fn terminated(&self) -> &[bool] {
        &self.terminated
    }

    pub fn truncated(&self) -> &[bool] {
        &self.truncated
    }

    /// Each transition's slot in the buffer it was sampled from, unless one was pushed by
    /// hand.
    pub fn slots(&self) -> Option<&[usize]> {
        (self.slots.len() == self.len()).then_some(self.slots.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, SeedableRng};

    fn transition(obs: &[f32], i: usize) -> Transition<'_> {
        Transition {
            obs,
            action: i % 2,
            reward: i as f64,
            next_obs: obs,
            terminated: i.is_multiple_of(3),
            truncated: i.is_multiple_of(5),
        }
    }

    #[test]
    fn the_latest_transition_is_the_last_pushed_before_and_after_wrapping() {
        let mut buffer = ReplayBuffer::new(3, 1);
        assert!(buffer.latest().is_none());
        for i in 0..7 {
            let obs = [i as f32];
            buffer.push(transition(&obs, i));
            assert_eq!(buffer.latest().unwrap().reward, i as f64, "after {i}");
        }
    }

    #[test]
    fn grows_lazily_then_wraps_over_the_oldest() {
        let mut buffer = ReplayBuffer::new(3, 2);
        assert!(buffer.is_empty());
        for i in 0..5 {
            let obs = [i as f32, -(i as f32)];
            buffer.push(transition(&obs, i));
            assert_eq!(buffer.len(), (i + 1).min(3));
        }
        // Slots 0 and 1 were overwritten by transitions 3 and 4; slot 2 still holds 2.
        let rewards: Vec<f64> = (0..3).map(|i| buffer.get(i).reward).collect();
        assert_eq!(rewards, [3.0, 4.0, 2.0]);
        assert_eq!(buffer.get(0).obs, &[3.0, -3.0]);
        assert_eq!(buffer.get(1).next_obs, &[4.0, -4.0]);
        assert!(buffer.get(0).terminated && !buffer.get(0).truncated);
        assert!(!buffer.get(1).terminated);
        assert!(buffer.records.len() == 3 * 6 && buffer.records.capacity() <= 3 * 6);
    }

    #[test]
    fn samples_are_stored_transitions_and_reuse_the_batch() {
        let mut buffer = ReplayBuffer::new(10, 1);
        for i in 0..7 {
            buffer.push(transition(&[i as f32], i));
        }
        let mut rng = StdRng::seed_from_u64(3);
        let mut batch = Batch::new();
        buffer.sample_into(32, &mut batch, &mut rng);
        assert_eq!(batch.len(), 32);
        for b in 0..32 {
            let i = batch.obs()[b] as usize;
            assert_eq!(batch.rewards()[b], i as f32);
            assert_eq!(batch.actions()[b] as usize, i % 2);
            assert_eq!(batch.terminated()[b], i.is_multiple_of(3));
            assert_eq!(batch.truncated()[b], i.is_multiple_of(5));
        }
        let capacity = batch.obs.capacity();
        buffer.sample_into(32, &mut batch, &mut rng);
        assert_eq!(batch.len(), 32);
        assert_eq!(batch.obs.capacity(), capacity);
    }

    #[test]
    fn sampling_covers_every_slot_uniformly() {
        let mut buffer = ReplayBuffer::new(4, 1);
        for i in 0..4 {
            buffer.push(transition(&[i as f32], i));
        }
        let mut rng = StdRng::seed_from_u64(0);
        let mut batch = Batch::new();
        buffer.sample_into(4000, &mut batch, &mut rng);
        let mut counts = [0usize; 4];
        for &o in batch.obs() {
            counts[o as usize] += 1;
        }
        assert!(
            counts.iter().all(|&c| (900..1100).contains(&c)),
            "{counts:?}"
        );
    }

    /// The records hand back what was pushed, to the bit: every flag pair, the largest
    /// action, rewards rounded to f32 as stored, observations of any bits (NaN payloads,
    /// negative zero, subnormals).
    #[test]
    fn a_record_keeps_every_field_to_the_bit() {
        let odd = [
            f32::from_bits(0x7fc0_1234),
            -0.0,
            f32::from_bits(1),
            f32::MAX,
            f32::NEG_INFINITY,
        ];
        let mut buffer = ReplayBuffer::new(8, odd.len());
        let next: Vec<f32> = odd.iter().rev().copied().collect();
        let actions = [0, 1, 2, tag::ACTIONS - 1];
        for (i, (terminated, truncated)) in
            [(false, false), (true, false), (false, true), (true, true)]
                .into_iter()
                .enumerate()
        {
            buffer.push(Transition {
                obs: &odd,
                action: actions[i],
                reward: 0.1 * i as f64 - 1e40,
                next_obs: &next,
                terminated,
                truncated,
            });
            let t = buffer.get(i);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(t.obs), bits(&odd));
            assert_eq!(bits(t.next_obs), bits(&next));
            assert_eq!(t.action, actions[i]);
            assert_eq!(t.reward, f64::from((0.1 * i as f64 - 1e40) as f32));
            assert_eq!((t.terminated, t.truncated), (terminated, truncated));
        }
        assert_eq!(transition_bytes(odd.len()), 48);
        assert_eq!(buffer.records.len() * 4, 4 * transition_bytes(odd.len()));
    }

    #[test]
    #[should_panic(expected = "fits in a replay record")]
    fn an_action_beyond_the_tag_is_refused() {
        let mut buffer = ReplayBuffer::new(2, 1);
        buffer.push(Transition {
            action: tag::ACTIONS,
            ..transition(&[0.0], 0)
        });
    }

    /// A sample is the batch of drawing each slot in turn and pushing its transition (the
    /// column buffer's way): the same slots from the same draws, the same values, wrapped
    /// or not.
    #[test]
    fn a_sample_is_each_drawn_transition_in_turn() {
        // Widths with a copy of their own (1–4, 6, 8) and without (5, 11).
        let cases = [1, 2, 3, 4, 5, 6, 8, 11].into_iter().flat_map(|w| {
            [(50, 30), (50, 137)]
                .into_iter()
                .map(move |(capacity, pushes)| (w, capacity, pushes))
        });
        for (width, capacity, pushes) in cases {
            let mut buffer = ReplayBuffer::new(capacity, width);
            for i in 0..pushes {
                let obs: Vec<f32> = (0..width).map(|k| (i * 16 + k) as f32).collect();
                let next: Vec<f32> = obs.iter().map(|x| -x - 0.5).collect();
                buffer.push(Transition {
                    next_obs: &next,
                    ..transition(&obs, i)
                });
            }
            for seed in 0..5 {
                let mut sampled = Batch::new();
                buffer.sample_into(64, &mut sampled, &mut StdRng::seed_from_u64(seed));
                let mut rng = StdRng::seed_from_u64(seed);
                let mut expected = Batch::new();
                expected.clear(width);
                for _ in 0..64 {
                    let slot = rng.random_range(0..buffer.len());
                    expected.push(buffer.get(slot));
                    expected.slots.push(slot);
                }
                assert_eq!(sampled, expected);
            }
        }
    }

    #[test]
    fn same_seed_same_sample() {
        let mut buffer = ReplayBuffer::new(100, 1);
        for i in 0..100 {
            buffer.push(transition(&[i as f32], i));
        }
        let draw = |seed| {
            let mut batch = Batch::new();
            buffer.sample_into(32, &mut batch, &mut StdRng::seed_from_u64(seed));
            batch
        };
        assert_eq!(draw(9), draw(9));
        assert_ne!(draw(9), draw(10));
    }
}
