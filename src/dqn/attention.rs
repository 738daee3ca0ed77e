//! A2T's attention (Rajendran et al., "Attend, Adapt and Transfer", ICLR 2017), for value
//! transfer: a network `f` gives each state a softmax over the N frozen sources and a base
//! network B, and the target task's Q is their mixture,
//!
//! ```text
//! Q_T(s, a) = Σ_i w_i(s)·Q_i(s, a) + w_B(s)·Q_B(s, a),      w(s) = softmax(f(s))
//! ```
//!
//! `f` learns by the TD error of `Q_T` (its own target copy, B's target network and the
//! sources in the target `r + γ·max_a' Q_T⁻(s', a')`), with the config's Huber loss; the
//! base learns by its own TD error, as a DQN, so that it stands on its own when no source
//! helps (A2T's base "learns the task independently"). Through the softmax,
//! `∂Q_T/∂f_k = w_k·(Q_k − Q_T)` ([`logit_gradient`]).
//!
//! The sources are frozen, so their values of each stored transition are computed once,
//! when it arrives, and read by every update that samples it ([`super::source_values`]):
//! the same bits as running the sources on each minibatch, for less (BENCHMARKS.md, issue 40).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use rand::Rng;

use super::backprop::Workspace;
use super::kernels::Isa;
use super::round::{round, Interrupt};
use super::source_values::SourceValues;
use super::{huber, Adam, Architecture, Batch, DqnConfig, DqnError, Init, QNet, ReplayBuffer};

/// The attention network, its target copy and its optimiser.
#[derive(Debug)]
pub struct AttentionLearner {
    online: QNet,
    target: QNet,
    optimizer: Adam,
    config: DqnConfig,
    steps: u64,
    updates: u64,
    interrupt: Interrupt,
    batch: Batch,
    /// The attention's passes, and every other network's (copied out of `scratch`).
    work: Workspace,
    scratch: Workspace,
    /// Per row of a batch: each network's Q-values `[networks][batch × actions]`, sources
    /// first, the base last; and the mixture's target.
    values: Vec<Vec<f32>>,
    targets: Vec<f32>,
    /// The sources' values of every stored transition, when kept (the default).
    source_values: Option<SourceValues>,
}

impl AttentionLearner {
    /// An attention over `sources` sources and a base on observations of `observation_size`,
    /// with `hidden` layers, initialised by `init` from `rng`.
    pub fn new(
        observation_size: usize,
        hidden: &[usize],
        sources: usize,
        init: Init,
        config: &DqnConfig,
        rng: &mut impl Rng,
    ) -> Result<Self, DqnError> {
        let architecture = Architecture::new(observation_size, hidden, sources + 1);
        let online = QNet::with_init(architecture, init, rng)?;
        Ok(Self {
            target: online.deep_copy()?,
            optimizer: Adam::new(online.parameters(), config),
            online,
            config: config.clone(),
            steps: 0,
            updates: 0,
            interrupt: Interrupt::default(),
            batch: Batch::new(),
            work: Workspace::default(),
            scratch: Workspace::default(),
            values: Vec::new(),
            targets: Vec::new(),
            source_values: Some(SourceValues::default()),
        })
    }

    /// Runs the sources on each minibatch instead of keeping their values of the buffer:
    /// the same numbers, at the old cost (the test of the kept values' bits).
    #[cfg(test)]
    fn without_kept_source_values(mut self) -> Self {
        self.source_values = None;
        self
    }

    /// A stop raised on `flag` ends nothing mid-update, but is heard between updates.
    pub fn interrupt_rounds_with(&mut self, flag: Arc<AtomicBool>) {
        self.interrupt = Interrupt::new(flag);
    }

    /// `w(s)`: the weights of the sources, then the base's, for one observation.
    pub fn weights(&self, obs: &[f32]) -> Result<Vec<f32>, DqnError> {
        let mut weights = self.online.q_values(obs)?;
        softmax_in_place(&mut weights);
        Ok(weights)
    }

    /// The sources' Q-values `[source][action]` of `obs`, when kept: `obs` is the next
    /// observation of the transition [`Self::observe`] saw last.
    pub fn kept_source_values(&self, obs: &[f32]) -> Option<&[f32]> {
        self.source_values.as_ref()?.of_latest_next(obs)
    }

    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// Call once per environment step, after its transition is in `replay`, as
    /// [`super::DqnAgent::observe`] is: the target copied every `target_update_interval`
    /// steps, then `gradient_steps` updates every `update_interval` steps once `replay`
    /// holds `replay_start_size` transitions. Returns the last update's loss, if any.
    pub fn observe(
        &mut self,
        replay: &ReplayBuffer,
        rng: &mut impl Rng,
        sources: &[&QNet],
        base: (&QNet, &QNet),
    ) -> Result<Option<f64>, DqnError> {
        self.steps += 1;
        if let Some(kept) = &mut self.source_values {
            kept.follow(Isa::current(), replay, sources)?;
        }
        if self
            .steps
            .is_multiple_of(self.config.target_update_interval)
        {
            self.target.copy_from(&self.online)?;
        }
        if replay.len() < self.config.replay_start_size
            || !self.steps.is_multiple_of(self.config.update_interval)
        {
            return Ok(None);
        }
        let interrupt = self.interrupt.clone();
        let loss = round(
            u64::from(self.config.gradient_steps),
            false,
            &interrupt,
            |_| {
                let mut batch = std::mem::take(&mut self.batch);
                replay.sample_into(self.config.batch_size, &mut batch, rng);
                let result = self.update(&batch, sources, base);
                self.batch = batch;
                result
            },
        )?;
        Ok(loss)
    }

    /// One update of the attention on `batch`; `base` is the base's online and target
    /// networks. Returns the loss; a non-finite one leaves the weights untouched.
    fn update(
        &mut self,
        batch: &Batch,
        sources: &[&QNet],
        base: (&QNet, &QNet),
    ) -> Result<f64, DqnError> {
        let isa = Isa::current();
        let n = batch.len();
        let networks = sources.len() + 1;
        let actions = base.0.architecture().action_count;
        // The target: max_a' of the mixture by the target attention, the sources and the
        // base's target network at s'.
        self.forward_all(isa, batch, true, sources, base.1)?;
        let mut next_weights = self
            .target
            .forward_with(isa, batch.next_obs(), n, &mut self.work)?
            .to_vec();
        next_weights
            .chunks_exact_mut(networks)
            .for_each(softmax_in_place);
        let gamma = self.config.gamma as f32;
        self.targets.clear();
        for b in 0..n {
            let weights = &next_weights[b * networks..(b + 1) * networks];
            let best = (0..actions)
                .map(|a| mixture(weights, &self.values, b * actions + a))
                .fold(f32::MIN, f32::max);
            let terminal = batch.terminated()[b]
                || (self.config.truncation_as_terminal && batch.truncated()[b]);
            let bootstrap = if terminal { 0.0 } else { gamma * best };
            self.targets.push(batch.rewards()[b] + bootstrap);
        }
        // The mixture at (s, a), and the gradient of the Huber loss on the logits.
        self.forward_all(isa, batch, false, sources, base.0)?;
        let logits = self
            .online
            .forward_with(isa, batch.obs(), n, &mut self.work)?;
        let mut grad = vec![0.0f32; n * networks];
        let mut loss = 0.0;
        let delta = self.config.huber_delta;
        let mut weights = vec![0.0f32; networks];
        let mut at_action = vec![0.0f32; networks];
        for b in 0..n {
            weights.copy_from_slice(&logits[b * networks..(b + 1) * networks]);
            softmax_in_place(&mut weights);
            let cell = b * actions + batch.actions()[b] as usize;
            for (value, network) in at_action.iter_mut().zip(&self.values) {
                *value = network[cell];
            }
            let q = mixture(&weights, &self.values, cell);
            let error = f64::from(q) - f64::from(self.targets[b]);
            loss += huber(error, delta);
            let g = (error.clamp(-delta, delta) / n as f64) as f32;
            let row = logit_gradient(&weights, &at_action, q, g);
            grad[b * networks..(b + 1) * networks].copy_from_slice(&row);
        }
        let loss = loss / n as f64;
        if !loss.is_finite() {
            let (step, update) = (self.steps, self.updates + 1);
            return Err(DqnError::NonFiniteLoss { step, update, loss });
        }
        self.online.backward_with(isa, &mut self.work, &grad)?;
        if !self.work.gradients().all_finite() {
            let (step, update) = (self.steps, self.updates + 1);
            return Err(DqnError::NonFiniteGradient { step, update, loss });
        }
        self.optimizer
            .step(self.online.parameters(), self.work.gradients())?;
        self.updates += 1;
        Ok(loss)
    }

    /// Every source's and `base`'s Q-values of `batch`'s observations (or its next ones)
    /// into `values`, sources first: the sources' from the kept values when the batch says
    /// its slots, else by running them.
    fn forward_all(
        &mut self,
        isa: Isa,
        batch: &Batch,
        next: bool,
        sources: &[&QNet],
        base: &QNet,
    ) -> Result<(), DqnError> {
        let n = batch.len();
        let obs = if next { batch.next_obs() } else { batch.obs() };
        self.values.resize_with(sources.len() + 1, Vec::new);
        let (from_sources, from_base) = self.values.split_at_mut(sources.len());
        let kept = self
            .source_values
            .as_ref()
            .and_then(|kept| kept.gather(batch, next, from_sources));
        if kept.is_none() {
            for (values, net) in from_sources.iter_mut().zip(sources) {
                let q = net.forward_with(isa, obs, n, &mut self.scratch)?;
                values.clear();
                values.extend_from_slice(q);
            }
        }
        let q = base.forward_with(isa, obs, n, &mut self.scratch)?;
        from_base[0].clear();
        from_base[0].extend_from_slice(q);
        Ok(())
    }
}

/// `Σ_k w_k·values[k][cell]`: the mixture of every network's Q-value at one cell.
fn mixture(weights: &[f32], values: &[Vec<f32>], cell: usize) -> f32 {
    weights.iter().zip(values).map(|(w, v)| w * v[cell]).sum()
}

/// `∂L/∂f_k = g·w_k·(q_k − Q_T)`: the gradient on the attention's logits of a loss whose
/// gradient on the mixture `Q_T` is `g`, through the softmax (`∂w_j/∂f_k = w_j(δ_jk − w_k)`).
pub fn logit_gradient(weights: &[f32], q: &[f32], mixed: f32, g: f32) -> Vec<f32> {
    weights
        .iter()
        .zip(q)
        .map(|(w, q)| g * w * (q - mixed))
        .collect()
}

/// A row of logits into its softmax, after subtracting its maximum.
pub fn softmax_in_place(row: &mut [f32]) {
    let max = row.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let mut sum = 0.0;
    for x in row.iter_mut() {
        *x = (*x - max).exp();
        sum += *x;
    }
    row.iter_mut().for_each(|x| *x /= sum);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Q_T = Σ_k w_k·q_k` of one state and action, from each network's Q-value there.
    fn mix(weights: &[f32], q: &[f32]) -> f32 {
        weights.iter().zip(q).map(|(w, q)| w * q).sum()
    }

    /// Every parameter of `net`, as bits.
    fn bits(net: &QNet) -> Vec<u32> {
        net.parameters()
            .iter()
            .flat_map(|p| {
                p.as_tensor()
                    .flatten_all()
                    .unwrap()
                    .to_vec1::<f32>()
                    .unwrap()
            })
            .map(f32::to_bits)
            .collect()
    }

    /// The kept source values change no bit of the update: two attentions from one seed,
    /// one running the sources on every minibatch, learn the same weights and losses, over
    /// a buffer that wraps, and from a buffer filled before the attention was made.
    #[test]
    fn kept_source_values_give_the_bits_of_running_the_sources() {
        use crate::dqn::Transition;
        use rand::{rngs::StdRng, SeedableRng};
        let config = DqnConfig {
            replay_start_size: 8,
            replay_capacity: 40,
            batch_size: 16,
            target_update_interval: 25,
            ..DqnConfig::default()
        };
        let mut rng = StdRng::seed_from_u64(5);
        let net = |hidden: &[usize], rng: &mut StdRng| {
            QNet::with_init(Architecture::new(3, hidden, 2), Init::LecunNormal, rng).unwrap()
        };
        let sources = [net(&[7], &mut rng), net(&[5, 4], &mut rng)];
        let sources: Vec<&QNet> = sources.iter().collect();
        let (base, base_target) = (net(&[6], &mut rng), net(&[6], &mut rng));
        let make = || {
            let rng = &mut StdRng::seed_from_u64(9);
            AttentionLearner::new(3, &[8], 2, Init::LecunNormal, &config, rng).unwrap()
        };
        let mut replay = ReplayBuffer::new(config.replay_capacity, 3);
        let mut obs = [0.1f32, -0.2, 0.3];
        let mut push = |replay: &mut ReplayBuffer, i: usize| {
            let next = [obs[1], obs[2] * 0.9, (i as f32 * 0.37).sin()];
            replay.push(Transition {
                obs: &obs,
                action: i % 2,
                reward: (i % 3) as f64,
                next_obs: &next,
                terminated: i % 11 == 10,
                truncated: i % 7 == 6,
            });
            obs = next;
        };
        for i in 0..12 {
            push(&mut replay, i);
        }
        let (mut kept, mut running) = (make(), make().without_kept_source_values());
        let (mut rng_kept, mut rng_running) = (StdRng::seed_from_u64(1), StdRng::seed_from_u64(1));
        for i in 12..120 {
            push(&mut replay, i);
            let a = kept
                .observe(&replay, &mut rng_kept, &sources, (&base, &base_target))
                .unwrap();
            let b = running
                .observe(&replay, &mut rng_running, &sources, (&base, &base_target))
                .unwrap();
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "loss at step {i}");
            // The values kept for the next step's action are the sources' own, bit for bit.
            let next = replay.latest().unwrap().next_obs.to_vec();
            let acting: Vec<u32> = sources
                .iter()
                .flat_map(|s| s.q_values(&next).unwrap())
                .map(f32::to_bits)
                .collect();
            let kept_values = kept.kept_source_values(&next).unwrap();
            assert_eq!(
                kept_values.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                acting
            );
            assert!(kept.kept_source_values(&[9.0, 9.0, 9.0]).is_none());
        }
        assert!(kept.updates() > 100);
        let followed = kept.source_values.as_ref().map(|v| v.pushes());
        assert_eq!(
            followed,
            Some(replay.pushes()),
            "the kept values followed the buffer"
        );
        assert_eq!(bits(&kept.online), bits(&running.online));
    }

    #[test]
    fn the_mixture_weighs_each_networks_value() {
        // The softmax of (0, ln 3) is (¼, ¾).
        let mut weights = [0.0, 3f32.ln()];
        softmax_in_place(&mut weights);
        assert!((weights[0] - 0.25).abs() < 1e-6 && (weights[1] - 0.75).abs() < 1e-6);
        // Q_T = ¼·8 + ¾·4 = 5.
        assert!((mix(&weights, &[8.0, 4.0]) - 5.0).abs() < 1e-6);
    }

    #[test]
    fn the_logits_gradient_is_the_softmax_jacobian_and_matches_finite_differences() {
        // By hand: w = (¼, ¾), q = (8, 4), Q_T = 5, g = 2: (2·¼·3, 2·¾·(−1)) = (1.5, −1.5).
        let weights = [0.25, 0.75];
        assert_eq!(logit_gradient(&weights, &[8.0, 4.0], 5.0, 2.0), [1.5, -1.5]);
        // Three networks: the derivative of Q_T(f) by central differences.
        let logits = [0.3f64, -1.2, 0.7];
        let q = [2.0f64, -1.0, 5.0];
        let q_t = |f: &[f64]| {
            let z: f64 = f.iter().map(|x| x.exp()).sum();
            f.iter().zip(&q).map(|(x, q)| x.exp() / z * q).sum::<f64>()
        };
        let mut w: Vec<f32> = logits.iter().map(|&x| x as f32).collect();
        softmax_in_place(&mut w);
        let q32: Vec<f32> = q.iter().map(|&x| x as f32).collect();
        let grad = logit_gradient(&w, &q32, mix(&w, &q32), 1.0);
        for k in 0..3 {
            let (mut up, mut down) = (logits, logits);
            up[k] += 1e-6;
            down[k] -= 1e-6;
            let numeric = (q_t(&up) - q_t(&down)) / 2e-6;
            assert!(
                (f64::from(grad[k]) - numeric).abs() < 1e-4,
                "{k}: {} vs {numeric}",
                grad[k]
            );
        }
    }
}
