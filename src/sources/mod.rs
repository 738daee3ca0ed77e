//! The library of source policies (paper III-B) — N DQNs of random architectures,
//! "assuming that a person cannot manually design an optimal hidden layer" — in
//! `<library>/<name>/source-<i>.{safetensors,ron}` with its manifest `library.ron`.
//!
//! - here: what the config plans (architectures, seeds, source tasks, the folder);
//! - [`train`]: `sapnet sources`, resumable;
//! - [`import`](mod@import): `sapnet sources import`, a policy trained elsewhere added;
//! - [`load`]: a library read for reuse, or trained first where allowed;
//! - [`manifest`]: the manifest, `library.ron`.

use std::path::{Path, PathBuf};

use anyhow::Result;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::config::Config;
use crate::env::EnvConfig;
use crate::policy_store;
use crate::seeds;

mod import;
mod load;
pub mod manifest;
pub mod mapping;
mod train;

pub use crate::env::mapping::{check_fit, native_spaces, InterTaskMapping, Spaces};
pub use import::{import, Imported};
pub use load::{evaluate, load_library, needs_training, Evaluation, LibraryRoot};
pub use manifest::{LibraryTraining, Manifest, ManifestEntry};
pub use train::{ensure_library, train_library};

/// Stream key of the source library's plan ([`seeds::library_v1`]), which no experiment uses.
pub(crate) const SOURCES_STREAM: u64 = u64::MAX;

/// One source policy to train.
#[derive(Debug, Clone, PartialEq)]
pub struct SourcePlan {
    pub name: String,
    pub hidden: Vec<usize>,
    pub seed: u64,
    /// Its task: an index into [`tasks`].
    pub task: usize,
}

/// A task of the library and how many of its policies train on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceTask {
    pub env: EnvConfig,
    pub count: usize,
    /// Its name in results, on the graph, and as SAP-Net's `SourceTask` category.
    pub label: String,
    /// χ_X and χ_A, for a task of another agent than the target's ([`mapping`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping: Option<InterTaskMapping>,
}

impl SourceTask {
    /// This task without its mapping: what its policies were trained on.
    pub fn trained(&self) -> SourceTask {
        SourceTask {
            mapping: None,
            ..self.clone()
        }
    }
}

/// The source task: `sources.env` when given, else the target task. For a library over
/// several tasks, the first.
pub fn source_task(config: &Config) -> &EnvConfig {
    match config.sources.tasks.first() {
        Some(task) => &task.env,
        None => config.sources.env.as_ref().unwrap_or(&config.env),
    }
}

/// The library's tasks in order: `sources.tasks`, or all `count` policies on the source
/// task.
pub fn tasks(config: &Config) -> Vec<SourceTask> {
    let s = &config.sources;
    if s.tasks.is_empty() {
        let env = source_task(config).clone();
        return vec![SourceTask {
            label: env.label(),
            env,
            count: s.count,
            mapping: None,
        }];
    }
    s.tasks
        .iter()
        .map(|t| SourceTask {
            label: t.label.clone().unwrap_or_else(|| t.env.label()),
            env: t.env.clone(),
            count: t.count,
            mapping: t.mapping.clone(),
        })
        .collect()
}

/// The library's folder name: `sources.name`, else the source task's (`cartpole`).
pub fn library_name(config: &Config) -> String {
    config
        .sources
        .name
        .clone()
        .unwrap_or_else(|| source_task(config).task_name().to_string())
}

/// `<library>/<library name>`, where the library of `config` lives.
pub fn library_dir(library: &Path, config: &Config) -> PathBuf {
    library.join(library_name(config))
}

/// The N architectures and seeds, drawn from the run seed: the number of hidden layers and
/// the units of each layer uniformly from the config's inclusive ranges; the first
/// policies on the first task, and so on.
pub fn plan(config: &Config) -> Vec<SourcePlan> {
    let s = &config.sources;
    let task_of: Vec<usize> = tasks(config)
        .iter()
        .enumerate()
        .flat_map(|(t, task)| std::iter::repeat_n(t, task.count))
        .collect();
    let mut rng = StdRng::seed_from_u64(seeds::library_v1(config.seed, &[SOURCES_STREAM]));
    (0..s.count)
        .map(|i| {
            let layers = rng.random_range(s.hidden_layers.0..=s.hidden_layers.1);
            let hidden = (0..layers)
                .map(|_| rng.random_range(s.units.0..=s.units.1))
                .collect();
            SourcePlan {
                name: format!("source-{i}"),
                hidden,
                seed: seeds::library_v1(config.seed, &[SOURCES_STREAM, i as u64]),
                task: task_of.get(i).copied().unwrap_or(0),
            }
        })
        .collect()
}

/// Names of every policy in `dir` with at least one of its two files.
fn policy_files(dir: &Path) -> Result<Vec<String>> {
    let mut names = policy_store::list(dir)?;
    for orphan in policy_store::orphan_weights(dir)? {
        if !names.contains(&orphan) {
            names.push(orphan);
        }
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plans_stay_in_range_and_follow_the_seed() {
        let mut config = Config::default();
        config.sources.count = 50;
        let plans = plan(&config);
        assert_eq!(plans.len(), 50);
        for p in &plans {
            assert!((1..=3).contains(&p.hidden.len()), "{p:?}");
            assert!(p.hidden.iter().all(|u| (50..=150).contains(u)), "{p:?}");
        }
        // All three depths occur among 50 draws (a failure here is a broken draw, not luck:
        // P(a depth missing) < 3·(2/3)^50 ≈ 5e-9).
        for layers in 1..=3 {
            assert!(plans.iter().any(|p| p.hidden.len() == layers));
        }
        assert_eq!(plans, plan(&config));
        config.seed = 1;
        assert_ne!(plans, plan(&config));
    }
}
