//! Training a library: one source at a time, each on disk and in the manifest as soon as
//! it is trained, resumed after a kill.

use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;

use anyhow::{bail, Context, Result};

use super::manifest::{self, LibraryTraining, Manifest, ManifestEntry};
use super::{
    library_dir, load_library, needs_training, plan, policy_files, tasks, LibraryRoot, SourcePlan,
};
use crate::config::Config;
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::trainer::{schedule, Observer};
use crate::trainer::{Command, Event, RunOutcome, RunSpec, SourcePolicy, TrainerError};

/// The library of `config`, trained first (or its training finished) if `root` allows it
/// and `<library>/<task>/` holds none or an unfinished one, with progress on stderr
/// (`stop` ends it), then loaded.
pub fn ensure_library(
    config: &Config,
    root: &LibraryRoot,
    stop: &Receiver<Command>,
) -> Result<Vec<SourcePolicy>> {
    let dir = library_dir(&root.path, config);
    if needs_training(config, &root.path)? {
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
    crate::trainer::memory::check(&specs, 1)?;
    crate::safe_io::real_dir(&dir)
        .with_context(|| format!("the library folder {}", dir.display()))?;
    // One trainer per library: a second `sapnet sources` (or a run training a missing
    // library) into the same folder is refused while this one trains.
    let _lock = crate::folder_lock::FolderLock::acquire(&dir, "library training")?;
    // What a killed import or save left is finished first, and said.
    super::import::recover_locked(&dir)?;
    // Policies imported from elsewhere are not the config's to replace: they stay, listed
    // as they were, whatever is trained again.
    let imported = manifest::read(&dir)?
        .map(|m| m.imported)
        .unwrap_or_default();
    if let Some(found) = manifest::read(&dir)?.filter(|m| m.complete && m.training == training) {
        if !retrain {
            // Asked for what is there: a notice, not an error.
            eprintln!(
                "{} already holds the {} policies this config describes: nothing to train \
                 (--retrain trains them again)",
                dir.display(),
                found.policies.len()
            );
            return Ok(dir);
        }
    }
    let kept = resumable(&dir, &training, &plans, retrain)?;
    crate::policy_store::remove_temporaries(&dir)
        .with_context(|| format!("removing a killed save's leftovers from {}", dir.display()))?;
    let mut manifest = Manifest {
        complete: false,
        training,
        policies: kept,
        imported,
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

    let mut progress = crate::progress::Progress::new(
        u64::from(config.sources.training_episodes) * todo.len() as u64,
        crate::progress::Unit::Episodes,
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
    remove_unplanned(&dir, &plans, &manifest.imported)?;
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
    progress: &mut crate::progress::Progress,
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
        source_task: spec.env.as_recorded(),
        training: TrainingBudget {
            episodes: u64::from(outcome.record.episodes),
            steps: outcome.record.steps,
        },
        seed: source.seed,
        final_score: (!returns.is_empty())
            .then(|| returns.iter().sum::<f64>() / returns.len() as f64),
        reused: None,
        origin: None,
    };
    policy_store::save(dir, &source.name, &outcome.net, &info)
        .with_context(|| format!("writing {} to {}", source.name, dir.display()))?;
    Ok(Some(ManifestEntry::of_policy(dir, &source.name)?.0))
}

/// Removes the policies in `dir` that neither `plans` nor `imported` name.
fn remove_unplanned(dir: &Path, plans: &[SourcePlan], imported: &[ManifestEntry]) -> Result<()> {
    for stale in policy_files(dir)?.iter().filter(|name| {
        !plans.iter().any(|p| &p.name == *name) && !imported.iter().any(|e| &e.name == *name)
    }) {
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
                    training.all_differences(&found.training).join("; ")
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

/// Progress of one source's training, and its outcome.
struct SourceTraining<'a> {
    progress: &'a mut crate::progress::Progress,
    outcome: Option<RunOutcome>,
}

impl Observer for SourceTraining<'_> {
    fn on_event(&mut self, event: Event) -> Result<()> {
        match event {
            Event::RunStarted { method, budget, .. } => {
                let planned = match budget {
                    crate::config::Budget::Episodes(n) => u64::from(n),
                    crate::config::Budget::Steps(n) => n,
                };
                self.progress.run_started(method.label(), 0, planned)
            }
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
