//! What one run trains, how, and for how long: the library it draws on, the method, the
//! task, the budget, the seed.

use std::sync::Arc;

use super::events::{MethodId, StreamOptions};
use super::TrainerError;
use crate::dqn::{DqnConfig, DqnError, FrozenNet, QNet};
use crate::env::EnvConfig;
use crate::reuse::{self, Method};
use crate::sapnet::{PolicyDescription, SapNetParams};
use crate::trainer::Budget;

/// A policy of the source library, ready to be reused.
#[derive(Debug)]
pub struct SourcePolicy {
    /// Its name in the library, e.g. `source-3`.
    pub name: String,
    /// The trained network; every run learns on a copy of it.
    pub net: QNet,
    pub description: PolicyDescription,
    pub final_score: Option<f64>,
    /// `net` laid out for acting on one observation (the same bits, a sixteenth of the
    /// work): a source as recorded never changes.
    acting: FrozenNet,
}

impl SourcePolicy {
    pub fn new(
        name: String,
        net: QNet,
        description: PolicyDescription,
        final_score: Option<f64>,
    ) -> Result<Self, DqnError> {
        Ok(Self {
            acting: FrozenNet::of(&net)?,
            name,
            net,
            description,
            final_score,
        })
    }

    /// The recorded network, for one observation's Q-values.
    pub fn acting(&self) -> &FrozenNet {
        &self.acting
    }
}

/// What one run trains, how, and for how long.
#[derive(Debug, Clone)]
pub struct RunSpec {
    /// Index of the independent run (0-based).
    pub run: u32,
    pub method: MethodId,
    /// The method with its knobs: who acts and who learns.
    pub reuse: Method,
    pub env: EnvConfig,
    pub dqn: DqnConfig,
    /// SAP-Net's graph and spreading (read by SAP-Net methods only).
    pub sapnet: SapNetParams,
    /// The library a reusing method draws on (empty for DQN from scratch).
    pub sources: Arc<Vec<SourcePolicy>>,
    /// Episodes, or environment steps, the run is given.
    pub budget: Budget,
    pub test_episodes: u32,
    pub seed: u64,
    pub stream: StreamOptions,
}

impl RunSpec {
    /// DQN from scratch with `hidden` layers, named `label` (the library's sources are
    /// trained this way too).
    #[allow(clippy::too_many_arguments)]
    pub fn scratch(
        run: u32,
        label: &str,
        env: EnvConfig,
        dqn: DqnConfig,
        hidden: Vec<usize>,
        episodes: u32,
        test_episodes: u32,
        seed: u64,
    ) -> Self {
        let reuse = Method::Dqn { hidden };
        let mut method = MethodId::new(0, &reuse);
        method.label = label.into();
        Self {
            run,
            method,
            reuse,
            env,
            dqn,
            sapnet: SapNetParams::default(),
            sources: Arc::new(Vec::new()),
            budget: Budget::Episodes(episodes),
            test_episodes,
            seed,
            stream: StreamOptions::episodes(),
        }
    }

    /// The descriptions of the library's sources, in its order.
    pub(super) fn descriptions(&self) -> Vec<PolicyDescription> {
        self.sources.iter().map(|s| s.description.clone()).collect()
    }
}

/// The selector of `spec`'s method over its sources: a run's first step, and a check a
/// front end makes before starting any run (an 𝒜 the graph cannot take, a best source
/// without scores).
pub fn selector(spec: &RunSpec) -> Result<Box<dyn reuse::Selector>, TrainerError> {
    let descriptions = spec.descriptions();
    let scores: Vec<Option<f64>> = spec.sources.iter().map(|s| s.final_score).collect();
    let library = reuse::Library {
        descriptions: &descriptions,
        scores: &scores,
        gamma: spec.dqn.gamma,
        return_range: spec.env.return_range(),
        discounted_return_range: spec.env.discounted_return_range(spec.dqn.gamma),
    };
    Ok(reuse::build(&spec.reuse, library, &spec.sapnet)?)
}
