//! Native classic-control environments, exact to Gymnasium's `classic_control` source.
//!
//! The API has Gymnasium's shape: [`Environment::reset`] returns an observation,
//! [`Environment::step`] returns a [`Step`] with `terminated` and `truncated` kept apart.
//! The internal state is `f64` and observations are `f32`, as Gymnasium returns them, so
//! trajectories recorded from Gymnasium replay bit for bit (`tests/env_vectors.rs`).
//!
//! Every physical constant comes from a parameter struct read from the config, so task
//! variants (a heavier pole, a weaker car) are a config change. This module depends on
//! nothing else in the crate.

mod acrobot;
mod cartpole;
mod mountain_car;
mod observation;
mod params;

pub use acrobot::Acrobot;
pub use cartpole::CartPole;
pub use mountain_car::MountainCar;
pub use observation::{Observation, MAX_OBSERVATION_SIZE};
pub use params::{AcrobotParams, CartPoleParams, EnvConfig, Integrator, MountainCarParams};

/// What one call of [`Environment::step`] returns (Gymnasium's 5-tuple without `info`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    pub obs: Observation,
    pub reward: f64,
    /// The task's terminal condition was reached: do not bootstrap from `obs`.
    pub terminated: bool,
    /// The time limit was reached. Set even when `terminated` is also set, as Gymnasium's
    /// `TimeLimit` wrapper does.
    pub truncated: bool,
}

impl Step {
    /// The episode is over, for either reason.
    pub fn done(&self) -> bool {
        self.terminated || self.truncated
    }
}

/// An error from setting an environment's internal state by hand.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StateError {
    #[error("{env} has a state of {expected} values, got {got}")]
    WrongLength {
        env: &'static str,
        expected: usize,
        got: usize,
    },
}

impl StateError {
    /// `state` as the fixed-size array an environment keeps, or the error naming `env`.
    fn check_length<const N: usize>(env: &'static str, state: &[f64]) -> Result<[f64; N], Self> {
        state.try_into().map_err(|_| StateError::WrongLength {
            env,
            expected: N,
            got: state.len(),
        })
    }
}

/// A Gymnasium-shaped episodic environment with discrete actions.
pub trait Environment: Send {
    /// Gymnasium's environment id, e.g. `CartPole-v1`.
    fn id(&self) -> &'static str;
    /// Length of an observation vector.
    fn observation_size(&self) -> usize;
    /// Number of discrete actions.
    fn action_count(&self) -> usize;
    /// Starts an episode. `Some(seed)` reseeds the environment's generator, `None` continues
    /// it (Gymnasium's `reset(seed=None)`).
    fn reset(&mut self, seed: Option<u64>) -> Observation;
    /// Applies `action` (`0..action_count()`).
    ///
    /// # Panics
    /// If `action` is out of range: that is a bug in the caller, not bad input.
    fn step(&mut self, action: usize) -> Step;
    /// The observation of the current state (Gymnasium's `_get_ob`), e.g. after
    /// [`set_state`](Environment::set_state).
    fn observation(&self) -> Observation;
    /// The internal `f64` state.
    fn state(&self) -> &[f64];
    /// Overwrites the internal state (as Gymnasium's `env.unwrapped.state = …`), for tests
    /// and replays. Does not touch the step counter.
    fn set_state(&mut self, state: &[f64]) -> Result<(), StateError>;
    /// Steps taken since the last reset.
    fn elapsed_steps(&self) -> u32;
}

/// Builds the environment a config describes.
pub fn make(config: &EnvConfig) -> Box<dyn Environment> {
    match config {
        EnvConfig::CartPole(p) => Box::new(CartPole::new(p.clone())),
        EnvConfig::MountainCar(p) => Box::new(MountainCar::new(p.clone())),
        EnvConfig::Acrobot(p) => Box::new(Acrobot::new(p.clone())),
    }
}
