//! What SAP-Net knows about a policy: the features it is categorised by (paper II-C).

use serde::{Deserialize, Serialize};

/// The features of a learned policy that prototypes read. Plain data: the Q-network itself
/// never enters SAP-Net.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolicyDescription {
    /// Units of each hidden layer, input side first.
    pub hidden: Vec<usize>,
    /// The hidden layers' activation function, e.g. `"relu"`.
    #[serde(default = "default_activation")]
    pub activation: String,
    /// The task the policy was trained on, e.g. `"CartPole-v1"`.
    #[serde(default)]
    pub source_task: String,
}

fn default_activation() -> String {
    "relu".to_string()
}

impl PolicyDescription {
    /// A ReLU network with these hidden layers, trained on `source_task`.
    pub fn new(hidden: Vec<usize>, source_task: impl Into<String>) -> Self {
        Self {
            hidden,
            activation: default_activation(),
            source_task: source_task.into(),
        }
    }
}
