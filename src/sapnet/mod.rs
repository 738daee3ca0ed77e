//! SAP-Net (paper section II): categories, the policy graph, selection, activation and
//! spreading. Pure maths over plain vectors: no candle, no I/O, no threads.
//!
//! - [`prototype`]: categories of policies and prototype matrices (II-C, eq. 5).
//! - [`graph`]: the SAP-Net 𝔾 and its weights M (II-D, eq. 2–5).
//! - [`selection`]: the softmax over activations (II-E, eq. 6).
//! - [`judgment`]: positive and negative transitions (II-F, eq. 7).
//! - [`spreading`]: activation and spreading (II-F, II-G, eq. 8–11, Algorithms 1–2).
//!
//! [`SapNet`] bundles them as Algorithm 3 uses them.

mod error;
pub mod graph;
pub mod judgment;
mod params;
mod policy;
pub mod prototype;
pub mod selection;
pub mod spreading;

use rand::Rng;

use selection::SelectionTerms;

pub use error::SapNetError;
pub use graph::Graph;
pub use judgment::judge;
pub use params::{BaseGraph, Paths, Prototype, SapNetParams, WeightedPrototype};
pub use policy::PolicyDescription;
pub use spreading::{
    Call, CallCount, NoTrace, SpreadState, Spreader, Spreading, TraceSink, TraceStep,
};

/// Most depositing `spread` calls one activation may make. Positive weights make every
/// walk end (eq. 10), but a light graph under a high threshold can still take longer than
/// anyone will wait; refuse it rather than hang.
pub const MAX_SPREAD_CALLS: f64 = 1e7;

/// Activations a SAP-Net is built to take with every activation staying a finite number:
/// more than any run makes (10¹² steps at a microsecond each are eleven days).
pub const MAX_ACTIVATIONS: f64 = 1e12;

/// Bounds the depositing calls of one activation: a call at hop h has Ω ≥ h·w_min and
/// deposits only while Ω < T_ω, so deposits happen at most H = ⌊T_ω / w_min⌋ hops deep
/// (⌊⌋ rather than ⌈⌉ − 1 allows for rounding in Ω's sum), at most Σ_{h=1..H} d^h of them
/// for the largest degree d. Calls the threshold stops are not made unless a trace asks
/// for them (at most d per deposit more).
///
/// Returns how much one activation with 𝒜 = 1 can add to one policy's activation at most:
/// 1 for eq. 8, and each deposit η/(h·Ω) ≤ 1/w_min (η ≤ 𝒜, h ≥ 1, Ω ≥ w_min).
fn check_spreading_bound(graph: &Graph, threshold: f64) -> Result<f64, SapNetError> {
    let lightest = (0..graph.len())
        .map(|i| graph.lightest(i))
        .fold(f64::INFINITY, f64::min);
    let degree = (0..graph.len()).map(|i| graph.degree(i)).max().unwrap_or(0);
    if !lightest.is_finite() || degree == 0 {
        return Ok(1.0);
    }
    let hops = (threshold / lightest).floor();
    let d = degree as f64;
    let calls = if degree == 1 {
        hops
    } else {
        d * (d.powf(hops) - 1.0) / (d - 1.0)
    };
    if calls > MAX_SPREAD_CALLS {
        return Err(SapNetError::UnboundedSpreading {
            calls,
            limit: MAX_SPREAD_CALLS,
            lightest,
            threshold,
            degree,
        });
    }
    Ok(1.0 + calls / lightest)
}

/// Refuses an 𝒜 with which [`MAX_ACTIVATIONS`] activations, each adding at most
/// `gain`·|𝒜| (see [`check_spreading_bound`]), could take an activation past the largest
/// f64 from where `activations` start: activations stay finite by construction.
fn check_activation_bound(
    gain: f64,
    coefficient: f64,
    activations: &[f64],
) -> Result<(), SapNetError> {
    let start = activations.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    let most = (f64::MAX - start) / (MAX_ACTIVATIONS * gain);
    if coefficient.abs() <= most {
        Ok(())
    } else {
        Err(SapNetError::ActivationOverflow { coefficient, most })
    }
}

/// A SAP-Net with its activations 𝔸: what the transfer loop selects from and activates.
#[derive(Debug, Clone, PartialEq)]
pub struct SapNet {
    graph: Graph,
    params: SapNetParams,
    activations: Vec<f64>,
    /// Eq. 6's terms for `activations`, updated whenever they change.
    selection: SelectionTerms,
}

impl SapNet {
    /// A SAP-Net over `graph` with every activation 0.
    pub fn new(graph: Graph, params: SapNetParams) -> Result<Self, SapNetError> {
        let activations = vec![0.0; graph.len()];
        Self::with_activations(graph, params, activations)
    }

    /// A SAP-Net whose graph is built from the policies' categories (eq. 3–5).
    pub fn from_policies(
        policies: &[PolicyDescription],
        params: SapNetParams,
    ) -> Result<Self, SapNetError> {
        let graph = Graph::from_categories(policies, &params)?;
        Self::new(graph, params)
    }

    /// A SAP-Net over `graph` starting from the given activations.
    pub fn with_activations(
        graph: Graph,
        params: SapNetParams,
        activations: Vec<f64>,
    ) -> Result<Self, SapNetError> {
        params.validate()?;
        let gain = check_spreading_bound(&graph, params.threshold)?;
        check_activations(graph.len(), &activations)?;
        check_activation_bound(gain, params.coefficient, &activations)?;
        let selection = SelectionTerms::new(&activations, params.temperature);
        Ok(Self {
            graph,
            params,
            activations,
            selection,
        })
    }

    pub fn graph(&self) -> &Graph {
        &self.graph
    }

    pub fn params(&self) -> &SapNetParams {
        &self.params
    }

    /// 𝔸, one activation per policy.
    pub fn activations(&self) -> &[f64] {
        &self.activations
    }

    /// N, the number of policies.
    pub fn len(&self) -> usize {
        self.graph.len()
    }

    pub fn is_empty(&self) -> bool {
        self.graph.is_empty()
    }

    /// T_ω and the walks spreading may take.
    pub fn spreading(&self) -> Spreading {
        Spreading {
            threshold: self.params.threshold,
            paths: self.params.paths,
        }
    }

    /// 𝒜 on a positive transition, 0 on a negative one (Algorithm 3).
    pub fn coefficient(&self, positive: bool) -> f64 {
        if positive {
            self.params.coefficient
        } else {
            0.0
        }
    }

    /// The selection probabilities of eq. 6.
    pub fn probabilities(&self) -> Vec<f64> {
        self.selection.probabilities()
    }

    /// Draws the policy that acts next with the probabilities of eq. 6.
    pub fn select(&self, rng: &mut impl Rng) -> usize {
        self.selection.draw(rng)
    }

    /// Eq. 6's probabilities over the candidates only, the `excluded` policies at 0.
    pub fn candidate_probabilities(&self, excluded: &[bool]) -> Vec<f64> {
        selection::candidate_probabilities(&self.activations, self.params.temperature, excluded)
    }

    /// Draws the policy that acts next among the candidates (`excluded[i]` false).
    pub fn select_candidate(&self, excluded: &[bool], rng: &mut impl Rng) -> usize {
        selection::select_candidate(&self.activations, self.params.temperature, excluded, rng)
    }

    /// The chosen policy after training: the highest activation, the lowest index on a tie.
    ///
    /// # Panics
    /// If there are no policies.
    pub fn chosen(&self) -> usize {
        let mut best = 0;
        for (i, &a) in self.activations.iter().enumerate() {
            if a > self.activations[best] {
                best = i;
            }
        }
        best
    }

    /// Eq. 7: whether a step that moved the acting policy's statistic loss from
    /// `e_before` to `e_after` was a positive transition.
    pub fn judge(e_before: f64, e_after: f64) -> bool {
        judgment::judge(e_before, e_after)
    }

    /// Activates policy `i` after a positive or negative transition and spreads
    /// (eq. 8–11). A negative transition activates with 0, which deposits 0 everywhere,
    /// so nothing is walked.
    ///
    /// # Panics
    /// If `i` is not a policy.
    pub fn activate(&mut self, i: usize, positive: bool) {
        assert!(i < self.len(), "policy {i} of {}", self.len());
        if positive {
            self.activate_traced(i, true, &mut NoTrace);
        }
    }

    /// As [`activate`](Self::activate), reporting every `spread` call to `sink`; a
    /// negative transition walks the graph too, so the trace shows its zero deposits.
    ///
    /// # Panics
    /// If `i` is not a policy.
    pub fn activate_traced<S: TraceSink>(&mut self, i: usize, positive: bool, sink: &mut S) {
        let coefficient = self.coefficient(positive);
        let spreading = self.spreading();
        spreading::activate(
            &self.graph,
            spreading,
            i,
            coefficient,
            &mut self.activations,
            sink,
        );
        self.selection
            .update(&self.activations, self.params.temperature);
    }

    /// The largest probability of eq. 6: how close selection is to an argmax.
    pub fn top_probability(&self) -> f64 {
        self.selection.top()
    }

    /// Sets τ of eq. 6, for a temperature that follows a schedule (beyond the paper, which
    /// keeps τ = 1).
    ///
    /// # Errors
    /// If `temperature` is not a finite number > 0.
    pub fn set_temperature(&mut self, temperature: f64) -> Result<(), SapNetError> {
        if !(temperature > 0.0 && temperature.is_finite()) {
            return Err(SapNetError::BadParameter {
                name: "temperature".into(),
                value: temperature,
                expected: "a finite number > 0",
            });
        }
        self.params.temperature = temperature;
        self.selection.update(&self.activations, temperature);
        Ok(())
    }

    /// `A ← λ·A` for every policy: activation decay, the spreading-activation literature's
    /// usual answer to activations that only grow (beyond the paper, whose λ is 1).
    pub fn decay(&mut self, lambda: f64) {
        self.activations.iter_mut().for_each(|a| *a *= lambda);
        self.selection
            .update(&self.activations, self.params.temperature);
    }

    /// Replaces the activations, e.g. with a state a front end stepped back to.
    pub fn set_activations(&mut self, activations: Vec<f64>) -> Result<(), SapNetError> {
        check_activations(self.len(), &activations)?;
        self.activations = activations;
        self.selection
            .update(&self.activations, self.params.temperature);
        Ok(())
    }
}

fn check_activations(n: usize, activations: &[f64]) -> Result<(), SapNetError> {
    if activations.len() != n {
        return Err(SapNetError::ActivationCount {
            n,
            got: activations.len(),
        });
    }
    match activations.iter().position(|a| !a.is_finite()) {
        Some(i) => Err(SapNetError::BadActivation {
            i,
            value: activations[i],
        }),
        None => Ok(()),
    }
}
