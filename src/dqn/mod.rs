//! Deep Q-learning on candle: the Q-network, the replay buffer, ε-greedy exploration, the
//! optimiser and the learner.
//!
//! Nothing outside this module and the policy store touches candle types. Every random
//! choice takes the caller's generator, so one seed gives the same numbers.
//!
//! The learner does not own its replay buffer: in the transfer loop (Algorithm 3) N learners
//! train from one shared buffer, so [`DqnAgent::observe`] borrows it.

mod agent;
mod attention;
mod backprop;
mod config;
mod distill;
mod error;
mod exploration;
mod frozen;
pub mod kernels;
mod live_units;
mod loss;
mod optim;
mod q_values;
mod qnet;
mod replay;
mod round;
mod scratch;
mod source_values;
mod target_values;

pub use agent::{DqnAgent, TdError, UpdateReport};
pub use attention::AttentionLearner;
pub use backprop::Gradients;
pub use config::{DqnConfig, Exploration};
pub use distill::distillation_loss;
pub use error::DqnError;
pub use exploration::EpsilonGreedy;
pub use frozen::FrozenNet;
pub use loss::{huber, td_huber_loss};
pub use optim::Adam;
pub use qnet::{Architecture, Init, QNet};
pub use replay::{transition_bytes, Batch, ReplayBuffer, Transition};
pub use target_values::BYTES_PER_TRANSITION as TARGET_VALUE_BYTES;
