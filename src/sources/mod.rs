//! `sapnet sources`: trains the library of source policies (paper III-B) — N DQNs of random
//! architectures, "assuming that a person cannot manually design an optimal hidden layer" —
//! and writes it to `<library>/<task>/source-<i>.{safetensors,ron}` with its manifest,
//! `<library>/<task>/library.ron`.

use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;

use anyhow::{bail, Context, Result};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::config::Config;
use crate::env::EnvConfig;
use crate::experiment::{schedule, Observer};
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::sapnet::PolicyDescription;
use crate::seeds;
use crate::trainer::{Command, Event, RunOutcome, RunSpec, SourcePolicy, TrainerError};

pub mod manifest;
pub use manifest::{LibraryTraining, Manifest, ManifestEntry};

/// Stream key of the source library's seeds, apart from the experiments' `[method, run]`.
const SOURCES_STREAM: u64 = u64::MAX;

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
        }];
    }
    s.tasks
        .iter()
        .map(|t| SourceTask {
            label: t.label.clone().unwrap_or_else(|| t.env.label()),
            env: t.env.clone(),
            count: t.count,
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
    let mut rng = StdRng::seed_from_u64(seeds::derive(config.seed, &[SOURCES_STREAM]));
    (0..s.count)
        .map(|i| {
            let layers = rng.random_range(s.hidden_layers.0..=s.hidden_layers.1);
            let hidden = (0..layers)
                .map(|_| rng.random_range(s.units.0..=s.units.1))
                .collect();
            SourcePlan {
                name: format!("source-{i}"),
                hidden,
                seed: seeds::derive(config.seed, &[SOURCES_STREAM, i as u64]),
                task: task_of.get(i).copied().unwrap_or(0),
            }
        })
        .collect()
}

/// Trains the library `config` describes into `<library>/<source task>/`, one policy at a
/// time, each on disk (and in the manifest) as soon as it is trained: a stop or a kill
/// costs at most the policy in training, and the same command resumes. A finished library
/// is replaced only when `retrain` is set; policies on disk that the config does not
/// describe are never silently mixed in.
pub fn train_library(
    config: &Config,
    library: &Path,
    retrain: bool,
    stop: &Receiver<Command>,
) -> Result<PathBuf> {
    let dir = library_dir(library, config);
    let training = LibraryTraining::of(config);
    let plans = plan(config);
    let specs: Vec<RunSpec> = plans
        .iter()
        .enumerate()
        .map(|(i, source)| source_spec(config, i, source))
        .collect();
    crate::experiment::memory::check(&specs, 1)?;
    let kept = resumable(&dir, &training, &plans, retrain)?;
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("creating the library folder {}", dir.display()))?;
    remove_temporaries(&dir)?;
    let mut manifest = Manifest {
        complete: false,
        training,
        policies: kept,
        crate_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    // Written before any policy: from here until `complete`, runs refuse the library.
    manifest::write(&dir, &manifest)?;
    let todo: Vec<(&SourcePlan, &RunSpec)> = plans
        .iter()
        .zip(&specs)
        .filter(|(p, _)| !manifest.policies.iter().any(|e| e.name == p.name))
        .collect();
    if !manifest.policies.is_empty() {
        eprintln!(
            "{}: {} of {} policies already trained and checked; training {}",
            dir.display(),
            manifest.policies.len(),
            plans.len(),
            todo.len()
        );
    }

    let mut progress = crate::headless::Progress::new(
        u64::from(config.sources.training_episodes) * todo.len() as u64,
        crate::headless::Unit::Episodes,
    );
    for (source, spec) in todo {
        let Some(entry) = train_source(&dir, source, spec, &mut progress, stop)? else {
            progress.finish(false);
            bail!(
                "stopped by the user: {} of {} policies are trained and kept in {}; the same \
                 command trains the rest",
                manifest.policies.len(),
                plans.len(),
                dir.display()
            );
        };
        manifest.policies.push(entry);
        manifest
            .policies
            .sort_by_key(|e| plans.iter().position(|p| p.name == e.name));
        manifest::write(&dir, &manifest)?;
    }
    progress.finish(true);
    // A smaller library replaces a larger one: its extra sources go before the library
    // is declared whole.
    remove_unplanned(&dir, &plans)?;
    manifest.complete = true;
    manifest::write(&dir, &manifest)?;
    Ok(dir)
}

/// Trains one source with `spec` and saves it in `dir`; its manifest entry, or `None` when
/// the user stopped it.
fn train_source(
    dir: &Path,
    source: &SourcePlan,
    spec: &RunSpec,
    progress: &mut crate::headless::Progress,
    stop: &Receiver<Command>,
) -> Result<Option<ManifestEntry>> {
    let mut training = SourceTraining {
        progress,
        outcome: None,
    };
    let stopped = schedule(vec![spec.clone()], 1, stop, &mut training)
        .with_context(|| format!("training {}", source.name))?;
    let outcome = training
        .outcome
        .expect("a run that neither failed nor was stopped has an outcome");
    if stopped || outcome.record.stopped {
        return Ok(None);
    }
    let returns = &outcome.record.test_returns;
    let info = PolicyInfo {
        source_task: spec.env.clone(),
        training: TrainingBudget {
            episodes: u64::from(outcome.record.episodes),
            steps: outcome.record.steps,
        },
        seed: source.seed,
        final_score: (!returns.is_empty())
            .then(|| returns.iter().sum::<f64>() / returns.len() as f64),
        reused: None,
    };
    policy_store::save(dir, &source.name, &outcome.net, &info)
        .with_context(|| format!("writing {} to {}", source.name, dir.display()))?;
    Ok(Some(ManifestEntry::of_policy(dir, &source.name)?.0))
}

/// Removes the policies in `dir` that `plans` does not name.
fn remove_unplanned(dir: &Path, plans: &[SourcePlan]) -> Result<()> {
    for stale in policy_files(dir)?
        .iter()
        .filter(|name| !plans.iter().any(|p| &p.name == *name))
    {
        let (weights, metadata) = policy_store::paths(dir, stale);
        for path in [metadata, weights] {
            match std::fs::remove_file(&path) {
                Err(err) if err.kind() != std::io::ErrorKind::NotFound => {
                    return Err(err)
                        .with_context(|| format!("removing the old policy {}", path.display()));
                }
                _ => {}
            }
        }
    }
    Ok(())
}

/// The run that trains `source`, the `i`-th of the plan: DQN from scratch on its source
/// task, with the sources' DQN settings.
fn source_spec(config: &Config, i: usize, source: &SourcePlan) -> RunSpec {
    RunSpec::scratch(
        i as u32,
        &source.name,
        tasks(config)[source.task].env.clone(),
        config.sources.dqn.as_ref().unwrap_or(&config.dqn).clone(),
        source.hidden.clone(),
        config.sources.training_episodes,
        config.protocol.test_episodes,
        source.seed,
    )
}

/// The policies already in `dir` that a (resumed) training of `training` keeps: those of
/// an unfinished training of the same config that still match their hashes, or, in a
/// folder without a manifest (an older sapnet, or a kill before the first policy), those
/// whose own metadata match the plan. Refuses to mix anything else in unless `retrain`.
fn resumable(
    dir: &Path,
    training: &LibraryTraining,
    plans: &[SourcePlan],
    retrain: bool,
) -> Result<Vec<ManifestEntry>> {
    match manifest::read(dir)? {
        Some(found) if &found.training == training => {
            if found.complete && !retrain {
                bail!(
                    "{} already holds the {} policies this config describes; pass --retrain to \
                     train them again",
                    dir.display(),
                    found.policies.len()
                );
            }
            if found.complete {
                return Ok(Vec::new());
            }
            Ok(found
                .policies
                .into_iter()
                .filter(|e| ManifestEntry::of_policy(dir, &e.name).is_ok_and(|(now, _)| &now == e))
                .collect())
        }
        Some(found) => {
            if !retrain {
                bail!(
                    "{} holds a {} library trained with other settings ({}); pass --retrain to \
                     replace it",
                    dir.display(),
                    if found.complete {
                        "finished"
                    } else {
                        "partly trained"
                    },
                    found.training.all_differences(training).join("; ")
                );
            }
            Ok(Vec::new())
        }
        None => {
            let on_disk = policy_files(dir)?;
            if retrain || on_disk.is_empty() {
                return Ok(Vec::new());
            }
            let adopted: Vec<ManifestEntry> = plans
                .iter()
                .filter(|p| on_disk.contains(&p.name))
                .filter_map(|p| {
                    let (entry, metadata) = ManifestEntry::of_policy(dir, &p.name).ok()?;
                    let planned = entry.seed == p.seed
                        && entry.hidden == p.hidden
                        && metadata.source_task == training.tasks[p.task].env
                        && metadata.training.episodes == u64::from(training.training_episodes);
                    planned.then_some(entry)
                })
                .collect();
            let foreign: Vec<&String> = on_disk
                .iter()
                .filter(|name| !adopted.iter().any(|e| &e.name == *name))
                .collect();
            if !foreign.is_empty() {
                bail!(
                    "{} holds policies without a manifest that this config does not describe \
                     ({}); pass --retrain to replace them",
                    dir.display(),
                    foreign
                        .iter()
                        .map(|n| n.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
            Ok(adopted)
        }
    }
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

/// Removes the hidden `*.tmp` files an interrupted save leaves behind.
fn remove_temporaries(dir: &Path) -> Result<()> {
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let path = entry?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with('.') && name.ends_with(".tmp") && path.is_file() {
            std::fs::remove_file(&path)
                .with_context(|| format!("removing the leftover {}", path.display()))?;
        }
    }
    Ok(())
}

/// Progress of one source's training, and its outcome.
struct SourceTraining<'a> {
    progress: &'a mut crate::headless::Progress,
    outcome: Option<RunOutcome>,
}

impl Observer for SourceTraining<'_> {
    fn on_event(&mut self, event: Event) -> Result<()> {
        match event {
            Event::RunStarted {
                method,
                planned_episodes,
                ..
            } => self
                .progress
                .run_started(method.label(), 0, u64::from(planned_episodes)),
            Event::EpisodeEnded(record) => self.progress.episode(&record),
            _ => {}
        }
        Ok(())
    }

    fn on_finished(&mut self, _order: usize, _spec: &RunSpec, outcome: RunOutcome) -> Result<()> {
        self.progress.run_finished(outcome.record.method.label(), 0);
        self.outcome = Some(outcome);
        Ok(())
    }

    fn on_failed(&mut self, _spec: &RunSpec, err: TrainerError) -> anyhow::Error {
        anyhow::Error::new(err)
    }
}

/// A source tested on the target task.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    pub name: String,
    /// Its task's label.
    pub task: String,
    pub hidden: Vec<usize>,
    /// Mean greedy return on its own task, as recorded when it was trained.
    pub own_score: Option<f64>,
    /// Mean greedy return on `config.env`.
    pub target_score: f64,
}

/// Tests every source of the library of `config` greedily on the target task, for
/// `protocol.test_episodes` episodes (at least one) from the config's seed: how useful each
/// would be unchanged, which a library over other tasks does not say by its scores.
pub fn evaluate(config: &Config, library: &Path) -> Result<Vec<Evaluation>> {
    let sources = load_library(config, library)?;
    let episodes = config.protocol.test_episodes.max(1);
    let seed = seeds::derive(config.seed, &[SOURCES_STREAM, u64::MAX]);
    sources
        .iter()
        .map(|source| {
            let mut env = crate::env::make(&config.env);
            let returns = crate::trainer::test_greedy(&source.net, env.as_mut(), episodes, seed)?;
            Ok(Evaluation {
                name: source.name.clone(),
                task: source.description.source_task.clone(),
                hidden: source.description.hidden.clone(),
                own_score: source.final_score,
                target_score: returns.iter().sum::<f64>() / returns.len() as f64,
            })
        })
        .collect()
}

/// Where a run finds its library, and whether it may train one that is missing.
#[derive(Debug, Clone)]
pub struct LibraryRoot {
    /// `<library>`: the task's library is `<library>/<source task>/`.
    pub path: PathBuf,
    /// Train a missing or unfinished library before the run (the default library, or
    /// `--train-library`). Otherwise a typo in `--library` is an error, not hours of
    /// training.
    pub train_if_missing: bool,
}

/// Reads the source library of `config` from `<library>/<source task>/` for reuse on the
/// target task. The library must be whole: its manifest complete, of the config's source
/// task and `sources.count`, every policy on disk with the hashes the manifest records and
/// no policy beside them; every policy must fit the target task's sizes.
pub fn load_library(config: &Config, library: &Path) -> Result<Vec<SourcePolicy>> {
    let dir = library_dir(library, config);
    let Some(found) = manifest::read(&dir)? else {
        let on_disk = policy_files(&dir)?;
        if on_disk.is_empty() {
            bail!(
                "the source library {} holds no policies; train it with `sapnet sources \
                 --config <FILE>`",
                dir.display()
            );
        }
        bail!(
            "{} holds {} policies but no manifest ({}): an older sapnet wrote them, or their \
             training was interrupted; `sapnet sources --config <FILE> --library {}` checks \
             them against the config, trains what is missing and writes the manifest",
            dir.display(),
            on_disk.len(),
            manifest::FILE,
            library.display()
        );
    };
    let manifest_path = manifest::path(&dir);
    let wanted = LibraryTraining::of(config);
    if found.training.tasks != wanted.tasks {
        let tasks = |t: &[SourceTask]| -> String {
            t.iter()
                .map(|t| format!("{} ×{}", t.label, t.count))
                .collect::<Vec<_>>()
                .join(", ")
        };
        bail!(
            "the library {} was trained on {}, but the config's source tasks are {}; retrain \
             the library with `sapnet sources --retrain` or use another --library",
            dir.display(),
            tasks(&found.training.tasks),
            tasks(&wanted.tasks)
        );
    }
    if !found.complete {
        let missing: Vec<String> = plan(config)
            .into_iter()
            .filter(|p| !found.policies.iter().any(|e| e.name == p.name))
            .map(|p| p.name)
            .collect();
        bail!(
            "the source library {} is unfinished: {} of {} policies trained (missing: {}); \
             `sapnet sources --config <FILE>` trains the rest",
            dir.display(),
            found.policies.len(),
            found.training.count(),
            missing.join(", ")
        );
    }
    if found.policies.len() != wanted.count() {
        bail!(
            "the library {} holds {} policies, the config's sources.count is {}; train one of \
             {} with `sapnet sources --retrain` or set sources.count",
            dir.display(),
            found.policies.len(),
            wanted.count(),
            wanted.count()
        );
    }
    for difference in wanted.differences(&found.training) {
        eprintln!(
            "warning: the library {} was trained with other settings than the config's \
             ({difference}): it is reused as it is",
            dir.display()
        );
    }
    if let Some(stray) = policy_files(&dir)?
        .into_iter()
        .find(|name| !found.policies.iter().any(|e| &e.name == name))
    {
        bail!(
            "{} holds policy {stray}, which its manifest {} does not list: remove it, or \
             retrain the library with `sapnet sources --retrain`",
            dir.display(),
            manifest_path.display()
        );
    }

    let env = crate::env::make(&config.env);
    let plans = plan(config);
    let mut sources = Vec::with_capacity(found.policies.len());
    for (entry, planned) in found.policies.iter().zip(&plans) {
        let task = &wanted.tasks[planned.task];
        let stored = policy_store::load_for_task(
            &dir,
            &entry.name,
            env.observation_size(),
            env.action_count(),
        )?;
        let metadata_path = policy_store::paths(&dir, &entry.name).1;
        let metadata_sha256 = policy_store::sha256_hex(
            &std::fs::read(&metadata_path)
                .with_context(|| format!("reading {}", metadata_path.display()))?,
        );
        if stored.metadata.weights_sha256 != entry.weights_sha256
            || metadata_sha256 != entry.metadata_sha256
        {
            bail!(
                "policy {} is not the one {} records (its files changed after the library was \
                 written); retrain the library with `sapnet sources --retrain`",
                metadata_path.display(),
                manifest_path.display()
            );
        }
        if entry.name != planned.name || stored.metadata.source_task != task.env {
            bail!(
                "policy {} was trained on {}, but the config puts {} on {}; retrain the library \
                 with `sapnet sources --retrain` or use another --library",
                metadata_path.display(),
                stored.metadata.source_task.label(),
                planned.name,
                task.label
            );
        }
        sources.push(SourcePolicy {
            description: PolicyDescription {
                hidden: stored.metadata.architecture.hidden.clone(),
                activation: stored.metadata.activation.clone(),
                source_task: task.label.clone(),
            },
            final_score: stored.metadata.final_score,
            net: stored.net,
            name: entry.name.clone(),
        });
    }
    Ok(sources)
}

/// The library of `config`, trained first (or its training finished) if `root` allows it
/// and `<library>/<task>/` holds none or an unfinished one, with progress on stderr
/// (`stop` ends it), then loaded.
pub fn ensure_library(
    config: &Config,
    root: &LibraryRoot,
    stop: &Receiver<Command>,
) -> Result<Vec<SourcePolicy>> {
    let dir = library_dir(&root.path, config);
    let unfinished = match manifest::read(&dir)? {
        Some(found) => !found.complete,
        None => policy_files(&dir)?.is_empty(),
    };
    if unfinished {
        let state = if dir.exists() {
            "an unfinished source library"
        } else {
            "no source library"
        };
        if !root.train_if_missing {
            bail!(
                "{state} in {}: train it with `sapnet sources --config <FILE> --library {}`, \
                 or pass --train-library to train it before this run",
                dir.display(),
                root.path.display()
            );
        }
        eprintln!(
            "{state} in {}: training {} source policies first ({} episodes each)",
            dir.display(),
            config.sources.count,
            config.sources.training_episodes
        );
        train_library(config, &root.path, false, stop)?;
    }
    load_library(config, &root.path)
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
