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

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use rand::Rng;

use super::backprop::Workspace;
use super::kernels::Isa;
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
    interrupt: Option<Arc<AtomicBool>>,
    batch: Batch,
    /// The attention's passes, and every other network's (copied out of `scratch`).
    work: Workspace,
    scratch: Workspace,
    /// Per row of a batch: each network's Q-values `[networks][batch × actions]`, sources
    /// first, the base last; and the mixture's target.
    values: Vec<Vec<f32>>,
    targets: Vec<f32>,
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
            interrupt: None,
            batch: Batch::new(),
            work: Workspace::default(),
            scratch: Workspace::default(),
            values: Vec::new(),
            targets: Vec::new(),
        })
    }

    /// A stop raised on `flag` ends nothing mid-update, but is heard between updates.
    pub fn interrupt_rounds_with(&mut self, flag: Arc<AtomicBool>) {
        self.interrupt = Some(flag);
    }

    /// `w(s)`: the weights of the sources, then the base's, for one observation.
    pub fn weights(&self, obs: &[f32]) -> Result<Vec<f32>, DqnError> {
        let mut weights = self.online.q_values(obs)?;
        softmax_in_place(&mut weights);
        Ok(weights)
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
        let mut loss = None;
        for k in 0..self.config.gradient_steps {
            if k > 0
                && self
                    .interrupt
                    .as_ref()
                    .is_some_and(|f| f.load(Ordering::Relaxed))
            {
                break;
            }
            let mut batch = std::mem::take(&mut self.batch);
            replay.sample_into(self.config.batch_size, &mut batch, rng);
            let result = self.update(&batch, sources, base);
            self.batch = batch;
            loss = Some(result?);
        }
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
        self.forward_all(isa, batch.next_obs(), n, sources, base.1)?;
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
        self.forward_all(isa, batch.obs(), n, sources, base.0)?;
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

    /// Every source's and `base`'s Q-values of `obs` into `values`, sources first.
    fn forward_all(
        &mut self,
        isa: Isa,
        obs: &[f32],
        batch: usize,
        sources: &[&QNet],
        base: &QNet,
    ) -> Result<(), DqnError> {
        self.values.resize_with(sources.len() + 1, Vec::new);
        for (values, net) in self
            .values
            .iter_mut()
            .zip(sources.iter().copied().chain([base]))
        {
            let q = net.forward_with(isa, obs, batch, &mut self.scratch)?;
            values.clear();
            values.extend_from_slice(q);
        }
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
