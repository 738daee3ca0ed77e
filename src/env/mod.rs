//! Native classic-control environments, exact to Gymnasium's `classic_control` source,
//! and any Gymnasium task through a Python worker process ([`gymnasium`]).
//!
//! The API has Gymnasium's shape: [`Environment::reset`] returns an observation,
//! [`Environment::step`] returns a [`Step`] with `terminated` and `truncated` kept apart.
//! The internal state is `f64` and observations are `f32`, as Gymnasium returns them, so
//! trajectories recorded from Gymnasium replay bit for bit (`tests/env_vectors.rs`).
//!
//! Every physical constant comes from a parameter struct read from the config, so task
//! variants (a heavier pole, a weaker car) are a config change. This module depends on
//! nothing else in the crate.
//!
//! Observations are borrowed from the environment ([`Step::obs`]): a native environment
//! keeps its few values inline, a Gymnasium one a buffer sized once, so no step allocates.

mod acrobot;
mod cartpole;
pub mod gymnasium;
pub mod mapping;
mod mountain_car;
mod params;
mod rules;

pub use acrobot::Acrobot;
pub use cartpole::CartPole;
pub use gymnasium::{GymnasiumParams, PythonSettings, WorkerTimeouts};
pub use mountain_car::MountainCar;
pub use params::{
    AcrobotParams, ActionSet, CartPoleParams, EnvConfig, Integrator, MountainCarParams,
};

/// What one call of [`Environment::step`] returns (Gymnasium's 5-tuple without `info`).
/// The observation is borrowed from the environment, which keeps it until its next step
/// or reset: no step allocates, however long the observation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step<'a> {
    pub obs: &'a [f32],
    pub reward: f64,
    /// The task's terminal condition was reached: do not bootstrap from `obs`.
    pub terminated: bool,
    /// The time limit was reached. Set even when `terminated` is also set, as Gymnasium's
    /// `TimeLimit` wrapper does.
    pub truncated: bool,
}

impl Step<'_> {
    /// The episode is over, for either reason.
    pub fn done(&self) -> bool {
        self.terminated || self.truncated
    }
}

/// Why an environment could not do what it was asked. The native environments fail only
/// on a state of the wrong length; a Gymnasium environment ([`gymnasium`]) also when its
/// Python side cannot start, raises, or dies.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EnvError {
    #[error("{env} has a state of {expected} values, got {got}")]
    WrongLength {
        env: String,
        expected: usize,
        got: usize,
    },
    #[error("{0}")]
    Gymnasium(String),
    /// A wait for a Gymnasium worker ended because the process is stopping (a signal).
    #[error("stopped while waiting for the Python side")]
    Interrupted,
}

impl EnvError {
    /// `state` as the fixed-size array an environment keeps, or the error naming `env`.
    fn check_length<const N: usize>(env: &str, state: &[f64]) -> Result<[f64; N], Self> {
        state.try_into().map_err(|_| EnvError::WrongLength {
            env: env.to_string(),
            expected: N,
            got: state.len(),
        })
    }
}

/// A Gymnasium-shaped episodic environment with discrete actions and a 1-D observation.
pub trait Environment: Send {
    /// Gymnasium's environment id, e.g. `CartPole-v1`.
    fn id(&self) -> &str;
    /// Length of an observation vector.
    fn observation_size(&self) -> usize;
    /// Number of discrete actions.
    fn action_count(&self) -> usize;
    /// Starts an episode and returns its first observation. `Some(seed)` reseeds the
    /// environment's generator, `None` continues it (Gymnasium's `reset(seed=None)`).
    fn reset(&mut self, seed: Option<u64>) -> Result<&[f32], EnvError>;
    /// Applies `action` (`0..action_count()`).
    ///
    /// # Panics
    /// If `action` is out of range: that is a bug in the caller, not bad input.
    fn step(&mut self, action: usize) -> Result<Step<'_>, EnvError>;
    /// The observation of the current state (Gymnasium's `_get_ob`), e.g. after
    /// [`set_state`](Environment::set_state).
    fn observation(&self) -> &[f32];
    /// The internal `f64` state (empty for an environment that does not expose one).
    fn state(&self) -> &[f64];
    /// Overwrites the internal state (as Gymnasium's `env.unwrapped.state = …`), for tests
    /// and replays. Does not touch the step counter.
    fn set_state(&mut self, state: &[f64]) -> Result<(), EnvError>;
    /// Steps taken since the last reset.
    fn elapsed_steps(&self) -> u32;
}

/// Builds the environment a config describes (for a Gymnasium task, starts its Python
/// side: [`gymnasium::Gymnasium::start`]).
pub fn make(config: &EnvConfig) -> Result<Box<dyn Environment>, EnvError> {
    Ok(match config {
        EnvConfig::CartPole(p) => Box::new(CartPole::new(p.clone())),
        EnvConfig::MountainCar(p) => Box::new(MountainCar::new(p.clone())),
        EnvConfig::Acrobot(p) => Box::new(Acrobot::new(p.clone())),
        EnvConfig::Gymnasium(p) => Box::new(gymnasium::Gymnasium::start(p)?),
    })
}

/// The observation size and action count of the task a config describes, without
/// stepping it (a Gymnasium task's are asked of it once per process and kept).
pub fn spaces(config: &EnvConfig) -> Result<(usize, usize), EnvError> {
    Ok(match config {
        EnvConfig::CartPole(p) => (4, p.actions.count()),
        EnvConfig::MountainCar(p) => (2, p.actions.count()),
        EnvConfig::Acrobot(_) => (6, 3),
        EnvConfig::Gymnasium(p) => gymnasium::spaces(p)?,
    })
}
