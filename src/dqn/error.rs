/// What can go wrong while acting or learning.
#[derive(Debug, thiserror::Error)]
pub enum DqnError {
    /// The loss diverged; the weights were left as they were before this update.
    #[error("DQN loss is {loss:?} (not finite) at step {step} of this policy (update {update})")]
    NonFiniteLoss { step: u64, update: u64, loss: f64 },
    /// The loss was finite but a gradient was not; the weights were left as they were.
    #[error(
        "DQN gradient is not finite at step {step} of this policy (update {update}, loss {loss:?})"
    )]
    NonFiniteGradient { step: u64, update: u64, loss: f64 },
    #[error("observation has {got} values, the Q-network takes {expected}")]
    ObservationSize { expected: usize, got: usize },
    #[error("action {action} is out of range for {action_count} actions")]
    ActionOutOfRange { action: usize, action_count: usize },
    #[error("invalid Q-network architecture: {0}")]
    Architecture(String),
    // Not a `source`: the message says it, and a chain prints it once.
    #[error("tensor operation failed: {0}")]
    Candle(candle_core::Error),
}

impl From<candle_core::Error> for DqnError {
    fn from(error: candle_core::Error) -> Self {
        DqnError::Candle(error)
    }
}
