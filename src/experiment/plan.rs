//! What an experiment runs: one [`RunSpec`] per (method, run), each seeded from the run
//! seed, over the source library when a method reuses one.

use std::sync::mpsc::Receiver;
use std::sync::Arc;

use anyhow::{Context, Result};

use super::memory;
use crate::config::Config;
use crate::seeds;
use crate::sources::{self, LibraryRoot};
use crate::trainer::{Command, MethodId, RunSpec, SourcePolicy, StreamOptions};

/// The runs of a protocol and the library they reuse.
#[derive(Debug)]
pub struct Plan {
    /// In the order they start: run 0 of every method, then run 1…
    pub specs: Vec<RunSpec>,
    /// The source library, loaded when a method reuses it.
    pub sources: Option<Arc<Vec<SourcePolicy>>>,
}

/// The ids of the config's methods, in the protocol's order.
pub fn method_ids(config: &Config) -> Vec<MethodId> {
    config
        .protocol
        .methods
        .iter()
        .enumerate()
        .map(|(i, method)| MethodId::new(i, method))
        .collect()
}

/// Loads the library if a method reuses one (training it first, with progress on stderr,
/// if `<library>/<source task>/` holds none or an unfinished one and `library` allows it;
/// `stop` ends that training), then plans every run.
///
/// Runs are refused, before the library is trained or anything allocated, if `jobs` of the
/// largest could not fit in the machine's memory together ([`memory::check`]).
pub fn plan(
    config: &Config,
    library: &LibraryRoot,
    jobs: usize,
    stop: &Receiver<Command>,
) -> Result<Plan> {
    memory::check(&run_specs(config, None), jobs)?;
    let reuses = config.protocol.methods.iter().any(|m| m.kind().reuses());
    let sources = if reuses {
        Some(Arc::new(sources::ensure_library(config, library, stop)?))
    } else {
        None
    };
    let specs = run_specs(config, sources.as_ref());
    memory::check(&specs, jobs)?;
    // A selector that cannot be built fails every run of its method: say so before any
    // run trains.
    for spec in specs
        .iter()
        .filter(|s| s.run == 0 && s.method.kind.reuses())
    {
        crate::trainer::selector(spec).with_context(|| format!("method {}", spec.method))?;
    }
    Ok(Plan { specs, sources })
}

/// One spec per (method, run), each with its own seed derived from the run seed, the
/// method's place in the protocol and the run's index.
pub fn run_specs(config: &Config, sources: Option<&Arc<Vec<SourcePolicy>>>) -> Vec<RunSpec> {
    let ids = method_ids(config);
    let none = Arc::new(Vec::new());
    let mut specs = Vec::new();
    for run in 0..config.protocol.runs {
        for (m, method) in config.protocol.methods.iter().enumerate() {
            let sources = match (method.kind().reuses(), sources) {
                (true, Some(sources)) => Arc::clone(sources),
                _ => Arc::clone(&none),
            };
            specs.push(RunSpec {
                run,
                method: ids[m].clone(),
                reuse: method.clone(),
                env: config.env.clone(),
                dqn: config.dqn.clone(),
                sapnet: config.sapnet.clone(),
                sources,
                episodes: config.protocol.episodes,
                max_steps: config.protocol.max_steps,
                test_episodes: config.protocol.test_episodes,
                seed: seeds::derive(config.seed, &[m as u64, u64::from(run)]),
                stream: StreamOptions::episodes(),
            });
        }
    }
    specs
}
