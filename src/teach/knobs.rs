//! Teach mode's live edits: the parameters a teacher turns to show what each one does to a
//! walk (T_ω, 𝒜, τ, the path mode, one edge's weight), and what the turn changed.
//!
//! An edit builds a new net with the same activations, so every bound the net keeps
//! (weights > 0, spreading that ends, activations that stay finite) refuses a turn too far
//! with the net's own message, and the lesson goes on unchanged.

use crate::sapnet::{Paths, SapNet, SapNetError};

/// What `+` and `−` change in teach mode, chosen with `1`…`5`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Knob {
    /// T_ω, the threshold on the path weight Ω (eq. 10).
    #[default]
    Threshold,
    /// 𝒜, the activated coefficient (eq. 8).
    Coefficient,
    /// τ, the softmax temperature (eq. 6).
    Temperature,
    /// Literal or simple walks (Algorithm 2).
    Paths,
    /// M_ij of the selected edge (eq. 3–5): a distance, the smaller the further activation
    /// spreads.
    EdgeWeight,
}

/// How far one `+` or `−` turns a knob.
const THRESHOLD_STEP: f64 = 0.1;
const COEFFICIENT_STEP: f64 = 0.5;
const WEIGHT_STEP: f64 = 0.1;
/// τ is a scale: `+` doubles it, `−` halves it.
const TEMPERATURE_FACTOR: f64 = 2.0;

impl Knob {
    pub const ALL: [Knob; 5] = [
        Knob::Threshold,
        Knob::Coefficient,
        Knob::Temperature,
        Knob::Paths,
        Knob::EdgeWeight,
    ];

    /// The key that chooses it.
    pub const fn key(self) -> char {
        match self {
            Knob::Threshold => '1',
            Knob::Coefficient => '2',
            Knob::Temperature => '3',
            Knob::Paths => '4',
            Knob::EdgeWeight => '5',
        }
    }

    /// Its symbol on screen.
    pub fn symbol(self) -> &'static str {
        match self {
            Knob::Threshold => "T_ω",
            Knob::Coefficient => "𝒜",
            Knob::Temperature => "τ",
            Knob::Paths => "paths",
            Knob::EdgeWeight => "M",
        }
    }

    /// The knob's value on `net` as shown (`edge`: the selected edge, for `EdgeWeight`).
    pub fn value(self, net: &SapNet, edge: Option<(usize, usize)>) -> String {
        let params = net.params();
        match self {
            Knob::Threshold => params.threshold.to_string(),
            Knob::Coefficient => params.coefficient.to_string(),
            Knob::Temperature => params.temperature.to_string(),
            Knob::Paths => paths_name(params.paths).to_string(),
            Knob::EdgeWeight => edge
                .and_then(|(i, j)| net.graph().weight(i, j))
                .map_or("-".to_string(), |w| w.to_string()),
        }
    }

    /// `net` with this knob turned one step `up` (or down), the activations kept.
    ///
    /// # Errors
    /// The net's refusal of the new value (a weight or T_ω ≤ 0, spreading that would not
    /// end, a τ of 0), or [`SapNetError::NoEdge`] for an edge weight with no edge selected.
    pub fn turn(
        self,
        net: &SapNet,
        edge: Option<(usize, usize)>,
        up: bool,
    ) -> Result<SapNet, SapNetError> {
        let sign = if up { 1.0 } else { -1.0 };
        let mut params = net.params().clone();
        let mut graph = net.graph().clone();
        match self {
            Knob::Threshold => params.threshold = stepped(params.threshold, sign * THRESHOLD_STEP),
            Knob::Coefficient => {
                params.coefficient = stepped(params.coefficient, sign * COEFFICIENT_STEP)
            }
            Knob::Temperature => {
                params.temperature *= TEMPERATURE_FACTOR.powf(sign);
            }
            Knob::Paths => {
                params.paths = match params.paths {
                    Paths::Literal => Paths::Simple,
                    Paths::Simple => Paths::Literal,
                }
            }
            Knob::EdgeWeight => {
                let (i, j) = edge.ok_or(SapNetError::NoEdge { i: 0, j: 0 })?;
                let weight = graph.weight(i, j).ok_or(SapNetError::NoEdge { i, j })?;
                graph = graph.with_weight(i, j, stepped(weight, sign * WEIGHT_STEP))?;
            }
        }
        SapNet::with_activations(graph, params, net.activations().to_vec())
    }
}

/// Why the net refused a turn, with its policies called as the screen calls them (`names`):
/// the net's own message numbers them from 0.
pub fn refusal(refused: &SapNetError, names: &[String]) -> String {
    match *refused {
        SapNetError::BadWeight { i, j, weight } => format!(
            "M({},{}) would weigh {weight}: every edge weight must be a finite number > 0, \
             or spreading would never end",
            names[i], names[j]
        ),
        SapNetError::NoEdge { i, j } => format!(
            "{} and {} are not joined: there is no edge to change",
            names[i], names[j]
        ),
        ref other => other.to_string(),
    }
}

pub fn paths_name(paths: Paths) -> &'static str {
    match paths {
        Paths::Literal => "literal",
        Paths::Simple => "simple",
    }
}

/// `value + step`, rounded to 9 decimals so that ten steps of 0.1 read 1, not
/// 0.9999999999999999.
fn stepped(value: f64, step: f64) -> f64 {
    ((value + step) * 1e9).round() / 1e9
}

/// What an edit changed: the setting, and the walk in progress run to its end before and
/// after (or, with no walk, the activations as they stand).
#[derive(Debug, Clone, PartialEq)]
pub struct EditReport {
    pub knob: Knob,
    /// The edge whose weight was edited (`EdgeWeight` only).
    pub edge: Option<(usize, usize)>,
    pub from: String,
    pub to: String,
    /// The walk that was restarted, if one was on screen.
    pub policy: Option<usize>,
    /// Calls of the whole walk before and after the edit.
    pub calls: (usize, usize),
    /// A at the walk's end before and after the edit.
    pub activations: (Vec<f64>, Vec<f64>),
    /// P (eq. 6) at the walk's end before and after the edit.
    pub probabilities: (Vec<f64>, Vec<f64>),
}

impl EditReport {
    /// After − before of A at the walk's end, per policy.
    pub fn activation_change(&self) -> Vec<f64> {
        difference(&self.activations)
    }

    /// After − before of P at the walk's end, per policy.
    pub fn probability_change(&self) -> Vec<f64> {
        difference(&self.probabilities)
    }
}

fn difference((before, after): &(Vec<f64>, Vec<f64>)) -> Vec<f64> {
    after.iter().zip(before).map(|(a, b)| a - b).collect()
}

/// The end of a walk activating `policy` from `before` on `net`: the activations, their
/// probabilities and the number of `spread` calls.
pub fn walk_end(
    net: &SapNet,
    policy: Option<usize>,
    before: &[f64],
) -> (Vec<f64>, Vec<f64>, usize) {
    let mut net = net.clone();
    net.set_activations(before.to_vec())
        .expect("activations of the same graph");
    let mut calls = crate::sapnet::CallCount::default();
    if let Some(i) = policy {
        net.activate_traced(i, true, &mut calls);
    }
    let probabilities = net.probabilities();
    (net.activations().to_vec(), probabilities, calls.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teach::lesson::TeachConfig;

    fn fig2() -> SapNet {
        TeachConfig::load(None).expect("embedded Fig. 2").net
    }

    #[test]
    fn each_knob_turns_its_own_setting_and_keeps_the_activations() {
        let mut net = fig2();
        net.activate(1, true);
        let edge = Some((0, 1));
        let up = |k: Knob| k.turn(&net, edge, true).unwrap();
        assert_eq!(up(Knob::Threshold).params().threshold, 1.1);
        assert_eq!(up(Knob::Coefficient).params().coefficient, 1.5);
        assert_eq!(up(Knob::Temperature).params().temperature, 2.0);
        assert_eq!(up(Knob::Paths).params().paths, Paths::Simple);
        assert_eq!(up(Knob::EdgeWeight).graph().weight(1, 0), Some(0.5));
        for knob in Knob::ALL {
            assert_eq!(up(knob).activations(), net.activations(), "{knob:?}");
        }
        let down = Knob::Temperature.turn(&net, edge, false).unwrap();
        assert_eq!(down.params().temperature, 0.5);
    }

    /// 𝒜 ≤ 0 is refused as the training config refuses it: 1 → 0.5, then no further.
    #[test]
    fn the_coefficient_stops_above_zero() {
        let net = Knob::Coefficient.turn(&fig2(), None, false).unwrap();
        assert_eq!(net.params().coefficient, 0.5);
        let refused = Knob::Coefficient.turn(&net, None, false).unwrap_err();
        let message = refusal(&refused, &[]);
        assert!(
            message.contains("coefficient") && message.contains("> 0"),
            "{message}"
        );
    }

    #[test]
    fn ten_steps_of_a_tenth_read_as_a_whole_number() {
        let mut net = fig2();
        for _ in 0..10 {
            net = Knob::Threshold.turn(&net, None, true).unwrap();
        }
        assert_eq!(net.params().threshold, 2.0);
    }

    #[test]
    fn a_turn_too_far_is_refused_with_the_nets_reason() {
        let mut net = fig2();
        for _ in 0..3 {
            net = Knob::EdgeWeight.turn(&net, Some((1, 3)), false).unwrap();
        }
        assert_eq!(net.graph().weight(1, 3), Some(0.1));
        let refused = Knob::EdgeWeight
            .turn(&net, Some((1, 3)), false)
            .unwrap_err();
        assert!(
            matches!(refused, SapNetError::BadWeight { i: 1, j: 3, .. }),
            "{refused}"
        );
        assert!(matches!(
            Knob::EdgeWeight.turn(&net, Some((0, 3)), true),
            Err(SapNetError::NoEdge { i: 0, j: 3 })
        ));
    }

    /// Fig. 2 by hand: from π1 (k = 3, η = 1/3) the walk deposits on π0, π2, π3 at
    /// Ω = 0.4 and goes one edge further (Ω = 0.8 < 1) but not two (Ω = 1.2). With
    /// T_ω = 0.5 only the first edges deposit: each neighbour gets η/(h×Ω) = (1/3)/0.4.
    #[test]
    fn a_lower_threshold_shortens_the_walk_as_eq_10_says() {
        let net = fig2();
        let before = net.activations().to_vec();
        let (_, _, calls) = walk_end(&net, Some(1), &before);
        let mut lower = net.clone();
        for _ in 0..5 {
            lower = Knob::Threshold.turn(&lower, None, false).unwrap();
        }
        assert_eq!(lower.params().threshold, 0.5);
        let (a, p, fewer) = walk_end(&lower, Some(1), &before);
        assert!(fewer < calls, "{fewer} < {calls}");
        let deposit = (1.0 / 3.0) / 0.4;
        assert_eq!(a, vec![deposit, 1.0, deposit, deposit]);
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
