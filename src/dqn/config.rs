//! The DQN's hyper-parameters (Table I, ChainerRL's defaults where the paper is silent), as
//! a config's `dqn` section reads them, with the ranges serde cannot check.

use serde::{Deserialize, Serialize};

use super::Init;
use crate::limits::{MAX_BATCH, MAX_GRADIENT_STEPS};
use crate::ron_file::check;

/// How ε of ε-greedy evolves over the steps of a policy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Exploration {
    /// The paper: ε constant (Table I: 0.03).
    Constant { epsilon: f64 },
    /// ε falls linearly from `start` to `end` over `steps` steps, then stays at `end`.
    Linear { start: f64, end: f64, steps: u64 },
}

/// DQN hyper-parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DqnConfig {
    /// γ, the discount rate (Table I: 0.99).
    pub gamma: f64,
    /// Adam's learning rate (ChainerRL's default 1e-3).
    pub learning_rate: f64,
    /// Adam's ε (Table I: 1e-3).
    pub adam_epsilon: f64,
    /// Adam's β₁ and β₂.
    pub adam_betas: (f64, f64),
    /// Minibatch size of one update (ChainerRL: 32).
    pub batch_size: usize,
    /// Transitions the replay buffer holds (Table I: 1e6).
    pub replay_capacity: usize,
    /// Steps stored before updates begin (Table I: 50 CartPole, 100 MountainCar).
    pub replay_start_size: usize,
    /// Environment steps between rounds of updates (ChainerRL: 1).
    pub update_interval: u64,
    /// Gradient updates per round (ChainerRL: 1).
    pub gradient_steps: u32,
    /// Steps between hard copies of the online network into the target network
    /// (ChainerRL's default 10,000; decides whether the paper's setting learns at all).
    pub target_update_interval: u64,
    /// Huber loss threshold (ChainerRL `clip_delta=True`: 1).
    pub huber_delta: f64,
    /// Clip the gradients' global norm to this value (SB3: 10; ChainerRL: none).
    pub max_grad_norm: Option<f64>,
    /// Decay of the statistic loss, the moving average the SAP-Net judgment reads
    /// (ChainerRL's `average_loss`: 0.99).
    pub loss_decay: f64,
    pub exploration: Exploration,
    /// Treat a time-limit truncation as terminal (old Gym and ChainerRL did); Gymnasium
    /// semantics (`false`) keep bootstrapping through it.
    pub truncation_as_terminal: bool,
    /// How a new Q-network is drawn: `LecunNormal` (Chainer's, the paper's) or
    /// `TorchDefault` (PyTorch's, Stable-Baselines3's).
    pub init: Init,
}

impl Default for DqnConfig {
    fn default() -> Self {
        Self {
            gamma: 0.99,
            learning_rate: 1e-3,
            adam_epsilon: 1e-3,
            adam_betas: (0.9, 0.999),
            batch_size: 32,
            replay_capacity: 1_000_000,
            replay_start_size: 50,
            update_interval: 1,
            gradient_steps: 1,
            target_update_interval: 10_000,
            huber_delta: 1.0,
            max_grad_norm: None,
            loss_decay: 0.99,
            exploration: Exploration::Constant { epsilon: 0.03 },
            truncation_as_terminal: false,
            init: Init::LecunNormal,
        }
    }
}

impl DqnConfig {
    /// Checks the ranges serde cannot, for the section at `prefix` (`dqn`, `sources.dqn`).
    pub fn validate(&self, prefix: &str) -> Result<(), String> {
        let d = self;
        check(
            d.gamma >= 0.0 && d.gamma <= 1.0,
            &format!("{prefix}.gamma"),
            "a number in [0, 1]",
            d.gamma,
        )?;
        let positive = |x: f64| x > 0.0 && x.is_finite();
        check(
            positive(d.learning_rate),
            &format!("{prefix}.learning_rate"),
            "a finite number > 0",
            d.learning_rate,
        )?;
        check(
            positive(d.adam_epsilon),
            &format!("{prefix}.adam_epsilon"),
            "a finite number > 0",
            d.adam_epsilon,
        )?;
        let (beta1, beta2) = d.adam_betas;
        check(
            (0.0..1.0).contains(&beta1) && (0.0..1.0).contains(&beta2),
            &format!("{prefix}.adam_betas"),
            "(β₁, β₂) with each in [0, 1)",
            format!("({beta1}, {beta2})"),
        )?;
        check(
            d.batch_size > 0,
            &format!("{prefix}.batch_size"),
            "at least 1",
            d.batch_size,
        )?;
        check(
            d.replay_capacity >= d.batch_size,
            &format!("{prefix}.replay_capacity"),
            "at least dqn.batch_size",
            d.replay_capacity,
        )?;
        check(
            d.update_interval > 0,
            &format!("{prefix}.update_interval"),
            "at least 1",
            d.update_interval,
        )?;
        check(
            (1..=MAX_GRADIENT_STEPS).contains(&d.gradient_steps),
            &format!("{prefix}.gradient_steps"),
            &format!("1 to {MAX_GRADIENT_STEPS} updates per round (0 never learns)"),
            d.gradient_steps,
        )?;
        check(
            d.batch_size <= MAX_BATCH,
            &format!("{prefix}.batch_size"),
            &format!("at most {MAX_BATCH}"),
            d.batch_size,
        )?;
        check(
            d.replay_start_size <= d.replay_capacity,
            &format!("{prefix}.replay_start_size"),
            &format!(
                "at most {prefix}.replay_capacity ({}): a buffer that never holds that many \
             never starts learning",
                d.replay_capacity
            ),
            d.replay_start_size,
        )?;
        check(
            d.target_update_interval > 0,
            &format!("{prefix}.target_update_interval"),
            "at least 1",
            d.target_update_interval,
        )?;
        check(
            positive(d.huber_delta),
            &format!("{prefix}.huber_delta"),
            "a number > 0",
            d.huber_delta,
        )?;
        check(
            d.loss_decay >= 0.0 && d.loss_decay < 1.0,
            &format!("{prefix}.loss_decay"),
            "a number in [0, 1)",
            d.loss_decay,
        )?;
        if let Some(norm) = d.max_grad_norm {
            check(
                norm > 0.0,
                &format!("{prefix}.max_grad_norm"),
                "a number > 0",
                norm,
            )?;
        }
        d.exploration.validate(&format!("{prefix}.exploration"))
    }
}

impl Exploration {
    /// ε values are probabilities; `field` is where the schedule sits in the config.
    pub fn validate(&self, field: &str) -> Result<(), String> {
        let probability = |value: f64, name: &str| {
            check(
                (0.0..=1.0).contains(&value),
                &format!("{field}.{name}"),
                "a number in [0, 1]",
                value,
            )
        };
        match *self {
            Exploration::Constant { epsilon } => probability(epsilon, "epsilon"),
            Exploration::Linear { start, end, .. } => {
                probability(start, "start").and_then(|()| probability(end, "end"))
            }
        }
    }
}
