//! Experience replay: a ring buffer of transitions, sampled uniformly with replacement.
//!
//! Transitions live in flat columns (one `Vec` per field, observations `obs_size` floats
//! apiece) that grow as transitions arrive, so a 1e6-transition buffer costs only what it
//! holds. Once full, the oldest transition is overwritten.

use rand::Rng;

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

/// A fixed-capacity ring buffer of transitions.
#[derive(Debug, Clone)]
pub struct ReplayBuffer {
    capacity: usize,
    obs_size: usize,
    /// Slot the next transition is written to once the buffer is full.
    next: usize,
    /// Transitions pushed since the buffer was made.
    pushes: u64,
    obs: Vec<f32>,
    next_obs: Vec<f32>,
    actions: Vec<u32>,
    rewards: Vec<f32>,
    terminated: Vec<bool>,
    truncated: Vec<bool>,
}

impl ReplayBuffer {
    /// # Panics
    /// If `capacity` or `obs_size` is 0.
    pub fn new(capacity: usize, obs_size: usize) -> Self {
        assert!(capacity > 0, "replay capacity must be at least 1");
        assert!(obs_size > 0, "observation size must be at least 1");
        Self {
            capacity,
            obs_size,
            next: 0,
            pushes: 0,
            obs: Vec::new(),
            next_obs: Vec::new(),
            actions: Vec::new(),
            rewards: Vec::new(),
            terminated: Vec::new(),
            truncated: Vec::new(),
        }
    }

    pub fn len(&self) -> usize {
        self.actions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }

    pub fn capacity(&self) -> usize {
        self.capacity
    }

    pub fn obs_size(&self) -> usize {
        self.obs_size
    }

    /// Stores a transition, overwriting the oldest one when full.
    ///
    /// # Panics
    /// If an observation is not `obs_size` long or the action exceeds `u32` (caller bugs).
    pub fn push(&mut self, t: Transition<'_>) {
        assert_eq!(t.obs.len(), self.obs_size, "observation size");
        assert_eq!(t.next_obs.len(), self.obs_size, "next observation size");
        let action = u32::try_from(t.action).expect("action index fits in u32");
        if self.len() < self.capacity {
            self.obs.extend_from_slice(t.obs);
            self.next_obs.extend_from_slice(t.next_obs);
            self.actions.push(action);
            self.rewards.push(t.reward as f32);
            self.terminated.push(t.terminated);
            self.truncated.push(t.truncated);
        } else {
            let i = self.next;
            let span = i * self.obs_size..(i + 1) * self.obs_size;
            self.obs[span.clone()].copy_from_slice(t.obs);
            self.next_obs[span].copy_from_slice(t.next_obs);
            self.actions[i] = action;
            self.rewards[i] = t.reward as f32;
            self.terminated[i] = t.terminated;
            self.truncated[i] = t.truncated;
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

    /// The observations and next observations of the slots `slots`, row-major.
    pub fn observations(&self, slots: std::ops::Range<usize>) -> (&[f32], &[f32]) {
        let span = slots.start * self.obs_size..slots.end * self.obs_size;
        (&self.obs[span.clone()], &self.next_obs[span])
    }

    /// The `i`-th stored transition in slot order (not age order).
    pub fn get(&self, i: usize) -> Transition<'_> {
        let span = i * self.obs_size..(i + 1) * self.obs_size;
        Transition {
            obs: &self.obs[span.clone()],
            action: self.actions[i] as usize,
            reward: f64::from(self.rewards[i]),
            next_obs: &self.next_obs[span],
            terminated: self.terminated[i],
            truncated: self.truncated[i],
        }
    }

    /// The transition stored last, if any.
    pub fn latest(&self) -> Option<Transition<'_>> {
        (!self.is_empty()).then(|| self.get(self.latest_slot()))
    }

    /// Fills `batch` with `size` transitions drawn uniformly with replacement, reusing its
    /// memory; the batch keeps their slots.
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
            batch.push(self.get(slot));
            batch.slots.push(slot);
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
        assert!(buffer.obs.len() == 6 && buffer.obs.capacity() < 1000);
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
