//! Reading a library for reuse: whole, of the config's tasks, fitting the target; or
//! trained first where that is allowed; and each source tested on the target.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::manifest::{self, LibraryTraining};
use super::{library_dir, plan, policy_files, InterTaskMapping, SourcePlan, SourceTask, Spaces};
use crate::config::Config;
use crate::policy_store;
use crate::sapnet::PolicyDescription;
use crate::seeds;
use crate::trainer::SourcePolicy;

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
    let seed = seeds::derive(config.seed, &[seeds::Part::Name("evaluate sources")]);
    sources
        .iter()
        .map(|source| {
            let mut env = crate::env::make(&config.env)?;
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
/// no policy beside them; every policy must fit the target task's sizes. The policies
/// imported into it (`sapnet sources import`) come after the planned ones.
pub fn load_library(config: &Config, library: &Path) -> Result<Vec<SourcePolicy>> {
    let dir = library_dir(library, config);
    if dir.is_dir() {
        super::import::recover(&dir)?;
    }
    let found = read_manifest(&dir, library)?;
    let wanted = LibraryTraining::of(config);
    check_against_config(config, &dir, &found, &wanted)?;
    let (observation_size, action_count) = crate::env::spaces(&config.env)?;
    let target = Spaces {
        observation_size,
        action_count,
    };
    let fits = task_spaces(&dir, &wanted, target)?;
    let mut sources = Vec::with_capacity(found.policies.len() + found.imported.len());
    for (entry, planned) in found.policies.iter().zip(&plan(config)) {
        let task = &wanted.tasks[planned.task];
        sources.push(planned_source(
            &dir,
            entry,
            planned,
            task,
            fits[planned.task],
            target,
        )?);
    }
    // An imported policy's category is the task it was imported for, named as the config
    // names that task.
    for entry in &found.imported {
        sources.push(imported_source(&dir, entry, &wanted, target)?);
    }
    Ok(sources)
}

/// The library's manifest; without one, what to do: train the library, or check the
/// policies an older sapnet left against the config.
fn read_manifest(dir: &Path, library: &Path) -> Result<manifest::Manifest> {
    let Some(found) = manifest::read(dir)? else {
        let on_disk = policy_files(dir)?;
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
    Ok(found)
}

/// The library is the config's: its tasks and their mappings, finished, of
/// `sources.count`, and nothing on disk that its manifest does not list (settings that
/// differ only warn: the library is reused as it is).
fn check_against_config(
    config: &Config,
    dir: &Path,
    found: &manifest::Manifest,
    wanted: &LibraryTraining,
) -> Result<()> {
    let manifest_path = manifest::path(dir);
    let trained = |tasks: &[SourceTask]| -> Vec<SourceTask> {
        tasks.iter().map(SourceTask::trained).collect()
    };
    if trained(&found.training.tasks) != trained(&wanted.tasks) {
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
    // The mapping says how a source is reused, not how it was trained: a library and a
    // config that declare different ones are told apart, and neither needs retraining.
    for (i, (theirs, ours)) in found.training.tasks.iter().zip(&wanted.tasks).enumerate() {
        if theirs.mapping != ours.mapping {
            let text = |m: &Option<InterTaskMapping>| {
                m.as_ref()
                    .map_or("none".to_string(), InterTaskMapping::summary)
            };
            bail!(
                "the library {} declares the mapping of {} as {} (training.tasks[{i}].mapping \
                 in {}), the config's sources.tasks[{i}].mapping as {}: make them the same \
                 (the mapping does not change the policies, so no retraining is needed)",
                dir.display(),
                ours.label,
                text(&theirs.mapping),
                manifest_path.display(),
                text(&ours.mapping)
            );
        }
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
    if let Some(stray) = policy_files(dir)?.into_iter().find(|name| {
        !found
            .policies
            .iter()
            .chain(&found.imported)
            .any(|e| &e.name == name)
    }) {
        bail!(
            "{} holds policy {stray}, which its manifest {} does not list: remove it, or \
             retrain the library with `sapnet sources --retrain`",
            dir.display(),
            manifest_path.display()
        );
    }
    Ok(())
}

/// Each source task's spaces, checked once against the target's through its mapping.
fn task_spaces(dir: &Path, wanted: &LibraryTraining, target: Spaces) -> Result<Vec<Spaces>> {
    let mut fits = Vec::with_capacity(wanted.tasks.len());
    for (i, task) in wanted.tasks.iter().enumerate() {
        let spaces = match &task.mapping {
            None => target,
            Some(_) => {
                let (observation_size, action_count) = crate::env::spaces(&task.env)?;
                Spaces {
                    observation_size,
                    action_count,
                }
            }
        };
        super::check_fit(
            &format!("sources.tasks[{i}]"),
            task.mapping.as_ref(),
            spaces,
            target,
        )
        .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
        fits.push(spaces);
    }
    Ok(fits)
}

/// A policy's files, loaded for `spaces` and checked against the hashes the manifest
/// records.
fn load_checked(
    dir: &Path,
    entry: &manifest::ManifestEntry,
    spaces: Spaces,
) -> Result<policy_store::StoredPolicy> {
    let stored = policy_store::load_for_task(
        dir,
        &entry.name,
        spaces.observation_size,
        spaces.action_count,
    )?;
    let metadata_path = policy_store::paths(dir, &entry.name).1;
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
            manifest::path(dir).display()
        );
    }
    Ok(stored)
}

/// A planned source: trained on its task as the config says, mapped to the target.
fn planned_source(
    dir: &Path,
    entry: &manifest::ManifestEntry,
    planned: &SourcePlan,
    task: &SourceTask,
    spaces: Spaces,
    target: Spaces,
) -> Result<SourcePolicy> {
    let mut stored = load_checked(dir, entry, spaces)?;
    let metadata_path = policy_store::paths(dir, &entry.name).1;
    if entry.name != planned.name || stored.metadata.source_task != task.env.as_recorded() {
        bail!(
            "policy {} was trained on {}, but the config puts {} on {}; retrain the library \
             with `sapnet sources --retrain` or use another --library",
            metadata_path.display(),
            stored.metadata.source_task.label(),
            planned.name,
            task.label
        );
    }
    if let Some(mapping) = &task.mapping {
        stored.net = mapping
            .translate(&stored.net, target)
            .with_context(|| format!("mapping {} to the target", metadata_path.display()))?;
    }
    Ok(SourcePolicy::new(
        entry.name.clone(),
        stored.net,
        PolicyDescription {
            hidden: stored.metadata.architecture.hidden.clone(),
            activation: stored.metadata.activation.clone(),
            source_task: task.label.clone(),
        },
        stored.metadata.final_score,
    )?)
}

/// An imported source, its category the config's name of the task it was imported for.
fn imported_source(
    dir: &Path,
    entry: &manifest::ManifestEntry,
    wanted: &LibraryTraining,
    target: Spaces,
) -> Result<SourcePolicy> {
    let stored = load_checked(dir, entry, target)?;
    let recorded = &stored.metadata.source_task;
    let label = wanted
        .tasks
        .iter()
        .find(|t| &t.env.as_recorded() == recorded)
        .map_or_else(|| recorded.label(), |t| t.label.clone());
    Ok(SourcePolicy::new(
        entry.name.clone(),
        stored.net,
        PolicyDescription {
            hidden: stored.metadata.architecture.hidden.clone(),
            activation: stored.metadata.activation.clone(),
            source_task: label,
        },
        stored.metadata.final_score,
    )?)
}

/// Whether the library of `config` under `library` is missing or its training unfinished
/// (a library without a manifest but with policies is not: loading it says what to do).
pub fn needs_training(config: &Config, library: &Path) -> Result<bool> {
    let dir = library_dir(library, config);
    Ok(match manifest::read(&dir)? {
        Some(found) => !found.complete,
        None => policy_files(&dir)?.is_empty(),
    })
}
