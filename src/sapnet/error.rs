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
        "one activation could make {} deposits (lightest edge {lightest}, \
         T_ω = {threshold}, a policy with {degree} neighbours); the limit is {limit:.0e}: \
         raise the lightest weight or lower the threshold",
        deposits(*.calls)
    )]
    UnboundedSpreading {
        calls: f64,
        limit: f64,
        lightest: f64,
        threshold: f64,
        degree: usize,
    },
    #[error("edge ({i}, {j}) names a policy that does not exist: {}", numbered(*.n))]
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
    #[error("policy {i} does not exist: {}", numbered(*.n))]
    NoSuchPolicy { i: usize, n: usize },
}

/// "the graph's policies are numbered from 0 to 9", or its one policy is numbered 0.
fn numbered(n: usize) -> String {
    match n {
        0 => "the graph has no policies".to_string(),
        1 => "the graph's one policy is numbered 0".to_string(),
        n => format!("the graph's policies are numbered from 0 to {}", n - 1),
    }
}

/// How many deposits an activation could make, where the count itself may overflow.
fn deposits(calls: f64) -> String {
    if calls.is_finite() {
        format!("up to {calls:.2e}")
    } else {
        "more than an f64 can count".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_read_as_english_at_one_and_at_infinity() {
        let one = SapNetError::NoSuchPolicy { i: 5, n: 1 }.to_string();
        assert_eq!(
            one,
            "policy 5 does not exist: the graph's one policy is numbered 0"
        );
        let ten = SapNetError::NoSuchPolicy { i: 10, n: 10 }.to_string();
        assert!(
            ten.ends_with("the graph's policies are numbered from 0 to 9"),
            "{ten}"
        );
        let endless = SapNetError::UnboundedSpreading {
            calls: f64::INFINITY,
            limit: 1e9,
            lightest: 1e-300,
            threshold: 1.0,
            degree: 3,
        }
        .to_string();
        assert!(
            endless.starts_with("one activation could make more than an f64 can count deposits"),
            "{endless}"
        );
    }
}
