//! The DQN learner (ChainerRL's `DQN` agent, with the hyper-parameters of `DqnConfig`).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use rand::Rng;

use super::backprop::Workspace;
use super::kernels::Isa;
use super::round::{round, Interrupt};
use super::scratch::{with_scratch, UpdateWork};
use super::target_values::TargetValues;
use super::{
    distillation_loss, td_huber_loss, Adam, Batch, DqnError, EpsilonGreedy, QNet, ReplayBuffer,
    Transition,
};
use crate::dqn::DqnConfig;

/// What one round of learning did, for SAP-Net's judgment `T_a = E_{t+1} − E_t` (eq. 7).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdateReport {
    /// The raw loss of the last gradient update of the round.
    pub loss: f64,
    /// The statistic loss `E_t` before the round.
    pub previous_statistic_loss: f64,
    /// The statistic loss `E_{t+1}` after it.
    pub statistic_loss: f64,
    /// The TD error of the transition stored last, before and after the round, when the
    /// learner was asked to measure it ([`DqnAgent::measure_td_error`]).
    pub td: Option<TdError>,
}

/// The TD error `δ = r + γ·(1 − done)·max_a' Q_target(s', a') − Q_online(s, a)` of one
/// transition, with the online net just before a round of updates and just after it (the
/// same target net: a target copy happens before the round). `done` is the update's own:
/// terminated, or truncated under `truncation_as_terminal`. In f32 as the update's targets,
/// reported as f64.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TdError {
    pub before: f64,
    pub after: f64,
}

impl UpdateReport {
    /// `T_a = E_{t+1} − E_t`; `≤ 0` is a positive transition.
    pub fn transition(&self) -> f64 {
        self.statistic_loss - self.previous_statistic_loss
    }
}

/// One policy that acts and learns: an online Q-network, its target copy and its Adam state.
/// It borrows the replay buffer, so several learners can share one.
#[derive(Debug)]
pub struct DqnAgent {
    online: QNet,
    target: QNet,
    optimizer: Adam,
    explorer: EpsilonGreedy,
    config: DqnConfig,
    /// Environment steps this policy has taken (drives ε, updates and target copies).
    steps: u64,
    updates: u64,
    /// `E`, ChainerRL's `average_loss`: an exponential moving average of the loss from 0.
    statistic_loss: f64,
    last_loss: Option<f64>,
    /// Whether each report carries the TD error of the latest transition ([`TdError`]).
    measure_td: bool,
    /// Raised when the run is asked to stop: a round of many updates ends at the next.
    interrupt: Interrupt,
    /// The teacher whose Q-values every update distils, if any (QDagger).
    teacher: Option<Teacher>,
    /// The policy whose value the learner estimates, if not its own greedy one: its
    /// network's greedy action at `s′` is the bootstrap's (GPI's evaluation of a source).
    evaluated_policy: Option<QNet>,
    /// `max_a Q_target(s′, a)` of the replay's transitions under the current target network.
    target_values: TargetValues,
    /// Reused between updates.
    batch: Batch,
    targets: Vec<f32>,
    next_actions: Vec<usize>,
    /// The bootstrap value of each transition of the minibatch (unused where terminal).
    next_values: Vec<f32>,
    /// The minibatch's transitions whose target values are not kept, and their `s′`.
    misses: Vec<usize>,
    miss_obs: Vec<f32>,
}

/// A teacher network distilled into the learner: `L = L_TD + weight · L_distil` at
/// `temperature` ([`distillation_loss`]).
#[derive(Debug)]
struct Teacher {
    net: QNet,
    temperature: f64,
    weight: f64,
}

impl DqnAgent {
    /// A learner that trains `online`; the target network starts as its copy.
    pub fn new(online: QNet, config: &DqnConfig) -> Result<Self, DqnError> {
        Ok(Self {
            target: online.deep_copy()?,
            optimizer: Adam::new(online.parameters(), config),
            explorer: EpsilonGreedy::new(config.exploration.clone()),
            online,
            config: config.clone(),
            steps: 0,
            updates: 0,
            statistic_loss: 0.0,
            last_loss: None,
            measure_td: false,
            interrupt: Interrupt::default(),
            teacher: None,
            evaluated_policy: None,
            target_values: TargetValues::new(),
            batch: Batch::new(),
            targets: Vec::new(),
            next_actions: Vec::new(),
            next_values: Vec::new(),
            misses: Vec::new(),
            miss_obs: Vec::new(),
        })
    }

    /// From now on the learner estimates the value of `policy`'s greedy policy, not of its
    /// own: every target bootstraps on `Q_target(s′, argmax_a policy(s′, a))` — TD
    /// evaluation of a fixed policy (GPI's `Q^{π_i}` on the target task).
    pub fn evaluate_policy_of(&mut self, policy: QNet) {
        self.evaluated_policy = Some(policy);
    }

    /// The ε-greedy action for `obs` at this policy's current step.
    pub fn act(&self, obs: &[f32], rng: &mut impl Rng) -> Result<usize, DqnError> {
        let actions = self.online.architecture().action_count;
        self.explorer
            .choose(self.steps, actions, rng, || self.online.greedy_action(obs))
    }

    /// The random action of this step's ε-greedy exploration, or `None` when the step is
    /// greedy: for a method that makes the greedy choice itself ([`act`](Self::act)'s draws).
    pub fn explore(&self, rng: &mut impl Rng) -> Option<usize> {
        let actions = self.online.architecture().action_count;
        self.explorer.explore(self.steps, actions, rng)
    }

    /// From now on every update also distils `teacher`'s Q-values at `temperature`, with
    /// the weight [`set_distillation_weight`](Self::set_distillation_weight) sets (1 until
    /// then).
    pub fn distil_from(&mut self, teacher: QNet, temperature: f64) {
        self.teacher = Some(Teacher {
            net: teacher,
            temperature,
            weight: 1.0,
        });
    }

    /// QDagger's `λ_t`: the weight of the distillation term from the next update on.
    pub fn set_distillation_weight(&mut self, weight: f64) {
        if let Some(teacher) = &mut self.teacher {
            teacher.weight = weight;
        }
    }

    /// One gradient update on a minibatch of `replay`, the target network copied after
    /// every `target_interval`-th of the learner's updates: a learner that learns without
    /// acting (GPI's evaluation of a source). Returns the loss; none from an empty buffer.
    pub fn learn_once(
        &mut self,
        replay: &ReplayBuffer,
        target_interval: u64,
        rng: &mut impl Rng,
    ) -> Result<Option<f64>, DqnError> {
        if replay.len() < self.config.replay_start_size.max(1) {
            return Ok(None);
        }
        let loss = self.sampled_update(replay, rng)?;
        if self.updates.is_multiple_of(target_interval.max(1)) {
            self.sync_target()?;
        }
        Ok(Some(loss))
    }

    /// `updates` gradient updates on minibatches of `replay` without acting (QDagger's
    /// offline phase), the target network copied every `target_interval` of them (CleanRL's
    /// `target_network_frequency`); returns the last loss. A stop ends the round early,
    /// its learning kept.
    pub fn offline_round(
        &mut self,
        replay: &ReplayBuffer,
        updates: u64,
        target_interval: u64,
        rng: &mut impl Rng,
    ) -> Result<Option<f64>, DqnError> {
        if replay.is_empty() {
            return Ok(None);
        }
        let interrupt = self.interrupt.clone();
        round(updates, true, &interrupt, |k| {
            let loss = self.sampled_update(replay, rng)?;
            if (k + 1).is_multiple_of(target_interval.max(1)) {
                self.sync_target()?;
            }
            Ok(loss)
        })
    }

    /// From now on, every [`UpdateReport`] carries the [`TdError`] of the transition stored
    /// last in the replay buffer: three forward passes of one observation per round (the
    /// target net once, the online net before and after), so it is off unless asked for.
    pub fn measure_td_error(&mut self, on: bool) {
        self.measure_td = on;
    }

    /// A round of updates (up to `gradient_steps`) ends early, its learning kept, once
    /// `flag` is raised: how the run that owns this learner tells it to stop.
    pub fn interrupt_rounds_with(&mut self, flag: Arc<AtomicBool>) {
        self.interrupt = Interrupt::new(flag);
    }

    /// `max_a Q_online(obs, a)`: the online net's value estimate of `obs`.
    pub fn value(&self, obs: &[f32]) -> Result<f64, DqnError> {
        self.online.max_q(obs).map(f64::from)
    }

    /// The greedy action, for testing a policy.
    pub fn greedy_action(&self, obs: &[f32]) -> Result<usize, DqnError> {
        self.online.greedy_action(obs)
    }

    /// Call once for every environment step this policy took, after its transition is in
    /// `replay`. Copies the target network every `target_update_interval` steps, then, once
    /// `replay` holds `replay_start_size` transitions, runs `gradient_steps` updates every
    /// `update_interval` steps (ChainerRL's order). Returns what the updates did, if any.
    pub fn observe(
        &mut self,
        replay: &ReplayBuffer,
        rng: &mut impl Rng,
    ) -> Result<Option<UpdateReport>, DqnError> {
        self.observe_joined(replay, rng, &[])
    }

    /// [`observe`](Self::observe), every target bootstrapping on the action that `joined`
    /// and this learner's online network value most at `s′`, `argmax_a max(Q(s′, a),
    /// max_i Q_i(s′, a))`, valued by the target network: SFQL's bootstrap on the GPI
    /// action, the networks of `joined` being its sources' values.
    pub fn observe_joined(
        &mut self,
        replay: &ReplayBuffer,
        rng: &mut impl Rng,
        joined: &[&QNet],
    ) -> Result<Option<UpdateReport>, DqnError> {
        self.steps += 1;
        if self
            .steps
            .is_multiple_of(self.config.target_update_interval)
        {
            self.sync_target()?;
        }
        if replay.len() < self.config.replay_start_size
            || !self.steps.is_multiple_of(self.config.update_interval)
            || self.config.gradient_steps == 0
        {
            return Ok(None);
        }
        let previous_statistic_loss = self.statistic_loss;
        let td_target = match (self.measure_td, replay.latest()) {
            (true, Some(t)) => Some((self.td_target(&t)?, t)),
            _ => None,
        };
        let td_before = match &td_target {
            Some((y, t)) => Some(self.td_error(*y, t)?),
            None => None,
        };
        // The run stops at its step's end; what the round learned so far is kept.
        let interrupt = self.interrupt.clone();
        let steps = u64::from(self.config.gradient_steps);
        let loss = round(steps, false, &interrupt, |_| {
            self.sampled_update_joined(replay, rng, joined)
        })?
        .unwrap_or(0.0);
        let td = match (td_target, td_before) {
            (Some((y, t)), Some(before)) => Some(TdError {
                before,
                after: self.td_error(y, &t)?,
            }),
            _ => None,
        };
        Ok(Some(UpdateReport {
            loss,
            previous_statistic_loss,
            statistic_loss: self.statistic_loss,
            td,
        }))
    }

    /// `y = r + γ·(1 − done)·max_a' Q_target(s', a')` of one transition, as
    /// [`compute_td_targets`](Self::compute_td_targets) computes it for a batch.
    fn td_target(&self, t: &Transition<'_>) -> Result<f32, DqnError> {
        let terminal = t.terminated || (self.config.truncation_as_terminal && t.truncated);
        let bootstrap = if terminal {
            0.0
        } else {
            self.config.gamma as f32 * self.target.max_q(t.next_obs)?
        };
        Ok(t.reward as f32 + bootstrap)
    }

    /// `δ = y − Q_online(s, a)` with the online net as it is now.
    fn td_error(&self, y: f32, t: &Transition<'_>) -> Result<f64, DqnError> {
        let q = self.online.q_values(t.obs)?[t.action];
        Ok(f64::from(y - q))
    }

    /// One gradient update on a minibatch sampled from `replay`.
    fn sampled_update(
        &mut self,
        replay: &ReplayBuffer,
        rng: &mut impl Rng,
    ) -> Result<f64, DqnError> {
        self.sampled_update_joined(replay, rng, &[])
    }

    /// [`sampled_update`](Self::sampled_update), bootstrapping as
    /// [`observe_joined`](Self::observe_joined) says.
    fn sampled_update_joined(
        &mut self,
        replay: &ReplayBuffer,
        rng: &mut impl Rng,
        joined: &[&QNet],
    ) -> Result<f64, DqnError> {
        let mut batch = std::mem::take(&mut self.batch);
        replay.sample_into(self.config.batch_size, &mut batch, rng);
        let result = self.update_joined(&batch, joined, Some(replay));
        self.batch = batch;
        result
    }

    /// One gradient update on `batch`; returns the loss and folds it into the statistic loss.
    /// A non-finite loss is an error and leaves the weights untouched.
    ///
    /// # Panics
    /// If `batch` is empty.
    pub fn update(&mut self, batch: &Batch) -> Result<f64, DqnError> {
        self.update_joined(batch, &[], None)
    }

    /// An update on `batch`, drawn from `replay` if given (whose slots' target values are
    /// then kept between updates).
    fn update_joined(
        &mut self,
        batch: &Batch,
        joined: &[&QNet],
        replay: Option<&ReplayBuffer>,
    ) -> Result<f64, DqnError> {
        assert!(!batch.is_empty(), "cannot learn from an empty batch");
        with_scratch(|scratch| {
            let work = scratch.for_shape(self.online.architecture(), batch.len());
            self.update_with(batch, work, joined, replay)
        })
    }

    /// [`update`](Self::update) with this thread's buffers for the network's shape.
    fn update_with(
        &mut self,
        batch: &Batch,
        work: &mut UpdateWork,
        joined: &[&QNet],
        replay: Option<&ReplayBuffer>,
    ) -> Result<f64, DqnError> {
        self.compute_td_targets(batch, &mut work.target, joined, replay)?;
        let isa = Isa::current();
        // The targets are copied out: the target's buffers can take the teacher's pass.
        let target_work = &mut work.target;
        let work = &mut work.online;
        let q = self
            .online
            .forward_with(isa, batch.obs(), batch.len(), work)?;
        let (actions, targets, delta) = (batch.actions(), &self.targets, self.config.huber_delta);
        let (mut loss, mut grad_q) = td_huber_loss(q, actions, targets, delta)?;
        if let Some(teacher) = self.teacher.as_ref().filter(|t| t.weight > 0.0) {
            let actions = self.online.architecture().action_count;
            let teacher_q = teacher
                .net
                .forward_with(isa, batch.obs(), batch.len(), target_work)?;
            let (distil, grad) = distillation_loss(q, teacher_q, actions, teacher.temperature);
            loss += teacher.weight * distil;
            for (g, d) in grad_q.iter_mut().zip(grad) {
                *g += (teacher.weight * f64::from(d)) as f32;
            }
        }
        if !loss.is_finite() {
            let (step, update) = (self.steps, self.updates + 1);
            return Err(DqnError::NonFiniteLoss { step, update, loss });
        }
        self.online.backward_with(isa, work, &grad_q)?;
        // A finite loss can still overflow in the backward pass; with finite gradients and
        // the validated Adam parameters the step keeps every weight finite, so the weights
        // are never worse than "last good".
        if !work.gradients().all_finite() {
            let (step, update) = (self.steps, self.updates + 1);
            return Err(DqnError::NonFiniteGradient { step, update, loss });
        }
        self.optimizer
            .step(self.online.parameters(), work.gradients())?;

        self.updates += 1;
        self.last_loss = Some(loss);
        // ChainerRL's two statements, so E matches it to the last bit.
        let decay = self.config.loss_decay;
        self.statistic_loss *= decay;
        self.statistic_loss += (1.0 - decay) * loss;
        Ok(loss)
    }

    /// `y = r + γ·max_a' Q_target(s', a')` for every transition of `batch` (or, for a
    /// learner that evaluates another policy, `γ·Q_target(s′, π(s′))`), without the
    /// bootstrap after a terminal state (or a truncation, if `truncation_as_terminal`).
    /// The values of `max_a' Q_target` of a minibatch drawn from `replay` are kept.
    fn compute_td_targets(
        &mut self,
        batch: &Batch,
        work: &mut Workspace,
        joined: &[&QNet],
        replay: Option<&ReplayBuffer>,
    ) -> Result<(), DqnError> {
        self.next_values.clear();
        self.next_values.resize(batch.len(), 0.0);
        let own_greedy = joined.is_empty() && self.evaluated_policy.is_none();
        match (own_greedy, replay, batch.slots()) {
            (true, Some(replay), Some(slots)) => {
                self.kept_next_values(batch, slots, replay, work)?
            }
            _ => self.computed_next_values(batch, work, joined)?,
        }
        let gamma = self.config.gamma as f32;
        self.targets.clear();
        for (b, &next_value) in self.next_values.iter().enumerate() {
            let bootstrap = if self.terminal(batch, b) {
                0.0
            } else {
                gamma * next_value
            };
            self.targets.push(batch.rewards()[b] + bootstrap);
        }
        Ok(())
    }

    /// Whether transition `b` of `batch` ends the bootstrap: terminated, or truncated
    /// under `truncation_as_terminal`.
    fn terminal(&self, batch: &Batch, b: usize) -> bool {
        batch.terminated()[b] || (self.config.truncation_as_terminal && batch.truncated()[b])
    }

    /// The bootstrap values of every transition of `batch` from one target pass over them
    /// all: `max_a' Q_target(s′, a′)`, or `Q_target(s′, a′)` at the action of the policy
    /// the learner evaluates (its own, or with `joined`, the GPI action).
    fn computed_next_values(
        &mut self,
        batch: &Batch,
        work: &mut Workspace,
        joined: &[&QNet],
    ) -> Result<(), DqnError> {
        if !joined.is_empty() {
            self.gpi_actions(batch, work, joined)?;
        } else if let Some(policy) = &self.evaluated_policy {
            let q = policy.forward_with(Isa::current(), batch.next_obs(), batch.len(), work)?;
            self.next_actions.clear();
            self.next_actions.extend(
                q.chunks_exact(q.len() / batch.len())
                    .map(super::q_values::argmax),
            );
        }
        let next_q =
            self.target
                .forward_with(Isa::current(), batch.next_obs(), batch.len(), work)?;
        let evaluated = self.evaluated_policy.is_some() || !joined.is_empty();
        let rows = next_q.chunks_exact(next_q.len() / batch.len());
        for ((b, row), value) in rows.enumerate().zip(&mut self.next_values) {
            *value = if evaluated {
                row[self.next_actions[b]]
            } else {
                greatest(row)
            };
        }
        Ok(())
    }

    /// `max_a' Q_target(s′, a′)` of the non-terminal transitions of `batch`, drawn from
    /// `replay`'s `slots`: kept values where the current target network gave them before,
    /// one target pass over the others (`target_values.rs`: the same bits either way).
    fn kept_next_values(
        &mut self,
        batch: &Batch,
        slots: &[usize],
        replay: &ReplayBuffer,
        work: &mut Workspace,
    ) -> Result<(), DqnError> {
        self.target_values.follow(replay);
        self.misses.clear();
        self.miss_obs.clear();
        let width = batch.obs_size();
        for (b, &slot) in slots.iter().enumerate() {
            if self.terminal(batch, b) {
                continue;
            }
            match self.target_values.get(slot) {
                Some(value) => self.next_values[b] = value,
                None => {
                    self.misses.push(b);
                    self.miss_obs
                        .extend_from_slice(&batch.next_obs()[b * width..(b + 1) * width]);
                }
            }
        }
        if self.misses.is_empty() {
            return Ok(());
        }
        let next_q =
            self.target
                .forward_with(Isa::current(), &self.miss_obs, self.misses.len(), work)?;
        let rows = next_q.chunks_exact(next_q.len() / self.misses.len());
        for (&b, row) in self.misses.iter().zip(rows) {
            let value = greatest(row);
            self.next_values[b] = value;
            self.target_values.set(slots[b], value);
        }
        Ok(())
    }

    /// The action at each `s′` of `batch` that this learner's online network and `joined`
    /// value most, into `next_actions`.
    fn gpi_actions(
        &mut self,
        batch: &Batch,
        work: &mut Workspace,
        joined: &[&QNet],
    ) -> Result<(), DqnError> {
        let isa = Isa::current();
        let (obs, n) = (batch.next_obs(), batch.len());
        let mut best = self.online.forward_with(isa, obs, n, work)?.to_vec();
        for net in joined {
            let q = net.forward_with(isa, obs, n, work)?;
            best.iter_mut().zip(q).for_each(|(b, &v)| *b = b.max(v));
        }
        self.next_actions.clear();
        self.next_actions.extend(
            best.chunks_exact(best.len() / n)
                .map(super::q_values::argmax),
        );
        Ok(())
    }

    /// Copies the online network into the target network.
    pub fn sync_target(&mut self) -> Result<(), DqnError> {
        self.target_values.forget();
        self.target.copy_from(&self.online)
    }

    /// ε of ε-greedy at this policy's current step.
    pub fn epsilon(&self) -> f64 {
        self.explorer.epsilon(self.steps)
    }

    /// The statistic loss `E` (0 before the first update).
    pub fn statistic_loss(&self) -> f64 {
        self.statistic_loss
    }

    /// The raw loss of the last update.
    pub fn last_loss(&self) -> Option<f64> {
        self.last_loss
    }

    pub fn steps(&self) -> u64 {
        self.steps
    }

    pub fn updates(&self) -> u64 {
        self.updates
    }

    pub fn online(&self) -> &QNet {
        &self.online
    }

    /// The target network, to read: only [`sync_target`](Self::sync_target) may change it
    /// (the learner keeps values it computed, `target_values.rs`).
    pub fn target(&self) -> &QNet {
        &self.target
    }

    /// The trained network, for saving to the policy library.
    pub fn into_online(self) -> QNet {
        self.online
    }
}

/// The largest of `q`, folded from `f32::MIN` in order (a NaN is passed over).
fn greatest(q: &[f32]) -> f32 {
    q.iter().copied().fold(f32::MIN, f32::max)
}
