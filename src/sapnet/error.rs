//! What can be wrong with a SAP-Net before it runs.

/// A graph or parameter SAP-Net refuses. Every variant names the pair, policy or parameter
/// at fault, so a config error can point at the line to fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SapNetError {
    #[error(
        "edge ({i}, {j}) weighs {weight:?}: every edge weight must be a finite number > 0, \
         or spreading would never end"
    )]
    BadWeight { i: usize, j: usize, weight: f64 },
    #[error(
        "one activation could make up to {calls:.2e} deposits (lightest edge {lightest}, \
         T_ω = {threshold}, a policy with {degree} neighbours); the limit is {limit:.0e}: \
         raise the lightest weight or lower the threshold"
    )]
    UnboundedSpreading {
        calls: f64,
        limit: f64,
        lightest: f64,
        threshold: f64,
        degree: usize,
    },
    #[error("edge ({i}, {j}) names a policy that does not exist: there are {n} policies, numbered from 0")]
    EdgeOutOfRange { i: usize, j: usize, n: usize },
    #[error("policies {i} and {j} are not joined: there is no edge to change")]
    NoEdge { i: usize, j: usize },
    #[error("edge ({i}, {i}) joins a policy to itself")]
    SelfLoop { i: usize },
    #[error("edge ({i}, {j}) is listed twice")]
    DuplicateEdge { i: usize, j: usize },
    #[error("parameter `{name}` is {value:?}: expected {expected}")]
    BadParameter {
        name: String,
        value: f64,
        expected: &'static str,
    },
    #[error(
        "the activated coefficient 𝒜 = {coefficient:?} is too large: 10^12 activations over \
         this graph could take an activation past the largest number an f64 holds (it would \
         read inf, and the probabilities NaN); expected |𝒜| ≤ {most:.3e}"
    )]
    ActivationOverflow { coefficient: f64, most: f64 },
    #[error("{got} initial activations given for {n} policies")]
    ActivationCount { n: usize, got: usize },
    #[error("initial activation of policy {i} is {value:?}: expected a finite number")]
    BadActivation { i: usize, value: f64 },
    #[error("policy {i} does not exist: there are {n} policies, numbered from 0")]
    NoSuchPolicy { i: usize, n: usize },
}
