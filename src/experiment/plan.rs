//! What an experiment runs: one [`RunSpec`] per (method, run), each seeded from the run
//! seed, over the source library when a method reuses one.

use std::sync::mpsc::Receiver;
use std::sync::Arc;

use anyhow::Result;

use crate::config::Config;
use crate::reuse::ReuseError;
use crate::sapnet::SapNetError;
use crate::seeds;
use crate::sources::{self, LibraryRoot};
use crate::trainer::{Command, MethodId, RunSpec, SourcePolicy, StreamOptions, TrainerError};

/// The runs of a protocol and the library they reuse.
#[derive(Debug)]
pub struct Plan {
    /// In the order they start: run 0 of every method, then run 1…
    pub specs: Vec<RunSpec>,
    /// The source library, loaded when a method reuses it.
    pub sources: Option<Arc<Vec<SourcePolicy>>>,
}

/// Loads the library if a method reuses one (training it first, with progress on stderr,
/// if `<library>/<source task>/` holds none or an unfinished one and `library` allows it;
/// `stop` ends that training), then plans every run.
///
/// Runs are refused, before the library is trained or anything allocated, if `jobs` of the
/// largest could not fit in the machine's memory together ([`crate::trainer::memory::check`]).
pub fn plan(
    config: &Config,
    library: &LibraryRoot,
    jobs: usize,
    stop: &Receiver<Command>,
) -> Result<Plan> {
    crate::trainer::memory::check(&run_specs(config, None), jobs)?;
    let reuses = config.protocol.methods.iter().any(|m| m.kind().reuses);
    let sources = if reuses {
        Some(Arc::new(sources::ensure_library(config, library, stop)?))
    } else {
        None
    };
    let specs = run_specs(config, sources.as_ref());
    crate::trainer::memory::check(&specs, jobs)?;
    // A selector that cannot be built fails every run of its method: say so before any
    // run trains.
    for spec in specs.iter().filter(|s| s.run == 0 && s.method.kind.reuses) {
        crate::trainer::selector(spec).map_err(|error| refused_method(spec, error))?;
    }
    Ok(Plan { specs, sources })
}

/// A method whose selector cannot be built over this library. When a field of the config
/// is to blame, the error's context is a [`ConfigField`], so that a front end can name the
/// config's file too.
fn refused_method(spec: &RunSpec, error: TrainerError) -> anyhow::Error {
    let method = spec.method.to_string();
    match error {
        TrainerError::Reuse(ReuseError::SapNet(SapNetError::ActivationOverflow { .. })) => {
            anyhow::Error::new(error).context(ConfigField {
                method,
                field: "sapnet.coefficient",
            })
        }
        error => anyhow::Error::new(error).context(format!("method {method}")),
    }
}

/// The config field a refused method is refused for.
#[derive(Debug)]
pub struct ConfigField {
    pub method: String,
    pub field: &'static str,
}

impl std::fmt::Display for ConfigField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "method {}: field `{}`", self.method, self.field)
    }
}

/// One spec per (method, run), each with its own seed derived from the run seed, the
/// method's label and the run's index ([`seeds::run_seed`]).
pub fn run_specs(config: &Config, sources: Option<&Arc<Vec<SourcePolicy>>>) -> Vec<RunSpec> {
    let ids = MethodId::all(&config.protocol.methods);
    let none = Arc::new(Vec::new());
    let mut specs = Vec::new();
    for run in 0..config.protocol.runs {
        for (m, method) in config.protocol.methods.iter().enumerate() {
            let sources = match (method.kind().reuses, sources) {
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
                budget: config.protocol.budget,
                test_episodes: config.protocol.test_episodes,
                seed: seeds::run_seed(config.seed, ids[m].label(), run),
                stream: StreamOptions::episodes(),
            });
        }
    }
    specs
}
